"""Recordings of fretting loops in text files, and the per-cycle results table.

:func:`read_recording` reads comma-, tab- or whitespace-separated columns with a header
line (lines starting with ``#`` and blank lines are skipped). By default the columns are
``displacement`` in µm and ``force`` in N, and an optional ``cycle``; names are matched
without regard to case. A damaged file raises :class:`RecordingError`, which names the
file and the 1-based line. :func:`results_table` turns :func:`ecofmaps.analyze_loops`'s
Dataset into the table that ``ecofmaps loops`` writes, in the tribologist's units, and
:func:`write_text` writes a file atomically.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from ecofmaps.io.files import FileLineError, atomic_path
from ecofmaps.units import parse_quantity

__all__ = [
    "RESULT_COLUMNS",
    "Recording",
    "RecordingError",
    "read_columns",
    "read_recording",
    "results_table",
    "write_text",
]

#: The columns of the results table: name -> (Dataset variable, factor from SI).
RESULT_COLUMNS = {
    "cycle": ("cycle", 1),
    "amplitude_um": ("amplitude", 1e6),
    "slip_amplitude_um": ("slip_amplitude", 1e6),
    "max_force_N": ("max_force", 1.0),
    "dissipated_energy_mJ": ("dissipated_energy", 1e3),
    "ecof": ("ecof", 1.0),
    "cof_max": ("cof_max", 1.0),
    "energy_ratio": ("energy_ratio", 1.0),
    "stiffness_MN_per_m": ("stiffness", 1e-6),
    "gicof": ("gicof", 1.0),
    "regime": ("regime", None),
}

_DELIMITERS = {".csv": ",", ".tsv": "\t", ".tab": "\t"}


class RecordingError(FileLineError):
    """A damaged recording: the message names the file and the 1-based line number."""


@dataclasses.dataclass(frozen=True, eq=False)
class Recording:
    """The samples read from a recording file, in SI units.

    Attributes
    ----------
    path : pathlib.Path
    displacement : numpy.ndarray
        [m]
    force : numpy.ndarray
        [N]
    cycle : numpy.ndarray or None
        The cycle number of each sample, if the file has a cycle column. [1]
    last_line : int
        1-based line number of the last sample in the file.
    """

    path: Path
    displacement: np.ndarray
    force: np.ndarray
    cycle: np.ndarray | None
    last_line: int


def _delimiter(path: Path, header: str):
    """The field separator: from the suffix, else the first of tab, comma or semicolon found
    in the header, else None (any run of whitespace)."""
    if path.suffix.lower() in _DELIMITERS:
        return _DELIMITERS[path.suffix.lower()]
    for candidate in ("\t", ",", ";"):
        if candidate in header:
            return candidate
    return None


def _numbers(path, name, cells, lines, scale, error=RecordingError) -> np.ndarray:
    """A column's cells as float64 times ``scale``; the first bad cell raises its line."""
    values = pd.to_numeric(pd.Series(cells, dtype=object), errors="coerce").to_numpy(
        dtype=np.float64
    )
    bad = ~np.isfinite(values)
    if bad.any():
        first = int(np.argmax(bad))
        raise error(path, lines[first], f"non-numeric value {cells[first]!r} in column {name!r}")
    return values * scale


