"""HDF5 and netCDF-4 files as xarray Datasets, through xarray's ``h5netcdf`` engine.

Each group of the file is one lazily read :class:`xarray.Dataset`; xarray decodes the CF
attributes (``scale_factor``, ``add_offset``, ``_FillValue``/``missing_value`` -> NaN) and
the text of attributes. A plain HDF5 file, whose datasets have no netCDF dimensions, is read
with xarray's "phony" dimensions (``phony_dim_0``, ...). Times are left as numbers. A
truncated or damaged file is refused when it is opened (HDF5 checks its own length and its
metadata's checksums), with a :class:`~ecofmaps.io.recording_types.RecordingError` naming
the file as damaged.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import xarray as xr

from ecofmaps.io.recording_types import RecordingError

__all__ = ["hdf5_groups", "open_hdf5_group"]

#: xarray's options for every opening: CF packing and fill values decoded, numbers left as
#: numbers, no copy of a whole variable kept in memory once read, and no lock of xarray's
#: (one for all HDF5 files of the process: h5py already serialises its calls, each reader
#: of :mod:`ecofmaps.io.binary` holds a lock of its own, and a forked process could inherit
#: that one held by a thread of its parent for good).
OPTIONS = {
    "engine": "h5netcdf",
    "lock": False,
    "phony_dims": "access",
    "mask_and_scale": True,
    "decode_times": False,
    "decode_timedelta": False,
    "decode_coords": False,
    "cache": False,
}


#: What h5py raises for a file whose structure is damaged (a flipped byte in a header).
_DAMAGE = (OSError, KeyError, RuntimeError, ValueError, TypeError)


def _refused(path: Path, error: Exception) -> RecordingError:
    reason = str(error).strip("'\"")  # a KeyError's text comes quoted
    return RecordingError(path, None, f"cannot open as HDF5 (truncated or damaged): {reason}")


def _checked(path) -> Path:
    """The path, once every group's and variable's attributes opened with h5py: a damaged
    file raises here, cleanly (h5netcdf would raise anything from KeyError to RuntimeError,
    and its half-made file object print a traceback when it is collected)."""

    def visit(_name, item):
        for name in item.attrs:
            item.attrs.get_id(name)

    path = Path(path)
    try:
        with h5py.File(path, "r") as handle:
            visit("/", handle)
            handle.visititems(visit)
    except _DAMAGE as error:
        raise _refused(path, error) from None
    return path


def hdf5_groups(path) -> dict[str, xr.Dataset]:
    """Every group of an HDF5 / netCDF-4 file as a lazily read Dataset, by its path
    (``'/'``, ``'/rig/run1'``)."""
    path = _checked(path)
    try:
        return xr.open_groups(path, **OPTIONS)
    except _DAMAGE as error:
        raise _refused(path, error) from None


def open_hdf5_group(path, group: str | None = None) -> xr.Dataset:
    """One group of an HDF5 / netCDF-4 file (by default the root) as a lazily read Dataset."""
    path = _checked(path)
    try:
        return xr.open_dataset(path, group=group or None, **OPTIONS)
    except OSError as error:
        if "not found" in str(error).lower() and group:
            raise RecordingError(path, None, f"no group {group!r}") from None
        raise _refused(path, error) from None
