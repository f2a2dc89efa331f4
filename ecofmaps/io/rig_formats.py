"""The rig formats' channels and variables: TDMS, HDF5 / netCDF-4 and zarr, through xarray.

The one face of :mod:`ecofmaps.io.tdms`, :mod:`ecofmaps.io.hdf5` and
:mod:`ecofmaps.io.zarr_store`: :func:`variables` lists a file's one-dimensional numeric
variables as :class:`Variable` (name, group, length, units, chunking), :func:`open_group`
opens the group of one, and :func:`check_complete` refuses a zarr variable with missing
chunk files. :mod:`ecofmaps.io.binary` reads the samples.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import xarray as xr

from ecofmaps.io.hdf5 import hdf5_groups, open_hdf5_group
from ecofmaps.io.recording_types import RecordingError
from ecofmaps.io.tdms import open_tdms_group, tdms_groups
from ecofmaps.io.zarr_store import missing_chunks, open_zarr_group, zarr_groups

__all__ = ["NOUNS", "Variable", "check_complete", "open_group", "variables"]

#: What each rig format calls a column, for messages.
NOUNS = {"tdms": "channel", "hdf5": "variable", "zarr": "variable"}

#: Attributes that give a variable's unit, in the order they are looked at.
UNIT_ATTRIBUTES = ("units", "unit", "Units", "Unit", "unit_string", "NI_UnitDescription")

_GROUPS = {"tdms": tdms_groups, "hdf5": hdf5_groups, "zarr": zarr_groups}
_GROUP = {"tdms": open_tdms_group, "hdf5": open_hdf5_group, "zarr": open_zarr_group}


@dataclasses.dataclass(frozen=True)
class Variable:
    """A one-dimensional channel or variable of a rig file."""

    name: str
    group: str
    short: str
    size: int
    units: tuple = ()
    chunk: int = 0


def _units(attrs) -> tuple:
    for key in UNIT_ATTRIBUTES:
        unit = attrs.get(key)
        if isinstance(unit, str) and unit.strip():
            return (unit.strip(),)
    return ()


def _chunk(variable: xr.Variable) -> int:
    chunks = variable.encoding.get("chunksizes") or variable.encoding.get("chunks")
    return int(chunks[0]) if chunks else 0


def _listed(group: str, dataset: xr.Dataset) -> list[Variable]:
    group = group.strip("/")
    return [
        Variable(
            name=f"{group}/{name}" if group else str(name),
            group=group,
            short=str(name),
            size=int(item.shape[0]),
            units=_units(item.attrs),
            chunk=_chunk(item),
        )
        for name, item in dataset.variables.items()
        if item.ndim == 1 and np.issubdtype(item.dtype, np.number)
    ]


def variables(path, kind: str) -> list[Variable]:
    """The one-dimensional numeric channels or variables of a rig file."""
    groups = _GROUPS[kind](Path(path))
    try:
        return [variable for name, ds in groups.items() for variable in _listed(name, ds)]
    finally:
        for dataset in groups.values():
            dataset.close()


def open_group(path, kind: str, group: str) -> xr.Dataset:
    """The group ``group`` (``''`` for the root) of a rig file, as a lazily read Dataset
    whose variables are named by :attr:`Variable.short`; close it after reading."""
    return _GROUP[kind](Path(path), group or None)


def check_complete(path, kind: str, variable: Variable) -> None:
    """Refuse a zarr variable some of whose chunk files are missing (zarr would read them
    as fill values); other formats check themselves when opened."""
    if kind != "zarr":
        return
    missing, expected = missing_chunks(path, variable.name)
    if missing:
        raise RecordingError(
            path,
            f"variable {variable.name!r}",
            f"{missing} of its {expected} chunks are missing (a truncated or partly copied store)",
        )
