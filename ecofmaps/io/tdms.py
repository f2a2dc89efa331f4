"""TDMS files (LabVIEW) as lazily read xarray Datasets through npTDMS, one per group, and the
xarray engine ``ecofmaps-tdms``; ``docs/formats.md`` says how channels and units map."""

from __future__ import annotations

import collections
import contextlib
import logging
import os
import threading
from pathlib import Path

import numpy as np
import xarray as xr
from nptdms import TdmsFile
from xarray.backends import BackendArray, BackendEntrypoint
from xarray.core import indexing

from ecofmaps._codes import warn
from ecofmaps.io.columns import listed_names
from ecofmaps.io.recording_types import RecordingError, RecordingWarning

#: A channel's properties that give its unit, in the order they are looked at.
UNIT_PROPERTIES = ("unit_string", "NI_UnitDescription")


class _Log(logging.Handler):
    """npTDMS's warnings in this thread: kept while a file is opened, else warned."""

    def __init__(self, keep: bool):
        super().__init__(logging.WARNING)
        self.keep, self.thread = keep, threading.get_ident()
        self.messages, self.undecoded = [], False

    def emit(self, record):
        if record.thread != self.thread:
            return
        if not self.keep:
            warn(f"TDMS reader: {record.getMessage()[:200]}", RecordingWarning)
        elif record.name == "nptdms.types":  # a text property that is not UTF-8: data intact
            self.undecoded = True
        else:
            self.messages.append(record.getMessage())


def _silenced(record) -> bool:
    return False


class _Quiet:
    """While npTDMS reads, its log records go to a :class:`_Log` only (not printed)."""

    lock, readers, propagate = threading.Lock(), 0, True

    @classmethod
    @contextlib.contextmanager
    def reading(cls, keep: bool = False):
        from nptdms.log import log_manager

        logger, log = logging.getLogger("nptdms"), _Log(keep)
        with cls.lock:
            if cls.readers == 0:
                cls.propagate, logger.propagate = logger.propagate, False
                log_manager.console_handler.addFilter(_silenced)
            cls.readers += 1
            logger.addHandler(log)
        try:
            yield log
        finally:
            with cls.lock:
                logger.removeHandler(log)
                cls.readers -= 1
                if cls.readers == 0:
                    logger.propagate = cls.propagate
                    log_manager.console_handler.removeFilter(_silenced)


def opened_tdms(path: Path) -> TdmsFile:
    """The file opened by npTDMS's streaming reader (the data read on demand)."""
    with _Quiet.reading(keep=True) as notices:
        try:
            handle = TdmsFile.open(path)
        except Exception as error:
            raise RecordingError(path, None, f"cannot read as TDMS: {error}") from None
    if notices.undecoded:
        warn(
            f"{path}: a text property of the file is not UTF-8; read with replacement "
            "characters (the samples are not affected)",
            RecordingWarning,
        )
    if notices.messages:
        handle.close()
        raise RecordingError(
            path, None, f"truncated or damaged TDMS file ({'; '.join(notices.messages)})"
        )
    return handle


class TdmsReader:
    """One TDMS file, opened on first read in each process, read by one thread at a time."""

    def __init__(self, path, handle=None):
        self.path = Path(path)
        self._handle = None if handle is None else (handle, os.getpid())
        self._lock = threading.Lock()

    def __reduce__(self):
        return TdmsReader, (self.path,)  # without the open file

    def samples(self, group: str, channel: str, start: int, count: int) -> np.ndarray:
        """``count`` samples of a channel from sample ``start`` (scaled by npTDMS)."""
        with self._lock:
            if self._handle is None or self._handle[1] != os.getpid():
                self._handle = (opened_tdms(self.path), os.getpid())
            with _Quiet.reading():
                return self._handle[0][group][channel].read_data(offset=start, length=count)

    def close(self) -> None:
        """Close the file (opened again on the next read)."""
        with self._lock:
            if self._handle is not None and self._handle[1] == os.getpid():
                self._handle[0].close()
            self._handle = None


class LazyArray(BackendArray):
    """A one-dimensional array xarray indexes lazily, ``read`` given each basic key."""

    def __init__(self, read, size: int, dtype):
        self.read, self.shape, self.dtype = read, (int(size),), np.dtype(dtype)

    def __getitem__(self, key):
        return indexing.explicit_indexing_adapter(
            key, self.shape, indexing.IndexingSupport.BASIC, self.read
        )


class TdmsArray(LazyArray):
    """A channel of a TDMS file, lazily indexed."""

    def __init__(self, reader: TdmsReader, group: str, channel: str, size: int, dtype):
        super().__init__(self._read, size, dtype)
        self.reader, self.group, self.channel = reader, group, channel

    def _read(self, key: tuple):
        (index,) = key
        single = not isinstance(index, slice)
        wanted = range(int(index), int(index) + 1) if single else range(self.shape[0])[index]
        if not wanted:
            return np.zeros(0, self.dtype)
        low, high = min(wanted[0], wanted[-1]), max(wanted[0], wanted[-1]) + 1
        data = self.reader.samples(self.group, self.channel, low, high - low)
        if wanted.step != 1:
            data = data[np.asarray(wanted) - low]
        return data[0] if single else data


