"""Reading recording files: formats, columns, units, damaged files."""

import os
import signal
import threading

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ecofmaps._interrupts import interrupts_stop_writes
from ecofmaps.io.recording_types import RecordingError, RecordingWarning
from ecofmaps.io.recordings import _options, read_recording, recording_blocks
from ecofmaps.io.text import LINE_BYTES, text_blocks
from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.paper import EXAMPLE_2
from tests.recordings import write_csv


@pytest.fixture(scope="module")
def recording():
    """Four whole cycles of the model (Example 2), 200 samples each: Δ [m], Q [N]."""
    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=5)
    return displacement[:801], force[:801]


# --- reading files ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("suffix", "separator"),
    [(".csv", ","), (".tsv", "\t"), (".txt", "  "), (".csv", ";"), (".csv", "\t"), (".dat", " ")],
)
def test_read_formats(tmp_path, recording, suffix, separator):
    """CSV, TSV and whitespace-separated text read the same samples, in SI units; the
    separator is found from the header whatever the suffix (a ';' or tab '.csv')."""
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
        ("displacement,force\n1,2\n3,4x\n", 3, "non-numeric value '4x' in column 'force'"),
        ("displacement;force\n1,5;2\n3,5;4;5\n", 3, "3 fields where the header has 2"),
        ("displacement\tforce\n1\t2\n3\n", 3, "1 fields where the header has 2"),
        ("displacement force\n1 2\n3\n", 3, "1 fields where the header has 2"),
        ("displacement,force\n1,2\n3,4,5\n", 3, "3 fields where the header has 2"),
        ("# only\n\ndistance,force\n1,2\n", 3, "no displacement column 'displacement'"),
        ("displacement,force\n", 1, "no data after the header"),
        ("# nothing here\n", 1, "no header line and no data"),
        ("1,2\n3,4\n", 1, "the first line holds numbers, not column names"),
        ("displacement,Force [N],force_kN\n1,2,3\n", 1, "several force columns match 'force'"),
        ("a,force\n1,2\n", 1, r"no displacement column 'displacement' .*\(columns: 'a', 'force'\)"),
        (
            "force [V],displacement\n1,2\n",
            1,
            "is in 'V', which is not a force unit; give force_unit",
        ),
        ("displacement,force,cycle N,cycle kN\n1,2,3,4\n", 1, "several cycle columns match"),
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


# --- what labs' files look like --------------------------------------------------------------


def read_bytes(tmp_path, content: bytes, name="messy.csv", **options):
    path = tmp_path / name
    path.write_bytes(content)
    return read_recording(path, **options)


def test_semicolon_and_decimal_comma_csv(tmp_path):
    """A European spreadsheet export: ';' separated, decimal comma, quoted cells."""
    content = 'Zeit;"displacement";force\n0;1,25;-3,5\n1;"-0,75";"2,0E+1"\n2;,5;7\n'
    read = read_bytes(tmp_path, content.encode())
    np.testing.assert_array_equal(read.displacement, np.array([1.25, -0.75, 0.5]) / 1e6)
    np.testing.assert_array_equal(read.force, [-3.5, 20.0, 7.0])


def test_decimal_comma_found_after_integer_lines(tmp_path):
    """Lines of integers decide nothing; the first decimal comma in a later block does."""
    lines = ["displacement;force"] + ["1;2"] * 50 + ["1,5;2,25"]
    path = tmp_path / "late.csv"
    path.write_text("\n".join(lines) + "\n")
    read = read_recording(path, block_bytes=64)
    assert read.force[-1] == 2.25 and read.displacement[-1] == 1.5e-6
    assert read.last_line == 52


def test_tab_csv_crlf_bom_and_quotes(tmp_path):
    """A tab-separated '.csv' with a UTF-8 byte-order mark, CRLF line ends, quoted numbers."""
    content = '\ufeff"displacement"\t"force"\r\n"1.25"\t"-3.5"\r\n2\t4\r\n'.encode()
    read = read_bytes(tmp_path, content)
    np.testing.assert_array_equal(read.displacement, [1.25e-6, 2e-6])
    np.testing.assert_array_equal(read.force, [-3.5, 4.0])
    assert read.last_line == 3
    assert read.columns == {"displacement": "displacement", "force": "force"}


