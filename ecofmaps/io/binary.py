"""Recordings in rig formats (TDMS, HDF5 / netCDF-4, zarr), each channel read range by range in
SI through :class:`Column`, any error naming the file, channel and samples (``docs/formats.md``)."""

from __future__ import annotations

import dataclasses
import os
import threading
import weakref
from pathlib import Path

import h5py
import numpy as np
import xarray as xr
from xarray.core import indexing

from ecofmaps._parallel import SOURCE
from ecofmaps.io.columns import ColumnError, column_scale, listed_names, matching_columns
from ecofmaps.io.recording_types import LAZY_SAMPLES, Recording, RecordingError, si_values
from ecofmaps.io.tdms import UNIT_PROPERTIES, LazyArray, carried_unit, open_tdms_group, tdms_groups

#: What each rig format calls a column, for messages.
_NOUNS = {"tdms": "channel", "hdf5": "variable", "zarr": "variable"}

#: Attributes that give a variable's unit, in the order they are looked at.
UNIT_ATTRIBUTES = ("units", "unit", "Units", "Unit", *UNIT_PROPERTIES)

#: xarray's decoding: CF packing and fill values decoded, numbers left as numbers.
_DECODING = dict(
    mask_and_scale=True, decode_times=False, decode_timedelta=False, decode_coords=False
)

#: xarray's options for HDF5: no copy kept once read, and no lock of xarray's (h5py serialises
#: its calls, each :class:`Column` has a lock, and a fork could inherit xarray's held for good).
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
    """Refuse a damaged file by reading every attribute with h5py (h5netcdf prints tracebacks)."""

    def visit(_name, item):
        for name in item.attrs:
            item.attrs.get_id(name)

    try:
        with h5py.File(path, "r") as handle:
            visit("/", handle)
            handle.visititems(visit)
    except _DAMAGE as error:
        raise _hdf5_refused(path, error) from None


def _hdf5_groups(path: Path, key: str | None = None) -> dict[str, xr.Dataset]:
    """As :func:`_zarr_groups`, for an HDF5 file."""
    _checked_hdf5(path)
    caught = _DAMAGE if key is None else OSError
    try:
        if key is None:
            return xr.open_groups(path, **_HDF5)
        return {key: xr.open_dataset(path, group=key, **_HDF5)}
    except caught as error:
        if key not in (None, "/") and "not found" in str(error).lower():
            return {}
        raise _hdf5_refused(path, error) from None


def _zarr_root(path: Path):
    import zarr  # here, not on import: xarray loads this module with its engines (0.3-1 s)

    try:
        return zarr.open(store=str(path), mode="r")
    except Exception as error:
        raise RecordingError(path, None, f"cannot open as a zarr store: {error}") from None


def _plain_zarr_groups(path: Path, root) -> dict[str, xr.Dataset]:
    """The groups of a store without dimension names (read over phony dimensions)."""
    import zarr  # as in _zarr_root

    members = [("", root)] if isinstance(root, zarr.Array) else list(root.members(max_depth=None))
    groups = {"/": {}} | {"/" + name: {} for name, item in members if isinstance(item, zarr.Group)}
    lengths: list[int] = []
    for name, item in members:
        if not isinstance(item, zarr.Array) or item.ndim != 1:
            continue
        group, _, short = (name or path.stem).rpartition("/")
        size = int(item.shape[0])
        lengths += [] if size in lengths else [size]
        data = indexing.LazilyIndexedArray(LazyArray(item.__getitem__, size, item.dtype))
        variable = xr.Variable((f"phony_dim_{lengths.index(size)}",), data, dict(item.attrs))
        variable.encoding["chunks"] = tuple(item.chunks)
        groups["/" + group][short] = variable
    return {name: xr.decode_cf(xr.Dataset(found), **_DECODING) for name, found in groups.items()}


def _zarr_groups(path: Path, key: str | None = None) -> dict[str, xr.Dataset]:
    """The groups of a store (all, or the one at ``key``), by path (``'/'``, ``'/rig/run1'``)."""
    root = _zarr_root(path)
    if hasattr(root, "members"):  # a group; a store without dimension names is read as plain
        consolidated = root.metadata.consolidated_metadata is not None  # else xarray looks
        try:
            if key is None:
                return xr.open_groups(path, consolidated=consolidated, **_ZARR)
            return {key: xr.open_dataset(path, group=key, consolidated=consolidated, **_ZARR)}
        except Exception as error:
            if not isinstance(error, KeyError) or all(n not in str(error) for n in _NO_DIMENSIONS):
                raise RecordingError(path, None, f"cannot open as a zarr store: {error}") from None
    return _plain_zarr_groups(path, root)


