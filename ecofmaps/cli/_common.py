"""What the subcommands share: quantities and counts read with units, the options that find a
recording's columns, the one rule for writing outputs, printed rows and sizes."""

from __future__ import annotations

import argparse
import math
import os
import warnings
from pathlib import Path

import numpy as np

from ecofmaps._nomenclature import QUANTITIES, RANGES, within
from ecofmaps.cli.main import CommandError
from ecofmaps.io.files import MANIFEST, written_by_ecofmaps
from ecofmaps.units import DIMENSIONS, bare_number_warning, parse_quantity, parse_values

__all__ = [
    "CACHE_DIR_HELP",
    "CommandError",
    "add_recording_options",
    "byte_size",
    "count",
    "option_adder",
    "print_rows",
    "quantity",
    "recording_options",
    "refuse_to_overwrite",
    "row",
    "unit",
]


def _in_range(name: str, values: np.ndarray, text: str) -> None:
    """Raise ``ValueError`` if ``values`` [SI] leave the valid range of quantity ``name``."""
    described = QUANTITIES[name]
    if described.valid is None or np.all(within(name, values)):
        return
    symbol = described.symbol or name
    unit = f" [{described.units}]" if described.units != "1" else ""
    valid = RANGES[described.valid][1].format(name=symbol)
    raise ValueError(f"{text!r} is out of range: the {described.words} must satisfy {valid}{unit}")


def quantity(name: str, grid: bool = False, option: str | None = None):
    """An argparse ``type`` reading a value of quantity ``name`` with units (with ``grid``, a
    list ``a,b,c`` or a range ``start:stop:num``), checked against its dimension and valid
    range; a bare number implausible in SI is warned of, naming ``option`` (``--name``)."""
    kind = QUANTITIES[name].kind
    option = option or "--" + name.replace("_", "-")

    def parse(text: str):
        try:
            value = parse_values(text, kind) if grid else parse_quantity(text, kind)
            _in_range(name, np.asarray(value), text)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None
        unique, counts = np.unique(value, return_counts=True)
        if np.any(counts > 1):
            raise argparse.ArgumentTypeError(
                f"{text!r} repeats the value {unique[counts > 1][0]:g}: a grid axis takes "
                "each value once"
            )
        items = text.split(":")[:2] if grid and ":" in text else text.split(",")
        for item in items if grid else [text]:
            if said := bare_number_warning(name, item, kind):
                warnings.warn(f"{option} {said}", stacklevel=2)
        return value

    parse.__name__, parse.option = kind, option
    return parse


def unit(kind: str):
    """An argparse ``type`` reading a unit of ``kind`` (``'um'``, ``'kN'``), kept as text: a
    unit of that dimension whose size is positive and finite (not a number, ``'0um'``)."""

    def parse(text: str) -> str:
        if not text.strip():
            example = DIMENSIONS[kind][1]
            raise argparse.ArgumentTypeError(f"an empty unit; give a {kind} unit such as {example}")
        number = text.strip()[0] in "0123456789.+-"
        try:
            scale = math.nan if number else parse_quantity(f"1 {text}", kind)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error).replace("'1 ", "'")) from None
        if not (0.0 < scale < math.inf):
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a unit (a number in front of it makes a quantity); give a "
                f"{kind} unit such as {DIMENSIONS[kind][1]}"
            )
        return text

    parse.__name__ = f"{kind} unit"
    return parse


def count(what: str):
    """An argparse ``type`` reading a whole number of ``what`` >= 1 (``4194304``, ``4e6``)."""

    def parse(text: str) -> int:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value.is_integer() and value >= 1):
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number of {what} >= 1")
        return int(value)

    parse.__name__ = what
    return parse


#: The help of ``--cache-dir`` (``ecofmaps map``, ``cache``).
CACHE_DIR_HELP = "cache directory (default: $ECOFMAPS_CACHE, else the per-user cache directory)"

#: The help of each option of :func:`add_recording_options`.
_RECORDING_HELP = {
    "--displacement-col": "name of the displacement column (default: displacement)",
    "--force-col": "name of the tangential force column (default: force)",
    "--cycle-col": "name of a column of cycle numbers, which must exist (default: 'cycle' if "
    "the file has it; else, or with 'none', cycles are cut at the reversals)",
    "--skip-rows": "lines of a text file to skip before its header line (default: metadata "
    "lines before the header are found)",
    "--displacement-unit": "unit of the displacement column (default: the one its name or the "
    "file gives, as in 'displacement [mm]' or a channel's unit, else um)",
    "--force-unit": "unit of the force column (default: from its name or the file, else N)",
    "--group": "TDMS group, or HDF5/netCDF/zarr group, holding the channels (default: any)",
}


def option_adder(parser, helps: dict):
    """``add(name, **keywords)``: add option ``name`` to ``parser``, its help ``helps[name]``."""

    def add(name: str, **keywords) -> None:
        parser.add_argument(name, help=helps[name], **keywords)

    return add


