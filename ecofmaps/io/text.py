"""Recordings in text files (CSV, TSV, spreadsheet exports), parsed by pandas in blocks of about
:data:`BLOCK_BYTES`, each sample with its line; what is accepted is in ``docs/formats.md``."""

from __future__ import annotations

import codecs
import contextlib
import csv
import gzip
import io
import itertools
import re
import zlib
from pathlib import Path

import numpy as np
import pandas as pd

from ecofmaps._codes import warn
from ecofmaps._interrupts import check_interrupted
from ecofmaps.io.columns import (
    ColumnError,
    column_scale,
    find_column,
    listed_names,
    matching_columns,
)
from ecofmaps.io.recording_types import (
    RecordingError,
    RecordingWarning,
    check_regular_file,
    si_values,
)

#: Bytes of text parsed at a time (cut at the last line end within).
BLOCK_BYTES = 1 << 24

#: The longest line read, in bytes (1 MiB); a longer one is refused at its line, at once.
LINE_BYTES = 1 << 20

#: Cell contents read as a missing sample (besides an empty cell and infinite values).
MISSING = ("nan", "NaN", "NAN", "-nan", "-NaN", "NA", "N/A", "n/a", "#N/A", "null", "NULL", "None")

#: Lines (not blank, not comments) among which the header is sought after a preamble.
PREAMBLE_LINES = 1000

_COMMA_DECIMAL = re.compile(r"(?:^|[;\t \"])[+-]?\d*,\d+(?:[eE][+-]?\d+)?(?=$|[;\t \"])", re.M)
_POINT_DECIMAL = re.compile(r"\d\.\d|(?:^|[;\t \"])[+-]?\.\d", re.MULTILINE)
_QUOTED_COMMA_DECIMAL = re.compile(r'"[+-]?\d*,\d+(?:[eE][+-]?\d+)?"')
_NUMBER = re.compile(r"^[+-]?(?:\d+[.,]?\d*|[.,]\d+)(?:[eE][+-]?\d+)?$")
_NOT_A_NUMBER = {"", "inf", "+inf", "-inf", "Inf", "-Inf", "infinity", "-infinity", *MISSING}
_LONE_CR = re.compile(rb"\r(?!\n)")
_GZIP = b"\x1f\x8b"
# pandas 3 parses floats exactly by default and deprecates the option; pandas 2 needs it.
_EXACT = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}


def _first_bytes(path: Path, stream, compressed: bool) -> bytes:
    """A UTF-16 file's text, read whole, as UTF-8 (else none, past a BOM)."""
    head = stream.read(8)
    if compressed and head.startswith((b"TDSm", b"\x89HDF")):
        kind = "TDMS" if head.startswith(b"TDSm") else "HDF5"
        raise RecordingError(
            path, None, f"a gzip-compressed {kind} file: decompress it first (gunzip)"
        )
    if head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)) and not head.startswith(
        codecs.BOM_UTF32_LE
    ):
        # A spreadsheet's "Unicode text": limited to about a million rows, so decoded whole.
        data = head + stream.read()
        try:
            return data.decode("utf-16").encode("utf-8")
        except UnicodeDecodeError as error:
            text = data[: error.start].decode("utf-16", errors="replace")
            raise RecordingError(
                path, text.count("\n") + 1, "damaged UTF-16 text (an odd byte)"
            ) from None
    stream.seek(len(codecs.BOM_UTF8) if head.startswith(codecs.BOM_UTF8) else 0)
    return b""


def _long_line(data: bytes) -> int | None:
    """The offset of the first line longer than :data:`LINE_BYTES` in ``data``, or None."""
    step = LINE_BYTES // 2
    for offset in range(0, len(data) - step + 1, step):
        if data.find(b"\n", offset, offset + step) == -1:
            start = data.rfind(b"\n", 0, offset) + 1
            end = data.find(b"\n", offset + step)
            if (len(data) if end == -1 else end) - start > LINE_BYTES:
                return start
    return None


