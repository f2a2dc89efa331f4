"""The ``--scar-profile FILE`` options that ``ecofmaps model`` and ``ecofmaps correct`` share.

A measured wear-scar profile (read by :func:`ecofmaps.read_scar_profile`) replaces the
parabolic groove of eq. 11; what the reading decided is printed on standard error, one line
each, and the rows show the half-width taken beside the alternative (docs/profiles.md).
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings

import numpy as np

from ecofmaps.cli._common import CommandError, option_adder, quantity, row, unit

__all__ = [
    "add_profile_options",
    "profile_rows",
    "read_profile",
    "two_columns_header",
    "two_values",
]

_DEFAULTS = {"x_column": "x", "z_column": "z", "no_level": False, "mapping": "scaled"}


_HELP = {
    "--scar-profile": "the scar's profile (CSV, TSV or whitespace-separated text)",
    "--x-column": "name of the position column (default: x)",
    "--z-column": "name of the height column (default: z)",
    "--x-unit": "unit of the positions (default: the one the column's name gives, else um)",
    "--z-unit": "unit of the heights (default: the one the column's name gives, else um)",
    "--no-level": "keep the trace's tilt and offset (default: level it on the unworn shoulders)",
    "--profile-half-width": "the scar's half-width W, e.g. 500um (default: the one detected at "
    "the edges)",
    "--smoothing": "length over which the slopes are smoothed, e.g. 10um; 0 for none (default: "
    "2%% of the half-width)",
    "--mapping": "where the pad at slip position x sits on the profile: 'scaled', X = x W/x_o "
    "(eq. 11, the paper's; default), or 'physical', X = x",
}


def add_profile_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--scar-profile FILE`` and its reading options, in a group of their own."""
    group = parser.add_argument_group(
        "measured scar profile",
        "a profilometer trace across the wear scar (text: a header line, then x and z per "
        "line, in um unless the names or --x-unit/--z-unit say otherwise), used instead of "
        "the parabolic groove of eq. 11",
    )
    option = option_adder(group, _HELP)
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
    parser.set_defaults(profile_command=parser.prog, profile_options=reading)


def read_profile(args, conflicting=()):
    """The profile ``--scar-profile`` names (read with its options), or ``None``.

    A groove option of the parabola (the destinations ``conflicting``) given with it, or a
    reading option without it, is a :class:`CommandError`. The reader's warnings are printed
    one line each, naming the file; for ambiguous edges the line ends with the
    ``--profile-half-width`` that takes the other half-width (the groove's or the band's).
    """
    given = [name for name in args.profile_options if getattr(args, name) is not None]
    if args.scar_profile is None and given:
        raise CommandError(f"{_options(given)} reads a --scar-profile: give the FILE too")
    for name, value in _DEFAULTS.items():
        if getattr(args, name) is None:
            setattr(args, name, value)
    if args.scar_profile is None:
        return None
    if given := [name for name in conflicting if getattr(args, name) is not None]:
        raise CommandError(
            f"give --scar-profile or {_options(given)}, not both (the profile gives the "
            "scar's shape, and its D/W)"
        )
    # JAX and the readers load with the first profile read, not with the command line
    from ecofmaps.io.scar_profiles import read_scar_profile
    from ecofmaps.model.profiles import ScarProfileWarning  # with the reader, as above

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ScarProfileWarning)
        profile = read_scar_profile(
            args.scar_profile,
            x_column=args.x_column,
            z_column=args.z_column,
            x_unit=args.x_unit,
            z_unit=args.z_unit,
            level=not args.no_level,
            half_width=args.profile_half_width,
            smoothing=args.smoothing,
        )
    args.profile_alternative = ""  # what the other half-width is, for profile_rows
    for item in caught:
        if not issubclass(item.category, ScarProfileWarning):
            warnings.warn_explicit(item.message, item.category, item.filename, item.lineno)
            continue
        said, hint = item.message, ""
        if said.alternative is not None:
            args.profile_alternative = said.alternative_name
            hint = f"; --profile-half-width {said.alternative * 1e6:.6g}um takes the "
            hint += said.alternative_name
        print(f"{args.profile_command}: warning: {said.summary}{hint}", file=sys.stderr)
    return profile


def _options(names) -> str:
    return ", ".join("--" + name.replace("_", "-") for name in names)


def profile_rows(args, profile) -> list:
    """Rows naming the profile: its file and samples, depth D, half-width W (and the
    alternative when the edges were ambiguous), D/W."""
    reading = [f"{profile.position.shape[-1]} samples", "as given" if args.no_level else "levelled"]
    if replaced := int(np.count_nonzero(np.asarray(profile.replaced))):
        reading.append(f"{replaced} outlier(s) replaced")
    if args.smoothing is not None:
        reading.append(f"slopes smoothed over {args.smoothing * 1e6:.6g} µm")
    # the other half-width is the groove's, the band's, or that of the edges read within
    # the roughness (the warning names it)
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


#: Width of the first value column when a profile's values stand beside the parabola's.
_COLUMN = 18


def two_values(name: str, on_profile, on_parabola, note: str = "") -> tuple[str, str, str]:
    """One row of :func:`ecofmaps.cli._common.row` with two values: profile, parabola."""
    words, symbol, first = row(name, on_profile, note)
    second = row(name, on_parabola)[2]
    return words, symbol, f"{first:<{_COLUMN}} {second}"


def two_columns_header() -> tuple[str, str, str]:
    """The header row over :func:`two_values`."""
    return "", "", f"{'on the profile':<{_COLUMN}} parabola of the same D/W (eq. 11 shortcut)"
