"""Rig formats: TDMS, HDF5 / netCDF-4 and zarr files written by their own libraries, read
through read_recording, whole and lazily; damaged files name the file and the channel."""

import contextlib
import gc
import itertools
import os
import pickle

import h5py
import numpy as np
import pytest
import xarray as xr
import zarr
from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

from ecofmaps._parallel import Slice, stretch
from ecofmaps.io.binary import Column, variables
from ecofmaps.io.recording_types import RecordingError, RecordingWarning
from ecofmaps.io.recordings import read_recording, recording_blocks, recording_format

SIZE = 5003
RNG = np.random.default_rng(7)
DISPLACEMENT = RNG.normal(0.0, 30.0, SIZE)  # µm
FORCE = RNG.normal(0.0, 0.3, SIZE)  # kN
CYCLE = np.arange(SIZE) // 250


def write_tdms(path, *, segments=3, force_size=SIZE, units=("um", "kN"), group="Rig"):
    """A LabVIEW-like file: channels 'Displacement', 'Ftr' and 'Cycle' in one group, the
    units in the first segment's properties, the data spread over several segments."""
    edges = np.linspace(0, SIZE, segments + 1).astype(int)
    with TdmsWriter(path) as writer:
        for k, (a, b) in enumerate(itertools.pairwise(edges)):
            first = k == 0
            objects = [
                RootObject({"name": "test"} if first else {}),
                GroupObject(group),
                ChannelObject(
                    group,
                    "Displacement",
                    DISPLACEMENT[a:b],
                    properties={"unit_string": units[0]} if first else {},
                ),
                ChannelObject(
                    group,
                    "Ftr",
                    FORCE[a : min(b, force_size)],
                    properties={"NI_UnitDescription": units[1]} if first else {},
                ),
                ChannelObject(group, "Cycle", CYCLE[a:b].astype(np.int32)),
                ChannelObject("Other", "Temperature", np.ones(b - a)),
            ]
            writer.write_segment(objects)
    return path


def write_hdf5(path, *, group="rig/run1"):
    with h5py.File(path, "w") as handle:
        handle.create_dataset(f"{group}/displacement", data=DISPLACEMENT, chunks=(1000,))
        handle[f"{group}/displacement"].attrs["units"] = b"um"
        handle.create_dataset(f"{group}/force_kN", data=FORCE, chunks=(1000,))
        handle[f"{group}/cycle"] = CYCLE
        handle["notes"] = np.bytes_("not a channel")
    return path


def write_zarr(path):
    root = zarr.open_group(str(path), mode="w")
    for name, data, unit in (("displacement", DISPLACEMENT, "um"), ("force", FORCE, "kN")):
        array = root.create_array(name, shape=data.shape, chunks=(1000,), dtype=data.dtype)
        array[:] = data
        array.attrs["units"] = unit
    return path


def check(recording):
    np.testing.assert_array_equal(recording.displacement, DISPLACEMENT / 1e6)
    np.testing.assert_array_equal(recording.force, FORCE * 1e3)


def test_tdms(tmp_path):
    """Channels found in their group by name; units from unit_string/NI_UnitDescription."""
    path = write_tdms(tmp_path / "rig.tdms")
    assert recording_format(path) == "tdms"
    read = read_recording(path, force_column="ftr")
    check(read)
    np.testing.assert_array_equal(read.cycle, CYCLE)
    assert read.columns == {
        "displacement": "Rig/Displacement",
        "force": "Rig/Ftr",
        "cycle": "Rig/Cycle",
    }
    assert read.units == {"displacement": "um", "force": "kN", "cycle": "1"}
    assert read.last_line is None and read.line(3) is None and read.position(3) == "sample 3"
    same = read_recording(path, force_column="Rig/Ftr", group="Rig", force_unit="kN")
    np.testing.assert_array_equal(same.force, read.force)


def test_hdf5_and_netcdf(tmp_path):
    """Variables in a group; units from attrs or the name; netCDF written by xarray too."""
    path = write_hdf5(tmp_path / "rig.h5")
    read = read_recording(path)
    check(read)
    np.testing.assert_array_equal(read.cycle, CYCLE)
    assert read.columns["force"] == "rig/run1/force_kN"
    nc = tmp_path / "rig.nc"
    dataset = xr.Dataset(
        {
            "displacement": ("time", DISPLACEMENT, {"units": "micrometre"}),
            "force": ("time", FORCE, {"units": "kN"}),
        }
    )
    dataset.to_netcdf(nc, engine="h5netcdf", group="test")
    check(read_recording(nc, group="/test"))