def _line_blocks(path: Path, block_bytes: int):
    """Blocks of about ``block_bytes`` of whole lines, with their first line's number and count."""
    check_regular_file(path)
    rest, line = b"", 1
    with open(path, "rb") as raw:
        compressed = raw.read(2) == _GZIP
        raw.seek(0)
        stream = gzip.GzipFile(fileobj=raw, mode="rb") if compressed else raw
        try:
            chunk = _first_bytes(path, stream, compressed)
            while chunk := chunk + stream.read(block_bytes):
                if chunk.endswith(b"\r"):  # its line feed may be the next byte
                    chunk += stream.read(1)
                if b"\r" in chunk and chunk.count(b"\r") != chunk.count(b"\r\n"):
                    chunk = _LONE_CR.sub(b"\n", chunk)
                check_interrupted()
                data, chunk = rest + chunk, b""
                if (start := _long_line(data)) is not None:
                    raise RecordingError(
                        path,
                        line + data.count(b"\n", 0, start),
                        f"a line longer than {LINE_BYTES} bytes (1 MiB): a recording's lines "
                        "hold a few numbers each; is this a text recording?",
                    )
                cut = data.rfind(b"\n") + 1
                rest = data[cut:]
                if cut:
                    count = data.count(b"\n", 0, cut)
                    yield data[:cut], line, count
                    line += count
        except (EOFError, gzip.BadGzipFile, zlib.error) as error:
            if not compressed:
                raise
            message = f"the compressed (gzip) data is truncated or damaged ({error})"
            raise RecordingError(path, line, message) from None
    if rest:
        yield rest, line, 1


def _text_lines(text: str) -> list[str]:
    """The lines of a decoded block, without their ends."""
    text = text.replace("\r\n", "\n")
    return (text[:-1] if text.endswith("\n") else text).split("\n")


class _Decoder:
    """UTF-8 text, falling back to Latin-1 (with a warning) from the first bad line on."""

    def __init__(self, path: Path):
        self.path, self.encoding = path, "utf-8"

    def __call__(self, data: bytes, first_line: int) -> str:
        if self.encoding == "utf-8":
            try:
                return data.decode("utf-8")
            except UnicodeDecodeError as error:
                line = first_line + data.count(b"\n", 0, error.start)
                warn(
                    f"{self.path}, line {line}: byte 0x{data[error.start]:02x} is not UTF-8; the "
                    "file is read as Latin-1 from this line on (numbers are the same in both)",
                    RecordingWarning,
                )
                self.encoding = "latin-1"
                return data[: error.start].decode("utf-8") + data[error.start :].decode("latin-1")
        return data.decode("latin-1")


def _separator(header: str):
    """The field separator of the header line."""
    unquoted = re.sub(r'"[^"]*"', "", header)
    return next((candidate for candidate in ("\t", ";", ",") if candidate in unquoted), None)


def _fields(line: str, separator) -> list[str]:
    """The cells of one line, quotes removed."""
    if separator is None:
        return [cell.strip('"') for cell in line.split()]
    if len(line) > csv.field_size_limit():  # the csv module refuses so long a cell
        return [cell.strip().strip('"') for cell in line.split(separator)]
    return [cell.strip() for cell in next(csv.reader([line], delimiter=separator))]


def _header_names(line: str, separator) -> list[str]:
    """The column names; with blank separators a bracketed unit joins the name before it."""
    names = _fields(line, separator)
    if separator is None:
        joined: list[str] = []
        for name in names:
            if joined and re.fullmatch(r"\[[^\]]*\]|\([^)]*\)", name):
                joined[-1] = f"{joined[-1]} {name}"
            else:
                joined.append(name)
        names = joined
    return [name.lstrip("\ufeff") for name in names]


def _numeric(cells) -> bool:
    """Whether every cell is a number or a missing sample."""
    return all(_NUMBER.match(cell) or cell in _NOT_A_NUMBER for cell in cells)


def _wanted(options: dict) -> dict:
    """The column asked for by role."""
    if "columns" in options:  # exactly the columns given
        return dict(options["columns"])
    wanted = {"displacement": options["displacement_column"], "force": options["force_column"]}
    for role in ("cycle", "load"):
        if options.get(f"{role}_column") not in (None, False):
            wanted[role] = options[f"{role}_column"]
    return wanted