def add_recording_options(parser) -> None:
    """The options that say where a recording's columns are and in which units."""
    option = option_adder(parser, _RECORDING_HELP)
    option("--displacement-col", default="displacement", metavar="NAME")
    option("--force-col", default="force", metavar="NAME")
    option("--cycle-col", metavar="NAME")
    option("--skip-rows", type=int, metavar="N")
    option("--displacement-unit", type=unit("length"), metavar="UNIT")
    option("--force-unit", type=unit("force"), metavar="UNIT")
    option("--group", metavar="NAME")


def recording_options(args) -> dict:
    """The keywords of :func:`ecofmaps.io.recordings.read_recording` the options give."""
    if args.cycle_col is not None and not args.cycle_col.strip():
        raise CommandError(
            f"--cycle-col {args.cycle_col!r} names no column: give the cycle column's name, "
            "or none to read no cycle column"
        )
    return {
        "displacement_column": args.displacement_col,
        "force_column": args.force_col,
        "cycle_column": False if args.cycle_col == "none" else args.cycle_col,
        "skip_rows": args.skip_rows,
        "displacement_unit": args.displacement_unit,
        "force_unit": args.force_unit,
        "group": args.group,
    }


def refuse_to_overwrite(outputs, inputs, *, overwrite: bool = False, folders=()) -> None:
    """Raise :class:`CommandError` unless the command may write its outputs: the one rule.

    An output is never an input; one that exists is replaced only with ``overwrite`` and only
    if ecofmaps wrote it, unchanged since (:func:`ecofmaps.io.files.written_by_ecofmaps`). A
    folder written into (``--plots``) may exist empty; one holding anything needs
    ``overwrite``. ``outputs`` and ``folders`` are (option, path or None); ``inputs`` paths.
    """
    outputs = [(option, Path(path)) for option, path in outputs if path is not None]
    sources = [Path(path) for path in inputs]
    for option, target in outputs:
        for source in sources:
            same = (
                os.path.samefile(source, target)
                if source.exists() and target.exists()
                else _resolved(source) == _resolved(target)
            )
            if same:
                raise CommandError(
                    f"{option} {target} would write over the input file {source}: "
                    "choose another output"
                )
    for option, folder in folders:
        if folder is None or overwrite or not Path(folder).is_dir():
            continue
        if any(item.name != MANIFEST for item in Path(folder).iterdir()):
            raise CommandError(
                f"{option} {folder} is a folder that is not empty: give a new or empty one, "
                "or --overwrite to replace the files ecofmaps wrote there (others are kept)"
            )
    for option, target in outputs:
        if not os.path.lexists(target):
            continue
        if written_by_ecofmaps(target):
            if not overwrite:
                raise CommandError(f"{option} {target} exists already: --overwrite replaces it")
            continue
        if not (target.is_dir() or target.is_file()):
            raise CommandError(
                f"{option} {target} is not a regular file (a device, a pipe or a socket): "
                "ecofmaps writes only regular files; choose a file name"
            )
        kind = "a folder" if target.is_dir() else "a file"
        raise CommandError(
            f"{option} {target} is {kind} that ecofmaps did not write (or that changed "
            f"since; see {MANIFEST} in its folder): it is not replaced; choose another name"
        )


def _resolved(path: Path) -> Path:
    """``path`` with its links followed, or :class:`CommandError` for links in a loop."""
    try:
        return path.resolve()
    except (RuntimeError, OSError):  # Python before 3.13 raises RuntimeError for a loop
        raise CommandError(
            f"{path}: symbolic links that point to each other in a loop: remove or correct the link"
        ) from None


def row(name: str, value, note: str = "") -> tuple[str, str, str]:
    """One printed row: the quantity's words (then ``note``) and symbol, and ``value`` [SI] in
    its display unit (text as it is; NaN ``undefined``; an infinite stiffness ``inf (rigid)``)."""
    quantity = QUANTITIES[name]
    words = f"{quantity.words} {note}".strip()
    if isinstance(value, str):
        return words, quantity.symbol, value
    if math.isnan(value):
        return words, quantity.symbol, "undefined"
    if name == "stiffness" and math.isinf(value):
        return words, quantity.symbol, "inf (rigid)"
    shown = f"{value * quantity.display_factor:.6g}"
    return words, quantity.symbol, f"{shown} {quantity.display_unit}".strip()


def print_rows(title: str, rows) -> None:
    """Print ``title`` and aligned rows of :func:`row` (``None`` prints an empty line)."""
    print(title)
    for item in rows:
        print("" if item is None else f"  {item[0]:<32} {item[1]:<8} {item[2]}".rstrip())


def byte_size(size: float) -> str:
    """``size`` [byte] in words: ``'88 TB'``, ``'512 kB'``, ``'12 B'`` (decimal units)."""
    power = min(int(math.log10(max(size, 1)) // 3), 5)
    return f"{size / 1000**power:.3g} {('B', 'kB', 'MB', 'GB', 'TB', 'PB')[power]}"
