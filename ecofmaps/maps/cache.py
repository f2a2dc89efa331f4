"""The disk cache of costly results: a netCDF file ``<function>-<key>.nc`` each, its arrays in
Fletcher-32 checksummed chunks, the rest under :func:`metadata_checksum` (docs/performance.md)."""

from __future__ import annotations

import contextlib
import functools
import gc
import hashlib
import os
import re
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import platformdirs
import xarray as xr

from ecofmaps._codes import warn
from ecofmaps._version import __version__
from ecofmaps.io.files import TEMPORARY_NAME, atomic_path, check_room

#: Environment variable that overrides the per-user cache directory.
ENVIRONMENT_VARIABLE = "ECOFMAPS_CACHE"

#: The folder of the cache where ``ecofmaps figures`` has JAX keep its compiled kernels.
JAX_CACHE_FOLDER = "jax"

#: Environment variable that sets the bound on the cache's size (``500MB``, ``2GB``, ``0``).
SIZE_VARIABLE = "ECOFMAPS_CACHE_SIZE"

#: The bound on the cache's total size when :data:`SIZE_VARIABLE` is not set. [byte]
DEFAULT_SIZE_BOUND = 10**9

# Global attributes that tie a cache file to its key and its metadata; removed on reading.
_KEY_ATTRIBUTE = "ecofmaps_cache_key"
_CHECKSUM_ATTRIBUTE = "ecofmaps_metadata_sha256"
# The sources, relative to the package, whose code decides what a cached map holds.
_MODEL_SOURCES = (
    "model/*.py",
    "maps/grid.py",
    "maps/tiles.py",
    "maps/dataset.py",
    "_nomenclature.py",
    "paper.py",
)
# Length of the key in file names: 128 bits of the hash.
_NAME_DIGITS = 32
_ENTRY = re.compile(rf"^(?P<function>[A-Za-z_][A-Za-z0-9_]*)-[0-9a-f]{{{_NAME_DIGITS}}}\.nc$")
# JAX's files of a compiled kernel: <name>-<sha256>-cache, and its last use, -atime.
_JAX_ENTRY = re.compile(r"^.+-[0-9a-f]{64}-(cache|atime)$")
# Largest chunk of an array, each with its own Fletcher-32 checksum. [byte]
_CHUNK_BYTES = 2**22
# Array types whose chunks carry a checksum; the values of the others (text) are hashed.
_CHUNKED_KINDS = "biufcmM"
# Sizes in ECOFMAPS_CACHE_SIZE: a number and an optional unit.
_SIZE = re.compile(r"^\s*(?P<number>[0-9.]+(?:e[0-9]+)?)\s*(?P<unit>[kMGT]i?B|B)?\s*$")
_UNITS = {"B": 1, "kB": 10**3, "MB": 10**6, "GB": 10**9, "TB": 10**12}
_UNITS.update({"KiB": 2**10, "kiB": 2**10, "MiB": 2**20, "GiB": 2**30, "TiB": 2**40})


class CacheWarning(UserWarning):
    """A cache file could not be used or written; the result is recomputed, or not stored."""


@dataclass(frozen=True)
class CacheEntry:
    """One file of the cache: its function, size [byte], last write and last use (UTC)."""

    path: Path
    function: str
    size: int
    modified: datetime
    used: datetime


def cache_directory(cache_dir=None) -> Path:
    """The cache directory: ``cache_dir``, else ``$ECOFMAPS_CACHE``, else the user's."""
    if cache_dir is not None:
        return Path(cache_dir)
    return Path(os.environ.get(ENVIRONMENT_VARIABLE) or platformdirs.user_cache_dir("ecofmaps"))


def cache_size_bound() -> int:
    """The bytes the cache may take (0 stores nothing): ``$ECOFMAPS_CACHE_SIZE``, else 1 GB."""
    text = os.environ.get(SIZE_VARIABLE, "").strip()
    if not text:
        return DEFAULT_SIZE_BOUND
    found = _SIZE.match(text)
    if found is None or found["number"].count(".") > 1:
        raise ValueError(
            f"{SIZE_VARIABLE}={text!r} is not a size: give bytes, or a number with a unit "
            f"among {', '.join(_UNITS)} (e.g. 500MB)"
        )
    return int(float(found["number"]) * _UNITS[found["unit"] or "B"])


