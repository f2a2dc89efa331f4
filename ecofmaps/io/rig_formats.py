"""The rig formats' channels and variables: TDMS, HDF5 / netCDF-4 and zarr, listed and opened.

:func:`variables` lists a rig file's one-dimensional numeric channels (TDMS) or variables
(HDF5, zarr) as :class:`Variable`: name, group, length, dtype, units (a TDMS channel's
``unit_string`` or ``NI_UnitDescription``, a variable's ``units`` attribute) and CF packing
(``scale_factor``, ``add_offset``, ``_FillValue``/``missing_value``). The openers refuse a
truncated file (HDF5 checks its own length, a TDMS file whose last segment is short is found
from npTDMS's notice, and a zarr store with missing chunk files from its chunk count).
:mod:`ecofmaps.io.binary` reads the samples.
"""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import numpy as np

from ecofmaps.io.recording_types import RecordingError

__all__ = ["Variable", "variables"]

_KIND = {"tdms": "channel", "hdf5": "variable", "zarr": "variable"}


_UNIT_ATTRIBUTES = ("units", "unit", "Units", "Unit", "unit_string", "NI_UnitDescription")


@dataclasses.dataclass(frozen=True)
class Variable:
    """A one-dimensional channel or variable of a rig file.

    Attributes
    ----------
    name : str
        Its full name, ``group/name`` (``Rig/Force``), or ``name`` at the root.
    group : str
        The group path (``''`` for the root).
    short : str
        Its own name, without the group (a TDMS channel's may hold a ``/``).
    size : int
        Number of samples.
    units : tuple of str
        The units its metadata gives (none, or one).
    chunk : int
        Samples per chunk in the file, or 0 if the file does not say.
    packing : tuple
        ``(scale_factor, add_offset, fill_values)`` of CF packing, or None.
    """

    name: str
    group: str
    short: str
    size: int
    units: tuple = ()
    chunk: int = 0
    packing: tuple | None = None


def _text(value) -> str | None:
    """An attribute as text (bytes decoded, arrays of one item unwrapped), or None."""
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.reshape(()).item()
    if isinstance(value, bytes):
        value = value.decode("utf-8", errors="replace")
    if isinstance(value, str) and value.strip():
        return value.strip()
    return None


def _units(attrs) -> tuple:
    for key in _UNIT_ATTRIBUTES:
        if key in attrs:
            unit = _text(attrs[key])
            if unit is not None:
                return (unit,)
    return ()


def _packing(attrs):
    """CF packing from a variable's attributes, or None."""
    keys = ("scale_factor", "add_offset", "_FillValue", "missing_value")
    if not any(key in attrs for key in keys):
        return None
    fills = tuple(
        float(np.asarray(attrs[key]).reshape(-1)[0])
        for key in ("_FillValue", "missing_value")
        if key in attrs and np.asarray(attrs[key]).size
    )
    scale = float(np.asarray(attrs.get("scale_factor", 1.0)).reshape(-1)[0])
    offset = float(np.asarray(attrs.get("add_offset", 0.0)).reshape(-1)[0])
    return scale, offset, fills


# --- TDMS ------------------------------------------------------------------------------------


class _TdmsNotices(logging.Handler):
    """Collects npTDMS's warnings while a file is opened (a short last segment)."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record):
        self.messages.append(record.getMessage())


def _open_tdms(path: Path):
    from nptdms import TdmsFile

    logger = logging.getLogger("nptdms")
    notices = _TdmsNotices()
    logger.addHandler(notices)
    propagate, logger.propagate = logger.propagate, False
    try:
        handle = TdmsFile.open(path)
    except Exception as error:
        raise RecordingError(path, None, f"cannot read as TDMS: {error}") from None
    finally:
        logger.removeHandler(notices)
        logger.propagate = propagate
    if notices.messages:
        handle.close()
        raise RecordingError(
            path, None, f"truncated or damaged TDMS file ({'; '.join(notices.messages)})"
        )
    return handle


def _tdms_variables(path: Path) -> list[Variable]:
    with _open_tdms(path) as handle:
        return [
            Variable(
                name=f"{group.name}/{channel.name}",
                group=group.name,
                short=channel.name,
                size=len(channel),
                units=_units(channel.properties),
            )
            for group in handle.groups()
            for channel in group.channels()
            if len(channel) and np.issubdtype(channel.dtype, np.number)
        ]


# --- HDF5 and netCDF-4 -----------------------------------------------------------------------


def _open_hdf5(path: Path):
    import h5py

    try:
        return h5py.File(path, "r")
    except OSError as error:
        message = f"cannot open as HDF5 (truncated or damaged): {error}"
        raise RecordingError(path, None, message) from None


def _hdf5_variables(path: Path) -> list[Variable]:
    import h5py

    found = []

    def visit(name, item):
        if not isinstance(item, h5py.Dataset) or item.ndim != 1:
            return
        if not np.issubdtype(item.dtype, np.number):
            return
        if "not a netCDF variable" in str(_text(item.attrs.get("NAME", b"")) or ""):
            return  # a netCDF dimension without values
        group, _, short = name.rpartition("/")
        found.append(
            Variable(
                name=name,
                group=group,
                short=short,
                size=int(item.shape[0]),
                units=_units(item.attrs),
                chunk=int(item.chunks[0]) if item.chunks else 0,
                packing=_packing(item.attrs),
            )
        )

    with _open_hdf5(path) as handle:
        handle.visititems(visit)
    return found


# --- zarr ------------------------------------------------------------------------------------


def _open_zarr(path: Path):
    import zarr

    try:
        return zarr.open(store=str(path), mode="r")
    except Exception as error:
        raise RecordingError(path, None, f"cannot open as a zarr store: {error}") from None


def _zarr_variables(path: Path) -> list[Variable]:
    import zarr

    root = _open_zarr(path)
    is_array = isinstance(root, zarr.Array)
    members = [("", root)] if is_array else list(root.members(max_depth=None))
    found = []
    for name, item in members:
        if not isinstance(item, zarr.Array) or item.ndim != 1:
            continue
        if not np.issubdtype(item.dtype, np.number):
            continue
        name = name or path.stem
        group, _, short = name.rpartition("/")
        found.append(
            Variable(
                name=name,
                group=group,
                short=short,
                size=int(item.shape[0]),
                units=_units(item.attrs),
                chunk=int(item.chunks[0]),
                packing=_packing(item.attrs),
            )
        )
    return found


def _zarr_array(root, variable: Variable):
    """The array of ``variable`` in a store opened at ``root`` (which may be the array)."""
    import zarr

    return root if isinstance(root, zarr.Array) else root[variable.name]


def _zarr_complete(path: Path, variable: Variable) -> None:
    """Refuse a zarr array some of whose chunk files are missing (read as fill values)."""
    array = _zarr_array(_open_zarr(path), variable)
    present, expected = array.nchunks_initialized, array.nchunks
    if present < expected:
        raise RecordingError(
            path,
            f"variable {variable.name!r}",
            f"{expected - present} of its {expected} chunks are missing "
            "(a truncated or partly copied store)",
        )


_LISTS = {"tdms": _tdms_variables, "hdf5": _hdf5_variables, "zarr": _zarr_variables}


def variables(path, kind: str) -> list[Variable]:
    """The one-dimensional numeric channels or variables of a rig file.

    Parameters
    ----------
    path : str or os.PathLike
    kind : {'tdms', 'hdf5', 'zarr'}
        The format (see :func:`ecofmaps.io.recordings.recording_format`).

    Returns
    -------
    variables : list of Variable
    """
    return _LISTS[kind](Path(path))
