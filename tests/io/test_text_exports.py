"""Text exports as instruments write them: preambles, quotes, decimal commas, separators,
gzip, line ends, a recorded normal load, and the usual column names."""

import gzip

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ecofmaps.cli.main import main
from ecofmaps.io.recording_types import RecordingError
from ecofmaps.io.recordings import read_recording, recording_blocks

PREAMBLE = "Test: 42\nDate: 2024-05-01 10:32\nOperator, J. Smith\n\n"


def write(tmp_path, content, name="export.csv"):
    """A file of ``content`` (text as UTF-8, or bytes as they are)."""
    path = tmp_path / name
    path.write_bytes(content.encode() if isinstance(content, str) else content)
    return path


# --- the four header lines refused before ----------------------------------------------------


@pytest.mark.parametrize(
    ("header", "displacement_scale", "force_scale"),
    [
        ("delta_mm,Ftr_kN", 1e-3, 1e3),
        ("Disp [um],Fx [N]", 1e-6, 1.0),
        ("Displacement (mm),Tangential force (kN)", 1e-3, 1e3),
        ("stroke_um,friction_force_N", 1e-6, 1.0),
    ],
)
def test_rig_headers_are_read_in_their_units(tmp_path, header, displacement_scale, force_scale):
    path = write(tmp_path, f"{header}\n0.025,0.5\n-0.025,-0.5\n")
    read = read_recording(path)
    np.testing.assert_allclose(read.displacement, np.array([0.025, -0.025]) * displacement_scale)
    np.testing.assert_allclose(read.force, np.array([0.5, -0.5]) * force_scale)
    assert list(read.columns.values()) == [name.strip() for name in header.split(",")]


def test_delta_mm_is_millimetres(tmp_path):
    """``delta_mm`` values are x1e-3 m exactly as typed: 0.05 mm is the float nearest 5e-5."""
    read = read_recording(write(tmp_path, "time_s,delta_mm,Ftr_kN\n0,0.05,0.3\n1,-0.05,-0.3\n"))
    assert read.displacement.tolist() == [5e-5, -5e-5]
    assert read.force.tolist() == [300.0, -300.0]
    assert read.units == {"displacement": "mm", "force": "kN"}


def test_two_candidates_are_an_error_naming_both(tmp_path):
    path = write(tmp_path, "x [mm],Disp [um],Fx [N]\n1,2,3\n")
    with pytest.raises(RecordingError, match="'x \\[mm\\]', 'Disp \\[um\\]'; choose one with") as e:
        read_recording(path)
    assert e.value.line == 1 and "--displacement-col" in str(e.value)
    assert read_recording(path, displacement_column="Disp").displacement[0] == 2e-6


def test_no_candidate_suggests_the_nearest(tmp_path):
    path = write(tmp_path, "Dsplacemnt [um],Fx [N]\n1,2\n")
    with pytest.raises(RecordingError, match="Did you mean 'Dsplacemnt \\[um\\]'\\?") as e:
        read_recording(path)
    assert "(columns: 'Dsplacemnt [um]', 'Fx [N]')" in str(e.value)


def test_an_explicit_name_is_matched_as_it_is(tmp_path):
    """A name given by the user finds no synonym: ``disp`` does not find ``delta_mm``."""
    path = write(tmp_path, "delta_mm,Ftr_kN\n1,2\n")
    with pytest.raises(RecordingError, match="no displacement column 'disp' \\(columns:"):
        read_recording(path, displacement_column="disp")


# --- preambles ---------------------------------------------------------------------------------


def test_a_preamble_before_the_header_is_found(tmp_path):
    path = write(tmp_path, PREAMBLE + "# channels\nDisp [um];Fx [N]\n1;2\n\n3;4\n")
    read = read_recording(path)
    assert read.displacement.tolist() == [1e-6, 3e-6] and read.force.tolist() == [2.0, 4.0]
    assert read.line([0, 1]).tolist() == [7, 9]


def test_a_bad_cell_after_a_preamble_names_its_line(tmp_path):
    path = write(tmp_path, PREAMBLE + "displacement,force\n1,2\n3,4\n5,oops\n")
    with pytest.raises(RecordingError, match="line 8: non-numeric value 'oops'") as raised:
        read_recording(path)
    assert raised.value.line == 8