def read_columns(path, required, optional=None, error=RecordingError):
    """Named numeric columns of a text table with a header line.

    Parameters
    ----------
    path : str or os.PathLike
        The file; separators and comment lines as for :func:`read_recording`.
    required : dict of str to str
        Role -> column name (matched without regard to case); each must exist.
    optional : dict of str to str, optional
        Role -> column name, read if the header has it.
    error : type of FileLineError
        The error raised, naming the file and the 1-based line.

    Returns
    -------
    values : dict of str to numpy.ndarray
        Each role's column as float64 (unscaled).
    lines : numpy.ndarray of int64
        The 1-based line number of each row.

    Raises
    ------
    error
        For no data, a missing column, a line with the wrong number of fields, or a
        non-numeric or non-finite cell.
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8-sig")
    numbered = [
        (number, line)
        for number, line in enumerate(text.splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not numbered:
        raise error(path, max(text.count("\n"), 1), "no header line and no data")
    header_line, header = numbered[0]
    separator = _delimiter(path, header)
    names = [name.strip().strip('"').strip().lower() for name in header.split(separator)]
    wanted = dict(required)
    wanted.update({role: name for role, name in (optional or {}).items() if name.lower() in names})
    columns = {}
    for role, name in wanted.items():
        if name.lower() not in names:
            raise error(
                path,
                header_line,
                f"no {role} column {name!r} in the header (columns: {', '.join(names)})",
            )
        columns[role] = names.index(name.lower())
    lines = np.array([number for number, _ in numbered[1:]], dtype=np.int64)
    if lines.size == 0:
        raise error(path, header_line, "no data after the header")
    rows = [line.split(separator) for _, line in numbered[1:]]
    widths = np.fromiter(map(len, rows), dtype=np.int64, count=len(rows))
    if np.any(widths != len(names)):
        first = int(np.argmax(widths != len(names)))
        raise error(
            path,
            lines[first],
            f"{widths[first]} fields where the header has {len(names)}",
        )
    values = {
        role: _numbers(path, wanted[role], [row[k] for row in rows], lines, 1.0, error)
        for role, k in columns.items()
    }
    return values, lines


def read_recording(
    path,
    *,
    displacement_column="displacement",
    force_column="force",
    cycle_column=None,
    displacement_unit="um",
    force_unit="N",
) -> Recording:
    """Read the displacement and force columns of a recording file.

    Parameters
    ----------
    path : str or os.PathLike
        A text file: a header line of column names, then one sample per line. Fields are
        separated by commas (``.csv``), tabs (``.tsv``) or, for other suffixes, by the
        first of tab, comma or semicolon found in the header, else by whitespace. Lines
        starting with ``#`` and blank lines are skipped.
    displacement_column, force_column : str
        Names of the displacement and tangential force columns.
    cycle_column : str, optional
        Name of a column of cycle numbers, which must then exist. By default a column
        named ``cycle`` is used if there is one.
    displacement_unit, force_unit : str
        Units of the displacement and force columns (``'um'``, ``'mm'``, ``'N'``,
        ``'kN'``, ...).

    Returns
    -------
    recording : Recording
        The samples in SI units (m, N).

    Raises
    ------
    RecordingError
        For a missing column, a line with the wrong number of fields, a non-numeric or
        non-finite cell, or no data; the message names the file and the line.
    ValueError
        For a unit of the wrong kind.
    OSError
        If the file cannot be read.
    """
    path = Path(path)
    metres = parse_quantity(f"1 {displacement_unit}", "length")
    newtons = parse_quantity(f"1 {force_unit}", "force")
    required = {"displacement": displacement_column, "force": force_column}
    if cycle_column is not None:
        required["cycle"] = cycle_column
    optional = {"cycle": "cycle"} if cycle_column is None else None
    values, lines = read_columns(path, required, optional)
    values["displacement"] = values["displacement"] * metres
    values["force"] = values["force"] * newtons
    return Recording(
        path=path,
        displacement=values["displacement"],
        force=values["force"],
        cycle=values.get("cycle"),
        last_line=int(lines[-1]),
    )


def results_table(results: xr.Dataset) -> pd.DataFrame:
    """The per-cycle results in the tribologist's units, one row per cycle.

    Parameters
    ----------
    results : xarray.Dataset
        From :func:`ecofmaps.analyze_loops`.

    Returns
    -------
    table : pandas.DataFrame
        Exactly the columns of :data:`RESULT_COLUMNS`: cycle, amplitude_um,
        slip_amplitude_um, max_force_N, dissipated_energy_mJ, ecof, cof_max,
        energy_ratio, stiffness_MN_per_m, gicof, regime.
    """
    return pd.DataFrame(
        {
            column: results[name].values if factor is None else results[name].values * factor
            for column, (name, factor) in RESULT_COLUMNS.items()
        }
    )


def write_text(path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (a temporary file, then a rename).

    Parameters
    ----------
    path : str or os.PathLike
        Destination; its directory must exist.
    text : str

    Returns
    -------
    path : pathlib.Path
    """
    path = Path(path)
    with atomic_path(path) as temporary:
        temporary.write_text(text, encoding="utf-8", newline="")
    return path
