"""What the subcommands share: quantities and counts read with units, the options that find a
recording's columns or read a scar profile, the one rule for writing outputs, printed rows."""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np

from ecofmaps._nomenclature import QUANTITIES, RANGES, within
from ecofmaps.cli.main import KEYWORD_OPTIONS, CommandError
from ecofmaps.io.files import MANIFEST, written_by_ecofmaps
from ecofmaps.units import DIMENSIONS, DOMAIN, bare_number_warning, parse_quantity, parse_values


def quantity(name: str, grid: bool = False, option: str | None = None):
    """An argparse ``type``: quantity ``name`` [SI] with units (``grid``: ``a,b,c``, ``a:b:num``) in
    its range and domain; a bare number implausible in SI warned of, naming ``option``."""
    described = QUANTITIES[name]
    kind, option = described.kind, option or "--" + name.replace("_", "-")

    def parse(text: str):
        try:
            value = parse_values(text, kind) if grid else parse_quantity(text, kind)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None
        unit = f" [{described.units}]" if described.units != "1" else ""
        if described.valid is not None and not np.all(within(name, np.asarray(value))):
            valid = RANGES[described.valid][1].format(name=described.symbol or name)
            raise argparse.ArgumentTypeError(
                f"{text!r} is out of range: the {described.words} must satisfy {valid}{unit}"
            )
        low, high = DOMAIN.get(name, (-math.inf, math.inf))
        if np.any(((value < low) | (value > high)) & (value != math.inf)):
            rigid = " (or inf, a rigid rig)" if described.valid == "positive_or_inf" else ""
            raise argparse.ArgumentTypeError(
                f"{text!r} is beyond the model's domain: the {described.words} must be "
                f"{low:g} to {high:g}{unit}{rigid}"
            )
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

    parse.__name__ = kind
    return parse


def unit(kind: str):
    """An argparse ``type`` reading a unit of ``kind`` (``'um'``, not ``'0um'``), kept as text."""
    example = DIMENSIONS[kind][1]

    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError(f"an empty unit; give a {kind} unit such as {example}")
        number = text.strip()[0] in "0123456789.+-"
        try:
            scale = math.nan if number else parse_quantity(f"1 {text}", kind)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error).replace("'1 ", "'")) from None
        if not (0.0 < scale < math.inf):
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a unit (a number in front of it makes a quantity); give a "
                f"{kind} unit such as {example}"
            )
        return text

    parse.__name__ = f"{kind} unit"
    return parse


def count(what: str, least: int = 1):
    """An argparse ``type`` reading a whole number of ``what`` >= ``least`` (``4e6``)."""

    def parse(text: str) -> int:
        value = math.nan
        with contextlib.suppress(ValueError):
            value = float(text)
        if not (math.isfinite(value) and value.is_integer() and value >= least):
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number of {what} >= {least}")
        return int(value)

    parse.__name__ = what
    return parse


#: The help of the shared options: outputs, a recording's columns, a scar profile's
#: (docs/profiles.md), the contact's.
OPTION_HELP = {
    "--overwrite": "replace what ecofmaps wrote before (never a file or folder it did not write)",
    "--quiet": "no progress bar (none is shown off a terminal)",
    "--cache-dir": "cache directory (default: $ECOFMAPS_CACHE, else the per-user cache directory)",
    "--displacement-col": "name of the displacement column (default: displacement)",
    "--force-col": "name of the tangential force column (default: force)",
    "--cycle-col": "cycle-number column (default: 'cycle' if any; 'none': cut at the reversals)",
    "--skip-rows": "lines before a text file's header to skip (default: found as metadata)",
    "--displacement-unit": "unit of the displacement (default: from its name or the file, else um)",
    "--force-unit": "unit of the force column (default: from its name or the file, else N)",
    "--group": "TDMS group, or HDF5/netCDF/zarr group, holding the channels (default: any)",
    "--scar-profile": "the scar's profile (CSV, TSV or whitespace-separated text)",
    "--x-column": "name of the position column (default: x)",
    "--z-column": "name of the height column (default: z)",
    "--x-unit": "unit of the positions (default: the one the column's name gives, else um)",
    "--z-unit": "unit of the heights (default: the one the column's name gives, else um)",
    "--no-level": "keep the trace's tilt and offset (default: level it on the unworn shoulders)",
    "--profile-half-width": "the scar's half-width W, e.g. 500um (default: detected at the edges)",
    "--smoothing": "length the slopes are smoothed over, e.g. 10um, 0 for none (default: 2%% of W)",
    "--mapping": "pad at x sits at X = x W/x_o ('scaled', eq. 11; default) or X = x ('physical')",
    "--length": "length of the line contact, with its unit, e.g. 5mm",
    "--sphere": "a sphere on a flat: the scar is round, its profile traced through its centre",
}


