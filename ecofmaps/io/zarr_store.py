"""zarr stores (formats 2 and 3) as xarray Datasets, through xarray's ``zarr`` engine.

Each group of the store is one lazily read :class:`xarray.Dataset`, decoded by xarray. A
store written by zarr alone has no dimension names: its arrays are read over "phony"
dimensions and decoded by :func:`xarray.decode_cf`; :func:`missing_chunks` refuses a store
with chunks never written.
"""

from __future__ import annotations

from pathlib import Path

import xarray as xr
from xarray.backends import BackendArray
from xarray.core import indexing

from ecofmaps.io.recording_types import RecordingError

__all__ = ["missing_chunks", "open_zarr_group", "zarr_groups"]

#: xarray's options for every opening: CF packing and fill values decoded, numbers left as
#: numbers, lazily indexed arrays (no dask), no copy of a whole variable kept once read.
OPTIONS = {
    "engine": "zarr",
    "chunks": None,
    "mask_and_scale": True,
    "decode_times": False,
    "decode_timedelta": False,
    "decode_coords": False,
    "cache": False,
}

_NO_DIMENSIONS = ("dimension_names", "_ARRAY_DIMENSIONS")


def _opened(path: Path):
    import zarr  # here, not on import: xarray loads this module with its engines (0.3-1 s)

    try:
        return zarr.open(store=str(path), mode="r")
    except Exception as error:
        raise RecordingError(path, None, f"cannot open as a zarr store: {error}") from None


def _consolidated(root) -> bool:
    """Whether the store (a group) has consolidated metadata (else xarray is told not to look)."""
    return root.metadata.consolidated_metadata is not None


class _ZarrRange(BackendArray):
    """A zarr array as a lazily indexed array (slices and indices read only their chunks)."""

    def __init__(self, array):
        self.array, self.shape, self.dtype = array, array.shape, array.dtype

    def __getitem__(self, key):
        return indexing.explicit_indexing_adapter(
            key, self.shape, indexing.IndexingSupport.BASIC, self._read
        )

    def _read(self, key):
        return self.array[key]


def _plain_groups(path: Path, root) -> dict[str, xr.Dataset]:
    """The groups of a store without dimension names (read over phony dimensions)."""
    import zarr  # as in _opened

    is_array = isinstance(root, zarr.Array)
    members = [("", root)] if is_array else list(root.members(max_depth=None))
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
    options = {k: v for k, v in OPTIONS.items() if k.startswith(("mask", "decode"))}
    return {name: xr.decode_cf(xr.Dataset(found), **options) for name, found in groups.items()}


def _xarray_groups(path: Path, root, key: str | None = None) -> dict | None:
    """The groups xarray opens (all, or the one at ``key``); None for a store without
    dimension names."""
    try:
        if key is None:
            return xr.open_groups(path, consolidated=_consolidated(root), **OPTIONS)
        return {key: xr.open_dataset(path, group=key, consolidated=_consolidated(root), **OPTIONS)}
    except Exception as error:
        if isinstance(error, KeyError) and any(name in str(error) for name in _NO_DIMENSIONS):
            return None
        raise RecordingError(path, None, f"cannot open as a zarr store: {error}") from None


def zarr_groups(path) -> dict[str, xr.Dataset]:
    """Every group of a zarr store as a lazily read Dataset, by its path (``'/'``,
    ``'/rig/run1'``)."""
    path = Path(path)
    root = _opened(path)
    groups = _xarray_groups(path, root) if hasattr(root, "members") else None
    return _plain_groups(path, root) if groups is None else groups


def open_zarr_group(path, group: str | None = None) -> xr.Dataset:
    """One group of a zarr store (by default the root) as a lazily read Dataset."""
    path = Path(path)
    key = "/" + (group or "").strip("/")
    root = _opened(path)
    if not hasattr(root, "members"):  # a store that is one array
        return _plain_groups(path, root)["/"]
    if (opened := _xarray_groups(path, root, key)) is not None:
        return opened[key]
    groups = _plain_groups(path, root)
    if key not in groups:
        raise RecordingError(path, None, f"no group {group!r}")
    return groups[key]


def missing_chunks(path, name: str) -> tuple[int, int]:
    """Chunks of array ``name`` (its path in the store) missing, and expected: zarr reads a
    missing chunk as its fill value, so a truncated or partly copied store would read."""
    root = _opened(Path(path))
    array = root[name] if hasattr(root, "members") else root
    expected = int(array.nchunks)
    return expected - int(array.nchunks_initialized), expected
