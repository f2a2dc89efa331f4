"""Recordings of fretting loops, text or rig files, read whole, in blocks or lazily, in SI
units; ``docs/formats.md`` describes the formats, columns and units."""

from __future__ import annotations

import dataclasses
import itertools
import numbers
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import xarray as xr

from ecofmaps.io.binary import read_binary
from ecofmaps.io.columns import column_scale
from ecofmaps.io.files import is_store
from ecofmaps.io.recording_types import (
    LineIndex,
    Recording,
    RecordingError,
    check_regular_file,
)
from ecofmaps.io.text import BLOCK_BYTES, text_blocks

_NAN_POLICIES = ("propagate", "raise")
_MAGIC = {b"TDSm": "tdms", b"\x89HDF\r\n\x1a\n": "hdf5"}
_NETCDF3 = (b"CDF\x01", b"CDF\x02")
_SUFFIXES = dict.fromkeys((".h5", ".hdf5", ".hdf", ".nc", ".nc4"), "hdf5")
_SUFFIXES |= {".tdms": "tdms", ".zarr": "zarr"}


def recording_format(path) -> str:
    """The format of a recording from its first bytes (a directory: its zarr metadata).

    Parameters
    ----------
    path : str or os.PathLike
        A file, or a zarr store (a directory).

    Returns
    -------
    format : {'text', 'tdms', 'hdf5', 'zarr'}
        Any file not of a rig format is text.

    Raises
    ------
    RecordingError
        For a directory not a zarr store, a pipe, device or socket, a netCDF-3 file, or a
        file whose suffix names a rig format its content is not.
    """
    path = Path(path)
    if path.is_dir():
        if is_store(path):
            return "zarr"
        raise RecordingError(path, None, "a directory, and not a zarr store (no zarr.json)")
    check_regular_file(path)
    with open(path, "rb") as stream:
        head = stream.read(8)
    if head.startswith(_NETCDF3):
        raise RecordingError(
            path,
            None,
            "a netCDF-3 (classic) file: save it as netCDF-4 (HDF5), e.g. with xarray: "
            "xr.open_dataset(path).to_netcdf(new_path, engine='h5netcdf')",
        )
    for magic, kind in _MAGIC.items():
        if head.startswith(magic):
            return kind
    expected = _SUFFIXES.get(path.suffix.lower())
    if expected is not None:
        raise RecordingError(
            path,
            None,
            f"not a {expected.upper()} file: it does not start with the format's signature "
            f"(an empty, truncated or mislabelled file; first bytes {head!r})",
        )
    return "text"


def _options(
    displacement_column="displacement",
    force_column="force",
    cycle_column=None,
    displacement_unit=None,
    force_unit=None,
    group=None,
    nan_policy="propagate",
    load_column=None,
    skip_rows=None,
) -> dict:
    """The reading options, checked, as one dict."""
    options = dict(locals())
    for name in ("displacement_column", "force_column"):
        if not isinstance(options[name], str) or not options[name].strip():
            raise ValueError(f"{name} must be a column name; got {options[name]!r}")
    for name in ("cycle_column", "load_column", "displacement_unit", "force_unit", "group"):
        value = options[name]
        if value is None or (name == "cycle_column" and value is False):
            continue
        if not isinstance(value, str) or not value.strip():
            raise ValueError(f"{name} must be a non-empty string or None; got {value!r}")
    if nan_policy not in _NAN_POLICIES:
        raise ValueError(f"nan_policy must be one of {_NAN_POLICIES}; got {nan_policy!r}")
    _check_count("skip_rows", skip_rows, 0, "a non-negative integer or None")
    for role, unit in (("displacement", displacement_unit), ("force", force_unit)):
        if unit is not None:
            column_scale(role, role, unit)  # a ValueError naming the option
    return {**options, "skip_rows": None if skip_rows is None else int(skip_rows)}


def _check_count(name: str, value, least: int = 1, what: str = "a positive integer") -> None:
    """An integer option of at least ``least`` (None allowed), or a ValueError naming it."""
    if value is not None and (
        isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < least
    ):
        raise ValueError(f"{name} must be {what}; got {value!r}")


def _text_recordings(path: Path, options: dict, block_bytes, samples=None) -> Iterator[Recording]:
    """A text file's samples as recordings of ``samples`` each (None: one of all of them)."""
    if options["group"] is not None:
        raise ValueError(
            f"group (--group) applies to TDMS, HDF5/netCDF and zarr files, not to text: {path}"
        )
    parts = text_blocks(path, options, block_bytes or BLOCK_BYTES)
    layout = next(parts)
    columns = {role: layout.names[k] for role, k in layout.columns.items()}
    pending: list = []  # parsed blocks not yet given out: (values by role, line numbers)
    held = first = 0
    for part in itertools.chain(parts, [None]):  # None: the end, give out the rest
        if part is not None:
            pending.append(part)
            held += part[1].size
        while held and (part is None or (samples is not None and held >= samples)):
            joined = {role: np.concatenate([p[0][role] for p in pending]) for role in columns}
            lines = np.concatenate([p[1] for p in pending])
            count = held if samples is None else min(samples, held)
            if samples is None:
                _check_not_empty(path, layout.header_line, joined, columns)
            yield Recording(
                path=path,
                **{role: values[:count] for role, values in joined.items()},
                last_line=int(lines[count - 1]),
                columns=columns,
                units=layout.units,
                start=first,
                lines=LineIndex.build(lines[:count], first),
                format="text",
                assumed_units=layout.assumed,
            )
            pending = [({role: joined[role][count:] for role in columns}, lines[count:])]
            held -= count
            first += count
    if first == 0:
        raise RecordingError(path, layout.header_line, "no data after the header")


