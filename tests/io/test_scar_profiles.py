"""read_scar_profile: the shipped trace, formats, columns and units, damaged files."""

import numpy as np
import pytest

import ecofmaps
from ecofmaps.io.scar_profiles import ScarProfileError
from ecofmaps.measured.synthetic import scar_example_path, scar_example_trace


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
