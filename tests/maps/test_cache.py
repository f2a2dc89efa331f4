"""The disk cache: round trips, keys, recovery from bad files, concurrent writers, clearing."""

import fnmatch
import multiprocessing
import os
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import ecofmaps
from ecofmaps import compute_map, compute_universal_map
from ecofmaps.maps import cache
from ecofmaps.maps.cache import CacheWarning, cache_entries, clear_cache

GRID = dict(
    stiffness_ratio=np.array([3e4, 7.7e4, np.inf]),
    aspect_ratio=np.linspace(0.0, 0.7, 4),
    amplitude=np.array([25e-6, 50e-6]),
    mu=0.8,
    load=450.0,
)


def only_entry(directory):
    entries = cache_entries(directory)
    assert len(entries) == 1
    return entries[0]


def test_round_trip_is_identical(tmp_path):
    computed = compute_map(**GRID, cache_dir=tmp_path)
    entry = only_entry(tmp_path)
    assert entry.function == "compute_map" and entry.size == entry.path.stat().st_size > 0
    assert entry.path.parent == tmp_path and entry.path.suffix == ".nc"
    read = compute_map(**GRID, cache_dir=tmp_path)
    xr.testing.assert_identical(read, computed)
    xr.testing.assert_identical(read, compute_map(**GRID, cache=False))
    assert read.regime.dtype == np.int32
    assert read.attrs == computed.attrs  # the cache's key attribute is not handed out
    universal = compute_universal_map(np.linspace(0, 1, 5), 0.2, np.array([0.5, 0.8]))
    xr.testing.assert_identical(
        universal, compute_universal_map(np.linspace(0, 1, 5), 0.2, np.array([0.5, 0.8]))
    )


def test_no_cache_writes_nothing(tmp_path):
    compute_map(**GRID, cache=False, cache_dir=tmp_path)
    assert cache_entries(tmp_path) == []
    assert list(tmp_path.iterdir()) == []


def test_directory_precedence(tmp_path, monkeypatch):
    monkeypatch.setenv("ECOFMAPS_CACHE", str(tmp_path / "environment"))
    assert cache.cache_directory() == tmp_path / "environment"
    assert cache.cache_directory(tmp_path / "argument") == tmp_path / "argument"
    compute_map(**GRID)
    assert len(cache_entries()) == 1 and cache_entries()[0].path.parent == tmp_path / "environment"
    monkeypatch.delenv("ECOFMAPS_CACHE")
    assert "ecofmaps" in str(cache.cache_directory())  # the per-user directory


def test_keys_tell_grids_apart(monkeypatch):
    axes = {"stiffness_ratio": np.array([1e4, 2e4]), "mu": np.float64(0.8), "load": None}
    key = cache.cache_key("compute_map", axes)
    assert key == cache.cache_key("compute_map", dict(axes))
    assert len(key) == 64
    nudged = np.array([1e4, np.nextafter(2e4, np.inf)])  # one ulp
    others = [
        cache.cache_key("compute_universal_map", axes),
        cache.cache_key("compute_map", {**axes, "stiffness_ratio": nudged}),
        cache.cache_key("compute_map", {**axes, "mu": np.array([0.8])}),  # 1-D, not scalar
        cache.cache_key("compute_map", {**axes, "load": np.float64(450.0)}),
    ]
    monkeypatch.setattr(cache, "__version__", "999.0")
    others.append(cache.cache_key("compute_map", axes))
    monkeypatch.undo()
    monkeypatch.setattr(cache, "model_revision", lambda: "an edited model")
    others.append(cache.cache_key("compute_map", axes))
    assert len({key, *others}) == len(others) + 1


def test_model_revision_hashes_the_model_sources():
    revision = cache.model_revision()
    assert len(revision) == 64 and revision == cache.model_revision()
    package = Path(ecofmaps.__file__).parent
    sources = [p.relative_to(package).as_posix() for p in package.rglob("*.py")]
    for pattern in cache._MODEL_SOURCES:  # every pattern names real files
        assert any(fnmatch.fnmatch(name, pattern) for name in sources), pattern


def test_an_edited_model_does_not_serve_its_old_maps(tmp_path, monkeypatch):
    """A map cached before a change of the model's source is not read after it (issue 8)."""
    old = compute_map(**GRID, cache_dir=tmp_path)
    stale = only_entry(tmp_path).path
    # Make the stored entry hold something the new model would not compute.
    with xr.open_dataset(stale, engine="h5netcdf") as stored:
        tampered = stored.load()
    tampered["ecof_ratio"] = tampered["ecof_ratio"] * 2.0
    tampered.attrs["ecofmaps_data_sha256"] = cache.data_checksum(tampered)
    cache.write_netcdf(tampered, stale)
    monkeypatch.setattr(cache, "model_revision", lambda: "an edited model")
    fresh = compute_map(**GRID, cache_dir=tmp_path)
    xr.testing.assert_identical(fresh, old)
    assert len(cache_entries(tmp_path)) == 2  # the new revision's entry beside the old one


def test_damaged_data_are_reported_removed_and_recomputed(tmp_path):
    """Bytes overwritten inside the data section give a checksum mismatch, not a map (issue 9)."""
    expected = compute_map(**GRID, cache_dir=tmp_path)
    path = only_entry(tmp_path).path
    content = bytearray(path.read_bytes())
    data = np.ascontiguousarray(expected["ecof_ratio"].values).tobytes()
    start = bytes(content).find(data)
    assert start > 0  # stored uncompressed, contiguous
    content[start + 8 : start + 16] = np.float64(32.5).tobytes()  # one value replaced
    path.write_bytes(bytes(content))
    with pytest.warns(CacheWarning, match="do not match their checksum"):
        recovered = compute_map(**GRID, cache_dir=tmp_path)
    xr.testing.assert_identical(recovered, expected)
    xr.testing.assert_identical(compute_map(**GRID, cache_dir=tmp_path), expected)  # valid now