def test_numbers_in_the_preamble_are_not_the_header(tmp_path):
    """A preamble line of names and numbers (``Stroke, Frequency`` / ``50, 10``) is not
    taken for the header: the header is the line naming both columns."""
    content = "Stroke, Frequency\n50, 10\n\nDisp,Force\n1,2\n3,4\n"
    read = read_recording(write(tmp_path, content))
    assert read.columns == {"displacement": "Disp", "force": "Force"}
    assert read.line(0) == 5


def test_skip_rows(tmp_path):
    """skip_rows skips lines before the header whatever they hold; a wrong count names the
    line taken for the header."""
    path = write(tmp_path, "displacement,force\n" + PREAMBLE + "displacement,force\n1,2\n")
    read = read_recording(path, skip_rows=5)
    assert read.size == 1 and read.last_line == 7
    with pytest.raises(RecordingError, match="line 2: no displacement column"):
        read_recording(path, skip_rows=1)
    with pytest.raises(RecordingError, match="line 7: no header line and no data"):
        read_recording(path, skip_rows=7)
    with pytest.raises(ValueError, match="skip_rows must be a non-negative integer"):
        read_recording(path, skip_rows=-1)


def test_skip_rows_on_the_command_line(tmp_path, capsys):
    """A first line that looks like the header is skipped with --skip-rows only."""
    source = write(tmp_path, "delta_mm;Ftr_kN\nrig;3\n\ndelta_mm;Ftr_kN\n0,5;1,5\n")
    target = tmp_path / "converted.csv"
    assert main(["convert", str(source), str(target)]) == 2
    assert "line 2: non-numeric value 'rig'" in capsys.readouterr().err
    assert main(["convert", str(source), str(target), "--skip-rows", "2"]) == 0
    read = read_recording(target)
    assert (read.displacement[0], read.force[0]) == (5e-4, 1500.0)


# --- quotes, decimal commas, separators, line ends, gzip -------------------------------------


@pytest.mark.parametrize(
    "content",
    [
        'displacement;force\n"0,5";"1,2"\n"-1,5";"2"\n',
        'displacement,force\n"0,5","1,2"\n"-1,5",2\n',  # a comma file, quoted decimal commas
        "displacement\tforce\n0,5\t1,2\n-1,5\t2\n",
        "displacement force\n0.5   1.2\n-1.5 2\n",
        "displacement;force\r0,5;1,2\r-1,5;2\r",  # CR-only
        "displacement;force\r\n0,5;1,2\r\n-1,5;2",  # CRLF, no final line end
    ],
)
def test_dialects(tmp_path, content):
    read = read_recording(write(tmp_path, content))
    assert read.displacement.tolist() == [0.5e-6, -1.5e-6]
    assert read.force.tolist() == [1.2, 2.0]
    assert read.line([0, 1]).tolist() == [2, 3]


def test_cr_only_errors_name_the_line(tmp_path):
    path = write(tmp_path, PREAMBLE.replace("\n", "\r") + "displacement,force\r1,2\r3,x\r")
    with pytest.raises(RecordingError, match="line 7: non-numeric value 'x'"):
        read_recording(path, block_bytes=8)


@pytest.mark.parametrize("name", ["export.csv.gz", "export.txt.gz", "export.dat"])
def test_gzip_is_read_by_its_magic_bytes(tmp_path, name):
    content = PREAMBLE + "Disp [mm];Fx [kN]\n0,5;1,25\n-0,5;-1,25\n"
    path = write(tmp_path, gzip.compress(content.encode()), name)
    read = read_recording(path, block_bytes=16)
    assert read.displacement.tolist() == [5e-4, -5e-4] and read.force.tolist() == [1250, -1250]
    assert read.last_line == 7