def test_netcdf_packing_and_fill_values(tmp_path):
    """CF packing is decoded: int16 counts times scale_factor plus add_offset; the fill
    value is a missing sample."""
    counts = np.array([10, -20, 30, -32767, 40], dtype=np.int16)
    dataset = xr.Dataset(
        {
            "displacement": ("t", counts.astype(np.float64) * 0.5 + 1.0),
            "force": ("t", np.arange(5.0)),
        }
    )
    dataset.displacement.attrs["units"] = "um"
    dataset.displacement[3] = np.nan
    encoding = {
        "displacement": {
            "dtype": "int16",
            "scale_factor": 0.5,
            "add_offset": 1.0,
            "_FillValue": -32767,
        }
    }
    path = tmp_path / "packed.nc"
    dataset.to_netcdf(path, engine="h5netcdf", encoding=encoding)
    with h5py.File(path) as handle:
        assert handle["displacement"].dtype == np.int16
    read = read_recording(path)
    np.testing.assert_array_equal(read.displacement * 1e6, [6.0, -9.0, 16.0, np.nan, 21.0])
    np.testing.assert_array_equal(read.missing, [0, 0, 0, 1, 0])
    with pytest.raises(RecordingError, match=r"variable 'displacement', sample 3: missing"):
        read_recording(path, nan_policy="raise")


def test_zarr(tmp_path):
    path = write_zarr(tmp_path / "rig.zarr")
    assert recording_format(path) == "zarr"
    read = read_recording(path)
    check(read)
    assert read.cycle is None


@pytest.mark.parametrize("kind", ["tdms", "h5", "zarr"])
def test_lazy_reading_is_blockwise_and_equal(tmp_path, kind):
    """lazy=True gives dask arrays whose blocks read equal to the eager read; slices and
    blocks keep their positions; the columns pickle without their open file."""
    path = {"tdms": write_tdms, "h5": write_hdf5, "zarr": write_zarr}[kind](
        tmp_path / f"rig.{kind}"
    )
    options = {"force_column": "ftr"} if kind == "tdms" else {}
    eager = read_recording(path, **options)
    lazy = read_recording(path, lazy=True, chunks=700, **options)
    assert lazy.lazy and lazy.displacement.chunks == ((700,) * 7 + (SIZE - 4900,),)
    np.testing.assert_array_equal(lazy.force.compute(), eager.force)
    np.testing.assert_array_equal(lazy.compute().displacement, eager.displacement)
    assert not lazy.missing.any().compute()
    part = lazy[1234:1300]
    assert part.start == 1234 and part.position(0) == "sample 1234"
    np.testing.assert_array_equal(part.force, eager.force[1234:1300])
    blocks = list(recording_blocks(path, samples=1500, **options))
    assert [b.start for b in blocks] == [0, 1500, 3000, 4500]
    np.testing.assert_array_equal(np.concatenate([b.force for b in blocks]), eager.force)
    copy = pickle.loads(pickle.dumps(lazy.force))
    np.testing.assert_array_equal(copy[100:110].compute(), eager.force[100:110])
    if kind != "zarr":  # a zarr store keeps no file open
        assert opened_by_this_process(path)
    del lazy, part, copy
    gc.collect()
    assert not opened_by_this_process(path), "the file is still open once nothing holds it"


def opened_by_this_process(path) -> bool:
    """Whether this process has ``path``, or a file in it, open (its descriptors are listed
    in /proc/self/fd, as on Linux)."""
    path = str(path.resolve())
    for descriptor in os.listdir("/proc/self/fd"):
        with contextlib.suppress(OSError):  # the listing's own descriptor, closed meanwhile
            target = os.readlink(f"/proc/self/fd/{descriptor}")
            if target == path or target.startswith(path + os.sep):
                return True
    return False


