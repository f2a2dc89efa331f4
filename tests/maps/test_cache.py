"""The disk cache: round trips, keys, recovery from damaged files, failed writes, the size bound,
concurrent writers, clearing."""

import errno
import fnmatch
import importlib.util
import multiprocessing
import os
import subprocess
import sys
import textwrap
import warnings
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
    computed = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    entry = only_entry(tmp_path)
    assert entry.function == "compute_map" and entry.size == entry.path.stat().st_size > 0
    assert entry.path.parent == tmp_path and entry.path.suffix == ".nc"
    read = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    xr.testing.assert_identical(read, computed)
    xr.testing.assert_identical(read, compute_map(**GRID, cache=False))
    assert read.regime.dtype == np.int32
    assert read.attrs == computed.attrs  # the cache's key attribute is not handed out
    assert all(not variable.encoding for variable in read.variables.values())  # not the cache's
    grid = (np.linspace(0, 1, 5), 0.2, np.array([0.5, 0.8]))
    universal = compute_universal_map(*grid, cache=True, cache_dir=tmp_path)
    xr.testing.assert_identical(universal, compute_universal_map(*grid, cache_dir=tmp_path))
    xr.testing.assert_identical(universal, compute_universal_map(*grid, cache=True))


def test_only_what_is_expensive_is_cached_by_default(tmp_path):
    """Closed-form maps compute faster than they read back: not cached unless asked; a map
    on a profile is."""
    compute_map(**GRID, cache_dir=tmp_path)
    compute_universal_map(0.5, 0.2, 0.8, cache_dir=tmp_path)
    assert cache_entries(tmp_path) == []
    profile = ecofmaps.flat_bottomed_profile(10e-6, 50e-6)
    on_profile = dict(stiffness_ratio=[4e4, 8e4], amplitude=50e-6, mu=0.8, profile=profile)
    computed = compute_map(**on_profile, cache_dir=tmp_path)
    assert only_entry(tmp_path).function == "compute_profile_map"
    xr.testing.assert_identical(compute_map(**on_profile, cache_dir=tmp_path), computed)


def test_no_cache_writes_nothing(tmp_path):
    compute_map(**GRID, cache=False, cache_dir=tmp_path)
    assert cache_entries(tmp_path) == []
    assert list(tmp_path.iterdir()) == []


def test_directory_precedence(tmp_path, monkeypatch):
    monkeypatch.setenv("ECOFMAPS_CACHE", str(tmp_path / "environment"))
    assert cache.cache_directory() == tmp_path / "environment"
    assert cache.cache_directory(tmp_path / "argument") == tmp_path / "argument"
    compute_map(**GRID, cache=True)
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
    """A map cached before a change of the model's source is not read after it."""
    old = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    stale = only_entry(tmp_path).path
    # Make the stored entry hold something the new model would not compute.
    with xr.open_dataset(stale, engine="h5netcdf") as stored:
        tampered = stored.load()
    tampered["ecof_ratio"] = tampered["ecof_ratio"] * 2.0
    stale.write_bytes(cache._file_image(tampered))  # a valid entry of the old key
    monkeypatch.setattr(cache, "model_revision", lambda: "an edited model")
    fresh = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    xr.testing.assert_identical(fresh, old)
    assert len(cache_entries(tmp_path)) == 2  # the new revision's entry beside the old one


def recovered(tmp_path, expected, match):
    """The map read after damage: a CacheWarning matching ``match``, the map recomputed."""
    with pytest.warns(CacheWarning, match=match) as caught:
        again = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    assert all("\n" not in str(warning.message) for warning in caught)  # one line each
    xr.testing.assert_identical(again, expected)
    xr.testing.assert_identical(compute_map(**GRID, cache=True, cache_dir=tmp_path), expected)
    return again