def test_damaged_gzip_names_the_file(tmp_path):
    lines = "displacement,force\n" + "".join(f"{k},{k + 1}\n" for k in range(5000))
    data = gzip.compress(lines.encode())
    path = write(tmp_path, data[: len(data) // 2], "cut.csv.gz")
    with pytest.raises(RecordingError, match="compressed \\(gzip\\) data is truncated") as raised:
        read_recording(path, block_bytes=1024)
    assert str(raised.value).startswith(f"{path}, line ")
    path = write(tmp_path, gzip.compress(b"TDSm\x04\x00\x00\x00rest"), "rig.tdms.gz")
    with pytest.raises(RecordingError, match="a gzip-compressed TDMS file: decompress it"):
        read_recording(path)


# --- a recorded normal load --------------------------------------------------------------------


def test_load_column(tmp_path):
    path = write(tmp_path, PREAMBLE + "x [um],Fx [N],Fz [kN]\n1,2,0.45\n3,4,\n5,6,0.46\n")
    read = read_recording(path, load_column="Fz")
    np.testing.assert_array_equal(read.load, [450.0, np.nan, 460.0])
    assert read.units["load"] == "kN" and read.columns["load"] == "Fz [kN]"
    assert read.missing.tolist() == [False, True, False]
    assert read[2:3].load.tolist() == [460.0]
    assert read_recording(path, load_column="load").columns["load"] == "Fz [kN]"  # a synonym
    assert read_recording(path).load is None
    lazy = read_recording(path, load_column="fz", lazy=True)
    assert lazy[0:1].load.tolist() == [450.0]
    blocks = list(recording_blocks(path, samples=2, load_column="Fz"))
    assert [block.load.size for block in blocks] == [2, 1] and blocks[1].load[0] == 460.0
    with pytest.raises(RecordingError, match="line 5: no load column 'P'"):
        read_recording(path, load_column="P")


def test_load_in_newtons_by_default_and_not_for_rig_files(tmp_path):
    read = read_recording(write(tmp_path, "disp,Q,normal load\n1,2,450\n"), load_column="load")
    assert read.load.tolist() == [450.0] and read.units["load"] == "N"
    path = tmp_path / "rig.h5"
    with h5py.File(path, "w") as file:
        for name in ("displacement", "force", "load"):
            file[name] = np.ones(4)
    with pytest.raises(ValueError, match="load_column applies to text files"):
        read_recording(path, load_column="load")


# --- any table in any dialect ------------------------------------------------------------------

FINITE = st.floats(-1e300, 1e300, allow_nan=False, width=64)  # finite in kN and mm too


@given(
    values=st.lists(st.tuples(FINITE, FINITE), min_size=1, max_size=30),
    separator=st.sampled_from([",", ";", "\t", " "]),
    comma=st.booleans(),
    quoted=st.booleans(),
    newline=st.sampled_from(["\n", "\r\n", "\r"]),
    preamble=st.lists(
        st.sampled_from(["Test: 42", "Date: 2024-05-01", "Operator, J. Smith", "", "# rig 3"]),
        max_size=5,
    ),
    compressed=st.booleans(),
    block_bytes=st.integers(1, 200),
)
@settings(suppress_health_check=[HealthCheck.function_scoped_fixture], max_examples=60)
def test_any_dialect_reads_back(
    tmp_path, values, separator, comma, quoted, newline, preamble, compressed, block_bytes
):
    """A table written in any dialect (separator, decimal comma, quotes, line ends, a
    preamble, gzip) reads back bit for bit, each sample with its line."""
    comma = comma and (separator != "," or quoted) and separator != " "
    quote = '"' if quoted and separator != " " else ""

    def cell(value):
        text = repr(value).replace(".", ",") if comma else repr(value)
        return f"{quote}{text}{quote}"

    lines = [*preamble, f"delta_mm{separator}Ftr_kN"]
    lines += [f"{cell(d)}{separator}{cell(f)}" for d, f in values]
    content = (newline.join(lines) + newline).encode()
    path = tmp_path / ("table.csv.gz" if compressed else "table.csv")
    path.write_bytes(gzip.compress(content) if compressed else content)
    read = read_recording(path, block_bytes=block_bytes)
    displacement, force = (np.array(column) for column in zip(*values, strict=True))
    np.testing.assert_array_equal(read.displacement, displacement / 1e3)
    np.testing.assert_array_equal(read.force, force * 1e3)
    first = len(preamble) + 2
    np.testing.assert_array_equal(read.line(np.arange(read.size)), first + np.arange(read.size))
