"""The ``--scar-profile FILE`` options that ``ecofmaps model`` and ``ecofmaps correct`` share.

A measured wear-scar profile (read by :func:`ecofmaps.read_scar_profile`, with its reading
options, which apply only with ``--scar-profile``) replaces the parabolic groove of eq. 11,
whose options cannot be given with it. What the reading decided (outliers replaced, ambiguous
edges) is printed on standard error, one line each, and the rows show the half-width taken
beside the alternative.
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings

import numpy as np

from ecofmaps.cli._common import CommandError, quantity, row, unit

__all__ = [
    "add_profile_options",
    "profile_rows",
    "read_profile",
    "two_columns_header",
    "two_values",
]

_DEFAULTS = {"x_column": "x", "z_column": "z", "no_level": False, "mapping": "scaled"}


def add_profile_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--scar-profile FILE`` and its reading options, in a group of their own."""
    group = parser.add_argument_group(
        "measured scar profile",
        "a profilometer trace across the wear scar (text: a header line, then x and z per "
        "line, in um unless the names or --x-unit/--z-unit say otherwise), used instead of "
        "the parabolic groove of eq. 11",
    )
    group.add_argument(
        "--scar-profile",
        metavar="FILE",
        help="the scar's profile (CSV, TSV or whitespace-separated text)",
    )
    group.add_argument(
        "--x-column",
        metavar="NAME",
        help="name of the position column (default: x)",
    )
    group.add_argument(
        "--z-column",
        metavar="NAME",
        help="name of the height column (default: z)",
    )
    group.add_argument(
        "--x-unit",
        type=unit("length"),
        metavar="UNIT",
        help="unit of the positions (default: the one the column's name gives, else um)",
    )
    group.add_argument(
        "--z-unit",
        type=unit("length"),
        metavar="UNIT",
        help="unit of the heights (default: the one the column's name gives, else um)",
    )
    group.add_argument(
        "--no-level",
        action="store_true",
        default=None,
        help="keep the trace's tilt and offset (default: level it on the unworn shoulders)",
    )
    group.add_argument(
        "--profile-half-width",
        type=quantity("scar_half_width", option="--profile-half-width"),
        metavar="W",
        help="the scar's half-width W, e.g. 500um (default: the one detected at the edges)",
    )
    group.add_argument(
        "--smoothing",
        type=quantity("smoothing"),
        metavar="LENGTH",
        help="length over which the slopes are smoothed, e.g. 10um; 0 for none "
        "(default: 2%% of the half-width)",
    )
    group.add_argument(
        "--mapping",
        choices=("scaled", "physical"),
        help="where the pad at slip position x sits on the profile: 'scaled', X = x W/x_o "
        "(eq. 11, the paper's; default), or 'physical', X = x",
    )
    reading = tuple(action.dest for action in group._group_actions[1:])  # need --scar-profile
    parser.set_defaults(profile_command=parser.prog, profile_options=reading)


def read_profile(args, conflicting=()):
    """The profile ``--scar-profile`` names (read with its options), or ``None``.

    A groove option of the parabola (the destinations ``conflicting``) given with it, or a
    reading option without it, is a :class:`CommandError`. The reader's warnings are printed
    one line each, naming the file; for ambiguous edges the line ends with the
    ``--profile-half-width`` that takes the other half-width (the groove's or the band's).
    """
    if args.scar_profile is None:
        given = [name for name in args.profile_options if getattr(args, name) is not None]
        if given:
            raise CommandError(f"{_options(given)} reads a --scar-profile: give the FILE too")
        for name, value in _DEFAULTS.items():
            setattr(args, name, value)
        return None
    given = [name for name in conflicting if getattr(args, name) is not None]
    if given:
        raise CommandError(
            f"give --scar-profile or {_options(given)}, not both (the profile gives the "
            "scar's shape, and its D/W)"
        )
    for name, value in _DEFAULTS.items():
        if getattr(args, name) is None:
            setattr(args, name, value)
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
        alternative = item.message.alternative
        if alternative is not None:
            args.profile_alternative = item.message.alternative_name
        hint = (
            ""
            if alternative is None
            else (
                f"; --profile-half-width {alternative * 1e6:.6g}um takes the "
                f"{item.message.alternative_name}"
            )
        )
        print(f"{args.profile_command}: warning: {item.message.summary}{hint}", file=sys.stderr)
    return profile


def _options(names) -> str:
    return ", ".join("--" + name.replace("_", "-") for name in names)


def profile_rows(args, profile) -> list:
    """Rows naming the profile: its file and samples, depth D, half-width W (and the
    alternative when the edges were ambiguous), D/W."""
    samples = int(profile.position.shape[-1])
    reading = [f"{samples} samples", "as given" if args.no_level else "levelled"]
    replaced = int(np.count_nonzero(np.asarray(profile.replaced)))
    if replaced:
        reading.append(f"{replaced} outlier(s) replaced")
    if args.smoothing is not None:
        reading.append(f"slopes smoothed over {args.smoothing * 1e6:.6g} µm")
    alternative = float(profile.alternative_half_width)
    half_width = float(profile.half_width)  # a float64 number, compared outside JAX's x64
    how = "(given)" if args.profile_half_width is not None else "(detected)"
    # the other half-width is the groove's, the band's, or that of the edges read within
    # the roughness (the warning names it)
    other = args.profile_alternative
    if not math.isnan(alternative):
        how = "(" + {"groove": "band", "band": "groove"}.get(other, "detected") + ")"
    rows = [
        ("scar profile", "", f"{args.scar_profile} ({', '.join(reading)})"),
        row("scar_depth", float(profile.depth)),
        row("scar_half_width", half_width, how),
    ]
    if not math.isnan(alternative):
        rows.append(row("scar_half_width", alternative, f"(or {other})"))
    rows.append(("scar aspect ratio", "D/W", f"{float(profile.aspect_ratio):.6g}"))
    return rows


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