def test_damaged_data_are_reported_removed_and_recomputed(tmp_path):
    """A value overwritten inside an array's chunk fails HDF5's Fletcher-32 checksum."""
    expected = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    path = only_entry(tmp_path).path
    content = bytearray(path.read_bytes())
    data = np.ascontiguousarray(expected["ecof_ratio"].values).tobytes()
    start = bytes(content).find(data)
    assert start > 0  # stored uncompressed, one chunk
    content[start + 8 : start + 16] = np.float64(32.5).tobytes()  # one value replaced
    path.write_bytes(bytes(content))
    recovered(tmp_path, expected, f"removed unusable cache file {path} .*filter returned failure")


def test_damaged_metadata_are_reported_removed_and_recomputed(tmp_path):
    """A letter of an attribute, or of the file's signature, changed: not served."""
    expected = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    path = only_entry(tmp_path).path
    original = path.read_bytes()
    for text, match in [(b"ECoF map of the", "metadata do not match"), (b"HDF", "signature")]:
        start = original.find(text)
        assert start >= 0, text
        content = bytearray(original)
        content[start + 1] ^= 0x01
        path.write_bytes(bytes(content))
        recovered(tmp_path, expected, f"removed unusable cache file {path} .*{match}")
        path.write_bytes(original)


@pytest.mark.slow
def test_any_flipped_byte_gives_the_map_or_a_warning(tmp_path):
    """Bytes flipped all over the file (headers, indexes, chunks, free space): each read gives
    the map itself, read or recomputed, never other values; in a child process, so that a
    crash of HDF5 fails the test rather than the run."""
    script = textwrap.dedent(
        f"""
        import warnings, numpy as np
        from ecofmaps import compute_map
        from ecofmaps.maps import cache
        grid = dict(stiffness_ratio=np.array([3e4, 7.7e4, np.inf]),
                    aspect_ratio=np.linspace(0.0, 0.7, 4), amplitude=np.array([25e-6, 50e-6]),
                    mu=0.8, load=450.0, cache=True, cache_dir={str(tmp_path)!r})
        expected = compute_map(**grid)
        path = cache.cache_entries({str(tmp_path)!r})[0].path
        original = path.read_bytes()
        warned = wrong = 0
        for offset in range(0, len(original), len(original) // 40):
            content = bytearray(original)
            content[offset] ^= 0x5A
            path.write_bytes(bytes(content))
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                wrong += not compute_map(**grid).identical(expected)
            warned += bool(caught)
        print(warned, wrong)
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=600, check=False
    )
    assert done.returncode == 0, done.stderr
    warned, wrong = map(int, done.stdout.split())
    assert wrong == 0 and warned > 0
    assert done.stderr == ""  # no "Exception ignored" from a half-opened file


def test_metadata_checksum_sees_all_but_the_chunked_values():
    dataset = compute_map(**GRID, cache=False).assign_coords(name=("amplitude", ["a", "b"]))
    checksum = cache.metadata_checksum(dataset)
    assert checksum == cache.metadata_checksum(dataset.copy(deep=True))
    changed = [
        dataset.assign_attrs(title="another"),
        dataset.rename({"ecof": "ecof2"}),
        dataset.assign(regime=dataset.regime.astype("int64")),
        dataset.assign_coords(name=("amplitude", ["a", "c"])),  # text: hashed
        dataset.assign_coords(load=451.0),  # a scalar: hashed
    ]
    ecof_ratio = dataset.ecof_ratio.copy()
    ecof_ratio.attrs["units"] = "%"
    changed.append(dataset.assign(ecof_ratio=ecof_ratio))
    for other in changed:
        assert cache.metadata_checksum(other) != checksum
    values = dataset.ecof_ratio.values.copy()
    values.flat[0] = 2.0  # in a chunk: Fletcher-32's to check
    in_chunk = (dataset.ecof_ratio.dims, values, dataset.ecof_ratio.attrs)
    assert cache.metadata_checksum(dataset.assign(ecof_ratio=in_chunk)) == checksum


def test_chunks_take_whole_trailing_dimensions_within_the_bound(monkeypatch):
    monkeypatch.setattr(cache, "_CHUNK_BYTES", 8000)  # 1000 float64
    assert cache._chunks((1000, 1000, 5, 2), 8) == (1, 100, 5, 2)
    assert cache._chunks((7, 5, 2), 8) == (7, 5, 2)
    assert cache._chunks((3, 4000), 8) == (1, 1000)
    assert cache._chunks((10**6,), 4) == (2000,)


def test_different_grids_are_different_entries(tmp_path):
    compute_map(**GRID, cache=True, cache_dir=tmp_path)
    compute_map(**{**GRID, "load": None}, cache=True, cache_dir=tmp_path)
    compute_map(**{**GRID, "mu": np.array([0.8])}, cache=True, cache_dir=tmp_path)
    assert len(cache_entries(tmp_path)) == 3


@pytest.mark.parametrize(
    "content",
    [b"", b"not a netCDF file at all", b"\x89HDF\r\n\x1a\n" + bytes(100)],
    ids=["empty", "text", "truncated-hdf5"],
)
def test_corrupt_file_is_reported_removed_and_recomputed(tmp_path, content):
    expected = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    path = only_entry(tmp_path).path
    path.write_bytes(content)
    with pytest.warns(CacheWarning, match=f"removed unusable cache file {path}"):
        recovered = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    xr.testing.assert_identical(recovered, expected)
    assert only_entry(tmp_path).path == path and path.stat().st_size > len(content)
    valid_now = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    xr.testing.assert_identical(valid_now, expected)


def test_foreign_file_is_reported_removed_and_recomputed(tmp_path):
    expected = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    path = only_entry(tmp_path).path
    xr.Dataset({"x": ("x", [1.0, 2.0])}).to_netcdf(path, engine="h5netcdf")
    with pytest.warns(CacheWarning, match="foreign file"):
        xr.testing.assert_identical(compute_map(**GRID, cache=True, cache_dir=tmp_path), expected)
    xr.testing.assert_identical(compute_map(**GRID, cache=True, cache_dir=tmp_path), expected)


def test_unwritable_cache_still_returns_the_map(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a directory")
    with pytest.warns(CacheWarning, match="could not write cache file") as caught:
        computed = compute_map(**GRID, cache=True, cache_dir=blocker / "cache")
    assert len(caught) == 1 and "\n" not in str(caught[0].message)
    xr.testing.assert_identical(computed, compute_map(**GRID, cache=False))
    assert blocker.read_text() == "not a directory"


def write_fails(tmp_path, expected_reason):
    """compute_map with the cache in ``tmp_path``: one warning, the map, nothing left."""
    before = sorted(tmp_path.iterdir())
    with pytest.warns(CacheWarning, match=f"could not write cache file .*{expected_reason}") as w:
        computed = compute_map(**GRID, cache=True, cache_dir=tmp_path)
    assert len(w) == 1 and "\n" not in str(w[0].message)
    xr.testing.assert_identical(computed, compute_map(**GRID, cache=False))
    assert sorted(tmp_path.iterdir()) == before  # no temporary, no entry


def test_a_full_disk_is_one_warning(tmp_path, monkeypatch):
    """The disk fills up half way through the entry: one line, the map, no temporary."""
    write_bytes = Path.write_bytes

    def half_then_full(self, data):
        write_bytes(self, data[: len(data) // 2])
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(self))

    monkeypatch.setattr(Path, "write_bytes", half_then_full)
    write_fails(tmp_path, "No space left on device")


def test_a_read_only_folder_is_one_warning(tmp_path):
    """A folder without write permission, or (for root, who writes there all the same) a
    read-only file system."""
    if os.geteuid() != 0:
        tmp_path.chmod(0o555)
        try:
            write_fails(tmp_path, "Permission denied")
        finally:
            tmp_path.chmod(0o755)
        return
    command = ["mount", "-t", "tmpfs", "-o", "ro,size=64k", "tmpfs", str(tmp_path)]
    if subprocess.run(command, capture_output=True, check=False).returncode != 0:
        pytest.skip("cannot mount a read-only tmpfs here")
    try:
        write_fails(tmp_path, "Read-only file system")
    finally:
        subprocess.run(["umount", str(tmp_path)], check=False)


def test_a_folder_where_the_entry_should_be_is_left_alone(tmp_path):
    compute_map(**GRID, cache=True, cache_dir=tmp_path)
    path = only_entry(tmp_path).path
    path.unlink()
    path.mkdir()
    (path / "thesis.txt").write_text("chapter 1")
    write_fails(tmp_path, "IsADirectoryError")
    assert (path / "thesis.txt").read_text() == "chapter 1"


@pytest.mark.slow
def test_a_full_tmpfs_is_one_warning_and_the_command_writes_its_output(tmp_path):
    """A real full disk: the cache on a 64 kB tmpfs with 20 kB free. ``ecofmaps map`` writes
    its output; a cached map and the explorer's start-up, whose writes fail, go on after one
    line. Skipped where mounting is not allowed."""
    tiny = tmp_path / "tiny"
    tiny.mkdir()
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(tiny)],
        capture_output=True,
        check=False,
    )
    if mounted.returncode != 0:
        pytest.skip("cannot mount a tmpfs here")
    try:
        (tiny / "filler").write_bytes(bytes(44 * 1024))
        (tiny / "cache").mkdir()
        environment = {**os.environ, "ECOFMAPS_CACHE": str(tiny / "cache")}
        environment["PYTHONPATH"] = str(Path(ecofmaps.__file__).parents[1])
        out = tmp_path / "m.nc"
        argv = ["--stiffness-ratio", "1e4:3e5:40", "--aspect-ratio", "0:0.4:40"]
        argv += ["--amplitude", "25um,50um", "--mu", "0.8", "--out", str(out)]

        def python(*arguments):
            run = [sys.executable, *arguments]
            return subprocess.run(run, env=environment, capture_output=True, text=True, timeout=600)

        done = python("-c", "from ecofmaps.cli.main import console; console()", "map", *argv)
        assert done.returncode == 0, done.stderr
        assert done.stderr == "" and done.stdout.startswith("ecofmaps map: ")
        with xr.open_dataset(out, engine="h5netcdf") as written:
            assert written.sizes["stiffness_ratio"] == 40
        assert sorted(p.name for p in (tiny / "cache").iterdir()) == []
        cached = "compute_map(1e5, numpy.linspace(0, 0.4, 1000), 50e-6, 0.8, cache=True)"
        done = python("-c", f"import numpy; from ecofmaps import compute_map; {cached}; print(1)")
        assert done.returncode == 0 and done.stdout == "1\n", done.stderr  # the write fails:
        assert done.stderr.count("\n") == 1 and "CacheWarning: could not write" in done.stderr
        assert "No space left on device" in done.stderr  # one line, and the work goes on
        assert sorted(p.name for p in (tiny / "cache").iterdir()) == []
        if importlib.util.find_spec("panel"):  # the explorer keeps its maps in memory
            done = python("-c", "from ecofmaps.web.explorer import warm_up; warm_up(); print(1)")
            assert done.returncode == 0 and done.stdout == "1\n" and done.stderr == ""
            assert sorted(p.name for p in (tiny / "cache").iterdir()) == []
    finally:
        subprocess.run(["umount", str(tiny)], check=False)


def test_the_least_recently_used_entries_go_first(tmp_path, monkeypatch):
    grids = [{**GRID, "mu": mu} for mu in (0.5, 0.6, 0.7)]
    for number, grid in enumerate(grids):
        compute_map(**grid, cache=True, cache_dir=tmp_path)
        path = max(cache_entries(tmp_path), key=lambda entry: entry.modified).path
        os.utime(path, (1e9 + number, 1e9 + number))  # used in this order, a second apart
    sizes = [entry.size for entry in cache_entries(tmp_path)]
    assert len(sizes) == 3
    first = compute_map(**grids[0], cache=True, cache_dir=tmp_path)  # read: now the latest
    monkeypatch.setenv(cache.SIZE_VARIABLE, f"{sum(sizes) + 10}B")
    kept = {entry.path.name for entry in cache_entries(tmp_path)}
    compute_map(**{**GRID, "mu": 0.9}, cache=True, cache_dir=tmp_path)  # one more
    left = {entry.path.name for entry in cache_entries(tmp_path)}
    assert len(left) == 3 and len(left - kept) == 1  # the new one, instead of ...
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # ... mu = 0.6, the least recently used: still a hit
        xr.testing.assert_identical(compute_map(**grids[0], cache=True, cache_dir=tmp_path), first)
    assert {entry.path.name for entry in cache_entries(tmp_path)} == left
    compute_map(**grids[1], cache=True, cache_dir=tmp_path)  # a miss: it was removed
    assert {entry.path.name for entry in cache_entries(tmp_path)} != left
    other = tmp_path / "notes.nc"
    other.write_text("not an entry: never removed")
    monkeypatch.setenv(cache.SIZE_VARIABLE, "0")  # store nothing
    compute_map(**{**GRID, "mu": 0.95}, cache=True, cache_dir=tmp_path)
    assert len(cache_entries(tmp_path)) == 3 and other.read_text().startswith("not an entry")


@pytest.mark.parametrize(
    ("text", "size"),
    [
        ("", 10**9),
        ("0", 0),
        ("12345", 12345),
        ("500MB", 5 * 10**8),
        ("1.5 GB", 1.5e9),
        ("2GiB", 2**31),
        ("64kB", 64000),
    ],
)
def test_the_size_bound_is_read_from_the_environment(monkeypatch, text, size):
    monkeypatch.setenv(cache.SIZE_VARIABLE, text)
    assert cache.cache_size_bound() == size


@pytest.mark.parametrize("text", ["lots", "-1GB", "5 parsecs", "1.2.3MB"])
def test_a_bad_size_bound_is_named(tmp_path, monkeypatch, text):
    monkeypatch.setenv(cache.SIZE_VARIABLE, text)
    with pytest.raises(ValueError, match=f"ECOFMAPS_CACHE_SIZE='{text}' is not a size"):
        compute_map(**GRID, cache=True, cache_dir=tmp_path)


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
        entry = dataset.assign_attrs(ecofmaps_cache_key=key)
        cache.write_netcdf(entry, directory / "race.nc", exclusive=False)
        compute_map(**GRID, cache=True, cache_dir=directory)


@pytest.mark.slow
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
    xr.testing.assert_identical(compute_map(**GRID, cache=True, cache_dir=tmp_path), expected)
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


def test_clear_removes_entries_and_leftovers_only(tmp_path):
    compute_map(**GRID, cache=True, cache_dir=tmp_path)
    compute_universal_map(0.5, 0.2, 0.8, cache=True, cache_dir=tmp_path)
    leftover = tmp_path / f".compute_map-{'0' * 32}.nc.{'a' * 32}.tmp"
    leftover.write_bytes(b"half")
    unrelated = tmp_path / "notes.nc"
    unrelated.write_text("keep me")
    (tmp_path / "jax").mkdir()  # JAX's kernels, one cut short by a full disk: never repaired
    (tmp_path / "jax" / f"jit__map_kernel-{'0' * 64}-cache").write_bytes(b"cut")
    (tmp_path / "jax" / "notes.txt").write_text("keep me")
    sizes = sum(e.size for e in cache_entries(tmp_path)) + 4 + 3
    assert [e.function for e in cache_entries(tmp_path)] == ["compute_map", "compute_universal_map"]
    assert clear_cache(tmp_path) == (4, sizes)
    assert cache_entries(tmp_path) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["jax", "notes.nc"]
    assert [p.name for p in (tmp_path / "jax").iterdir()] == ["notes.txt"]
    assert clear_cache(tmp_path) == (0, 0)
    assert clear_cache(tmp_path / "missing") == (0, 0)
    assert cache_entries(tmp_path / "missing") == []
    assert os.path.exists(unrelated)
