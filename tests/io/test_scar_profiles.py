"""read_scar_profile: the shipped trace, formats, columns and units, damaged files."""

import numpy as np
import pytest

import ecofmaps
from ecofmaps.io.scar_profiles import ScarProfileError
from ecofmaps.measured.synthetic import scar_example_path, scar_example_trace
from ecofmaps.model.profiles import ScarProfileWarning


def write(path, text):
    path.write_text(text)
    return path


def trace_rows(separator=",", x_scale=1e6, z_scale=1e6):
    x, z = scar_example_trace()
    return "\n".join(
        f"{a * x_scale:.9f}{separator}{b * z_scale:.9f}" for a, b in zip(x, z, strict=True)
    )


def test_shipped_example_is_found_and_levelled():
    """The shipped trace: levelled (tilt 0.004 removed), edges at 1340 ± 500 µm, D/W 0.16."""
    profile = ecofmaps.read_scar_profile(scar_example_path())
    assert float(profile.centre) == pytest.approx(1340e-6, abs=1e-6)
    assert float(profile.half_width) == pytest.approx(500e-6, rel=2e-3)
    assert float(profile.aspect_ratio) == pytest.approx(0.16, rel=5e-3)
    assert float(profile.reference_slope) == 0.0
    raw = ecofmaps.read_scar_profile(scar_example_path(), level=False)
    assert float(raw.reference_slope) == pytest.approx(0.004, rel=2e-3)
    np.testing.assert_allclose(raw.slope - raw.reference_slope, profile.slope, atol=1e-12)


@pytest.mark.parametrize(
    ("name", "text", "options"),
    [
        ("trace.tsv", "x\tz\n" + trace_rows("\t"), {}),
        ("trace.txt", "# a comment\nX Z\n" + trace_rows(" "), {}),
        (
            "trace.dat",
            "pos_mm;height_nm\n" + trace_rows(";", 1e3, 1e9),
            dict(x_column="pos_mm", z_column="height_nm", x_unit="mm", z_unit="nm"),
        ),
    ],
)
def test_formats_columns_and_units(tmp_path, name, text, options):
    """Tabs, whitespace with comments, other names and units: the same profile."""
    profile = ecofmaps.read_scar_profile(write(tmp_path / name, text), **options)
    x, z = scar_example_trace()
    expected = ecofmaps.scar_profile(x, z, level=True)
    # the text holds nine decimals
    assert float(profile.half_width) == pytest.approx(float(expected.half_width), rel=1e-7)
    np.testing.assert_allclose(profile.slope, expected.slope, atol=1e-7)


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("x,z\n", 1, "no data after the header"),
        ("x,height\n1,2\n", 1, r"no z column 'z' \(columns: 'x', 'height'\)"),
        ("x,z\n1,2\n2,abc\n", 3, "non-numeric value 'abc' in column 'z'"),
        ("x,z\n1,2\n2,nan\n", 3, "missing value 'nan' in column 'z'"),
        ("x,z\n1,2\n2\n", 3, "1 fields where the header has 2"),
        ("x,z\n1,0\n3,0\n2,0\n", 4, "position 2.0 goes back from 3.0 on line 3"),
        ("# c\nx,z\n1,0\n1,0\n", 4, "position 1.0 repeats 1.0 on line 3"),
        ("x,z\n" + "\n".join(f"{i},0" for i in range(100)), 2, r"lines 2-101\): z: no depre"),
    ],
)
def test_damaged_files_name_the_file_and_line(tmp_path, text, line, message):
    path = write(tmp_path / "scar.csv", text)
    with pytest.raises(ScarProfileError, match=message) as caught:
        ecofmaps.read_scar_profile(path)
    assert caught.value.line == line and caught.value.path == path
    assert str(caught.value).startswith(f"{path}, line {line}: ")


def test_units_must_be_lengths(tmp_path):
    path = write(tmp_path / "scar.csv", "x,z\n1,2\n")
    with pytest.raises(ValueError, match="z_unit='N' is not a length unit"):
        ecofmaps.read_scar_profile(path, z_unit="N")


# --- instruments' exports, outliers and ambiguous edges ----------------