def test_column_pickles_without_its_file(tmp_path):
    """A Column keeps its open file per process: a pickled copy opens its own, and every
    copy of it unpickled in one process while one is held is that one object (one open
    file for the tasks a worker holds), until the file's stamp changes."""
    path = write_hdf5(tmp_path / "rig.h5")
    variable = next(v for v in variables(path, "hdf5") if v.short == "force_kN")
    column = Column(path, "hdf5", variable, 1e3, "propagate", stamp=(1, 2))
    np.testing.assert_array_equal(column[10:20], FORCE[10:20] * 1e3)
    copy = pickle.loads(pickle.dumps(column))
    assert copy._handle is None and column._handle is not None
    np.testing.assert_array_equal(copy[(slice(5, 9),)], FORCE[5:9] * 1e3)
    assert pickle.loads(pickle.dumps(column)) is copy and copy._handle is not None
    other = Column(path, "hdf5", variable, 1e3, "propagate", stamp=(1, 3))
    assert pickle.loads(pickle.dumps(other)) is not copy
    with pytest.raises(TypeError, match="slice"):
        column[3]
    column.close()
    copy.close()


_FORK_SCRIPT = """
import multiprocessing, sys, threading
import numpy as np
from ecofmaps._parallel import SOURCE
from ecofmaps.io.recordings import read_recording

def read_in_a_fork(start):
    # whether the column opened its own file, and whether 200 reads gave the file's values
    right = all(np.array_equal(COLUMN[start + k : start + k + 500],
                               EXPECTED[start + k : start + k + 500])
                for k in range(0, 2000, 10))
    return COLUMN._handle[0] is not PARENT, right

EVENT = threading.Event()

def hold(lock):
    with lock:
        EVENT.wait()

if __name__ == "__main__":
    options = {"force_column": "ftr"} if sys.argv[1].endswith("tdms") else {}
    COLUMN = getattr(read_recording(sys.argv[1], lazy=True, **options).force, SOURCE)
    EXPECTED = read_recording(sys.argv[1], **options).force
    assert np.array_equal(COLUMN[0:10], EXPECTED[0:10])  # opened here
    PARENT = COLUMN._handle[0]
    reading = threading.Thread(target=hold, args=(COLUMN._lock,), daemon=True)
    reading.start()  # a thread of this process holds the lock while the children fork
    with multiprocessing.get_context("fork").Pool(2) as pool:
        found = pool.map_async(read_in_a_fork, [0, 1000, 2000, 500]).get(timeout=60)
    assert found == [(True, True)] * 4, found
    EVENT.set()
    reading.join()
    assert np.array_equal(COLUMN[100:3000], EXPECTED[100:3000])  # still open here
"""


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["tdms", "hdf5"])
def test_a_forked_process_opens_the_file_again(tmp_path, kind):
    """A process forked after a column opened its file reads through a file of its own (a
    shared one shares its position: two processes reading at once read each other's
    bytes), and leaves the parent's open; it reads while one of the parent's threads holds
    the column's lock (the child's copy of that lock would never be let go). In a fresh
    process: this one may run JAX's threads, which forking could deadlock."""
    import subprocess
    import sys

    path = {"tdms": write_tdms, "hdf5": write_hdf5}[kind](tmp_path / kind)
    done = subprocess.run(
        [sys.executable, "-c", _FORK_SCRIPT, str(path)], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("kind", ["tdms", "hdf5", "zarr"])
def test_tasks_read_ranges_from_the_column(tmp_path, kind):
    """A lazily read channel hands a task a Slice of its Column, read without dask, equal
    to the dask array's values; an array computed from it is sliced by dask."""
    path = {"tdms": write_tdms, "hdf5": write_hdf5, "zarr": write_zarr}[kind](tmp_path / kind)
    options = {"force_column": "ftr"} if kind == "tdms" else {}
    lazy = read_recording(path, lazy=True, chunks=700, **options)
    for array in (lazy.displacement, lazy.force):
        part = stretch(array, 650, 1720)
        assert isinstance(part, Slice) and isinstance(part.source, Column)
        read = pickle.loads(pickle.dumps(part)).read()
        np.testing.assert_array_equal(read, array[650:1720].compute())
    derived = stretch(lazy.force * 2.0, 650, 1720)
    assert not isinstance(derived, Slice)
    np.testing.assert_array_equal(derived.compute(), 2.0 * lazy.force[650:1720].compute())


def test_group_choice(tmp_path):
    """The same channel names in two groups: ambiguous without group, found with it."""
    path = tmp_path / "two.h5"
    with h5py.File(path, "w") as handle:
        for group, scale in (("a", 1.0), ("b", 2.0)):
            handle[f"{group}/displacement"] = DISPLACEMENT * scale
            handle[f"{group}/force"] = FORCE * scale
    with pytest.raises(RecordingError, match=r"several displacement variables match .*'a/displ"):
        read_recording(path)
    read = read_recording(path, group="b", force_unit="kN")
    np.testing.assert_array_equal(read.force, FORCE * 2e3)
    read = read_recording(path, displacement_column="a/displacement", force_column="A/Force")
    np.testing.assert_array_equal(read.displacement, DISPLACEMENT / 1e6)
    with pytest.raises(RecordingError, match=r"no group 'c' with channels \(groups: 'a', 'b'\)"):
        read_recording(path, group="c")


# --- damaged files ---------------------------------------------------------------------------


def test_missing_channel_names_the_file_and_the_channels(tmp_path):
    path = write_tdms(tmp_path / "rig.tdms")
    with pytest.raises(RecordingError) as raised:
        read_recording(path)
    assert str(raised.value) == (
        f"{path}: no force channel 'force' (channels: 'Rig/Displacement', 'Rig/Ftr', "
        "'Rig/Cycle', 'Other/Temperature')"
    )
    with pytest.raises(RecordingError, match="no cycle variable 'n'"):
        read_recording(write_zarr(tmp_path / "rig.zarr"), cycle_column="n")


def test_channel_of_another_length(tmp_path):
    path = write_tdms(tmp_path / "short.tdms", force_size=SIZE - 10)
    with pytest.raises(RecordingError) as raised:
        read_recording(path, force_column="Ftr")
    assert str(raised.value) == (
        f"{path}, channel 'Rig/Ftr': {SIZE - 10} samples where the displacement channel "
        f"'Rig/Displacement' has {SIZE}"
    )


def test_truncated_tdms(tmp_path):
    path = write_tdms(tmp_path / "rig.tdms")
    data = path.read_bytes()
    for cut in (len(data) - 3000, 40):
        damaged = tmp_path / f"cut{cut}.tdms"
        damaged.write_bytes(data[:cut])
        with pytest.raises(RecordingError, match=rf"cut{cut}.tdms: truncated or damaged TDMS"):
            read_recording(damaged, force_column="ftr")


def test_truncated_hdf5(tmp_path):
    path = write_hdf5(tmp_path / "rig.h5")
    damaged = tmp_path / "cut.h5"
    damaged.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    with pytest.raises(RecordingError, match=r"cut.h5: cannot open as HDF5 \(truncated"):
        read_recording(damaged)


def test_zarr_with_missing_or_damaged_chunks(tmp_path):
    """A missing chunk file (zarr would read the fill value) is refused when the store is
    opened; a damaged one when its block is read, naming the variable and the samples."""
    path = write_zarr(tmp_path / "rig.zarr")
    (path / "force" / "c" / "2").unlink()
    with pytest.raises(RecordingError, match=r"variable 'force': 1 of its 6 chunks are missing"):
        read_recording(path)
    path = write_zarr(tmp_path / "rig2.zarr")
    (path / "force" / "c" / "3").write_bytes(b"\x00" * 10)
    lazy = read_recording(path, lazy=True, chunks=1000)
    np.testing.assert_array_equal(lazy.force[:3000].compute(), FORCE[:3000] * 1e3)
    with pytest.raises(RecordingError, match=r"rig2.zarr, variable 'force', samples 3000 to 3999"):
        lazy.force.compute()


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("empty.tdms", b"", "not a TDMS file"),
        ("text.h5", b"displacement,force\n1,2\n", "not a HDF5 file"),
        ("old.nc", b"CDF\x01\x00\x00\x00\x00", "a netCDF-3 .classic. file"),
    ],
)
def test_mislabelled_files(tmp_path, name, content, message):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(RecordingError, match=message):
        read_recording(path)


