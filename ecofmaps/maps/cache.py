"""The disk cache of computed maps: netCDF files keyed by the grid and the package version.

A map is stored as one netCDF file (engine h5netcdf) named ``<function>-<key>.nc``, where the
key is a SHA-256 hash of the package version, the function's name and the exact float64 bytes
(and shapes) of every input. The directory is, in order of precedence, the ``cache_dir``
argument, the ``ECOFMAPS_CACHE`` environment variable, or the per-user cache directory
(``platformdirs.user_cache_dir("ecofmaps")``).

Files are written atomically (a temporary file in the same directory, then ``os.replace``),
so a reader never sees a half-written file and two processes writing the same entry leave one
valid file. A file that cannot be read, or that holds another key, is reported with a
:class:`CacheWarning`, removed and recomputed.
"""

from __future__ import annotations

import hashlib
import os
import re
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import platformdirs
import xarray as xr

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
    "write_netcdf",
]

#: Environment variable that overrides the per-user cache directory.
ENVIRONMENT_VARIABLE = "ECOFMAPS_CACHE"

# The global attribute that ties a cache file to its key; removed again on reading.
_KEY_ATTRIBUTE = "ecofmaps_cache_key"
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


def cache_key(function: str, inputs: Mapping[str, object]) -> str:
    """SHA-256 key of a computation: package version, function name, exact input values.

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
    from ecofmaps import __version__

    digest = hashlib.sha256(f"ecofmaps {__version__}\0{function}\0".encode())
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
    dataset.attrs = {name: v for name, v in dataset.attrs.items() if name != _KEY_ATTRIBUTE}
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
            warnings.warn(
                f"removed unusable cache file {path} ({type(error).__name__}: {error}); "
                "recomputing",
                CacheWarning,
                stacklevel=3,
            )
            path.unlink(missing_ok=True)
    dataset = compute()
    try:
        directory.mkdir(parents=True, exist_ok=True)
        write_netcdf(dataset.assign_attrs({_KEY_ATTRIBUTE: key}), path)
    except OSError as error:
        warnings.warn(f"could not write cache file {path}: {error}", CacheWarning, stacklevel=3)
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
