"""The disk cache of computed maps: netCDF files keyed by the grid and the model's revision.

A map is stored as one netCDF file (engine h5netcdf) named ``<function>-<key>.nc``, where the
key is a SHA-256 hash of the package version, the model's revision (a hash of the source of
the modules that compute maps, :func:`model_revision`, so an edited model never serves a
stale map), the function's name and the exact float64 bytes (and shapes) of every input. The
directory is, in order of precedence, the ``cache_dir`` argument, the ``ECOFMAPS_CACHE``
environment variable, or the per-user cache directory (``platformdirs.user_cache_dir``).

Files are written atomically (a temporary file in the same directory, then ``os.replace``),
so a reader never sees a half-written file and two processes writing the same entry leave one
valid file. Each file also holds a SHA-256 checksum of its data (every variable's and
coordinate's values, dtype and shape), verified when it is read. A file that cannot be read,
that holds another key, or whose data do not match their checksum (damaged on disk) is
reported with a :class:`CacheWarning`, removed and recomputed.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import platformdirs
import xarray as xr

from ecofmaps._codes import warn
from ecofmaps._version import __version__
from ecofmaps.io.files import TEMPORARY_NAME, atomic_path

__all__ = [
    "ENVIRONMENT_VARIABLE",
    "CacheEntry",
    "CacheWarning",
    "cache_directory",
    "cache_entries",
    "cache_key",
    "cached_dataset",
    "clear_cache",
    "data_checksum",
    "model_revision",
    "write_netcdf",
]

#: Environment variable that overrides the per-user cache directory.
ENVIRONMENT_VARIABLE = "ECOFMAPS_CACHE"

# The global attributes that tie a cache file to its key and to its data; removed on reading.
_KEY_ATTRIBUTE = "ecofmaps_cache_key"
_CHECKSUM_ATTRIBUTE = "ecofmaps_data_sha256"
# The sources, relative to the package, whose code decides what a cached map holds.
_MODEL_SOURCES = (
    "model/*.py",
    "maps/grid.py",
    "maps/tiles.py",
    "maps/dataset.py",
    "maps/on_profile.py",
    "_nomenclature.py",
    "paper.py",
)
# Length of the key in file names: 128 bits of the hash.
_NAME_DIGITS = 32
_ENTRY = re.compile(rf"^(?P<function>[A-Za-z_][A-Za-z0-9_]*)-[0-9a-f]{{{_NAME_DIGITS}}}\.nc$")


class CacheWarning(UserWarning):
    """A cache file could not be used (unreadable, foreign) or written; the map is recomputed."""


@dataclass(frozen=True)
class CacheEntry:
    """One file of the cache.

    Attributes
    ----------
    path : pathlib.Path
        The netCDF file.
    function : str
        The function whose result it holds (``compute_map``, ...).
    size : int
        File size. [byte]
    modified : datetime.datetime
        Time of the last write (UTC).
    """

    path: Path
    function: str
    size: int
    modified: datetime


def cache_directory(cache_dir=None) -> Path:
    """The cache directory in use (it need not exist yet).

    Parameters
    ----------
    cache_dir : str or os.PathLike, optional
        An explicit directory; by default the ``ECOFMAPS_CACHE`` environment variable, else
        ``platformdirs.user_cache_dir("ecofmaps")``.

    Returns
    -------
    directory : pathlib.Path
    """
    if cache_dir is not None:
        return Path(cache_dir)
    environment = os.environ.get(ENVIRONMENT_VARIABLE)
    if environment:
        return Path(environment)
    return Path(platformdirs.user_cache_dir("ecofmaps"))


@functools.cache
def model_revision() -> str:
    """SHA-256 of the source of the modules that compute maps (the model, the grid, the names).

    Returns
    -------
    revision : str
        64 hexadecimal digits; any edit of those files gives another revision, and so other
        cache keys.
    """
    package = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for pattern in _MODEL_SOURCES:
        for path in sorted(package.glob(pattern)):
            digest.update(f"{path.relative_to(package).as_posix()}\0".encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def data_checksum(dataset: xr.Dataset) -> str:
    """SHA-256 of a Dataset's data: every variable's and coordinate's name, dtype, shape, values.

    Parameters
    ----------
    dataset : xarray.Dataset

    Returns
    -------
    checksum : str
        64 hexadecimal digits. Attributes are not included.
    """
    digest = hashlib.sha256()
    for name in sorted(map(str, dataset.variables)):
        values = np.asarray(dataset[name].values)
        if values.dtype.kind in "OUS":  # text: its characters
            values = np.asarray(values.astype(str), dtype="U")
        digest.update(f"{name}\0{values.dtype.str}\0{values.shape}\0".encode())
        digest.update(np.ascontiguousarray(values).tobytes())
    return digest.hexdigest()


def cache_key(function: str, inputs: Mapping[str, object]) -> str:
    """SHA-256 key of a computation: version, model revision, function, exact input values.

    Parameters
    ----------
    function : str
        Name of the function computing the result.
    inputs : mapping of str to array_like or None
        Every input that the result depends on, by name. Values are hashed as little-endian
        float64 bytes together with their shape, so a scalar and a one-element array differ.

    Returns
    -------
    key : str
        64 hexadecimal digits.
    """
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


def write_netcdf(dataset: xr.Dataset, path) -> Path:
    """Write ``dataset`` to ``path`` (engine h5netcdf) atomically.

    The data go to a temporary file in the same directory, are flushed to disk, and the file
    is then renamed onto ``path`` (``os.replace``). On any failure the temporary file is
    removed and ``path`` is left as it was.

    Parameters
    ----------
    dataset : xarray.Dataset
        The data to write.
    path : str or os.PathLike
        The netCDF file to create or replace; its directory must exist.

    Returns
    -------
    path : pathlib.Path
    """
    path = Path(path)
    with atomic_path(path) as temporary:
        dataset.to_netcdf(temporary, engine="h5netcdf")
    return path


def _read(path: Path, key: str) -> xr.Dataset:
    """The dataset stored under ``key`` at ``path``; ``ValueError`` if it holds another key."""
    with xr.open_dataset(path, engine="h5netcdf") as stored:
        dataset = stored.load()
    if dataset.attrs.get(_KEY_ATTRIBUTE) != key:
        raise ValueError("it is not the cache entry of this computation (foreign file)")
    if dataset.attrs.get(_CHECKSUM_ATTRIBUTE) != data_checksum(dataset):
        raise ValueError("its data do not match their checksum (the file is damaged)")
    private = (_KEY_ATTRIBUTE, _CHECKSUM_ATTRIBUTE)
    dataset.attrs = {name: v for name, v in dataset.attrs.items() if name not in private}
    return dataset


def cached_dataset(
    function: str,
    inputs: Mapping[str, object],
    compute: Callable[[], xr.Dataset],
    cache_dir=None,
) -> xr.Dataset:
    """The cached result of ``compute()``, computing and storing it on a miss.

    Parameters
    ----------
    function : str
        Name of the computing function (a valid Python identifier), part of the key and
        of the file name.
    inputs : mapping of str to array_like or None
        Everything the result depends on (see :func:`cache_key`).
    compute : callable
        Called without arguments on a miss; returns the dataset.
    cache_dir : str or os.PathLike, optional
        See :func:`cache_directory`.

    Returns
    -------
    dataset : xarray.Dataset
        Identical (``xarray.testing.assert_identical``) whether read or computed.

    Warns
    -----
    CacheWarning
        When the file is unreadable or foreign (it is removed and the result recomputed),
        or when the result cannot be written (it is returned all the same).
    """
    directory = cache_directory(cache_dir)
    key = cache_key(function, inputs)
    path = directory / f"{function}-{key[:_NAME_DIGITS]}.nc"
    if path.exists():
        try:
            return _read(path, key)
        except Exception as error:  # any unreadable file is recomputed, whatever h5py says
            warn(
                f"removed unusable cache file {path} ({type(error).__name__}: {error}); "
                "recomputing",
                CacheWarning,
            )
            path.unlink(missing_ok=True)
    dataset = compute()
    try:
        directory.mkdir(parents=True, exist_ok=True)
        stamps = {_KEY_ATTRIBUTE: key, _CHECKSUM_ATTRIBUTE: data_checksum(dataset)}
        write_netcdf(dataset.assign_attrs(stamps), path)
    except OSError as error:
        warn(f"could not write cache file {path}: {error}", CacheWarning)
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
        Only files named like cache entries (``<function>-<32 hex digits>.nc``); other
        files in the directory are ignored.
    """
    entries = []
    for path in _files(cache_directory(cache_dir), _ENTRY):
        try:
            status = path.stat()
        except FileNotFoundError:  # removed meanwhile by another process
            continue
        entries.append(
            CacheEntry(
                path=path,
                function=_ENTRY.match(path.name)["function"],
                size=status.st_size,
                modified=datetime.fromtimestamp(status.st_mtime, tz=UTC),
            )
        )
    return entries


def clear_cache(cache_dir=None) -> tuple[int, int]:
    """Remove every cache entry, and temporary files left by interrupted writes.

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

    Notes
    -----
    Other files in the directory (not named like cache entries) are left alone.
    """
    directory = cache_directory(cache_dir)
    count = size = 0
    for path in _files(directory, _ENTRY) + _files(directory, TEMPORARY_NAME):
        try:
            file_size = path.stat().st_size
            path.unlink()
        except FileNotFoundError:  # removed meanwhile by another process
            continue
        count += 1
        size += file_size
    return count, size
