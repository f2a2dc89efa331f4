"""Tables of reported ECoF values (the input of ``ecofmaps correct``, described in
``docs/formats.md``) corrected row by row to the contact CoF."""

from __future__ import annotations

import csv
import io
import warnings
from pathlib import Path

import numpy as np

from ecofmaps import _nomenclature as nomenclature
from ecofmaps.correction.inversion import correct_ecof
from ecofmaps.correction.outcomes import CorrectionStatus
from ecofmaps.io.files import FileLineError

#: Input columns: column name -> quantity name (its unit and range in the nomenclature).
COLUMNS = {
    nomenclature.column(name): name
    for name in (
        "ecof",
        "amplitude",
        "load",
        "stiffness",
        "aspect_ratio",
        "scar_depth",
        "scar_half_width",
    )
}
#: Columns added to the output.
ADDED_COLUMNS = ("mu", "correction_factor")
#: Column added on a profile: the contact CoF of the parabola of the same D/W (eq. 11).
SHORTCUT_COLUMN = "mu_parabolic"
#: Column added when a row could not be corrected: each row's :class:`CorrectionStatus` label.
STATUS_COLUMN = "status"

_REQUIRED = tuple(nomenclature.column(n) for n in ("ecof", "amplitude", "load", "stiffness"))
_SCAR = tuple(nomenclature.column(n) for n in ("scar_depth", "scar_half_width"))
# When a one-column header suggests the wrong separator was guessed.
_SEPARATOR_HINT = " (the header holds no tab, ';' or ',': separate the columns with one of them)"


class TableError(FileLineError):
    """A bad table: the message names the file and the 1-based line number (header: 1)."""


class TableRowWarning(UserWarning):
    """A row that could not be corrected (``bad_rows="nan"``), named as by :class:`TableError`."""


def _number(path, line: int, name: str, text: str, decimal_comma: bool) -> float:
    """The cell ``text`` of column ``name`` in SI, range-checked (``0,83`` if ``decimal_comma``)."""
    quantity = nomenclature.QUANTITIES[COLUMNS[name]]
    unit = f" in {quantity.display_unit}" if quantity.display_unit else ""
    if decimal_comma and text.count(",") == 1 and "." not in text:
        text = text.replace(",", ".")
    try:
        value = float(text)
    except ValueError:
        raise TableError(
            path, line, f"{name} = {text.strip()!r} is not a number (the {quantity.words}{unit})"
        ) from None
    if not nomenclature.within(COLUMNS[name], value):
        valid = nomenclature.RANGES[quantity.valid][1].format(name=name)
        raise TableError(path, line, f"{name} must satisfy {valid}, got {text.strip()}")
    return value / quantity.display_factor


def _read(path: Path, on_profile: bool, keep_bad: bool):
    """Header, (row, line) records, SI columns (NaN in a bad row), separator, whether it has
    decimal commas, and the errors of the bad rows by index (raised at once unless ``keep_bad``)."""
    try:
        with open(path, encoding="utf-8-sig", newline="") as stream:
            lines = ["\n" if line.lstrip().startswith("#") else line for line in stream]
        header_line = next((line for line in lines if line.strip()), ",")
        delimiter = "\t" if "\t" in header_line else ";" if ";" in header_line else ","
        reader = csv.reader(lines, delimiter=delimiter)
        # each non-blank row with the file line it ends on (csv counts the lines it reads)
        records = [(row, reader.line_num) for row in reader if any(cell.strip() for cell in row)]
    except UnicodeDecodeError as error:
        raise TableError(path, 1, f"not a UTF-8 text file ({error.reason})") from None
    except csv.Error as error:
        raise TableError(path, 1, f"not a CSV table ({error})") from None
    if not records:
        raise TableError(path, 1, "the file is empty; expected a header line")
    (header, header_line), records = records[0], records[1:]
    header = [name.strip() for name in header]
    problem = _header_problem(header, on_profile, keep_bad)
    if problem:
        raise TableError(path, header_line, problem)
    if not records:
        raise TableError(path, header_line, "the table has a header but no data rows")
    column = {name: header.index(name) for name in COLUMNS if name in header}
    commas = delimiter != ","
    names = _REQUIRED if on_profile else (*_REQUIRED, "aspect_ratio")
    rows, bad = [], {}
    for index, (row, line) in enumerate(records):
        if len(row) != len(header):
            hint = "" if len(header) > 1 else _SEPARATOR_HINT
            message = f"{len(row)} fields, but the header has {len(header)} columns{hint}"
            raise TableError(path, line, message)
        try:
            rows.append(_row_values(path, line, row, column, on_profile, commas))
        except TableError as error:
            if not keep_bad:
                raise
            bad[index] = error
            rows.append(dict.fromkeys(names, np.nan))
    si = {name: np.asarray([values[name] for values in rows]) for name in names}
    cells = [row[column[name]] for row, _ in records for name in column]
    return header, records, si, delimiter, commas and any("," in cell for cell in cells), bad


