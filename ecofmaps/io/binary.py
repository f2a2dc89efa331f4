"""Recordings in rig formats (TDMS, HDF5 / netCDF-4, zarr), read lazily through :class:`Column`:
a range of samples on demand, in float64 and SI, pickled without its open file (so a dask
cluster's workers read their own blocks), any error naming the file, channel and samples.
``docs/formats.md`` describes the formats.
"""

from __future__ import annotations

import os
import threading
import weakref
from pathlib import Path

import numpy as np

from ecofmaps._parallel import SOURCE
from ecofmaps.io.columns import ColumnError, listed_names, matching_columns, role_scale
from ecofmaps.io.recording_types import LAZY_SAMPLES, Recording, RecordingError, si_values
from ecofmaps.io.rig_formats import NOUNS, Variable, check_complete, open_group, variables

__all__ = ["DEFAULT_CHUNK", "Column", "read_binary"]

#: Samples per dask block when the file does not suggest a chunking.
DEFAULT_CHUNK = 1 << 22


class Column:
    """One channel or variable as an array-like of float64 in SI, read range by range."""

    def __init__(self, path: Path, kind: str, variable: Variable, factor: float, nan_policy, stamp):
        self.arguments = (path, kind, variable, factor, nan_policy, stamp)
        self.path, self.kind, self.variable, self.factor, self.nan_policy, _ = self.arguments
        self.shape = (variable.size,)
        self.dtype = np.dtype(np.float64)
        self.ndim = 1
        self._handle = None
        self._lock = threading.Lock()
        _COLUMNS.add(self)

    def __reduce__(self):
        """Pickled without the open file; unpickled by :func:`_column`."""
        return _column, self.arguments

    def __len__(self) -> int:
        return self.variable.size

    def _source(self):
        """The open channel or dataset (opened on first use in this process)."""
        if self._handle is not None and self._handle[2] != os.getpid():
            self._handle = None  # the parent's, left to the parent
        if self._handle is None:
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
        if not isinstance(key, slice):
            raise TypeError("a Column is read by a slice start:stop")
        start, stop, step = key.indices(self.variable.size)
        if step != 1:
            raise TypeError("a Column is read by a slice start:stop (step 1)")
        stop = max(start, stop)
        noun = NOUNS[self.kind]
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
    noun = NOUNS[kind]
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
    """A rig file as a :class:`~ecofmaps.io.recording_types.Recording` (see
    :func:`ecofmaps.io.read_recording` for the options)."""
    chosen = _select(path, kind, variables(path, kind), options)
    for variable in chosen.values():
        check_complete(path, kind, variable)
    columns, units, assumed = {}, {}, ()
    stat = path.stat()
    stamp = (stat.st_mtime_ns, stat.st_size)
    for role, variable in chosen.items():
        factor, units[role], unknown = 1.0, "1", False
        if role != "cycle":
            try:
                factor, units[role], unknown = role_scale(
                    role, variable.short, options[f"{role}_unit"], variable.units, variable.name
                )
            except ColumnError as error:
                raise RecordingError(path, f"{NOUNS[kind]} {variable.name!r}", str(error)) from None
        assumed += (role,) if unknown else ()
        columns[role] = Column(path, kind, variable, factor, options["nan_policy"], stamp)
    size = chosen["displacement"].size
    if size == 0:
        raise RecordingError(path, f"{NOUNS[kind]} {chosen['displacement'].name!r}", "no samples")
    lazy = size > LAZY_SAMPLES if lazy is None else lazy
    if lazy:
        import dask.array as da
        from dask.base import tokenize

        native = max(v.chunk for v in chosen.values()) or 1
        block = int(chunks) if chunks else max(native, DEFAULT_CHUNK // native * native)
        token = tokenize(str(path.resolve()), *stamp, options, block)
        arrays = {
            role: da.from_array(
                column,
                chunks=(min(block, size),),
                asarray=False,
                lock=False,
                name=f"ecofmaps-{kind}-{role}-{token}",
                meta=np.empty(0, np.float64),
            )
            for role, column in columns.items()
        }
        for role, column in columns.items():  # read directly by the tasks of an analysis
            setattr(arrays[role], SOURCE, column)
    else:
        arrays = {}
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