def stylus_export(path, separator, x_mm, z_um, header=('"Distance [mm]"', '"Profile (um)"')):
    """A stylus export: quoted names with units, quoted values with decimal commas."""
    rows = [separator.join(header)]
    pairs = zip(x_mm, z_um, strict=True)
    rows += [f'"{a:.6f}"{separator}"{b:.5f}"'.replace(".", ",") for a, b in pairs]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("separator", [",", ";"], ids=["comma", "semicolon"])
def test_quoted_decimal_comma_exports_with_units_in_the_names(tmp_path, separator):
    """ "Distance [mm]","Profile (um)" / "0,000500","-0,01200": read as the arrays."""
    x, z = scar_example_trace()
    path = stylus_export(tmp_path / "stylus.csv", separator, x * 1e3, z * 1e6)
    profile = ecofmaps.read_scar_profile(path, x_column="Distance", z_column="Profile")
    expected = ecofmaps.scar_profile(np.round(x * 1e3, 6) / 1e3, np.round(z * 1e6, 5) / 1e6,
                                     level=True)  # fmt: skip
    assert float(profile.half_width) == pytest.approx(float(expected.half_width), rel=1e-9)
    assert float(profile.depth) == pytest.approx(float(expected.depth), rel=1e-9)


def test_a_damaged_cell_of_an_export_names_the_file_and_line(tmp_path):
    x, z = scar_example_trace()
    path = stylus_export(tmp_path / "stylus.csv", ",", x * 1e3, z * 1e6)
    lines = path.read_text(encoding="utf-8").splitlines()
    lines[4] = '"0,008000","-0,0x1"'
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(ScarProfileError, match="non-numeric value '-0,0x1' in column") as caught:
        ecofmaps.read_scar_profile(path, x_column="Distance", z_column="Profile")
    assert caught.value.path == path and caught.value.line == 5


def test_a_dropout_is_replaced_and_its_line_named(tmp_path):
    """A dropout 30 µm down on line 702 of the file: replaced, the warning names the file
    and the line, and the profile is the clean trace's."""
    x, z = scar_example_trace()
    text = "x,z\n" + "\n".join(f"{a * 1e6:.1f},{b * 1e6:.4f}" for a, b in zip(x, z, strict=True))
    clean = ecofmaps.read_scar_profile(write(tmp_path / "clean.csv", text))
    lines = text.splitlines()
    a, b = (float(v) for v in lines[701].split(","))
    lines[701] = f"{a:.1f},{b - 30.0:.4f}"
    path = write(tmp_path / "dropout.csv", "\n".join(lines))
    where = rf"line 702 \(x = {a:.6g} µm, 30 µm below its neighbours\)$"
    with pytest.warns(ScarProfileWarning, match=rf"^{path}: 1 outlier\(s\) .*: {where}"):
        profile = ecofmaps.read_scar_profile(path)
    assert np.flatnonzero(np.asarray(profile.replaced)).tolist() == [700]
    assert float(profile.depth) == pytest.approx(float(clean.depth), rel=1e-4)
    assert float(profile.half_width) == pytest.approx(float(clean.half_width), rel=1e-4)


def test_ambiguous_edges_are_a_warning_naming_the_file(tmp_path):
    """A groove 31 µm in half-width inside a band 170 µm wide between ridges: the band is
    taken, the warning names the file and gives both half-widths."""
    x = np.arange(-400.0, 400.01, 0.5)  # µm
    z = np.where(np.abs(x) < 31, -3 * (1 - (x / 31) ** 2), 0.0)
    z += np.where((np.abs(x) >= 31) & (np.abs(x) < 70), 0.35 + 0.15 * np.sin(x / 1.75), 0.0)
    v = (np.abs(x) - 70) / 30  # ridges cresting at ±85 µm
    z += np.where((v > 0) & (v < 1), 1.5 * np.sin(np.pi * v) ** 2, 0.0)
    text = "x,z\n" + "\n".join(f"{a:.1f},{b:.5f}" for a, b in zip(x, z, strict=True))
    path = write(tmp_path / "track.csv", text)
    with pytest.warns(ScarProfileWarning, match=rf"^{path}: ambiguous scar edges") as caught:
        profile = ecofmaps.read_scar_profile(path)
    assert float(profile.half_width) == pytest.approx(85e-6, abs=1e-6)
    assert float(profile.alternative_half_width) == pytest.approx(31e-6, abs=1e-6)
    assert caught[0].message.alternative == float(profile.alternative_half_width)