def carried_unit(attrs, keys=UNIT_PROPERTIES) -> str | None:
    """The first non-blank text among the ``keys`` of ``attrs`` (a unit), stripped, or None."""
    units = (attrs.get(key) for key in keys)
    return next((unit.strip() for unit in units if isinstance(unit, str) and unit.strip()), None)


def _plain(value):
    """A property as an attribute value netCDF can hold (a time as ISO text)."""
    return value if isinstance(value, str | int | float | np.number) else str(value)


def _group_dataset(reader: TdmsReader, group) -> xr.Dataset:
    channels = [c for c in group.channels() if np.issubdtype(c.dtype, np.number)]
    common = collections.Counter(len(c) for c in channels).most_common(1)
    variables = {}
    for channel in channels:
        size = len(channel)
        dim = "sample" if common and size == common[0][0] else f"sample_{size}"
        array = TdmsArray(reader, group.name, channel.name, size, channel.dtype)
        attrs = {key: _plain(value) for key, value in channel.properties.items()}
        if "units" not in attrs and (unit := carried_unit(attrs)):
            attrs["units"] = unit
        variables[channel.name] = xr.Variable((dim,), indexing.LazilyIndexedArray(array), attrs)
    dataset = xr.Dataset(variables, attrs={k: _plain(v) for k, v in group.properties.items()})
    dataset.set_close(reader.close)
    return dataset


def tdms_groups(path) -> dict[str, xr.Dataset]:
    """Every group of a TDMS file as a lazily read Dataset by its path (``'/'``, ``'/Rig'``)."""
    path = Path(path)
    handle = opened_tdms(path)
    reader = TdmsReader(path, handle)  # reads through the file opened to list the groups
    root = xr.Dataset(attrs={k: _plain(v) for k, v in handle.properties.items()})
    root.set_close(reader.close)
    return {"/": root} | {
        f"/{group.name}": _group_dataset(reader, group) for group in handle.groups()
    }


def open_tdms_group(path, group: str | None = None) -> xr.Dataset:
    """One group of a TDMS file as a lazily read Dataset (see :func:`tdms_groups`)."""
    groups = {name: ds for name, ds in tdms_groups(path).items() if name != "/"}
    if group is None and groups:
        return next(iter(groups.values()))
    key = "/" + (group or "").strip("/")
    if key not in groups:
        listed = listed_names([name[1:] for name in groups]) or "none"
        raise RecordingError(path, None, f"no group {group!r} (groups: {listed})")
    return groups[key]


class TdmsBackendEntrypoint(BackendEntrypoint):
    """xarray's engine ``ecofmaps-tdms``: a TDMS group as a Dataset (channels as variables,
    ``units`` from :data:`UNIT_PROPERTIES`, read lazily); the whole file as a DataTree."""

    description = "TDMS (LabVIEW) files through npTDMS, one group a Dataset (ecofmaps)"
    open_dataset_parameters = ("filename_or_obj", "drop_variables", "group")

    def open_dataset(self, filename_or_obj, *, drop_variables=None, group=None) -> xr.Dataset:
        """The group ``group`` (by default the first) of the file."""
        dataset = open_tdms_group(engine_path(filename_or_obj, "ecofmaps-tdms"), group)
        return dataset.drop_vars(drop_variables or [], errors="ignore")

    def open_groups_as_dict(self, filename_or_obj, *, drop_variables=None) -> dict:
        """Every group (and the root's properties) by its path."""
        groups = tdms_groups(engine_path(filename_or_obj, "ecofmaps-tdms"))
        return {k: v.drop_vars(drop_variables or [], errors="ignore") for k, v in groups.items()}

    def open_datatree(self, filename_or_obj, *, drop_variables=None) -> xr.DataTree:
        """The file as a tree: the root's properties, a node for each group."""
        groups = self.open_groups_as_dict(filename_or_obj, drop_variables=drop_variables)
        return xr.DataTree.from_dict(groups)

    def guess_can_open(self, filename_or_obj) -> bool:
        """A path ending in ``.tdms``."""
        return has_suffix(filename_or_obj, (".tdms",))


def engine_path(filename_or_obj, engine: str) -> Path:
    """The path an xarray engine of ecofmaps reads: a TypeError for anything but a path."""
    if not isinstance(filename_or_obj, str | os.PathLike):
        raise TypeError(f"the {engine} engine reads a file by its path; got {filename_or_obj!r}")
    return Path(filename_or_obj)


def has_suffix(filename_or_obj, suffixes) -> bool:
    """Whether xarray's ``filename_or_obj`` is a path ending in one of ``suffixes``."""
    try:
        return Path(filename_or_obj).suffix.lower() in suffixes
    except TypeError:
        return False