def _check_not_empty(path: Path, header_line: int, values: dict, columns: dict) -> None:
    for role, data in values.items():
        if not np.isfinite(data).any():
            hint = "cycle_column=False (--cycle-col none) reads no cycle column"
            raise RecordingError(
                path,
                header_line,
                f"the {role} column {columns[role]!r} holds no number: all its {data.size} "
                f"samples are missing; {hint if role == 'cycle' else 'is it the right column?'}",
            )


def read_recording(
    path,
    *,
    displacement_column="displacement",
    force_column="force",
    cycle_column=None,
    displacement_unit=None,
    force_unit=None,
    group=None,
    nan_policy="propagate",
    lazy=None,
    chunks=None,
    block_bytes=None,
    load_column=None,
    skip_rows=None,
) -> Recording:
    """Read the displacement and force (and cycle) columns of a recording, in SI units
    (formats, columns and units: ``docs/formats.md``).

    Parameters
    ----------
    path : str or os.PathLike
        A text, TDMS, HDF5 or netCDF-4 file, or a zarr store (a directory), found by content.
    displacement_column, force_column : str
        Their columns (channels, variables), case and a unit in the name aside; in a text
        file the defaults also find :data:`ecofmaps.io.columns.SYNONYMS`.
    cycle_column : str or False, optional
        A column of cycle numbers; by default ``cycle`` if any; False: none (cycles are cut
        at the displacement reversals).
    displacement_unit, force_unit : str, optional
        Their units (``'um'``, ``'kN'``, ...); by default the file's, else µm and N.
    group : str, optional
        TDMS group or HDF5/netCDF/zarr group path; by default the one holding the channels.
    nan_policy : {'propagate', 'raise'}
        Missing samples are NaN (:attr:`Recording.missing`), or an error naming the first.
    lazy : bool, optional
        Dask arrays (True) or NumPy arrays (False); by default lazy for a rig file of more than
        :data:`~ecofmaps.io.recording_types.LAZY_SAMPLES` samples (a text file is parsed into
        memory either way).
    chunks : int, optional
        Samples per dask block; by default a multiple of the file's own chunks near 2**22.
    block_bytes : int, optional
        Bytes of a text file parsed at a time (:data:`ecofmaps.io.text.BLOCK_BYTES`).
    load_column : str, optional
        A normal-load column of a text file, read into :attr:`Recording.load` [N].
    skip_rows : int, optional
        Lines of a text file before its header; by default the header is the first line
        naming the columns among the first :data:`ecofmaps.io.text.PREAMBLE_LINES`.

    Returns
    -------
    recording : Recording
        The samples in SI units (m, N).

    Raises
    ------
    RecordingError
        For a missing, ambiguous or doubtful column, a bad line or cell, no data, channels of
        different lengths, a damaged file: naming the file and the line, or channel and sample.
    ValueError
        For an option of the wrong kind, naming it.

    Examples
    --------
    >>> import ecofmaps
    >>> recording = ecofmaps.read_recording(ecofmaps.measured.synthetic.example_path())
    >>> recording.size, recording.units["displacement"], recording.lazy
    (24000, 'um', False)
    """
    options = _options(
        displacement_column,
        force_column,
        cycle_column,
        displacement_unit,
        force_unit,
        group,
        nan_policy,
        load_column,
        skip_rows,
    )
    if lazy not in (None, True, False):
        raise ValueError(f"lazy must be True, False or None; got {lazy!r}")
    _check_count("chunks", chunks)
    _check_count("block_bytes", block_bytes)
    path = Path(path)
    kind = recording_format(path)
    if kind != "text":
        for name in ("load_column", "skip_rows"):
            if options[name] is not None:
                raise ValueError(f"{name} applies to text files, not to {kind.upper()}")
        return read_binary(path, kind, options, lazy=lazy, chunks=chunks)
    (recording,) = _text_recordings(path, options, block_bytes)
    if not lazy:
        return recording
    import dask.array as da

    size = chunks or recording.size
    return dataclasses.replace(
        recording,
        **{role: da.from_array(a, chunks=size) for role, a in recording.arrays().items()},
    )


def open_recording(path, **options) -> xr.Dataset:
    """A recording as one xarray Dataset over ``sample`` in SI units.

    Parameters
    ----------
    path, **options
        As in :func:`read_recording`.

    Returns
    -------
    dataset : xarray.Dataset
        As :meth:`Recording.to_dataset` gives it.

    Raises
    ------
    RecordingError, ValueError
        As :func:`read_recording`.

    Examples
    --------
    >>> from ecofmaps.io import open_recording
    >>> from ecofmaps.measured.synthetic import example_path
    >>> dataset = open_recording(example_path())
    >>> dataset.displacement.attrs["units"], dataset.displacement.attrs["unit_assumed"]
    ('m', 1)
    """
    return read_recording(path, **options).to_dataset()


def recording_blocks(path, samples: int = 1 << 20, **options) -> Iterator[Recording]:
    """A recording block by block, each in memory, with bounded memory overall.

    Parameters
    ----------
    path, **options
        As in :func:`read_recording` (but ``lazy`` and ``chunks``).
    samples : int
        Samples per block (the last may be shorter).

    Yields
    ------
    block : Recording
        NumPy arrays; ``block.start`` is the index of its first sample in the file.
    """
    _check_count("samples", samples)
    block_bytes = options.pop("block_bytes", None)
    _check_count("block_bytes", block_bytes)
    path = Path(path)
    if recording_format(path) == "text":
        yield from _text_recordings(path, _options(**options), block_bytes, int(samples))
        return
    with read_recording(path, lazy=True, chunks=int(samples), **options) as recording:
        for first in range(0, recording.size, int(samples)):
            yield recording[first : first + int(samples)]