def command_parser(subparsers, name: str, **texts) -> argparse.ArgumentParser:
    """The parser of subcommand ``name``: ``description`` filled to 80 columns, ``epilog`` as is."""
    texts["description"] = textwrap.fill(texts["description"], width=80)
    formatter = argparse.RawDescriptionHelpFormatter
    return subparsers.add_parser(name, formatter_class=formatter, **texts)


def option_adder(parser, helps: dict | None = None):
    """``add(name, **keywords)``: add ``name`` to ``parser``, helped by ``helps`` or OPTION_HELP."""
    helps = OPTION_HELP | (helps or {})

    def add(name: str, **keywords) -> None:
        parser.add_argument(name, help=helps[name], **keywords)

    return add


def add_recording_options(parser) -> None:
    """The options that say where a recording's columns are and in which units."""
    option = option_adder(parser)
    option("--displacement-col", default="displacement", metavar="NAME")
    option("--force-col", default="force", metavar="NAME")
    option("--cycle-col", metavar="NAME")
    option("--skip-rows", type=count("lines", least=0), metavar="N")
    option("--displacement-unit", type=unit("length"), metavar="UNIT")
    option("--force-unit", type=unit("force"), metavar="UNIT")
    option("--group", metavar="NAME")


def recording_options(args) -> dict:
    """The keywords of :func:`ecofmaps.io.recordings.read_recording` the options give."""
    if args.cycle_col is not None and not args.cycle_col.strip():
        raise CommandError(f"--cycle-col {args.cycle_col!r} names no column: give a name or 'none'")
    dests = {key: option[2:].replace("-", "_") for key, option in KEYWORD_OPTIONS.items()}
    keywords = {key: getattr(args, dest) for key, dest in dests.items() if dest != "load"}
    keywords["cycle_column"] = False if args.cycle_col == "none" else args.cycle_col
    return {**keywords, "group": args.group}


_PROFILE_DEFAULTS = {"x_column": "x", "z_column": "z", "no_level": False, "mapping": "scaled"}


