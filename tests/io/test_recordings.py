"""Reading recording files: formats, columns, units, damaged files."""

import numpy as np
import pandas as pd
import pytest

from ecofmaps.io.recordings import RecordingError, read_recording
from ecofmaps.measured.synthetic import synthetic_recording

POINT = dict(amplitude=50e-6, load=450.0, stiffness=35e6, mu=0.8, aspect_ratio=0.2)


@pytest.fixture(scope="module")
def recording():
    """Four whole cycles of the model (Example 2), 200 samples each: Δ [m], Q [N]."""
    displacement, force = synthetic_recording(**POINT, cycles=5)
    return displacement[:801], force[:801]


def write_csv(path, displacement, force, separator=",", header=("displacement", "force")):
    """A recording file: displacement in µm, force in N, with a comment line."""
    lines = [f"# a test recording written by {__name__}", separator.join(header)]
    lines += [f"{d * 1e6:.9f}{separator}{f:.9f}" for d, f in zip(displacement, force, strict=True)]
    path.write_text("\n".join(lines) + "\n")
    return path


# --- reading files ---------------------------------------------------------------------------


@pytest.mark.parametrize(("suffix", "separator"), [(".csv", ","), (".tsv", "\t"), (".txt", "  ")])
def test_read_formats(tmp_path, recording, suffix, separator):
    """CSV, TSV and whitespace-separated text read the same samples, in SI units."""
    displacement, force = recording
    path = write_csv(tmp_path / f"loops{suffix}", displacement, force, separator)
    read = read_recording(path)
    np.testing.assert_allclose(read.displacement, displacement, rtol=0, atol=1e-15)
    np.testing.assert_allclose(read.force, force, rtol=0, atol=1e-9)
    assert read.cycle is None
    assert read.last_line == 2 + displacement.size


def test_read_columns_units_and_cycles(tmp_path, recording):
    """Other column names (any case), units and an explicit cycle column."""
    displacement, force = recording
    table = pd.DataFrame(
        {
            "Time": np.arange(displacement.size),
            "Cycle No": np.repeat([1, 2, 3, 4, 5], [200, 200, 200, 200, 1]),
            "Disp": displacement * 1e3,  # mm
            "Q": force / 1e3,  # kN
        }
    )
    path = tmp_path / "rig.tsv"
    table.to_csv(path, sep="\t", index=False)
    read = read_recording(
        path,
        displacement_column="disp",
        force_column="q",
        cycle_column="cycle no",
        displacement_unit="mm",
        force_unit="kN",
    )
    np.testing.assert_allclose(read.displacement, displacement, rtol=1e-15)
    np.testing.assert_allclose(read.force, force, rtol=1e-15)
    np.testing.assert_array_equal(read.cycle, table["Cycle No"])


def test_default_cycle_column_is_used(tmp_path, recording):
    displacement, force = recording
    path = tmp_path / "with_cycles.csv"
    lines = ["displacement,force,cycle"]
    lines += [
        f"{float(d) * 1e6!r},{float(f)!r},{i // 200}"
        for i, (d, f) in enumerate(zip(*recording, strict=True))
    ]
    path.write_text("\n".join(lines) + "\n")
    read = read_recording(path)
    np.testing.assert_array_equal(read.cycle, np.arange(displacement.size) // 200)
    np.testing.assert_array_equal(read.force, force)  # repr round-trips exactly


@pytest.mark.parametrize(
    ("content", "line", "message"),
    [
        ("# note\ndisplacement,force\n1,2\n3,x4\n", 4, "non-numeric value 'x4' in column 'force'"),
        ("displacement,force\n1,2\n\n3,\n", 4, "non-numeric value '' in column 'force'"),
        ("displacement,force\n1,2\n3,nan\n", 3, "non-numeric value 'nan' in column 'force'"),
        ("displacement,force\n1,2\n3,4,5\n", 3, "3 fields where the header has 2"),
        ("# only\n\ndisp,force\n1,2\n", 3, "no displacement column 'displacement'"),
        ("displacement,force\n", 1, "no data after the header"),
        ("# nothing here\n", 1, "no header line and no data"),
    ],
)
def test_damaged_files_name_the_line(tmp_path, content, line, message):
    path = tmp_path / "damaged.csv"
    path.write_text(content)
    with pytest.raises(RecordingError, match=message) as raised:
        read_recording(path)
    assert raised.value.line == line
    assert str(raised.value).startswith(f"{path}, line {line}: ")


def test_missing_explicit_cycle_column(tmp_path, recording):
    path = write_csv(tmp_path / "loops.csv", *recording)
    with pytest.raises(RecordingError, match="line 2: no cycle column 'n'"):
        read_recording(path, cycle_column="n")
