"""write_map: netCDF and zarr round trips, chunked maps block by block, atomic on failure."""

import signal

import numpy as np
import pytest
import xarray as xr

from ecofmaps import Regime, compute_map, compute_universal_map, write_map
from ecofmaps._interrupts import interrupts_stop_writes
from ecofmaps.io.files import atomic_store
from ecofmaps.maps import tiles

AXES = (np.geomspace(1e4, 3e5, 23), np.linspace(0.0, 0.7, 11), np.array([25e-6, 50e-6]), 0.8)


def read(path):
    if path.suffix == ".zarr":
        with xr.open_zarr(path) as stored:
            return stored.compute()
    with xr.open_dataset(path, engine="h5netcdf") as stored:
        return stored.load()


@pytest.mark.parametrize("name", ["map.nc", "map.zarr"])
@pytest.mark.parametrize("chunks", [None, 37, {"aspect_ratio": 4}])
def test_round_trip_is_identical(tmp_path, name, chunks):
    """In memory or chunked, written to netCDF or zarr: read back identical."""
    expected = compute_map(*AXES, 450.0, cache=False)
    dataset = compute_map(*AXES, 450.0, chunks=chunks, cache=False if chunks is None else None)
    assert write_map(dataset, tmp_path / name) == ()
    xr.testing.assert_identical(read(tmp_path / name), expected)
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]


def test_zarr_chunks_are_the_blocks(tmp_path):
    dataset = compute_universal_map(np.linspace(0.0, 2.0, 50), np.linspace(0, 0.5, 6), 0.8,
                                    chunks={"compliance_ratio": 20})  # fmt: skip
    write_map(dataset, tmp_path / "u.zarr")
    with xr.open_zarr(tmp_path / "u.zarr") as stored:
        assert stored.ecof_ratio.encoding["chunks"] == (20, 6)
        assert stored.ecof_ratio.chunks == ((20, 20, 10), (6,))
        xr.testing.assert_identical(stored.compute(), dataset.compute())


def test_also_is_computed_in_the_same_pass(tmp_path, monkeypatch):
    calls = []
    block = tiles._block

    def counted(*args):
        calls.append(args[4])
        return block(*args)

    monkeypatch.setattr(tiles, "_block", counted)
    dataset = compute_map(*AXES, chunks=100)
    also = [(dataset.regime == code).sum().data for code in Regime] + [dataset.ecof_ratio.max()]
    *counts, top = write_map(dataset, tmp_path / "m.zarr", also=also)
    blocks = np.prod([len(c) for c in dataset.regime.chunks])
    assert len(calls) == blocks == 6  # each block evaluated once for the store and the sums
    expected = compute_map(*AXES, cache=False)
    assert counts == [int((expected.regime == code).sum()) for code in Regime]
    assert float(top) == float(expected.ecof_ratio.max())


def failing_blocks(monkeypatch, after: int, error: BaseException):
    """Make the block evaluation raise ``error`` once ``after`` blocks were evaluated."""
    calls = []
    block = tiles._block

    def failing(*args):
        calls.append(None)
        if len(calls) > after:
            raise error
        return block(*args)

    monkeypatch.setattr(tiles, "_block", failing)


@pytest.mark.parametrize("name", ["map.nc", "map.zarr"])
@pytest.mark.parametrize("error", [MemoryError("simulated"), KeyboardInterrupt()])
def test_a_failure_mid_write_leaves_nothing_complete_looking(tmp_path, monkeypatch, name, error):
    """A block failing halfway: no output, no temporary left, an old output kept as it was."""
    old = compute_map(*AXES, cache=False)
    write_map(old, tmp_path / name)
    (tmp_path / "new").mkdir()
    failing_blocks(monkeypatch, 3, error)
    dataset = compute_map(*AXES, 450.0, chunks=50)
    with pytest.raises(type(error)):
        write_map(dataset, tmp_path / name)
    assert sorted(p.name for p in tmp_path.iterdir()) == [name, "new"]
    xr.testing.assert_identical(read(tmp_path / name), old)
    with pytest.raises(type(error)):
        write_map(dataset, tmp_path / "new" / name)
    assert list((tmp_path / "new").iterdir()) == []


def test_an_existing_store_is_replaced_and_other_directories_are_refused(tmp_path):
    write_map(compute_map(*AXES, cache=False), tmp_path / "m.zarr")
    new = compute_map(*AXES, 450.0, chunks=200)
    write_map(new, tmp_path / "m.zarr")
    xr.testing.assert_identical(read(tmp_path / "m.zarr"), new.compute())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.zarr"]
    notes = tmp_path / "notes.zarr"
    notes.mkdir()
    (notes / "keep.txt").write_text("mine")
    with pytest.raises(ValueError, match=r"notes\.zarr is a directory but not a zarr store"):
        write_map(new, notes)
    with pytest.raises(ValueError, match="a netCDF file cannot replace it"):
        write_map(new, tmp_path)
    assert (notes / "keep.txt").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.zarr", "notes.zarr"]


def test_a_store_is_replaced_whole_and_not_after_ctrl_c(tmp_path):
    """After Ctrl-C on the command line the store is not renamed into place."""
    path = tmp_path / "store"
    path.mkdir()
    (path / ".zgroup").write_text("{}")  # a zarr store: replaced whole
    (path / "a").write_text("old")
    with pytest.raises(KeyboardInterrupt), interrupts_stop_writes():
        signal.raise_signal(signal.SIGINT)  # the first Ctrl-C: a flag
        with atomic_store(path, overwrite=True) as temporary:
            temporary.mkdir()
            (temporary / "a").write_text("new")
    assert [p.name for p in tmp_path.iterdir()] == ["store"]
    assert (path / "a").read_text() == "old"
    with atomic_store(path, overwrite=True) as temporary:
        temporary.mkdir()
        (temporary / "a").write_text("new")
    assert (path / "a").read_text() == "new" and not (path / ".zgroup").exists()
    with (
        pytest.raises(IsADirectoryError, match="not a store"),  # a folder is never replaced
        atomic_store(path, overwrite=True) as temporary,
    ):
        temporary.write_text("file")
    assert (path / "a").read_text() == "new" and [p.name for p in tmp_path.iterdir()] == ["store"]
