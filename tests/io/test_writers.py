"""Writing recordings block by block, converting them, and never leaving a partial store."""

import os
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

from ecofmaps.io.binary import variables
from ecofmaps.io.files import TEMPORARY_NAME, atomic_path, atomic_store
from ecofmaps.io.recording_types import RecordingError
from ecofmaps.io.recordings import read_recording
from ecofmaps.io.writers import CHUNK_BYTES, RecordingWriter, convert_recording
from ecofmaps.measured.synthetic import example_path

RNG = np.random.default_rng(3)
SIZE = 2345
DISPLACEMENT = RNG.normal(0.0, 3e-5, SIZE)
FORCE = RNG.normal(0.0, 300.0, SIZE)
CYCLE = np.arange(SIZE) // 100 + 1


@pytest.mark.parametrize("suffix", [".zarr", ".h5", ".nc", ".tdms", ".csv"])
def test_writer_round_trip(tmp_path, suffix):
    """Blocks of any size in, the same bits out, with units; chunks as asked."""
    path = tmp_path / f"out{suffix}"
    with RecordingWriter(path, cycle=True, chunk_samples=500, attrs={"rig": "B3"}) as writer:
        for start in range(0, SIZE, 777):
            stop = start + 777
            writer.write(DISPLACEMENT[start:stop], FORCE[start:stop], CYCLE[start:stop])
    assert writer.size == SIZE
    read = read_recording(path)
    np.testing.assert_array_equal(read.displacement, DISPLACEMENT)
    np.testing.assert_array_equal(read.force, FORCE)
    np.testing.assert_array_equal(read.cycle, CYCLE)
    assert (read.units["displacement"], read.units["force"]) == ("m", "N")
    if suffix in (".zarr", ".h5"):
        kind = "zarr" if suffix == ".zarr" else "hdf5"
        assert {v.chunk for v in variables(path, kind)} == {500}
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


@pytest.mark.parametrize("suffix", [".zarr", ".nc"])
def test_stores_open_in_xarray(tmp_path, suffix):
    """The stores are ordinary xarray datasets over 'sample', with units attributes."""
    path = tmp_path / f"out{suffix}"
    with RecordingWriter(path, chunk_samples=1000) as writer:
        writer.write(DISPLACEMENT, FORCE)
    opened = xr.open_zarr(path) if suffix == ".zarr" else xr.open_dataset(path)
    with opened as dataset:
        assert dataset.force.dims == ("sample",)
        assert dataset.force.attrs["units"] == "N"
        np.testing.assert_array_equal(dataset.displacement.values, DISPLACEMENT)


def test_writer_errors_leave_nothing(tmp_path):
    path = tmp_path / "out.zarr"
    with pytest.raises(ValueError, match="one length"), RecordingWriter(path) as writer:
        writer.write(DISPLACEMENT, FORCE[:-1])
    with (
        pytest.raises(ValueError, match="cycle numbers are required"),
        RecordingWriter(path, cycle=True) as writer,
    ):
        writer.write(DISPLACEMENT, FORCE)
    with pytest.raises(ValueError, match="format must be one of"):
        RecordingWriter(tmp_path / "out.xyz")
    with pytest.raises(ValueError, match="chunk_samples must be a positive integer"):
        RecordingWriter(path, chunk_samples=0)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("suffix", [".zarr", ".h5", ".tdms", ".csv"])
def test_interrupted_writer_leaves_no_store(tmp_path, suffix):
    """An interruption after some chunks are written: no store under the name, no
    temporary left, an older store kept as it was."""
    path = tmp_path / f"out{suffix}"
    with RecordingWriter(path) as writer:
        writer.write(DISPLACEMENT[:10], FORCE[:10])
    with (
        pytest.raises(KeyboardInterrupt),
        RecordingWriter(path, chunk_samples=100, overwrite=True) as writer,
    ):
        writer.write(DISPLACEMENT, FORCE)
        assert writer.size == 2300  # whole chunks are on disk already
        raise KeyboardInterrupt
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]
    np.testing.assert_array_equal(read_recording(path).force, FORCE[:10])


def test_existing_destination_needs_overwrite(tmp_path):
    path = tmp_path / "out.zarr"
    with RecordingWriter(path) as writer:
        writer.write(DISPLACEMENT[:5], FORCE[:5])
    with pytest.raises(FileExistsError, match="overwrite=True replaces it"):
        RecordingWriter(path).__enter__()
    with RecordingWriter(path, overwrite=True) as writer:
        writer.write(DISPLACEMENT, FORCE)
    assert read_recording(path).size == SIZE
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.zarr"]