_GROUPS = {"tdms": tdms_groups, "hdf5": _hdf5_groups, "zarr": _zarr_groups}


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
                full, size = f"{group}/{name}" if group else str(name), int(item.shape[0])
                chunk = int(chunks[0]) if chunks else 0
                units = tuple(filter(None, [carried_unit(item.attrs, UNIT_ATTRIBUTES)]))
                found.append(Variable(full, group, str(name), size, units, chunk))
    finally:
        for dataset in groups.values():
            dataset.close()
    return found


def open_group(path, kind: str, group: str) -> xr.Dataset:
    """The group ``group`` (``''``: the root) of a rig file as a lazily read Dataset."""
    if kind == "tdms":
        return open_tdms_group(path, group or None)
    key = "/" + group.strip("/")
    groups = _GROUPS[kind](Path(path), key)
    if key not in groups:
        raise RecordingError(path, None, f"no group {group!r}")
    return groups[key]


#: Samples per dask block when the file does not suggest a chunking.
DEFAULT_CHUNK = 1 << 22


class Column:
    """One channel or variable as an array-like of float64 in SI, read range by range."""

    def __init__(self, path: Path, kind: str, variable: Variable, factor: float, nan_policy, stamp):
        self.arguments = (path, kind, variable, factor, nan_policy, stamp)
        self.path, self.kind, self.variable, self.factor, self.nan_policy, _ = self.arguments
        self.shape, self.dtype, self.ndim = (variable.size,), np.dtype(np.float64), 1
        self._handle, self._lock = None, threading.Lock()
        _COLUMNS.add(self)

    def __reduce__(self):
        """Pickled without the open file; unpickled by :func:`_column`."""
        return _column, self.arguments

    def __len__(self) -> int:
        return self.variable.size

    def _source(self):
        """The open channel or dataset (opened on first use in this process)."""
        if self._handle is None or self._handle[2] != os.getpid():  # none, or the parent's
            dataset = open_group(self.path, self.kind, self.variable.group)
            self._handle = (dataset, dataset[self.variable.short].variable, os.getpid())
        return self._handle[1]

    def __del__(self):
        try:  # noqa: SIM105 - contextlib may be gone at interpreter shutdown
            self.close()
        except Exception:
            pass

    def close(self) -> None:
        """Close the file (it is opened again on the next read)."""
        with self._lock:
            if self._handle is not None and self._handle[2] == os.getpid():
                self._handle[0].close()
            self._handle = None

    def __getitem__(self, key):
        if isinstance(key, tuple) and len(key) == 1:
            key = key[0]
        if not isinstance(key, slice) or key.step not in (None, 1):
            raise TypeError("a Column is read by a slice start:stop (step 1)")
        start, stop, _ = key.indices(self.variable.size)
        stop = max(start, stop)
        noun = _NOUNS[self.kind]
        where = f"{noun} {self.variable.name!r}, samples {start} to {stop - 1}"
        try:
            with self._lock:
                source = self._source()
                raw = None if self.kind == "zarr" else source[start:stop].values
            if raw is None:  # zarr reads from several threads at once
                raw = source[start:stop].values
        except RecordingError:
            raise
        except Exception as error:
            raise RecordingError(
                self.path, where, f"cannot read (a damaged file, or changed while read): {error}"
            ) from None
        if raw.shape != (stop - start,):
            raise RecordingError(
                self.path, where, f"read {raw.size} samples where {stop - start} were expected"
            )
        values = raw.astype(np.float64, copy=not raw.flags.writeable)  # a copy, or the new array
        missing = ~np.isfinite(values)
        if missing.any():
            if self.nan_policy == "raise":
                first = int(np.argmax(missing))
                raise RecordingError(
                    self.path,
                    f"{noun} {self.variable.name!r}, sample {start + first}",
                    f"missing value ({values[first]})",
                )
            values[missing] = np.nan
        return si_values(values, self.factor)


#: The columns of this process, each given a new lock in a forked process.
_COLUMNS = weakref.WeakSet()


def _new_locks() -> None:
    for column in list(_COLUMNS):
        column._lock = threading.Lock()


if hasattr(os, "register_at_fork"):  # where processes fork
    os.register_at_fork(after_in_child=_new_locks)


#: The columns unpickled in this process, by their arguments: held weakly, so that a column
#: (and its open file) goes with the last task or recording that holds it.
_UNPICKLED = weakref.WeakValueDictionary()


def _column(*arguments) -> Column:
    """The column of these arguments, one object per process while any copy is held."""
    column = _UNPICKLED.get(arguments)
    if column is None:
        column = _UNPICKLED[arguments] = Column(*arguments)
    return column


