"""Tables of reported ECoF values, corrected row by row to the contact CoF.

:func:`correct_table` reads the table ``ecofmaps correct`` takes, corrects each row with
:func:`ecofmaps.correct_ecof` and writes it back with ``mu`` and ``correction_factor`` added;
a bad row raises :class:`TableError` naming the file and the line. The table's format is
described in ``docs/formats.md``.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ecofmaps import _nomenclature as nomenclature
from ecofmaps.correction.inversion import correct_ecof
from ecofmaps.correction.outcomes import CorrectionStatus
from ecofmaps.io.files import FileLineError

__all__ = [
    "ADDED_COLUMNS",
    "COLUMNS",
    "SHORTCUT_COLUMN",
    "TableDialect",
    "TableError",
    "correct_table",
    "table_dialect",
]

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

_REQUIRED = tuple(nomenclature.column(n) for n in ("ecof", "amplitude", "load", "stiffness"))
_SCAR = tuple(nomenclature.column(n) for n in ("scar_depth", "scar_half_width"))


class TableError(FileLineError):
    """A bad table: the message names the file and the 1-based line number (header: 1)."""


class TableDialect(NamedTuple):
    """How a table is written: its separator, and whether its numbers use decimal commas."""

    delimiter: str
    decimal_comma: bool


def table_dialect(header_line: str) -> TableDialect:
    """The separator the header line uses (tab, else ``;``, else ``,``)."""
    delimiter = "\t" if "\t" in header_line else ";" if ";" in header_line else ","
    return TableDialect(delimiter, False)


def _number(path, line: int, name: str, text: str, decimal_comma: bool = False) -> float:
    """The cell ``text`` of column ``name`` in SI, range-checked (``0,83`` read as 0.83 when the
    table's separator is not a comma)."""
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


def _read(path: Path, on_profile: bool = False):
    """Header, rows (cells as written), their line numbers, the SI columns and the dialect."""
    try:
        with open(path, encoding="utf-8-sig", newline="") as stream:
            lines = ["\n" if _is_comment(line) else line for line in stream]
        header_line = next((line for line in lines if line.strip()), ",")
        dialect = table_dialect(header_line)
        records = list(_records(csv.reader(lines, delimiter=dialect.delimiter)))
    except UnicodeDecodeError as error:
        raise TableError(path, 1, f"not a UTF-8 text file ({error.reason})") from None
    except csv.Error as error:
        raise TableError(path, 1, f"not a CSV table ({error})") from None
    if not records:
        raise TableError(path, 1, "the file is empty; expected a header line")
    (header, header_line), records = records[0], records[1:]
    header = [name.strip() for name in header]
    _check_header(path, header_line, header, on_profile)
    if not records:
        raise TableError(path, header_line, "the table has a header but no data rows")
    column = {name: header.index(name) for name in COLUMNS if name in header}
    values = {name: [] for name in (*_REQUIRED, "aspect_ratio")}
    commas = dialect.delimiter != ","
    for row, line in records:
        if len(row) != len(header):
            raise TableError(
                path,
                line,
                f"{len(row)} fields, but the header has {len(header)} columns"
                + _separator_hint(header),
            )
        for name in _REQUIRED:
            values[name].append(_number(path, line, name, row[column[name]], commas))
        if on_profile:
            continue
        given_ratio = "aspect_ratio" in column and row[column["aspect_ratio"]].strip() != ""
        given_scar = [name in column and row[column[name]].strip() != "" for name in _SCAR]
        if given_ratio == any(given_scar) or (any(given_scar) and not all(given_scar)):
            raise TableError(
                path,
                line,
                "give the aspect ratio one way: aspect_ratio, or both scar_depth_um and "
                "scar_half_width_um",
            )
        ratio = (
            _number(path, line, "aspect_ratio", row[column["aspect_ratio"]], commas)
            if given_ratio
            else _number(path, line, "scar_depth_um", row[column["scar_depth_um"]], commas)
            / _number(path, line, "scar_half_width_um", row[column["scar_half_width_um"]], commas)
        )
        values["aspect_ratio"].append(ratio)
    si = {name: np.asarray(values[name]) for name in values if values[name]}
    numbers = [row[column[name]] for row, _ in records for name in column]
    decimal_comma = commas and any("," in cell for cell in numbers)
    return header, records, si, dialect._replace(decimal_comma=decimal_comma)


def _is_comment(line: str) -> bool:
    """True for a comment line: ``#`` its first character other than spaces."""
    return line.lstrip().startswith("#")


def _separator_hint(header: list[str]) -> str:
    """A hint when a one-column header suggests the wrong separator was guessed."""
    if len(header) > 1:
        return ""
    return " (the header holds no tab, ';' or ',': separate the columns with one of them)"


def _records(reader):
    """Non-blank rows with the file line each ends on (csv counts the lines it reads)."""
    for row in reader:
        if any(cell.strip() for cell in row):
            yield row, reader.line_num


def _check_header(path, line: int, header: list[str], on_profile: bool) -> None:
    duplicates = sorted({name for name in header if header.count(name) > 1})
    if duplicates:
        raise TableError(path, line, f"repeated column(s) {', '.join(duplicates)}")
    if on_profile:
        shapes = [name for name in ("aspect_ratio", *_SCAR) if name in header]
        if shapes:
            raise TableError(
                path,
                line,
                f"column(s) {', '.join(shapes)} give the scar, but so does the "
                "profile: drop the columns, or correct without the profile",
            )
    missing = [name for name in _REQUIRED if name not in header]
    if not on_profile and "aspect_ratio" not in header and not all(n in header for n in _SCAR):
        missing.append("aspect_ratio (or " + " + ".join(_SCAR) + ")")
    if missing:
        raise TableError(
            path,
            line,
            f"missing column(s) {', '.join(missing)}; the table needs {', '.join(_REQUIRED)} "
            f"and aspect_ratio or {' + '.join(_SCAR)}",
        )
    added = (*ADDED_COLUMNS, SHORTCUT_COLUMN) if on_profile else ADDED_COLUMNS
    taken = [name for name in added if name in header]
    if taken:
        raise TableError(
            path, line, f"column(s) {', '.join(taken)} would be overwritten by the results"
        )


def correct_table(path, profile=None, mapping="scaled") -> tuple[str, int]:
    r"""Correct every row of a table of reported ECoF values (format: ``docs/formats.md``).

    Parameters
    ----------
    path : str or os.PathLike
        The table: separated by commas, semicolons or tabs, with ``#`` comment lines.
    profile : ScarProfile, optional
        A measured wear-scar profile that gives every row's scar (the table then has no
        scar columns).
    mapping : {'scaled', 'physical'}
        On a profile: :math:`X = xW/\Delta^*` (eq. 11) or :math:`X = x`.

    Returns
    -------
    text : str
        The output table with the input's separator: the input columns and cells, then
        ``mu`` and ``correction_factor`` (both to 10 significant digits, with a decimal
        comma if the input has them), and on a profile ``mu_parabolic``.
    rows : int
        The number of data rows.

    Raises
    ------
    TableError
        For a file that cannot be read as such a table, a bad value, or a row whose ECoF
        cannot be corrected (the reason, as :func:`ecofmaps.correct_ecof` gives it); the
        first such row is named by its line.
    OSError
        If the file cannot be opened.
    """
    path = Path(path)
    header, records, si, dialect = _read(path, on_profile=profile is not None)
    rig = dict(amplitude=si["amplitude_um"], load=si["load_N"], stiffness=si["stiffness_MN_per_m"])
    if profile is None:
        scar = {"aspect_ratio": si["aspect_ratio"]}
        added = [[] for _ in records]
    else:
        scar = {"profile": profile, "mapping": mapping}
        shortcut, _ = correct_ecof(
            si["ecof"], **rig, aspect_ratio=float(profile.aspect_ratio), return_status=True
        )
        added = [[_written(value, dialect)] for value in np.asarray(shortcut)]
    mu, status = correct_ecof(si["ecof"], **rig, **scar, return_status=True)
    mu, status = np.asarray(mu), np.asarray(status)
    failed = np.flatnonzero(status != CorrectionStatus.CORRECTED)
    if failed.size:
        i = int(failed[0])
        one = {name: value[i] if name == "aspect_ratio" else value for name, value in scar.items()}
        try:  # a single point raises with its reason
            correct_ecof(si["ecof"][i], **{name: value[i] for name, value in rig.items()}, **one)
        except ValueError as error:
            raise TableError(path, records[i][1], str(error)) from None
    stream = io.StringIO()
    writer = csv.writer(stream, delimiter=dialect.delimiter, lineterminator="\n")
    writer.writerow([*header, *ADDED_COLUMNS, *([] if profile is None else [SHORTCUT_COLUMN])])
    for (row, _), value, ecof, more in zip(records, mu, si["ecof"], added, strict=True):
        writer.writerow([*row, _written(value, dialect), _written(value / ecof, dialect), *more])
    return stream.getvalue(), len(records)


def _written(value: float, dialect: TableDialect) -> str:
    """A result cell: 10 significant digits, with a decimal comma if the table uses them."""
    text = f"{value:.10g}"
    return text.replace(".", ",") if dialect.decimal_comma else text