def _row_values(path, line: int, row, column: dict, on_profile: bool, commas: bool) -> dict:
    """The SI values of one row: the required columns and (not on a profile) its aspect ratio."""

    def number(name: str) -> float:
        return _number(path, line, name, row[column[name]], commas)

    values = {name: number(name) for name in _REQUIRED}
    if not on_profile:
        depth, width = _SCAR
        has = [n in column and row[column[n]].strip() != "" for n in ("aspect_ratio", *_SCAR)]
        if has not in ([True, False, False], [False, True, True]):  # the ratio, or D and W
            message = "give the aspect ratio one way: aspect_ratio, or both " + " and ".join(_SCAR)
            raise TableError(path, line, message)
        values["aspect_ratio"] = number("aspect_ratio") if has[0] else number(depth) / number(width)
    return values


def _header_problem(header: list[str], on_profile: bool, keep_bad: bool) -> str | None:
    duplicates = sorted({name for name in header if header.count(name) > 1})
    if duplicates:
        return f"repeated column(s) {', '.join(duplicates)}"
    shapes = [name for name in ("aspect_ratio", *_SCAR) if name in header] if on_profile else []
    if shapes:
        return (
            f"column(s) {', '.join(shapes)} give the scar, but so does the profile: drop the "
            "columns, or correct without the profile"
        )
    missing = [name for name in _REQUIRED if name not in header]
    if not on_profile and "aspect_ratio" not in header and not all(n in header for n in _SCAR):
        missing.append("aspect_ratio (or " + " + ".join(_SCAR) + ")")
    if missing:
        return (
            f"missing column(s) {', '.join(missing)}; the table needs {', '.join(_REQUIRED)} "
            f"and aspect_ratio or {' + '.join(_SCAR)}"
        )
    added = (*ADDED_COLUMNS, *[SHORTCUT_COLUMN] * on_profile, *[STATUS_COLUMN] * keep_bad)
    taken = [name for name in added if name in header]
    return f"column(s) {', '.join(taken)} would be overwritten by the results" if taken else None


def correct_table(path, profile=None, mapping="scaled", bad_rows="raise") -> tuple[str, int]:
    """The table at ``path`` (``docs/formats.md``) with each row's results, as text in its dialect,
    and its number of rows; ``bad_rows='nan'`` gives a bad row NaN, a ``status`` and a
    :class:`TableRowWarning` instead of raising :class:`TableError`."""
    if bad_rows not in ("raise", "nan"):
        raise ValueError(f"bad_rows must be 'raise' or 'nan', got {bad_rows!r}")
    path = Path(path)
    header, records, si, sep, commas, bad = _read(path, profile is not None, bad_rows == "nan")
    read = ~np.isin(np.arange(len(records)), list(bad))
    rig = {name: si[nomenclature.column(name)][read] for name in ("amplitude", "load", "stiffness")}
    mu, added = np.full(len(records), np.nan), [[] for _ in records]
    status = np.full(len(records), int(CorrectionStatus.INVALID))
    if profile is None:
        scar = {"aspect_ratio": si["aspect_ratio"][read]}
    else:
        scar = {"profile": profile, "mapping": mapping}
        shortcut = np.full(len(records), np.nan)
        shortcut[read], _ = correct_ecof(
            si["ecof"][read], **rig, aspect_ratio=float(profile.aspect_ratio), return_status=True
        )
        added = [[_written(value, commas)] for value in shortcut]
    if read.any():
        mu[read], status[read] = correct_ecof(si["ecof"][read], **rig, **scar, return_status=True)
    for i, index in enumerate(np.flatnonzero(read)):
        if status[index] != CorrectionStatus.CORRECTED:
            one = {k: v[i] if k == "aspect_ratio" else v for k, v in scar.items()}
            try:  # a single point raises with its reason
                correct_ecof(si["ecof"][index], **{k: v[i] for k, v in rig.items()}, **one)
            except ValueError as error:
                bad[index] = TableError(path, records[index][1], str(error))
    for index in sorted(bad):
        if bad_rows == "raise":
            raise bad[index]
        warnings.warn(str(bad[index]), TableRowWarning, stacklevel=2)
    stream = io.StringIO()
    writer = csv.writer(stream, delimiter=sep, lineterminator="\n")
    more = ([] if profile is None else [SHORTCUT_COLUMN]) + ([STATUS_COLUMN] if bad else [])
    writer.writerow([*header, *ADDED_COLUMNS, *more])
    for (row, _), value, factor, cells, code in zip(
        records, mu, mu / si["ecof"], added, status, strict=True
    ):
        label = [CorrectionStatus(int(code)).label] if bad else []
        writer.writerow([*row, *(_written(v, commas) for v in (value, factor)), *cells, *label])
    return stream.getvalue(), len(records)


def _written(value: float, decimal_comma: bool) -> str:
    """A result cell: 10 significant digits, with a decimal comma if the table uses them."""
    text = f"{value:.10g}"
    return text.replace(".", ",") if decimal_comma else text