def test_quoted_comma_decimals_in_a_semicolon_file(tmp_path):
    read = read_bytes(tmp_path, b'"displacement";"force"\n"1,5";"2,5"\n"-1,5";"-2,5"\n')
    np.testing.assert_array_equal(read.force, [2.5, -2.5])


def test_latin1_byte_is_read_with_a_warning(tmp_path):
    """An old rig PC's 'µm' in Latin-1: read as such, with a warning naming file and line;
    the unit in the header is understood."""
    content = "# Prüfstand 3\ndisplacement [µm];force [N]\n1,5;2\n".encode("latin-1")
    with pytest.warns(RecordingWarning, match=r"messy.csv, line 1: byte 0xfc is not UTF-8"):
        read = read_bytes(tmp_path, content)
    assert read.displacement[0] == 1.5e-6
    assert read.units == {"displacement": "µm", "force": "N"}


def test_latin1_byte_in_a_later_block_names_its_line(tmp_path):
    lines = ["displacement,force"] + ["1,2"] * 30 + ["3,4 # \xb0C"]
    with (
        pytest.warns(RecordingWarning, match=r"line 32: byte 0xb0"),
        pytest.raises(RecordingError, match="line 32: non-numeric value '4 # °C'"),
    ):
        read_bytes(tmp_path, "\n".join(lines).encode("latin-1"), block_bytes=40)


def test_utf16_export(tmp_path):
    """A spreadsheet's 'Unicode text' export: UTF-16 with a byte-order mark, tabs."""
    content = "displacement (µm)\tforce (kN)\r\n1,5\t0,25\r\n".encode("utf-16")
    read = read_bytes(tmp_path, content, name="export.txt")
    assert (read.displacement[0], read.force[0]) == (1.5e-6, 250.0)


@pytest.mark.parametrize(
    ("header", "displacement_factor", "force_factor"),
    [
        ("delta_mm,Ftr_kN", 1e-3, 1e3),
        ("displacement [m],force [N]", 1.0, 1.0),
        ("displacement (um),force (mN)", 1e-6, 1e-3),
        ("Displacement/µm,Force/kN", 1e-6, 1e3),
        ("disp [micron],F / N", 1e-6, 1.0),
        ("Displacement_um,Force N", 1e-6, 1.0),
    ],
)
def test_units_carried_by_column_names(tmp_path, header, displacement_factor, force_factor):
    """The unit in a column's name is used when no unit option is given; the default
    names match whatever unit follows them."""
    path = tmp_path / "units.csv"
    path.write_text(f"{header}\n2,3\n-4,5\n")
    names = [name.strip() for name in header.split(",")]
    d_name = "displacement" if names[0].lower().startswith("displacement") else names[0]
    f_name = "force" if names[1].lower().startswith("force") else names[1]
    if d_name.startswith("disp "):
        d_name = "disp"
    read = read_recording(path, displacement_column=d_name, force_column=f_name)
    np.testing.assert_allclose(read.displacement, np.array([2.0, -4.0]) * displacement_factor)
    np.testing.assert_allclose(read.force, np.array([3.0, 5.0]) * force_factor)
    assert read.columns["displacement"] == names[0]


def test_unit_option_and_carried_unit(tmp_path):
    """An option that agrees with the header is fine; one that disagrees is an error naming
    both; an option overrules a unit of another kind (a raw channel in volts)."""
    path = tmp_path / "units.csv"
    path.write_text("displacement [mm],force [V]\n2,3\n")
    read = read_recording(path, displacement_unit="mm", force_unit="kN")
    assert (read.displacement[0], read.force[0]) == (2e-3, 3e3)
    with pytest.raises(
        RecordingError, match=r"line 1: the displacement column .* is in 'mm', but "
    ):
        read_recording(path, displacement_unit="um", force_unit="N")
    with pytest.raises(RecordingError, match="force_unit"):
        read_recording(path)