def _select(path: Path, kind: str, found: list[Variable], options: dict) -> dict:
    """The variable for each role, by name (and group)."""
    noun = _NOUNS[kind]
    if options["group"] is not None:
        group = options["group"].strip("/")
        groups = sorted({v.group for v in found})
        found = [v for v in found if v.group == group]
        if not found:
            listed = listed_names(groups)
            raise RecordingError(path, None, f"no group {group!r} with channels (groups: {listed})")
    if not found:
        raise RecordingError(path, None, f"no one-dimensional numeric {noun} in the file")
    wanted = {"displacement": options["displacement_column"], "force": options["force_column"]}
    if options["cycle_column"] is not False:
        wanted["cycle"] = options["cycle_column"] or "cycle"
    chosen = {}
    for role, name in wanted.items():
        required = role != "cycle" or options["cycle_column"] is not None
        full = [k for k, v in enumerate(found) if v.name.strip("/").lower() == name.lower()]
        matches = full or matching_columns([v.short for v in found], name)
        if role != "displacement" and len(matches) != 1:
            # The force and cycle channels are sought in the displacement's group first.
            group = chosen["displacement"].group
            beside = [k for k in matches if found[k].group == group]
            matches = beside if len(beside) == 1 or not required else matches
        if len(matches) > 1:
            names = listed_names([found[k].name for k in matches])
            raise RecordingError(
                path,
                None,
                f"several {role} {noun}s match {name!r}: {names}; choose one with its full "
                "name or with group",
            )
        if not matches:
            if not required:
                continue
            names = listed_names([v.name for v in found])
            raise RecordingError(path, None, f"no {role} {noun} {name!r} ({noun}s: {names})")
        chosen[role] = found[matches[0]]
    if chosen["displacement"] == chosen["force"]:
        raise RecordingError(
            path,
            None,
            f"the displacement and force {noun}s are the same {noun} {chosen['force'].name!r}",
        )
    reference = chosen["displacement"]
    for variable in chosen.values():
        if variable.size != reference.size:
            raise RecordingError(
                path,
                f"{noun} {variable.name!r}",
                f"{variable.size} samples where the displacement {noun} "
                f"{reference.name!r} has {reference.size}",
            )
    return chosen


def read_binary(path: Path, kind: str, options: dict, *, lazy=None, chunks=None) -> Recording:
    """A rig file as a Recording (options as in :func:`ecofmaps.io.read_recording`)."""
    chosen = _select(path, kind, variables(path, kind), options)
    noun = _NOUNS[kind]
    if kind == "zarr":  # zarr reads a missing chunk as its fill value: refuse a partial store
        root = _zarr_root(path)
        for variable in chosen.values():
            array = root[variable.name] if hasattr(root, "members") else root
            expected = int(array.nchunks)
            if missing := expected - int(array.nchunks_initialized):
                raise RecordingError(
                    path,
                    f"variable {variable.name!r}",
                    f"{missing} of its {expected} chunks are missing (a truncated or partly "
                    "copied store)",
                )
    columns, units, assumed = {}, {}, ()
    stat = path.stat()
    stamp = (stat.st_mtime_ns, stat.st_size)
    for role, variable in chosen.items():
        try:
            factor, units[role], unknown = column_scale(
                role, variable.short, options.get(f"{role}_unit"), variable.units, variable.name
            )
        except ColumnError as error:
            raise RecordingError(path, f"{noun} {variable.name!r}", str(error)) from None
        assumed += (role,) if unknown else ()
        columns[role] = Column(path, kind, variable, factor, options["nan_policy"], stamp)
    size = chosen["displacement"].size
    if size == 0:
        raise RecordingError(path, f"{noun} {chosen['displacement'].name!r}", "no samples")
    arrays = {}
    if lazy or (lazy is None and size > LAZY_SAMPLES):
        import dask.array as da
        from dask.base import tokenize

        native = max(v.chunk for v in chosen.values()) or 1
        block = int(chunks) if chunks else max(native, DEFAULT_CHUNK // native * native)
        token = tokenize(str(path.resolve()), *stamp, options, block)
        for role, column in columns.items():
            name, meta = f"ecofmaps-{kind}-{role}-{token}", np.empty(0, np.float64)
            arrays[role] = da.from_array(
                column, (min(block, size),), name, asarray=False, meta=meta
            )
            setattr(arrays[role], SOURCE, column)  # read directly by the tasks of an analysis
    else:
        for role, column in columns.items():
            arrays[role] = column[0:size]
            column.close()
    return Recording(
        path=path,
        **arrays,
        columns={role: variable.name for role, variable in chosen.items()},
        units=units,
        format=kind,
        assumed_units=assumed,
    )