class _Layout:
    """What the header says: separator, names, the columns wanted and their scales."""

    def __init__(self, path: Path, header_line: int, header: str, options: dict):
        self.path, self.header_line = path, header_line
        self.separator = _separator(header)
        self.names = _header_names(header, self.separator)
        wanted = _wanted(options)
        try:
            if self.names and all(_NUMBER.match(name) for name in self.names):
                raise ColumnError(
                    "the first line holds numbers, not column names: add a header line "
                    "(e.g. displacement,force)"
                )
            optional = "columns" not in options and options.get("cycle_column") is None
            if optional and find_column(self.names, "cycle", "cycle", required=False) is not None:
                wanted["cycle"] = "cycle"  # a cycle column if there is one
            self.columns = {
                role: find_column(self.names, name, role) for role, name in wanted.items()
            }
            for other, role in itertools.combinations(self.columns, 2):
                if self.columns[role] == self.columns[other]:
                    raise ColumnError(
                        f"the {other} and {role} columns are the same column "
                        f"{self.names[self.columns[role]]!r}"
                    )
            self.scales, self.units, self.assumed = {}, {}, ()
            for role, index in self.columns.items():
                self.scales[role], self.units[role], unknown = column_scale(
                    role, self.names[index], options.get(f"{role}_unit")
                )
                self.assumed += (role,) if unknown else ()
        except ColumnError as error:
            raise RecordingError(path, header_line, str(error)) from None
        self.width = len(self.names)
        self.decimal = None  # comma or point: from the first block whose numbers show one
        self.nan_policy = options["nan_policy"]

    def field_error(self, lines: list[str], numbers) -> None:
        """Raise for the first line whose number of cells is not the header's."""
        for line, number in zip(lines, numbers, strict=True):
            count = len(_fields(line, self.separator))
            if count != self.width:
                raise RecordingError(
                    self.path, number, f"{count} fields where the header has {self.width}"
                )

    def parse(self, body, numbers: np.ndarray, lines: list[str] | None = None):
        """The wanted columns of ``body`` (text or UTF-8) in SI; None if amiss and no ``lines``."""
        careful = lines is not None
        raw = isinstance(body, bytes)
        if self.decimal is None:
            text = body.decode("utf-8", errors="replace") if raw else body
            comma = _QUOTED_COMMA_DECIMAL if self.separator == "," else _COMMA_DECIMAL
            if comma.search(text):
                self.decimal = ","
            elif _POINT_DECIMAL.search(text):
                self.decimal = "."
        count = numbers.size
        separator = self.separator.encode() if raw and self.separator else self.separator
        if separator is None:
            counted = len(body.split()) == count * self.width
        else:
            counted = body.count(separator) == count * (self.width - 1)
        if not counted:  # a line with too few or too many cells, or separators in quotes
            if not careful:
                return None
            self.field_error(lines, numbers)
        try:
            frame = pd.read_csv(
                io.BytesIO(body) if raw else io.StringIO(body),
                sep=self.separator or r"\s+",
                header=None,
                names=list(range(self.width)),
                usecols=sorted(set(self.columns.values())),
                engine="c",
                decimal=self.decimal or ".",
                quotechar='"',
                keep_default_na=False,
                na_values=["", *MISSING],
                skip_blank_lines=False,
                skipinitialspace=True,
                lineterminator=None if raw else "\n",
                encoding="utf-8" if raw else None,
                **_EXACT,
            )
        except (pd.errors.ParserError, UnicodeDecodeError) as error:
            if not careful:
                return None
            self.field_error(lines, numbers)
            raise RecordingError(self.path, numbers[0], f"cannot parse: {error}") from None
        if len(frame) != count:  # a quoted line end, or a lone carriage return
            if not careful:
                return None
            raise RecordingError(self.path, numbers[0], "a quoted cell spans lines")
        values = {}
        for role, index in self.columns.items():
            column = frame[index]
            if not pd.api.types.is_numeric_dtype(column.dtype):
                if not careful:
                    return None
                cells = column.astype(object).where(column.notna(), None)
                if self.decimal == ",":
                    cells = cells.str.replace(",", ".", regex=False)
                bad = (pd.to_numeric(cells, errors="coerce").isna() & column.notna()).to_numpy()
                first = int(np.argmax(bad))
                raise RecordingError(
                    self.path,
                    numbers[first],
                    f"non-numeric value {listed_names([column.iloc[first]])} in column "
                    f"{listed_names([self.names[index]])}",
                )
            values[role] = column.to_numpy(dtype=np.float64)
        missing = {role: ~np.isfinite(data) for role, data in values.items()}
        if self.nan_policy == "raise" and any(bad.any() for bad in missing.values()):
            if not careful:
                return None
            first, role = min(
                (int(np.argmax(bad)), role) for role, bad in missing.items() if bad.any()
            )
            index = self.columns[role]
            cell = _fields(lines[first], self.separator)[index]
            what = "non-finite" if np.isinf(values[role][first]) else "missing"
            raise RecordingError(
                self.path,
                numbers[first],
                f"{what} value {cell!r} in column {listed_names([self.names[index]])}",
            )
        return {
            role: si_values(np.where(missing[role], np.nan, data), self.scales[role])
            for role, data in values.items()
        }