def test_the_same_column_twice(tmp_path):
    path = tmp_path / "same.csv"
    path.write_text("displacement,force\n1,2\n")
    with pytest.raises(RecordingError, match="line 1: the displacement and force columns are the"):
        read_recording(path, force_column="Displacement")


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("displacement_unit", "N", "displacement_unit='N' is not a length unit"),
        ("force_unit", "mm", "force_unit='mm' is not a force unit"),
        ("force_unit", "", "force_unit must be a non-empty string"),
        ("nan_policy", "omit", "nan_policy must be one of"),
        ("displacement_column", None, "displacement_column must be a column name"),
        ("group", "Rig", r"group \(--group\) applies to TDMS, .*, not to text: .*loops.csv"),
        ("lazy", "yes", "lazy must be True, False or None"),
        ("chunks", 0, "chunks must be a positive integer"),
        ("chunks", 2.5, "chunks must be a positive integer"),
        ("block_bytes", "big", "block_bytes must be a positive integer"),
    ],
)
def test_bad_options_name_the_option(tmp_path, recording, option, value, message):
    path = write_csv(tmp_path / "loops.csv", *recording)
    with pytest.raises(ValueError, match=message) as raised:
        read_recording(path, **{option: value})
    assert not isinstance(raised.value, RecordingError)


MISSING_CELLS = "displacement;force\n1;2\n2;\n3;nan\n# a note\n4;NA\n;5\n6;inf\n7;8\n"


def test_missing_samples_are_nan_with_their_lines(tmp_path):
    """Empty cells, NaN, NA and infinities are missing samples: NaN, with their lines."""
    read = read_bytes(tmp_path, MISSING_CELLS.encode())
    assert read.size == 7
    np.testing.assert_array_equal(read.missing, [0, 1, 1, 1, 1, 1, 0])
    np.testing.assert_array_equal(read.line(np.flatnonzero(read.missing)), [3, 4, 6, 7, 8])
    assert np.isnan(read.displacement[4]) and np.isnan(read.force[[1, 2, 3, 5]]).all()
    assert read.force[6] == 8.0 and read.last_line == 9
    assert read.position(6) == 9
    assert str(read.error("too few", 4)) == f"{read.path}, line 7: too few"


@pytest.mark.parametrize(
    ("content", "line", "message"),
    [
        (MISSING_CELLS, 3, "missing value '' in column 'force'"),
        ("displacement,force\n1,2\n3,nan\n", 3, "missing value 'nan' in column 'force'"),
        ("displacement,force\n1,2\n3,-inf\n", 3, "non-finite value '-inf' in column 'force'"),
        ("displacement force cycle\n1 2 1\n3 4 NA\n", 3, "missing value 'NA' in column 'cycle'"),
    ],
)
def test_nan_policy_raise_names_the_line(tmp_path, content, line, message):
    with pytest.raises(RecordingError, match=message) as raised:
        read_bytes(tmp_path, content.encode(), nan_policy="raise")
    assert raised.value.line == line


def test_crlf_and_comments_keep_line_numbers(tmp_path):
    """CRLF ends, comments and blank lines anywhere: every sample keeps its line."""
    content = "# a\r\n\r\ndisplacement,force\r\n1,2\r\n# b\r\n\r\n3,4\r\n  \r\n5,x\r\n"
    with pytest.raises(RecordingError, match="line 9: non-numeric value 'x'"):
        read_bytes(tmp_path, content.encode())
    read = read_bytes(tmp_path, content.replace("5,x", "5,6").encode())
    np.testing.assert_array_equal(read.line([0, 1, 2]), [4, 7, 9])


