"""A recording as read (:class:`Recording`, in SI, with where each sample came from) and the
error naming that place (:class:`RecordingError`); ``docs/formats.md``."""

from __future__ import annotations

import dataclasses
import difflib
import errno
import functools
import os
import stat
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from ecofmaps._nomenclature import attrs
from ecofmaps._parallel import SOURCE
from ecofmaps.io.files import FileLineError

#: What a path that is not a regular file is, by ``stat`` test.
_NOT_FILES = {
    stat.S_ISFIFO: "a named pipe (FIFO)",
    stat.S_ISCHR: "a character device",
    stat.S_ISBLK: "a block device",
    stat.S_ISSOCK: "a socket",
}

#: Rig files with more samples than this are read lazily (dask arrays) by default.
LAZY_SAMPLES = 1 << 24

#: The SI unit of each role's samples.
SI_UNITS = {"displacement": "m", "force": "N", "cycle": "1", "load": "N"}


def si_values(values: np.ndarray, factor: float) -> np.ndarray:
    """``values`` (changed in place) times ``factor``; a factor 10^-k divides by the exact 10^k,
    so that ``25`` µm is the float nearest 25e-6 m (one rounding, not two)."""
    if factor == 1.0:
        return values
    inverse = round(1.0 / factor)
    if factor < 1.0 and inverse == 1.0 / factor and float(inverse) == inverse:
        values /= float(inverse)
    else:
        values *= factor
    return values


class RecordingError(FileLineError):
    """A damaged recording, named as a :class:`~ecofmaps.io.FileLineError` names it."""


class _MissingFile(FileNotFoundError):
    """Said as ``<path>: no such file[: did you mean ...]``."""

    def __str__(self) -> str:
        return f"{self.filename}: {self.strerror}"