def write_text(path, rows, header="cycle;displacement [µm];force [kN]"):
    lines = [header] + [
        f"{c};{float(d) * 1e6!r};{float(f) / 1e3!r}".replace(".", ",") for c, d, f in rows
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("suffix", [".zarr", ".h5", ".tdms"])
def test_convert_csv(tmp_path, suffix):
    """A European CSV in µm and kN, converted block by block into a store in m and N."""
    source = write_text(tmp_path / "big.csv", zip(CYCLE, DISPLACEMENT, FORCE, strict=True))
    destination = convert_recording(source, tmp_path / f"big{suffix}", chunk_samples=400)
    read = read_recording(destination)
    text = read_recording(source)
    np.testing.assert_array_equal(read.displacement, text.displacement)
    np.testing.assert_array_equal(read.force, text.force)
    np.testing.assert_array_equal(read.cycle, CYCLE)
    np.testing.assert_allclose(read.force, FORCE, rtol=1e-15)
    if suffix == ".zarr":
        with xr.open_zarr(destination) as dataset:
            assert dataset.attrs["source_units"] == "displacement: µm, force: kN, cycle: 1"
            assert dataset.force.chunks[0][0] == 400


def stored_bytes(path) -> int:
    """The bytes of a file, or of the files of a store."""
    if path.is_file():
        return path.stat().st_size
    return sum(item.stat().st_size for item in path.rglob("*") if item.is_file())


#: Bytes a converted store may take besides its chunks: names, attributes, indexes.
METADATA_BYTES = 64 * 1024


@pytest.mark.parametrize("size", [8000, 300_000])
def test_converted_stores_take_the_room_of_their_samples(tmp_path, size):
    """Converted with the default chunks, a short recording is one chunk of its own length;
    a long one is chunks of CHUNK_BYTES, the last one part filled. Both read back the
    source's values."""
    source = tmp_path / "source.tdms"
    with RecordingWriter(source, cycle=True) as writer:
        writer.write(RNG.normal(0.0, 3e-5, size), RNG.normal(0.0, 300.0, size), np.arange(size))
    expected = read_recording(source)
    chunk = min(size, CHUNK_BYTES // 8)
    allocated = -(-size // chunk) * chunk * 3 * 8  # three columns of 8-byte numbers
    for suffix, kind in [(".h5", "hdf5"), (".nc", "hdf5"), (".zarr", "zarr")]:
        destination = convert_recording(source, tmp_path / f"out{suffix}")
        assert {v.chunk for v in variables(destination, kind)} == {chunk}
        assert stored_bytes(destination) <= allocated + METADATA_BYTES
        read = read_recording(destination)
        for role in ("displacement", "force", "cycle"):
            np.testing.assert_array_equal(getattr(read, role), getattr(expected, role))


def test_convert_failure_midway_leaves_nothing(tmp_path):
    """A bad line after several blocks were written: the error names it, and neither the
    store nor a temporary is left."""
    rows = list(zip(CYCLE, DISPLACEMENT, FORCE, strict=True))
    source = write_text(tmp_path / "big.csv", rows)
    lines = source.read_text().splitlines()
    lines[2000] = "7;1,0;oops"
    source.write_text("\n".join(lines) + "\n")
    with pytest.raises(RecordingError, match=r"big.csv, line 2001: non-numeric value 'oops'"):
        convert_recording(source, tmp_path / "big.zarr", chunk_samples=300, block_bytes=2000)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.csv"]
    with pytest.raises(ValueError, match="would write over its source"):
        convert_recording(source, tmp_path / "." / "big.csv")


def test_atomic_store_leaves_only_hidden_names(tmp_path):
    """A crash inside the block (here: an exception) leaves nothing; during the write the
    store exists only under a hidden temporary name."""
    path = tmp_path / "store.zarr"
    with pytest.raises(RuntimeError), atomic_store(path) as temporary:
        temporary.mkdir()
        (temporary / "zarr.json").write_text("{}")
        assert TEMPORARY_NAME.match(temporary.name)
        assert not path.exists()
        raise RuntimeError
    assert list(tmp_path.iterdir()) == []


def test_a_folder_is_never_removed_to_make_room(tmp_path):
    """A file, or a store, onto a user's folder: refused before anything is written, and the
    folder with its files left as it was (it was moved aside and deleted before)."""
    folder = tmp_path / "results"
    folder.mkdir()
    (folder / "thesis.txt").write_text("chapter 1")
    with pytest.raises(IsADirectoryError, match="not a store"), atomic_path(folder):
        pytest.fail("the block must not run")
    with pytest.raises(IsADirectoryError, match="not a store"):
        convert_recording(example_path(), folder, format="zarr", overwrite=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results"]
    assert [p.name for p in folder.iterdir()] == ["thesis.txt"]
    assert (folder / "thesis.txt").read_text() == "chapter 1"


def test_two_writers_of_one_new_file_never_lose_a_result_silently(tmp_path):
    """The second to finish is refused, naming the file, and the first's file is kept."""
    path = tmp_path / "table.csv"
    with pytest.raises(FileExistsError) as raised, atomic_path(path) as late:
        late.write_text("late")
        with atomic_path(path) as early:
            early.write_text("early")
    assert raised.value.filename == str(path)
    assert "written by another program meanwhile" in str(raised.value)
    assert path.read_text() == "early"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.csv"]
    with atomic_path(path) as again:  # an existing file is replaced as before
        again.write_text("again")
    assert path.read_text() == "again"


def test_temporaries_of_killed_runs_are_removed_by_the_next_write(tmp_path):
    ended = subprocess.Popen([sys.executable, "-c", ""])
    ended.wait()
    hex32 = "a" * 32
    dead = tmp_path / f".table.csv.{ended.pid}.{hex32}.tmp"
    living = tmp_path / f".table.csv.{os.getppid()}.{hex32}.tmp"
    other = tmp_path / f".other.csv.{ended.pid}.{hex32}.tmp"  # another file's
    users = tmp_path / ".table.csv.notes.tmp"  # not a name ecofmaps gives
    for item in (dead, living, other, users):
        item.write_bytes(b"")
    with atomic_path(tmp_path / "table.csv") as temporary:
        temporary.write_text("x")
    assert not dead.exists() and living.exists() and other.exists() and users.exists()