@pytest.mark.parametrize(
    ("block_bytes", "samples"), [(16, 150), (50, 300), (333, 801), (4096, 801)]
)
def test_blocks_give_the_same_arrays_as_the_whole(tmp_path, recording, block_bytes, samples):
    """Parsing in blocks of any size (cut inside the header, between comments) gives the
    same arrays and lines as reading the file whole, and the same errors."""
    displacement, force = (array[:samples] for array in recording)
    lines = ["# rig 3", "", "cycle;displacement [mm];force [kN]"]
    for i, (d, f) in enumerate(zip(displacement, force, strict=True)):
        lines.append(f"{i // 200};{float(d) * 1e3!r};{float(f) / 1e3!r}".replace(".", ","))
        if i % 97 == 0:
            lines.append("# a note")
    path = tmp_path / "blocks.csv"
    path.write_text("\n".join(lines) + "\n")
    whole = read_recording(path)
    read = read_recording(path, block_bytes=block_bytes)
    for name in ("displacement", "force", "cycle"):
        np.testing.assert_array_equal(getattr(read, name), getattr(whole, name))
    np.testing.assert_allclose(whole.displacement, displacement, rtol=1e-15)
    np.testing.assert_allclose(whole.force, force, rtol=1e-15)
    everywhere = np.arange(read.size)
    np.testing.assert_array_equal(read.line(everywhere), whole.line(everywhere))
    assert read.last_line == whole.last_line == len(lines)
    blocks = list(recording_blocks(path, samples=123, block_bytes=block_bytes))
    assert [b.start for b in blocks] == list(range(0, read.size, 123))
    np.testing.assert_array_equal(np.concatenate([b.force for b in blocks]), whole.force)
    np.testing.assert_array_equal(
        np.concatenate([b.line(np.arange(b.size)) for b in blocks]), whole.line(everywhere)
    )
    assert blocks[-1].last_line == whole.last_line
    damaged = path.read_text().splitlines()
    bad = len(damaged) - 20
    damaged[bad] = damaged[bad].replace(";", ";x", 1)
    path.write_text("\n".join(damaged) + "\n")
    with pytest.raises(RecordingError, match=f"line {bad + 1}: non-numeric value 'x"):
        read_recording(path, block_bytes=block_bytes)
    with pytest.raises(RecordingError, match=f"line {bad + 1}: non-numeric value 'x"):
        list(recording_blocks(path, samples=50, block_bytes=block_bytes))


def test_lazy_text_and_slices(tmp_path, recording):
    """lazy=True wraps the parsed arrays in dask; a slice keeps the file's lines."""
    path = write_csv(tmp_path / "loops.csv", *recording)
    read = read_recording(path, lazy=True, chunks=100)
    assert read.lazy and read.displacement.chunks[0][0] == 100
    part = read[150:160]
    assert not part.lazy and part.start == 150 and part.size == 10
    assert part.line(0) == 153 and part.last_line == 162
    np.testing.assert_array_equal(part.force, read.compute().force[150:160])
    assert not read.missing.compute().any()


FINITE = st.floats(allow_nan=False, allow_infinity=False, width=64)