def check_regular_file(path) -> None:
    """Refuse a pipe, device or socket (it blocks or never ends); a missing file's error names
    the nearest name in its folder."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        folder = Path(path).parent
        names = [p.name for p in folder.iterdir()] if folder.is_dir() else []
        near = difflib.get_close_matches(Path(path).name, names, n=1, cutoff=0.8)
        hint = f": did you mean {str(folder / near[0])!r}?" if near else ""
        raise _MissingFile(errno.ENOENT, f"no such file{hint}", str(path)) from None
    if stat.S_ISREG(mode):
        return
    what = next((kind for test, kind in _NOT_FILES.items() if test(mode)), "not a regular file")
    raise RecordingError(
        path, None, f"{what}, not a regular file: save the data to a file and read that"
    )


class RecordingWarning(UserWarning):
    """A recording read in a way the user should know (e.g. as Latin-1)."""


@dataclasses.dataclass(frozen=True)
class LineIndex:
    """The 1-based line of each sample of a text file, as runs: from sample ``starts[k]`` on,
    line = sample + ``offsets[k]``."""

    starts: np.ndarray
    offsets: np.ndarray

    @classmethod
    def build(cls, lines: np.ndarray, first: int) -> LineIndex:
        offset = lines - np.arange(first, first + lines.size)
        runs = np.concatenate([[0], np.flatnonzero(np.diff(offset)) + 1])
        return cls(runs + first, offset[runs])

    def __call__(self, index):
        index = np.asarray(index, dtype=np.int64)
        run = np.searchsorted(self.starts, index, side="right") - 1
        return index + self.offsets[run]


@dataclasses.dataclass(frozen=True, eq=False)
class Recording:
    """The samples read from a recording file, in SI units: NumPy arrays, or dask arrays for a
    rig file read lazily (``recording[start:stop]`` reads a range, :meth:`compute` all).

    Attributes
    ----------
    path : pathlib.Path
    displacement, force : numpy.ndarray or dask.array.Array
        [m] and [N]; NaN where a sample is missing.
    cycle, load : numpy.ndarray or dask.array.Array or None
        The cycle number of each sample [1] and the normal load [N], if read.
    last_line : int or None
        1-based line number of the last sample, for a text file.
    columns, units : Mapping[str, str]
        For each role read: the column as named in the file, and the unit it was read in.
    start : int
        0-based index in the file of the first sample (non-zero for a block).
    format : str or None
        ``'text'``, ``'tdms'``, ``'hdf5'`` or ``'zarr'``.
    assumed_units : tuple of str
        The roles whose unit neither the file nor an option gave (the default, µm or N).
    """

    path: Path
    displacement: Any
    force: Any
    cycle: Any = None
    load: Any = None
    last_line: int | None = None
    columns: Mapping[str, str] = dataclasses.field(default_factory=dict)
    units: Mapping[str, str] = dataclasses.field(default_factory=dict)
    start: int = 0
    lines: LineIndex | None = dataclasses.field(default=None, repr=False)
    format: str | None = None
    assumed_units: tuple = ()

    @property
    def size(self) -> int:
        """Number of samples."""
        return int(self.displacement.shape[0])

    def __len__(self) -> int:
        return self.size

    @property
    def lazy(self) -> bool:
        """Whether the arrays are dask arrays, read when computed."""
        return not isinstance(self.displacement, np.ndarray)

    def arrays(self) -> dict:
        """The arrays read, by role (displacement, force, then cycle and load if read)."""
        read = {role: getattr(self, role) for role in SI_UNITS}
        return {role: array for role, array in read.items() if array is not None}

    @functools.cached_property
    def missing(self):
        """Mask of the missing samples (NaN in any column read): numpy or dask, as the data."""
        return ~functools.reduce(np.logical_and, map(np.isfinite, self.arrays().values()))

    def line(self, index):
        """The 1-based lines in a text file (else None) of samples ``index`` (int or array_like)."""
        if self.lines is None:
            return None
        lines = self.lines(np.asarray(index) + self.start)
        return int(lines) if np.ndim(lines) == 0 else lines

    def position(self, index=None) -> str | int | None:
        """Where sample ``index`` is: its line (int) in a text file, else ``'sample N'`` (0-based
        in the file); for ``index=None`` the end of the file (its last line, or None)."""
        if index is None:
            return self.last_line
        return self.line(index) if self.lines is not None else f"sample {self.start + int(index)}"

    def error(self, message: str, index=None) -> RecordingError:
        """A :class:`RecordingError` at sample ``index`` (by default the end of the file)."""
        return RecordingError(self.path, self.position(index), message)

    def __getitem__(self, key: slice) -> Recording:
        """Samples ``start:stop`` (step 1) in memory, keeping their positions in the file."""
        if not isinstance(key, slice) or key.step not in (None, 1):
            raise TypeError("a Recording is indexed by a slice start:stop")
        first, stop, _ = key.indices(self.size)
        stop = max(stop, first)
        taken = {role: array[first:stop] for role, array in self.arrays().items()}
        if self.lazy:
            import dask

            taken = dict(zip(taken, dask.compute(*taken.values()), strict=True))
        last = int(self.lines(self.start + stop - 1)) if self.lines and stop > first else None
        return dataclasses.replace(self, **taken, last_line=last, start=self.start + first)

    def close(self) -> None:
        """Close the files a lazy recording reads (a later read opens them), as ``with`` does."""
        for array in self.arrays().values():
            source = getattr(array, SOURCE, None)
            if source is not None:
                source.close()

    def __enter__(self) -> Recording:
        return self

    def __exit__(self, *raised) -> None:
        self.close()

    def compute(self) -> Recording:
        """The recording with NumPy arrays (reads a lazy one whole; else itself)."""
        return self[:] if self.lazy else self

    def to_dataset(self) -> xr.Dataset:
        """The recording as one Dataset over ``sample`` (dask-backed if lazy): each role a
        variable with ``units`` (SI), ``long_name``, ``source_column``, ``source_units`` and
        ``unit_assumed`` (1 or 0); attributes ``source`` (the path), ``format`` and
        ``first_sample``."""
        variables = {}
        for role, data in self.arrays().items():
            variables[role] = xr.Variable(
                ("sample",),
                data,
                {
                    **attrs(role),
                    "units": SI_UNITS[role],
                    "source_column": self.columns.get(role, role),
                    "source_units": self.units.get(role, SI_UNITS[role]),
                    "unit_assumed": int(role in self.assumed_units),
                },
            )
        source = {"source": str(self.path), "format": self.format or "arrays"}
        return xr.Dataset(variables, attrs={**source, "first_sample": self.start})
