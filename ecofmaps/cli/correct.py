"""``ecofmaps correct``: reported ECoF values corrected to the contact CoF (a point or a table)."""

from __future__ import annotations

import sys
import warnings

from ecofmaps._version import __version__
from ecofmaps.cli import common
from ecofmaps.cli.main import CommandError
from ecofmaps.io.files import record_written, write_text

POINT_OPTIONS = ("ecof", "amplitude", "load", "stiffness")
GROOVE_OPTIONS = ("aspect_ratio", "scar_depth", "scar_half_width")

_HELP = {
    "table": "table of reported ECoFs (',', ';' or tab separated)",
    "--out": "write the corrected table here, with the table's separator (default: stdout)",
    "--ecof": "reported energy CoF μ_E, e.g. 0.83",
    "--amplitude": "displacement amplitude Δ*, e.g. 50um",
    "--load": "normal load P, e.g. 450N",
    "--stiffness": "rig stiffness S, e.g. 35MN/m ('inf' for a rigid rig)",
    "--aspect-ratio": "scar depth over half-width z_o/x_o = D/W, e.g. 0.2",
    "--scar-depth": "scar depth D, e.g. 8um",
    "--scar-half-width": "scar half-width W, e.g. 40um",
}


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "correct",
        help="correct reported ECoF values to the contact CoF (one point or a CSV table)",
        description="Correct a reported energy CoF μ_E to the contact CoF μ, given amplitude, "
        "load, rig stiffness and scar depth over half-width z_o/x_o = D/W (eq. 11; x_o = Δ*). One "
        "point: --ecof --amplitude --load --stiffness and --aspect-ratio (or --scar-depth and "
        "--scar-half-width). A TABLE: columns ecof, amplitude_um, load_N, stiffness_MN_per_m and "
        "aspect_ratio or scar_depth_um + scar_half_width_um ('#' lines skipped; decimal commas "
        "with ';'), written with mu and correction_factor. --scar-profile FILE: a measured scar "
        "instead (also for a table without scar columns), beside the parabola of the same D/W "
        "(mu_parabolic). A failing row gets NaN, its reason in a status column and an error line "
        "naming file, line (header: 1) and column (exit status 1).",
    )
    option = common.option_adder(parser, _HELP)
    option("table", nargs="?", metavar="TABLE")
    option("--out", metavar="OUT")
    option("--overwrite", action="store_true")
    for name in (*POINT_OPTIONS, *GROOVE_OPTIONS):
        option(common.options([name]), type=common.quantity(name))
    common.add_profile_options(parser)


def run(args) -> int:
    from ecofmaps.correction.inversion import correct_ecof

    given = [name for name in (*POINT_OPTIONS, *GROOVE_OPTIONS) if getattr(args, name) is not None]
    if args.table is not None:
        if given:
            given = common.options(given)
            raise CommandError(f"give a TABLE or one point's options, not both ({given})")
        inputs = [path for path in (args.table, args.scar_profile) if path is not None]
        common.refuse_to_overwrite([("--out", args.out)], inputs, overwrite=args.overwrite)
        return _table(args, common.read_profile(args))
    if args.out is not None:
        raise CommandError("--out writes a corrected TABLE; give the TABLE too")
    if missing := ["--" + name for name in POINT_OPTIONS if getattr(args, name) is None]:
        raise CommandError(f"give {', '.join(missing)} (or a TABLE)")
    profile = common.read_profile(args, conflicting=GROOVE_OPTIONS)
    rig = {name: getattr(args, name) for name in POINT_OPTIONS[1:]}
    rows = [common.row("ecof", args.ecof, "(reported)"), *map(common.row, rig, rig.values())]
    title = f"ecofmaps {__version__}: reported ECoF corrected to the contact CoF"
    if profile is not None:  # beside the D/W shortcut (eq. 11)
        mu = float(correct_ecof(args.ecof, **rig, profile=profile, mapping=args.mapping))
        ratio = float(profile.aspect_ratio)  # the parabola's: NaN ('undefined') where it cannot
        shortcut = float(correct_ecof(args.ecof, **rig, aspect_ratio=ratio, return_status=True)[0])
        rows += [*common.profile_rows(args, profile), None, common.TWO_COLUMNS]
        rows.append(common.two_values("mu", mu, shortcut))
        rows.append(common.two_values("correction_factor", mu / args.ecof, shortcut / args.ecof))
        mapping = "X = x" if args.mapping == "physical" else "X = x W/Δ*, eq. 11"
        common.print_rows(f"{title} on a measured scar profile ({mapping})", rows)
        return 0
    scar = {name: getattr(args, name) for name in GROOVE_OPTIONS if name in given}
    if list(scar) not in (["aspect_ratio"], ["scar_depth", "scar_half_width"]):
        raise CommandError("give --aspect-ratio, or both --scar-depth and --scar-half-width")
    ratio_text = f"{args.aspect_ratio:.6g}" if "aspect_ratio" in scar else ""
    if "scar_depth" in scar:
        depth, width = args.scar_depth, args.scar_half_width
        ratio_text = f"{depth / width:.6g} (scar {depth * 1e6:.6g} µm deep, "
        ratio_text += f"{width * 1e6:.6g} µm half-width)"
    mu = float(correct_ecof(args.ecof, **rig, **scar))
    rows += [common.row("aspect_ratio", ratio_text), None, common.row("mu", mu)]
    rows.append(common.row("correction_factor", mu / args.ecof))
    common.print_rows(f"{title} (x_o = Δ*)", rows)
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
