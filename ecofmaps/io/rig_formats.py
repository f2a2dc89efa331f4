"""The rig formats' channels and variables: TDMS (:mod:`ecofmaps.io.tdms`), HDF5 / netCDF-4
and zarr (through xarray's ``h5netcdf`` and ``zarr`` engines), each group a lazily read
Dataset, CF attributes decoded, times left as numbers, arrays without dimension names read
over "phony" dimensions, a damaged file refused when opened. :mod:`ecofmaps.io.binary` reads
the samples; ``docs/formats.md`` describes the formats.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import h5py
import numpy as np
import xarray as xr
from xarray.backends import BackendArray
from xarray.core import indexing

from ecofmaps.io.recording_types import RecordingError
from ecofmaps.io.tdms import open_tdms_group, tdms_groups

__all__ = ["NOUNS", "Variable", "check_complete", "open_group", "variables"]

#: What each rig format calls a column, for messages.
NOUNS = {"tdms": "channel", "hdf5": "variable", "zarr": "variable"}

#: Attributes that give a variable's unit, in the order they are looked at.
UNIT_ATTRIBUTES = ("units", "unit", "Units", "Unit", "unit_string", "NI_UnitDescription")

#: xarray's decoding: CF packing and fill values decoded, numbers left as numbers.
_DECODING = dict(
    mask_and_scale=True, decode_times=False, decode_timedelta=False, decode_coords=False
)

#: xarray's options for HDF5: no copy of a whole variable kept in memory once read, and no
#: lock of xarray's (one for all HDF5 files of the process: h5py already serialises its
#: calls, each reader of :mod:`ecofmaps.io.binary` holds a lock of its own, and a forked
#: process could inherit that one held by a thread of its parent for good).
_HDF5 = {"engine": "h5netcdf", "lock": False, "phony_dims": "access", "cache": False, **_DECODING}

#: xarray's options for zarr: lazily indexed arrays (no dask), no copy kept once read.
_ZARR = {"engine": "zarr", "chunks": None, "cache": False, **_DECODING}

#: What h5py raises for a file whose structure is damaged (a flipped byte in a header).
_DAMAGE = (OSError, KeyError, RuntimeError, ValueError, TypeError)

_NO_DIMENSIONS = ("dimension_names", "_ARRAY_DIMENSIONS")


@dataclasses.dataclass(frozen=True)
class Variable:
    """A one-dimensional channel or variable of a rig file."""

    name: str
    group: str
    short: str
    size: int
    units: tuple = ()
    chunk: int = 0


def _hdf5_refused(path: Path, error: Exception) -> RecordingError:
    reason = str(error).strip("'\"")  # a KeyError's text comes quoted
    return RecordingError(path, None, f"cannot open as HDF5 (truncated or damaged): {reason}")


def _checked_hdf5(path: Path) -> None:
    """Open every group's and variable's attributes with h5py: a damaged file raises here,
    cleanly (h5netcdf would raise anything from KeyError to RuntimeError, and its half-made
    file object print a traceback when it is collected)."""

    def visit(_name, item):
        for name in item.attrs:
            item.attrs.get_id(name)

    try:
        with h5py.File(path, "r") as handle:
            visit("/", handle)
            handle.visititems(visit)
    except _DAMAGE as error:
        raise _hdf5_refused(path, error) from None


def _hdf5_groups(path: Path) -> dict[str, xr.Dataset]:
    _checked_hdf5(path)
    try:
        return xr.open_groups(path, **_HDF5)
    except _DAMAGE as error:
        raise _hdf5_refused(path, error) from None


def _hdf5_group(path: Path, group: str | None) -> xr.Dataset:
    _checked_hdf5(path)
    try:
        return xr.open_dataset(path, group=group, **_HDF5)
    except OSError as error:
        if "not found" in str(error).lower() and group:
            raise RecordingError(path, None, f"no group {group!r}") from None
        raise _hdf5_refused(path, error) from None


def _zarr_root(path: Path):
    import zarr  # here, not on import: xarray loads this module with its engines (0.3-1 s)

    try:
        return zarr.open(store=str(path), mode="r")
    except Exception as error:
        raise RecordingError(path, None, f"cannot open as a zarr store: {error}") from None


class _ZarrRange(BackendArray):
    """A zarr array as a lazily indexed array (slices and indices read only their chunks)."""

    def __init__(self, array):
        self.array, self.shape, self.dtype = array, array.shape, array.dtype

    def __getitem__(self, key):
        return indexing.explicit_indexing_adapter(
            key, self.shape, indexing.IndexingSupport.BASIC, self.array.__getitem__
        )


def _plain_zarr_groups(path: Path, root) -> dict[str, xr.Dataset]:
    """The groups of a store without dimension names (read over phony dimensions)."""
    import zarr  # as in _zarr_root

    members = [("", root)] if isinstance(root, zarr.Array) else list(root.members(max_depth=None))
    groups = {"/": {}}
    groups.update({"/" + name: {} for name, item in members if isinstance(item, zarr.Group)})
    lengths: list[int] = []
    for name, item in members:
        if not isinstance(item, zarr.Array) or item.ndim != 1:
            continue
        group, _, short = (name or path.stem).rpartition("/")
        size = int(item.shape[0])
        lengths += [] if size in lengths else [size]
        data = indexing.LazilyIndexedArray(_ZarrRange(item))
        variable = xr.Variable((f"phony_dim_{lengths.index(size)}",), data, dict(item.attrs))
        variable.encoding["chunks"] = tuple(item.chunks)
        groups["/" + group][short] = variable
    return {name: xr.decode_cf(xr.Dataset(found), **_DECODING) for name, found in groups.items()}


def _xarray_zarr_groups(path: Path, root, key: str | None = None) -> dict | None:
    """The groups xarray opens (all, or the one at ``key``); None for a store without
    dimension names."""
    consolidated = root.metadata.consolidated_metadata is not None  # else xarray looks
    try:
        if key is None:
            return xr.open_groups(path, consolidated=consolidated, **_ZARR)
        return {key: xr.open_dataset(path, group=key, consolidated=consolidated, **_ZARR)}
    except Exception as error:
        if isinstance(error, KeyError) and any(name in str(error) for name in _NO_DIMENSIONS):
            return None
        raise RecordingError(path, None, f"cannot open as a zarr store: {error}") from None


def _zarr_groups(path: Path, key: str | None = None) -> dict[str, xr.Dataset]:
    """The groups of a store (all, or the one at ``key``), by path (``'/'``, ``'/rig/run1'``)."""
    root = _zarr_root(path)
    groups = _xarray_zarr_groups(path, root, key) if hasattr(root, "members") else None
    return _plain_zarr_groups(path, root) if groups is None else groups


def _zarr_group(path: Path, group: str | None) -> xr.Dataset:
    key = "/" + (group or "").strip("/")
    groups = _zarr_groups(path, key)
    if key not in groups:
        raise RecordingError(path, None, f"no group {group!r}")
    return groups[key]


_GROUPS = {"tdms": tdms_groups, "hdf5": _hdf5_groups, "zarr": _zarr_groups}
_GROUP = {"tdms": open_tdms_group, "hdf5": _hdf5_group, "zarr": _zarr_group}


def _units(attrs) -> tuple:
    for key in UNIT_ATTRIBUTES:
        unit = attrs.get(key)
        if isinstance(unit, str) and unit.strip():
            return (unit.strip(),)
    return ()


def variables(path, kind: str) -> list[Variable]:
    """The one-dimensional numeric channels or variables of a rig file."""
    groups = _GROUPS[kind](Path(path))
    found = []
    try:
        for key, dataset in groups.items():
            group = key.strip("/")
            for name, item in dataset.variables.items():
                if item.ndim != 1 or not np.issubdtype(item.dtype, np.number):
                    continue
                chunks = item.encoding.get("chunksizes") or item.encoding.get("chunks")
                found.append(
                    Variable(
                        name=f"{group}/{name}" if group else str(name),
                        group=group,
                        short=str(name),
                        size=int(item.shape[0]),
                        units=_units(item.attrs),
                        chunk=int(chunks[0]) if chunks else 0,
                    )
                )
    finally:
        for dataset in groups.values():
            dataset.close()
    return found


def open_group(path, kind: str, group: str) -> xr.Dataset:
    """The group ``group`` (``''`` for the root) of a rig file, as a lazily read Dataset
    whose variables are named by :attr:`Variable.short`; close it after reading."""
    return _GROUP[kind](Path(path), group or None)


def check_complete(path, kind: str, variable: Variable) -> None:
    """Refuse a zarr variable some of whose chunks are missing (zarr reads a missing chunk
    as its fill value, so a truncated or partly copied store would read); other formats
    check themselves when opened."""
    if kind != "zarr":
        return
    root = _zarr_root(Path(path))
    array = root[variable.name] if hasattr(root, "members") else root
    expected = int(array.nchunks)
    if missing := expected - int(array.nchunks_initialized):
        raise RecordingError(
            path,
            f"variable {variable.name!r}",
            f"{missing} of its {expected} chunks are missing (a truncated or partly copied store)",
        )