@functools.cache
def model_revision() -> str:
    """SHA-256 (hex) of the source of the modules that compute maps."""
    package = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for pattern in _MODEL_SOURCES:
        for path in sorted(package.glob(pattern)):
            digest.update(f"{path.relative_to(package).as_posix()}\0".encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def _chunked(variable: xr.Variable) -> bool:
    return variable.ndim > 0 and variable.size > 0 and variable.dtype.kind in _CHUNKED_KINDS


def metadata_checksum(dataset: xr.Dataset) -> str:
    """SHA-256 (hex) of all that the chunks' checksums do not cover."""
    digest = hashlib.sha256()

    def add(*parts) -> None:
        for part in parts:
            digest.update(f"{part!s}\0".encode())

    def add_attributes(attributes: Mapping) -> None:
        for name in sorted(map(str, attributes)):
            if name != _CHECKSUM_ATTRIBUTE:
                add(name, np.asarray(attributes[name]).tolist())

    add_attributes(dataset.attrs)
    for name in sorted(map(str, dataset.variables)):
        variable = dataset.variables[name]
        add(name, variable.dims, variable.dtype.str, variable.shape)
        add_attributes(variable.attrs)
        if not _chunked(variable):
            add(np.asarray(variable.values).tolist())
    return digest.hexdigest()


def cache_key(function: str, inputs: Mapping[str, object]) -> str:
    """SHA-256 key (hex) of version, model revision, ``function`` and ``inputs`` (float64 bytes)."""
    digest = hashlib.sha256(f"ecofmaps {__version__}\0{model_revision()}\0{function}\0".encode())
    for name, value in inputs.items():
        digest.update(f"{name}\0".encode())
        if value is None:
            digest.update(b"None\0")
            continue
        array = np.asarray(value, dtype="<f8")  # not ascontiguousarray: it makes 0-d 1-d
        digest.update(f"{array.shape}\0".encode())
        digest.update(array.tobytes(order="C"))
    return digest.hexdigest()


def write_netcdf(dataset: xr.Dataset, path, *, exclusive: bool = True) -> Path:
    """``path``, where ``dataset`` is written as netCDF atomically (or left as it was)."""
    path = Path(path)
    with atomic_path(path, exclusive=exclusive) as temporary:
        check_room(temporary, dataset.nbytes)
        dataset.to_netcdf(temporary, engine="h5netcdf")
    return path


def _chunks(shape: tuple[int, ...], itemsize: int) -> tuple[int, ...]:
    """Chunk shape of at most :data:`_CHUNK_BYTES`: whole trailing dimensions, then rows."""
    room = max(1, _CHUNK_BYTES // itemsize)  # elements a chunk may hold
    chunks = []
    for length in reversed(shape):
        chunks.append(max(1, min(length, room)))
        room //= length
    return tuple(reversed(chunks))


def _file_image(dataset: xr.Dataset) -> bytes:
    """``dataset``'s checksummed netCDF file, built in memory (no half-written file is left)."""
    import h5netcdf
    import h5py

    encoding = {
        name: {"fletcher32": True, "chunksizes": _chunks(variable.shape, variable.dtype.itemsize)}
        for name, variable in dataset.variables.items()
        if _chunked(variable)
    }
    memory = h5py.File(
        "cache entry", "w", driver="core", backing_store=False, track_order=True, libver="v110"
    )
    try:
        with h5netcdf.File(memory, "w") as netcdf:  # leaves `memory` open
            dataset.dump_to_store(xr.backends.H5NetCDFStore(netcdf, mode="w"), encoding=encoding)
            written = xr.open_dataset(xr.backends.H5NetCDFStore(netcdf, mode="r"))
            netcdf.attrs[_CHECKSUM_ATTRIBUTE] = metadata_checksum(written)
        memory.flush()
        return memory.id.get_file_image()
    finally:
        memory.close()


def _read(path: Path, key: str) -> xr.Dataset:
    """The dataset stored under ``key`` at ``path``; ``ValueError`` if foreign or damaged."""
    with xr.open_dataset(path, engine="h5netcdf") as stored:
        dataset = stored.load()
    if dataset.attrs.get(_KEY_ATTRIBUTE) != key:
        raise ValueError("it is not the cache entry of this computation (foreign file)")
    if dataset.attrs.get(_CHECKSUM_ATTRIBUTE) != metadata_checksum(dataset):
        raise ValueError("its metadata do not match their checksum (the file is damaged)")
    private = (_KEY_ATTRIBUTE, _CHECKSUM_ATTRIBUTE)
    dataset.attrs = {name: v for name, v in dataset.attrs.items() if name not in private}
    for variable in dataset.variables.values():  # not the cache's storage
        variable.encoding = {}
    return dataset


def _stored(path: Path, key: str) -> xr.Dataset | None:
    """The dataset stored at ``path``, or None: an unusable one is removed, with one warning."""
    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: None  # finalizers of half-opened HDF5 objects
    try:
        try:
            return _read(path, key)
        except FileNotFoundError:  # removed meanwhile by another process
            return None
        except Exception as error:  # any unreadable file is recomputed, whatever h5py says
            reason = _reason(error)
        gc.collect()  # the half-opened objects, while their finalizers are quiet
    finally:
        sys.unraisablehook = hook
    warn(f"removed unusable cache file {path} ({reason}); recomputing", CacheWarning)
    path.unlink(missing_ok=True)
    return None


def _reason(error: BaseException) -> str:
    text = " ".join(str(error).split()) or "no reason given"
    if isinstance(error, OSError) and error.strerror:
        text = error.strerror  # h5py's messages run over several lines with their buffers
    return f"{type(error).__name__}: {text}"


def _store(dataset: xr.Dataset, path: Path, key: str, bound: int) -> None:
    """Store ``dataset`` if it fits in ``bound`` [byte], evicting the least recently used others."""
    if dataset.nbytes > bound:
        return
    image = _file_image(dataset.assign_attrs({_KEY_ATTRIBUTE: key}))
    if len(image) > bound:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path, exclusive=False) as temporary:  # the same entry, whoever wins
        temporary.write_bytes(image)
    entries = sorted(cache_entries(path.parent), key=lambda entry: entry.used)
    total = sum(entry.size for entry in entries)
    for entry in entries:
        if total <= bound:
            break
        if entry.path != path:
            entry.path.unlink(missing_ok=True)
            total -= entry.size


def cached_dataset(
    function: str, inputs: Mapping[str, object], compute: Callable[[], xr.Dataset], cache_dir=None
) -> xr.Dataset:
    """``compute()``, from the cache under the key of ``function`` and ``inputs``, or stored."""
    bound = cache_size_bound()  # a bad ECOFMAPS_CACHE_SIZE is refused before any work
    key = cache_key(function, inputs)
    path = cache_directory(cache_dir) / f"{function}-{key[:_NAME_DIGITS]}.nc"
    dataset = _stored(path, key) if path.is_file() else None  # not a folder of the user's
    if dataset is not None:
        with contextlib.suppress(OSError):  # the access time orders eviction; only a hint
            os.utime(path, ns=(time.time_ns(), path.stat().st_mtime_ns))
        return dataset
    dataset = compute()
    try:
        _store(dataset, path, key, bound)
    except Exception as error:  # whatever the reason, the result is returned all the same
        warn(f"could not write cache file {path} ({_reason(error)})", CacheWarning)
    return dataset


def _files(directory: Path, pattern: re.Pattern) -> list[Path]:
    if not directory.is_dir():
        return []
    return sorted(p for p in directory.iterdir() if pattern.match(p.name) and p.is_file())


def cache_entries(cache_dir=None) -> list[CacheEntry]:
    """The files in the cache, sorted by name.

    Parameters
    ----------
    cache_dir : str or os.PathLike, optional
        See :func:`cache_directory`.

    Returns
    -------
    entries : list of CacheEntry
        The files named ``<function>-<32 hex digits>.nc`` (no other file in the directory).
    """
    entries = []
    for path in _files(cache_directory(cache_dir), _ENTRY):
        try:
            status = path.stat()
        except FileNotFoundError:  # removed meanwhile by another process
            continue
        times = (status.st_mtime, max(status.st_atime, status.st_mtime))
        modified, used = (datetime.fromtimestamp(t, tz=UTC) for t in times)
        function = _ENTRY.match(path.name)["function"]
        entries.append(CacheEntry(path, function, status.st_size, modified, used))
    return entries


def clear_cache(cache_dir=None) -> tuple[int, int]:
    """Remove every cache entry, JAX's compiled kernels (a write cut short by a full disk is
    never repaired by JAX), and temporary files left by interrupted writes (no other file).

    Parameters
    ----------
    cache_dir : str or os.PathLike, optional
        See :func:`cache_directory`.

    Returns
    -------
    count : int
        Number of files removed.
    size : int
        Their total size. [byte]
    """
    directory = cache_directory(cache_dir)
    count = size = 0
    kernels = _files(directory / JAX_CACHE_FOLDER, _JAX_ENTRY)
    for path in _files(directory, _ENTRY) + _files(directory, TEMPORARY_NAME) + kernels:
        try:
            file_size = path.stat().st_size
            path.unlink()
        except FileNotFoundError:  # removed meanwhile by another process
            continue
        count += 1
        size += file_size
    return count, size