def test_checksum_sees_every_value():
    dataset = compute_map(**GRID, cache=False)
    checksum = cache.data_checksum(dataset)
    assert checksum == cache.data_checksum(dataset.copy(deep=True))
    assert checksum == cache.data_checksum(dataset.assign_attrs(note="attributes do not count"))
    for name in ("ecof_ratio", "regime", "aspect_ratio"):
        values = dataset[name].values.copy()
        values.flat[np.flatnonzero(np.isfinite(values))[0]] += 1
        changed = dataset.assign_coords if name in dataset.coords else dataset.assign
        assert cache.data_checksum(changed({name: (dataset[name].dims, values)})) != checksum


def test_different_grids_are_different_entries(tmp_path):
    compute_map(**GRID, cache_dir=tmp_path)
    compute_map(**{**GRID, "load": None}, cache_dir=tmp_path)
    compute_map(**{**GRID, "mu": np.array([0.8])}, cache_dir=tmp_path)
    assert len(cache_entries(tmp_path)) == 3


@pytest.mark.parametrize(
    "content",
    [b"", b"not a netCDF file at all", b"\x89HDF\r\n\x1a\n" + bytes(100)],
    ids=["empty", "text", "truncated-hdf5"],
)
def test_corrupt_file_is_reported_removed_and_recomputed(tmp_path, content):
    expected = compute_map(**GRID, cache_dir=tmp_path)
    path = only_entry(tmp_path).path
    path.write_bytes(content)
    with pytest.warns(CacheWarning, match=f"removed unusable cache file {path}"):
        recovered = compute_map(**GRID, cache_dir=tmp_path)
    xr.testing.assert_identical(recovered, expected)
    assert only_entry(tmp_path).path == path and path.stat().st_size > len(content)
    xr.testing.assert_identical(compute_map(**GRID, cache_dir=tmp_path), expected)  # valid now


def test_foreign_file_is_reported_removed_and_recomputed(tmp_path):
    expected = compute_map(**GRID, cache_dir=tmp_path)
    path = only_entry(tmp_path).path
    xr.Dataset({"x": ("x", [1.0, 2.0])}).to_netcdf(path, engine="h5netcdf")
    with pytest.warns(CacheWarning, match="foreign file"):
        xr.testing.assert_identical(compute_map(**GRID, cache_dir=tmp_path), expected)
    xr.testing.assert_identical(compute_map(**GRID, cache_dir=tmp_path), expected)


def test_unwritable_cache_still_returns_the_map(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a directory")
    with pytest.warns(CacheWarning, match="could not write cache file"):
        computed = compute_map(**GRID, cache_dir=blocker / "cache")
    xr.testing.assert_identical(computed, compute_map(**GRID, cache=False))


def test_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "map.nc"
    good = compute_map(**GRID, cache=False)
    cache.write_netcdf(good, path)
    before = path.read_bytes()
    bad = good.assign_attrs(unwritable={"a dict": "cannot be a netCDF attribute"})
    with pytest.raises(TypeError):
        cache.write_netcdf(bad, path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["map.nc"]
    with xr.open_dataset(path, engine="h5netcdf") as stored:
        xr.testing.assert_identical(stored.load(), good)


def _write_repeatedly(directory, barrier, repeats):
    """Child process: store the same cache entry ``repeats`` times, racing the other one."""
    dataset = compute_map(**GRID, cache=False)
    key = cache.cache_key("race", {"n": 1.0})
    barrier.wait()
    for _ in range(repeats):
        cache.write_netcdf(dataset.assign_attrs(ecofmaps_cache_key=key), directory / "race.nc")
        compute_map(**GRID, cache_dir=directory)


def test_two_concurrent_writers_leave_a_valid_file(tmp_path):
    context = multiprocessing.get_context("spawn")  # JAX is multithreaded: no fork
    barrier = context.Barrier(2)
    writers = [
        context.Process(target=_write_repeatedly, args=(tmp_path, barrier, 15)) for _ in range(2)
    ]
    for writer in writers:
        writer.start()
    for writer in writers:
        writer.join(timeout=300)
        assert writer.exitcode == 0
    expected = compute_map(**GRID, cache=False)
    with xr.open_dataset(tmp_path / "race.nc", engine="h5netcdf") as stored:
        raced = stored.load()
    assert raced.attrs.pop("ecofmaps_cache_key") == cache.cache_key("race", {"n": 1.0})
    xr.testing.assert_identical(raced, expected)
    xr.testing.assert_identical(compute_map(**GRID, cache_dir=tmp_path), expected)
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


def test_clear_removes_entries_and_leftovers_only(tmp_path):
    compute_map(**GRID, cache_dir=tmp_path)
    compute_universal_map(0.5, 0.2, 0.8, cache_dir=tmp_path)
    leftover = tmp_path / f".compute_map-{'0' * 32}.nc.{'a' * 32}.tmp"
    leftover.write_bytes(b"half")
    unrelated = tmp_path / "notes.nc"
    unrelated.write_text("keep me")
    sizes = sum(e.size for e in cache_entries(tmp_path)) + 4
    assert [e.function for e in cache_entries(tmp_path)] == ["compute_map", "compute_universal_map"]
    assert clear_cache(tmp_path) == (3, sizes)
    assert cache_entries(tmp_path) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.nc"]
    assert clear_cache(tmp_path) == (0, 0)
    assert clear_cache(tmp_path / "missing") == (0, 0)
    assert cache_entries(tmp_path / "missing") == []
    assert os.path.exists(unrelated)