def test_a_directory_that_is_not_a_store(tmp_path):
    with pytest.raises(RecordingError, match="a directory, and not a zarr store"):
        read_recording(tmp_path)


def test_units_in_metadata_and_options(tmp_path):
    """A unit option that disagrees with a channel's unit_string is an error naming the
    channel; one of another kind in the file (volts) needs the option."""
    path = write_tdms(tmp_path / "rig.tdms")
    with pytest.raises(RecordingError, match=r"channel 'Rig/Displacement': .* is in 'um', but"):
        read_recording(path, force_column="Ftr", displacement_unit="mm")
    volts = write_tdms(tmp_path / "volts.tdms", units=("V", "kN"))
    with pytest.raises(RecordingError, match="is in 'V', which is not a length unit"):
        read_recording(volts, force_column="Ftr")
    read = read_recording(volts, force_column="Ftr", displacement_unit="mm")
    np.testing.assert_array_equal(read.displacement, DISPLACEMENT / 1e3)


def test_nan_policy_on_lazy_reads(tmp_path):
    """With nan_policy='raise' a missing sample is an error when its block is read."""
    data = DISPLACEMENT.copy()
    data[4321] = np.nan
    path = tmp_path / "gap.h5"
    with h5py.File(path, "w") as handle:
        handle["displacement"] = data
        handle["force"] = FORCE
    read = read_recording(path)
    assert np.flatnonzero(read.missing).tolist() == [4321]
    lazy = read_recording(path, lazy=True, chunks=1000, nan_policy="raise")
    lazy.displacement[:4000].compute()
    with pytest.raises(RecordingError, match=r"variable 'displacement', sample 4321: missing"):
        lazy.displacement.compute()