def add_profile_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--scar-profile FILE`` and its reading options, in a group of their own."""
    group = parser.add_argument_group(
        "measured scar profile",
        "a profilometer trace across the wear scar (text: a header line, then x and z per line), "
        "used instead of the parabolic groove of eq. 11",
    )
    option = option_adder(group)
    option("--scar-profile", metavar="FILE")
    option("--x-column", metavar="NAME")
    option("--z-column", metavar="NAME")
    option("--x-unit", type=unit("length"), metavar="UNIT")
    option("--z-unit", type=unit("length"), metavar="UNIT")
    option("--no-level", action="store_true", default=None)
    half_width = quantity("scar_half_width", option="--profile-half-width")
    option("--profile-half-width", type=half_width, metavar="W")
    option("--smoothing", type=quantity("smoothing"), metavar="LENGTH")
    option("--mapping", choices=("scaled", "physical"))
    reading = tuple(action.dest for action in group._group_actions[1:])  # need --scar-profile
    parser.set_defaults(profile_options=reading)


def read_profile(args, conflicting=()):
    """The profile ``--scar-profile`` names, or None; refuses with it an option ``conflicting``,
    without it a reading option; its warnings one line each, naming the other W."""
    given = [name for name in args.profile_options if getattr(args, name) is not None]
    if args.scar_profile is None and given:
        raise CommandError(f"{options(given)} reads a --scar-profile: give the FILE too")
    for name, value in _PROFILE_DEFAULTS.items():
        if getattr(args, name) is None:
            setattr(args, name, value)
    if args.scar_profile is None:
        return None
    if given := [name for name in conflicting if getattr(args, name) is not None]:
        raise CommandError(f"give --scar-profile or {options(given)}, not both: it gives the D/W")
    from ecofmaps.io.scar_profiles import read_scar_profile  # JAX: not with the command line
    from ecofmaps.model.profiles import ScarProfileWarning

    reading = {name: getattr(args, name) for name in ("x_column", "z_column", "x_unit", "z_unit")}
    reading |= {"level": not args.no_level, "half_width": args.profile_half_width}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ScarProfileWarning)
        profile = read_scar_profile(args.scar_profile, smoothing=args.smoothing, **reading)
    args.profile_alternative = ""  # what the other half-width is, for profile_rows
    for item in caught:
        if not issubclass(item.category, ScarProfileWarning):
            warnings.warn_explicit(item.message, item.category, item.filename, item.lineno)
            continue
        said, hint = item.message, ""
        if said.alternative is not None:
            args.profile_alternative = other = said.alternative_name
            hint = f"; --profile-half-width {said.alternative * 1e6:.6g}um takes the {other}"
        print(f"{args.command_prog}: warning: {said.summary}{hint}", file=sys.stderr)
    return profile


def options(names) -> str:
    """The options of the destinations ``names``: ``'--x-unit, --z-unit'``."""
    return ", ".join("--" + name.replace("_", "-") for name in names)


def profile_rows(args, profile) -> list:
    """Rows of the profile: file and samples, depth D, half-width W (and the other), D/W."""
    reading = [f"{profile.position.shape[-1]} samples", "as given" if args.no_level else "levelled"]
    if replaced := int(np.count_nonzero(np.asarray(profile.replaced))):
        reading.append(f"{replaced} outlier(s) replaced")
    if args.smoothing is not None:
        reading.append(f"slopes smoothed over {args.smoothing * 1e6:.6g} µm")
    # the other W is the groove's, the band's, or the edges' read within the roughness
    other, alternative = args.profile_alternative, float(profile.alternative_half_width)
    how = "(given)" if args.profile_half_width is not None else "(detected)"
    if not math.isnan(alternative):
        how = "(" + {"groove": "band", "band": "groove"}.get(other, "detected") + ")"
    rows = [
        ("scar profile", "", f"{args.scar_profile} ({', '.join(reading)})"),
        row("scar_depth", float(profile.depth)),
        row("scar_half_width", float(profile.half_width), how),
    ]
    if not math.isnan(alternative):
        rows.append(row("scar_half_width", alternative, f"(or {other})"))
    return [*rows, ("scar aspect ratio", "D/W", f"{float(profile.aspect_ratio):.6g}")]


def _length(text: str) -> float:
    """``--length``: a length that must carry its unit (``5mm``)."""
    try:
        float(text)
    except ValueError:
        return quantity("scar_half_width")(text)
    raise argparse.ArgumentTypeError(f"{text!r} has no unit: give the contact's length as 5mm")


def add_contact_options(parser, required: bool) -> None:
    """``--length L`` (a line contact) or ``--sphere`` (a round scar), for the wear volume."""
    option = option_adder(parser.add_mutually_exclusive_group(required=required))
    option("--length", type=_length, metavar="L")
    option("--sphere", action="store_true")


def contact(args) -> str | None:
    """The contact :func:`add_contact_options` named: ``'sphere'``, ``'line'`` or None."""
    return "sphere" if args.sphere else None if args.length is None else "line"


def read_scar_file(path, command: str, x_unit=None, z_unit=None):
    """The levelled profile in ``path``, the reading's warnings printed as ``command``'s."""
    from ecofmaps.io.scar_profiles import read_scar_profile

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            profile = read_scar_profile(path, x_unit=x_unit, z_unit=z_unit)
        except ValueError as error:
            text = str(error)
            raise ValueError(text if text.startswith(str(path)) else f"{path}: {text}") from None
    for item in caught:
        print(f"ecofmaps {command}: warning: {path}: {item.message}", file=sys.stderr)
    return profile


def refuse_to_overwrite(outputs, inputs, *, overwrite: bool = False, folders=()) -> None:
    """:class:`CommandError` unless ``outputs`` and ``folders`` ((option, path or None) each) may
    be written: into an existing directory (``folders`` are made), never over an input; over a
    file ecofmaps wrote, unchanged, or into a folder not empty only with ``overwrite``."""
    outputs = [(option, Path(path)) for option, path in outputs if path is not None]
    made = [option for option, _ in folders]
    for option, target in outputs:
        if option not in made and not target.parent.is_dir():
            raise CommandError(f"cannot write {target} ({option}): its directory does not exist")
        for source in map(Path, inputs):
            if source.exists() and target.exists():
                same = os.path.samefile(source, target)
            else:
                same = _resolved(source) == _resolved(target)
            if same:
                raise CommandError(f"{option} {target} would write over the input file {source}")
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
                f"{option} {target} is not a regular file (a device, pipe or socket)"
            )
        kind = "a folder" if target.is_dir() else "a file"
        raise CommandError(
            f"{option} {target} is {kind} that ecofmaps did not write (or that changed "
            f"since; see {MANIFEST} in its folder): it is not replaced; choose another name"
        )


@contextlib.contextmanager
def made_folder(folder: Path):
    """Create ``folder`` and its parents for the block; if it fails, those made still empty go."""
    missing = [path for path in (folder, *folder.parents) if not path.exists()]
    folder.mkdir(parents=True, exist_ok=True)
    try:
        yield folder
    except BaseException:
        for path in missing:  # the deepest first; a folder holding anything stays
            with contextlib.suppress(OSError):
                path.rmdir()
        raise


def _resolved(path: Path) -> Path:
    """``path`` with its links followed, or :class:`CommandError` for links in a loop."""
    try:
        return path.resolve()
    except (RuntimeError, OSError):  # Python before 3.13 raises RuntimeError for a loop
        raise CommandError(
            f"{path}: symbolic links that point to each other in a loop: remove or correct the link"
        ) from None


def row(name: str, value, note: str = "") -> tuple[str, str, str]:
    """One printed row: the quantity's words (and ``note``), symbol, ``value`` [SI] displayed."""
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


#: Width of the profile's column beside the parabola's, and their header row (:func:`two_values`).
_COLUMN = 18
TWO_COLUMNS = ("", "", f"{'on the profile':<{_COLUMN}} parabola of the same D/W (eq. 11 shortcut)")


def two_values(name: str, on_profile, on_parabola) -> tuple[str, str, str]:
    """One :func:`row` with two values: profile, parabola."""
    words, symbol, first = row(name, on_profile)
    return words, symbol, f"{first:<{_COLUMN}} {row(name, on_parabola)[2]}"


def progress_bar(total: int, name: str, **options):
    """A tqdm progress bar of ``total`` steps on standard error, named ``name``."""
    from tqdm import tqdm

    return tqdm(total=total, desc=name, file=sys.stderr, dynamic_ncols=True, **options)


def byte_size(size: float) -> str:
    """``size`` [byte] in words: ``'88 TB'``, ``'512 kB'``, ``'12 B'`` (decimal units)."""
    power = min(int(math.log10(max(size, 1)) // 3), 5)
    return f"{size / 1000**power:.3g} {('B', 'kB', 'MB', 'GB', 'TB', 'PB')[power]}"
