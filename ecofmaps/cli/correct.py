"""``ecofmaps correct``: reported ECoF values corrected to the contact CoF (a point or a table)."""

from __future__ import annotations

import sys
import warnings

from ecofmaps._version import __version__
from ecofmaps.cli._common import (
    TWO_COLUMNS,
    CommandError,
    add_profile_options,
    option_adder,
    print_rows,
    profile_rows,
    quantity,
    read_profile,
    refuse_to_overwrite,
    row,
    two_values,
)
from ecofmaps.io.files import record_written, write_text

__all__ = ["add", "run"]

POINT_OPTIONS = ("ecof", "amplitude", "load", "stiffness")
GROOVE_OPTIONS = ("aspect_ratio", "scar_depth", "scar_half_width")

_HELP = {
    "table": "table of reported ECoFs (',', ';' or tab separated)",
    "--out": "write the corrected table here (the table's separator; default: standard output)",
    "--overwrite": "replace --out if ecofmaps wrote it (never a file ecofmaps did not write)",
    "--ecof": "reported energy CoF μ_E, e.g. 0.83",
    "--amplitude": "displacement amplitude Δ*, e.g. 50um",
    "--load": "normal load P, e.g. 450N",
    "--stiffness": "rig stiffness S, e.g. 35MN/m ('inf' for a rigid rig)",
    "--aspect-ratio": "wear scar depth over half-width z_o/x_o = D/W, e.g. 0.2",
    "--scar-depth": "scar depth D, e.g. 8um",
    "--scar-half-width": "scar half-width W, e.g. 40um",
}


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "correct",
        help="correct reported ECoF values to the contact CoF (one point or a CSV table)",
        description="Correct a reported energy CoF μ_E to the contact CoF μ behind it, given the "
        "amplitude, load, rig stiffness and scar depth over half-width z_o/x_o = D/W (eq. 11; x_o "
        "= Δ*). One point: --ecof --amplitude --load --stiffness and --aspect-ratio (or "
        "--scar-depth and --scar-half-width). A TABLE: columns ecof, amplitude_um, load_N, "
        "stiffness_MN_per_m and aspect_ratio or scar_depth_um + scar_half_width_um ('#' lines "
        "skipped; decimal commas with ';'); the output keeps every column and adds mu and "
        "correction_factor. --scar-profile FILE: a measured scar instead (of the point, or every "
        "row of a table without scar columns), beside the parabola of the same D/W (mu_parabolic "
        "in a table). A row that cannot be corrected (a cell not a number, an ECoF no gross-slip "
        "loop gives) gets NaN, its reason in a status column and an error line naming file, line "
        "(the header is 1) and column; the other rows are written, exit status 1.",
    )
    option = option_adder(parser, _HELP)
    option("table", nargs="?", metavar="TABLE")
    option("--out", metavar="OUT")
    option("--overwrite", action="store_true")
    for name in (*POINT_OPTIONS, *GROOVE_OPTIONS):
        option("--" + name.replace("_", "-"), type=quantity(name))
    add_profile_options(parser)


def run(args) -> int:
    """Run ``ecofmaps correct`` with the parsed ``args``; the exit status."""
    from ecofmaps.correction.inversion import correct_ecof

    given = [name for name in (*POINT_OPTIONS, *GROOVE_OPTIONS) if getattr(args, name) is not None]
    if args.table is not None:
        if given:
            options = ", ".join("--" + name.replace("_", "-") for name in given)
            raise CommandError(f"give a TABLE or one point's options, not both ({options})")
        inputs = [path for path in (args.table, args.scar_profile) if path is not None]
        refuse_to_overwrite([("--out", args.out)], inputs, overwrite=args.overwrite)
        return _table(args, read_profile(args))
    if args.out is not None:
        raise CommandError("--out writes a corrected TABLE; give the TABLE too")
    if missing := ["--" + name for name in POINT_OPTIONS if getattr(args, name) is None]:
        raise CommandError(f"give {', '.join(missing)} (or a TABLE)")
    profile = read_profile(args, conflicting=GROOVE_OPTIONS)
    rig = dict(amplitude=args.amplitude, load=args.load, stiffness=args.stiffness)
    rows = [row("ecof", args.ecof, "(reported)"), *(row(name, rig[name]) for name in rig)]
    title = f"ecofmaps {__version__}: reported ECoF corrected to the contact CoF"
    if profile is not None:  # beside the D/W shortcut (eq. 11)
        mu = float(correct_ecof(args.ecof, **rig, profile=profile, mapping=args.mapping))
        shortcut, _ = correct_ecof(  # NaN (printed 'undefined') where the parabola cannot
            args.ecof, **rig, aspect_ratio=float(profile.aspect_ratio), return_status=True
        )
        shortcut = float(shortcut)
        rows += [*profile_rows(args, profile), None, TWO_COLUMNS, two_values("mu", mu, shortcut)]
        rows.append(two_values("correction_factor", mu / args.ecof, shortcut / args.ecof))
        mapping = "X = x" if args.mapping == "physical" else "X = x W/Δ*, eq. 11"
        print_rows(f"{title} on a measured scar profile ({mapping})", rows)
        return 0
    scar = [value is not None for value in (args.scar_depth, args.scar_half_width)]
    if (args.aspect_ratio is not None) == any(scar) or any(scar) != all(scar):
        raise CommandError("give --aspect-ratio, or both --scar-depth and --scar-half-width")
    if args.aspect_ratio is not None:
        scar, ratio_text = {"aspect_ratio": args.aspect_ratio}, f"{args.aspect_ratio:.6g}"
    else:
        scar = {"scar_depth": args.scar_depth, "scar_half_width": args.scar_half_width}
        ratio_text = (
            f"{args.scar_depth / args.scar_half_width:.6g} (scar {args.scar_depth * 1e6:.6g} µm "
            f"deep, {args.scar_half_width * 1e6:.6g} µm half-width)"
        )
    mu = float(correct_ecof(args.ecof, **rig, **scar))
    rows += [row("aspect_ratio", ratio_text), None, row("mu", mu)]
    print_rows(f"{title} (x_o = Δ*)", [*rows, row("correction_factor", mu / args.ecof)])
    return 0


def _table(args, profile) -> int:
    """The TABLE corrected; a row that cannot be is NaN and an error line (exit status 1)."""
    from ecofmaps.correction.tables import TableRowWarning, correct_table

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", TableRowWarning)
        text, rows = correct_table(args.table, profile, args.mapping, bad_rows="nan")
    failed = [item for item in caught if issubclass(item.category, TableRowWarning)]
    for item in caught:
        if item in failed:
            print(f"ecofmaps correct: error: {item.message}", file=sys.stderr)
        else:
            warnings.warn_explicit(item.message, item.category, item.filename, item.lineno)
    if args.out is None:
        sys.stdout.write(text)
        return 1 if failed else 0  # the rows are on standard output
    write_text(args.out, text)
    record_written([args.out])
    on = "" if profile is None else f" on the scar profile {args.scar_profile}"
    corrected = f"{rows - len(failed)} of {rows}" if failed else rows
    others = f", {len(failed)} not (NaN, the reason in the status column)" if failed else ""
    print(f"wrote {args.out}: {corrected} rows corrected{on}{others}")
    return 1 if failed else 0