@given(
    values=st.lists(st.tuples(FINITE, FINITE), min_size=1, max_size=40),
    separator=st.sampled_from([",", ";", "\t", " "]),
    comma=st.booleans(),
    quoted=st.booleans(),
    newline=st.sampled_from(["\n", "\r\n"]),
    notes=st.sets(st.integers(0, 40), max_size=5),
    block_bytes=st.integers(1, 300),
)
@settings(suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_text_round_trip(tmp_path, values, separator, comma, quoted, newline, notes, block_bytes):
    """Any float64 written as repr, in any of the styles labs' files come in (decimal comma
    when the separator allows it, quotes, CRLF, comment lines anywhere), reads back bit for
    bit, each sample with its line, whatever the block size."""
    comma = comma and separator != ","
    quote = '"' if quoted and separator != " " else ""

    def cell(value):
        text = repr(value).replace(".", ",") if comma else repr(value)
        return f"{quote}{text}{quote}"

    lines, numbers = [f"displacement [m]{separator}force [N]"], []
    for k, (d, f) in enumerate(values):
        if k in notes:
            lines.append("# a note, with: separators; inside")
        lines.append(f"{cell(d)}{separator}{cell(f)}")
        numbers.append(len(lines))
    path = tmp_path / "round.csv"
    path.write_bytes(newline.join(lines).encode() + newline.encode())
    read = read_recording(path, block_bytes=block_bytes)
    displacement, force = (np.array(column) for column in zip(*values, strict=True))
    np.testing.assert_array_equal(read.displacement.view(np.int64), displacement.view(np.int64))
    np.testing.assert_array_equal(read.force.view(np.int64), force.view(np.int64))
    np.testing.assert_array_equal(read.line(np.arange(read.size)), numbers)


# --- inputs that never end ---------------------------------------------------------------


def read_in_a_thread(path, **options):
    """What read_recording(path) raises, from a thread given a minute (an unguarded read of a
    pipe blocks until a writer comes, and would hang the test rather than fail it)."""
    caught = []

    def reading():
        try:
            read_recording(path, **options)
        except Exception as error:  # the one to check
            caught.append(error)

    thread = threading.Thread(target=reading, daemon=True)
    thread.start()
    thread.join(60)
    assert not thread.is_alive(), f"reading {path} did not return"
    return caught[0] if caught else None


def test_a_pipe_or_a_device_is_refused_by_name(tmp_path):
    fifo = tmp_path / "rig.csv"
    os.mkfifo(fifo)
    error = read_in_a_thread(fifo)
    assert isinstance(error, RecordingError)
    assert str(error).startswith(f"{fifo}: a named pipe (FIFO), not a regular file")
    error = read_in_a_thread("/dev/null")
    assert isinstance(error, RecordingError)
    assert str(error).startswith("/dev/null: a character device, not a regular file")


@pytest.mark.parametrize("newline", [True, False])
def test_a_line_longer_than_the_bound_is_refused_at_that_line(tmp_path, newline):
    """Refused at its line whether it ends within the block read or goes on past it, and
    whether it is many blocks long or fits in one."""
    path = tmp_path / "long.csv"
    line = b"1" * (LINE_BYTES + 1) + b",2" + (b"\n" if newline else b"")
    path.write_bytes(b"displacement,force\n1,2\n# a note\n3,4\n" + line + b"5,6\n" * 10)
    for block_bytes in (1 << 16, 1 << 24):
        with pytest.raises(RecordingError) as refused:
            read_recording(path, block_bytes=block_bytes)
        assert str(refused.value).startswith(f"{path}, line 5: a line longer than 1048576 bytes")
    path.write_bytes(b"displacement,force\n1,2\n#" + b"-" * (LINE_BYTES - 1) + b"\n3,4\n")
    assert read_recording(path).size == 2  # a line of the bound itself is read


def test_a_stop_signal_is_honoured_between_blocks_while_parsing(tmp_path):
    path = tmp_path / "rig.csv"
    path.write_bytes(b"displacement,force\n" + b"1.5,2.5\n" * 20000)
    blocks = text_blocks(path, _options(), block_bytes=1 << 12)
    with pytest.raises(KeyboardInterrupt), interrupts_stop_writes():
        next(blocks)  # the header
        next(blocks)
        os.kill(os.getpid(), signal.SIGTERM)
        for _ in blocks:
            pass
    blocks.close()


def test_cells_and_names_beyond_the_csv_field_limit_are_read_or_named_cut(tmp_path):
    """A cell or a column name longer than the csv module's field limit (131072 characters)
    is no error of its own: a long name is an extra column, a long cell a value named (cut)
    at its line."""
    named = tmp_path / "named.csv"
    named.write_text('displacement,force,"' + "x" * 200_000 + '"\n1,2,3\n4,5,6\n')
    assert read_recording(named).force.tolist() == [2.0, 5.0]
    cell = tmp_path / "cell.csv"
    cell.write_text('displacement,force\n1,2\n3,"' + "1x" * 250_000 + '"\n')
    with pytest.raises(RecordingError) as raised:
        read_recording(cell)
    assert str(raised.value) == (
        f"{cell}, line 3: non-numeric value '{'1x' * 18}... in column 'force'"
    )