def test_tdms_channel_names_with_units_and_groups(tmp_path):
    """LabVIEW channel names carry units ('Displacement/µm', 'Force [kN]'); the force and
    cycle channels are taken from the displacement's group when others match too."""
    path = tmp_path / "named.tdms"
    with TdmsWriter(path) as writer:
        writer.write_segment(
            [
                RootObject(),
                GroupObject("Rig"),
                ChannelObject("Rig", "Displacement/µm", DISPLACEMENT),
                ChannelObject("Rig", "Force [kN]", FORCE),
                ChannelObject("Rig", "cycle", CYCLE),
                ChannelObject("Calibration", "Force [N]", FORCE[:10]),
                ChannelObject("Calibration", "cycle", CYCLE[:10]),
            ]
        )
    read = read_recording(path)
    check(read)
    np.testing.assert_array_equal(read.cycle, CYCLE)
    assert read.columns == {
        "displacement": "Rig/Displacement/µm",
        "force": "Rig/Force [kN]",
        "cycle": "Rig/cycle",
    }
    lazy = read_recording(path, lazy=True, chunks=2000)
    np.testing.assert_array_equal(lazy.force.compute(), read.force)


def test_empty_variables_and_two_chunkings(tmp_path):
    """No samples is an error; two lazy reads with other chunks are other dask arrays."""
    path = tmp_path / "empty.h5"
    with h5py.File(path, "w") as handle:
        handle["displacement"] = np.zeros(0)
        handle["force"] = np.zeros(0)
    with pytest.raises(RecordingError, match="variable 'displacement': no samples"):
        read_recording(path)
    path = write_zarr(tmp_path / "rig.zarr")
    first = read_recording(path, lazy=True, chunks=1000).force
    second = read_recording(path, lazy=True, chunks=3000).force
    assert first.name != second.name
    np.testing.assert_array_equal((first - second).compute(), 0.0)


@pytest.mark.parametrize("kind", ["hdf5", "netcdf"])
def test_flipped_bytes_in_the_header_name_the_file_as_damaged(tmp_path, capfd, kind):
    """A byte flipped at offsets all through the metadata: each file reads as it is (a byte
    that nothing reads) or is refused as damaged, naming the file; never another error, and
    nothing on stderr (h5netcdf's half-opened file printed a traceback when collected)."""
    if kind == "hdf5":
        path = write_hdf5(tmp_path / "rig.h5")
    else:
        path = tmp_path / "rig.nc"
        xr.Dataset(
            {"displacement": ("time", DISPLACEMENT, {"units": "um"}),
             "force": ("time", FORCE, {"units": "kN"})}
        ).to_netcdf(path, engine="h5netcdf")  # fmt: skip
    original = path.read_bytes()
    damaged = tmp_path / f"damaged{path.suffix}"
    refused = 0
    for offset in range(8, 4096, 37):
        flipped = bytearray(original)
        flipped[offset] ^= 0xFF
        damaged.write_bytes(bytes(flipped))
        try:
            read = read_recording(damaged)
            np.asarray(read.displacement), np.asarray(read.force)
        except RecordingError as error:
            refused += 1
            assert str(error).startswith(f"{damaged}"), offset
            assert "(truncated or damaged)" in str(error) or "(a damaged file" in str(error)
    assert refused >= 10
    assert capfd.readouterr().err == ""


# --- no file left to the garbage collector ----------------------------------------------------