def text_blocks(path: Path, options: dict, block_bytes: int = BLOCK_BYTES):
    """Parse a text recording block by block."""
    decoder = _Decoder(path)
    with contextlib.closing(_line_blocks(path, block_bytes)) as blocks:
        lines, header = _head(blocks, decoder, options)
        if header is None:
            raise RecordingError(path, max(len(lines), 1), "no header line and no data")
        layout = _Layout(path, header + 1, lines[header], options)
        yield layout
        yield from _parsed_lines(layout, lines[header + 1 :], header + 2)
        del lines  # the first block's text, not held while the others are read
        for raw, start, count in blocks:
            check_interrupted()
            if decoder.encoding == "utf-8" and b"#" not in raw:
                # Most blocks hold data lines only: parsed from the bytes as they are.
                numbers = start + np.arange(count, dtype=np.int64)
                values = layout.parse(raw[:-1] if raw.endswith(b"\n") else raw, numbers)
                if values is not None:
                    yield values, numbers
                    continue
            # Comments, blank lines, or something amiss: line by line.
            yield from _parsed_lines(layout, _text_lines(decoder(raw, start)), start)


def _head(blocks, decoder: _Decoder, options: dict) -> tuple[list[str], int | None]:
    """The first lines of the file, decoded, and the index among them of the header line."""
    skip = options.get("skip_rows")
    needed = 1 if skip is not None else PREAMBLE_LINES + 1
    lines: list[str] = []
    data: list[int] = []  # the indices of the lines after ``skip`` that are not blank or comments
    for raw, start, _ in blocks:
        check_interrupted()
        first = len(lines)
        lines += _text_lines(decoder(raw, start))
        added = range(max(skip or 0, first), len(lines))
        found = (k for k in added if lines[k].strip()[:1] not in ("", "#"))
        data += itertools.islice(found, needed - len(data))
        if len(data) >= needed:
            break
    if skip is not None or not data:
        return lines, data[0] if data else None
    wanted = _wanted(options)
    following = [lines[k] for k in data[1:]] + [None]
    for k, after in zip(data, following, strict=True):  # the first line naming the columns
        separator = _separator(lines[k])
        names = _header_names(lines[k], separator)
        if _numeric(names) or (after is not None and len(_fields(after, separator)) != len(names)):
            continue
        if all(matching_columns(names, name, role) for role, name in wanted.items()):
            return lines, k
    numbers = [i for i, k in enumerate(data) if _numeric(_fields(lines[k], _separator(lines[k])))]
    return lines, data[numbers[0] - 1] if numbers and numbers[0] > 0 else data[0]


def _parsed_lines(layout: _Layout, lines: list[str], start: int):
    """The values and line numbers of the data in decoded ``lines`` (the first is ``start``)."""
    body = "\n".join(lines)
    if lines and "#" not in body:
        numbers = start + np.arange(len(lines), dtype=np.int64)
        values = layout.parse(body, numbers)
        if values is not None:
            yield values, numbers
            return
    blanks = " \r" if layout.separator == "\t" else " \t\r"  # not the separator
    kept = [k for k, line in enumerate(lines) if (text := line.strip(blanks)) and text[0] != "#"]
    if kept:
        numbers = start + np.asarray(kept, dtype=np.int64)
        lines = [lines[k] for k in kept]
        yield layout.parse("\n".join(lines), numbers, lines=lines), numbers