def open_hdf5_files(folder) -> list:
    """The h5netcdf files in ``folder`` (a test's own) this process still has open."""
    import gc

    import h5netcdf

    files = [f for f in gc.get_objects() if isinstance(f, h5netcdf.File) and not f._closed]
    return [f for f in files if os.path.dirname(f.filename) == str(folder)]


def test_a_lazy_recording_closes_its_files_on_leaving_its_block(tmp_path):
    """A lazy recording read and closed (``with``, or ``close()``) leaves no HDF5 file open
    for the garbage collector to close, though the recording itself is still alive."""
    path = write_hdf5(tmp_path / "rig.h5")
    assert open_hdf5_files(tmp_path) == []
    with read_recording(path, lazy=True, group="rig/run1") as recording:
        whole = recording.compute()
        assert open_hdf5_files(tmp_path)  # open while it is read
    assert open_hdf5_files(tmp_path) == []
    np.testing.assert_array_equal(recording.compute().displacement, whole.displacement)
    recording.close()  # the read above opened it again
    assert open_hdf5_files(tmp_path) == []


@pytest.fixture
def left_to_gc(monkeypatch):
    """The files of the rig-file columns that the garbage collector found still open (the
    collector, not the code that read them, closed them)."""
    import gc

    left = []
    collect = Column.__del__

    def watched(column):
        if column._handle is not None:
            left.append(str(column.path))
        collect(column)

    monkeypatch.setattr(Column, "__del__", watched)
    yield lambda: gc.collect() * 0 or left


def test_blocks_of_a_rig_file_close_it_when_done_or_given_up(tmp_path, left_to_gc):
    path = write_hdf5(tmp_path / "rig.h5")
    blocks = recording_blocks(path, 1000, group="rig/run1")
    next(blocks)
    blocks.close()  # the reader stops early
    assert sum(block.size for block in recording_blocks(path, 1000, group="rig/run1")) == SIZE
    assert left_to_gc() == [] and open_hdf5_files(tmp_path) == []


def test_the_loops_command_closes_a_lazy_recording_whose_analysis_fails(
    tmp_path, capsys, monkeypatch, left_to_gc
):
    """A lazy rig file that cannot be analysed: the error is reported and the file closed,
    not left open in the error's traceback for the garbage collector."""
    from ecofmaps import cli
    from ecofmaps.io import binary

    monkeypatch.setattr(binary, "LAZY_SAMPLES", 1000)  # read lazily, in this process
    path = write_hdf5(tmp_path / "rig.h5")  # noise: no fretting cycles in it
    status = cli.main(
        ["loops", str(path), "--group", "rig/run1", "--load", "450N", "--out",
         str(tmp_path / "t.csv")]
    )  # fmt: skip
    assert status != 0 and "error" in capsys.readouterr().err
    assert left_to_gc() == [] and open_hdf5_files(tmp_path) == []


def test_a_tdms_text_property_not_utf8_is_one_warning_and_npTDMS_prints_nothing(tmp_path, capfd):
    path = write_tdms(tmp_path / "rig.tdms")
    data = path.read_bytes()
    path.write_bytes(data.replace(b"test", b"t\xffst", 1))
    with pytest.warns(RecordingWarning) as caught:
        check(read_recording(path, force_column="ftr", lazy=False))
    assert {str(w.message) for w in caught} == {  # the same one each time the file is opened
        f"{path}: a text property of the file is not UTF-8; read with replacement "
        "characters (the samples are not affected)"
    }
    assert capfd.readouterr().err == ""  # not '[nptdms.types WARNING] ...'


def test_npTDMS_logging_is_as_it_was_outside_the_reads(tmp_path, capfd):
    """Quieted while a file is read only: importing ecofmaps or reading changes no logging;
    what npTDMS logs while it reads is a warning, not a line it prints."""
    import logging

    from nptdms.log import log_manager

    from ecofmaps.io import tdms

    def state():
        loggers = [logging.getLogger("nptdms"), *log_manager.loggers.values()]
        return [(lg.propagate, list(lg.handlers)) for lg in loggers], console.filters[:]

    console = log_manager.console_handler
    before = state()
    assert all(console in handlers for _, handlers in before[0][1:]) and before[1] == []
    path = write_tdms(tmp_path / "rig.tdms")
    check(read_recording(path, force_column="ftr", lazy=False))
    assert state() == before
    with pytest.warns(RecordingWarning, match="^TDMS reader: a note$"), tdms._Quiet.reading():
        logging.getLogger("nptdms.types").warning("a note")
    assert capfd.readouterr().err == "" and state() == before
