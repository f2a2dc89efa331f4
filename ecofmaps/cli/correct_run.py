"""The work of ``ecofmaps correct`` (its options are in :mod:`ecofmaps.cli.correct`): a
reported ECoF, or a table of them, corrected to the contact CoF."""

from __future__ import annotations

import sys
from pathlib import Path

from ecofmaps._version import __version__
from ecofmaps.cli._common import CommandError, print_rows, refuse_to_overwrite, row
from ecofmaps.cli._profile import profile_rows, read_profile, two_columns_header, two_values
from ecofmaps.cli.correct import GROOVE_OPTIONS, POINT_OPTIONS
from ecofmaps.correction.inversion import correct_ecof
from ecofmaps.correction.tables import correct_table
from ecofmaps.io.files import record_written, write_text

__all__ = ["run"]


def run(args) -> int:
    """Run ``ecofmaps correct`` with the parsed ``args``; the exit status."""
    given = [name for name in (*POINT_OPTIONS, *GROOVE_OPTIONS)
             if getattr(args, name) is not None]  # fmt: skip
    if args.table is not None:
        if given:
            options = ", ".join("--" + name.replace("_", "-") for name in given)
            raise CommandError(f"give a TABLE or one point's options, not both ({options})")
        if args.out is not None and not Path(args.out).parent.is_dir():
            raise CommandError(f"cannot write {args.out}: its directory does not exist")
        inputs = [path for path in (args.table, args.scar_profile) if path is not None]
        refuse_to_overwrite([("--out", args.out)], inputs, overwrite=args.overwrite)
        profile = read_profile(args)
        text, rows = correct_table(args.table, profile=profile, mapping=args.mapping)
        if args.out is None:
            sys.stdout.write(text)
            return 0
        write_text(args.out, text)
        record_written([args.out])
        on = "" if profile is None else f" on the scar profile {args.scar_profile}"
        print(f"wrote {args.out}: {rows} rows corrected{on}")
        return 0
    if args.out is not None:
        raise CommandError("--out writes a corrected TABLE; give the TABLE too")
    missing = ["--" + name for name in POINT_OPTIONS if getattr(args, name) is None]
    if missing:
        raise CommandError(f"give {', '.join(missing)} (or a TABLE)")
    profile = read_profile(args, conflicting=GROOVE_OPTIONS)
    if profile is not None:
        return _point_on_profile(args, profile)
    scar = [value is not None for value in (args.scar_depth, args.scar_half_width)]
    if (args.aspect_ratio is not None) == any(scar) or any(scar) != all(scar):
        raise CommandError("give --aspect-ratio, or both --scar-depth and --scar-half-width")
    point = dict(amplitude=args.amplitude, load=args.load, stiffness=args.stiffness)
    if args.aspect_ratio is not None:
        ratio = args.aspect_ratio
        ratio_text = f"{ratio:.6g}"
    else:
        ratio = args.scar_depth / args.scar_half_width
        ratio_text = (
            f"{ratio:.6g} (scar {args.scar_depth * 1e6:.6g} µm deep, "
            f"{args.scar_half_width * 1e6:.6g} µm half-width)"
        )
    scar = (
        {"aspect_ratio": ratio}
        if args.aspect_ratio is not None
        else {"scar_depth": args.scar_depth, "scar_half_width": args.scar_half_width}
    )
    mu = float(correct_ecof(args.ecof, **point, **scar))
    rows = [
        row("ecof", args.ecof, "(reported)"),
        row("amplitude", args.amplitude),
        row("load", args.load),
        row("stiffness", args.stiffness),
        row("aspect_ratio", ratio_text),
        None,
        row("mu", mu),
        row("correction_factor", mu / args.ecof),
    ]
    print_rows(
        f"ecofmaps {__version__}: reported ECoF corrected to the contact CoF (x_o = Δ*)", rows
    )
    return 0


def _point_on_profile(args, profile) -> int:
    """One ECoF corrected on the measured profile, beside the D/W shortcut (eq. 11)."""
    rig = dict(amplitude=args.amplitude, load=args.load, stiffness=args.stiffness)
    mu = float(correct_ecof(args.ecof, **rig, profile=profile, mapping=args.mapping))
    shortcut, _ = correct_ecof(
        args.ecof, **rig, aspect_ratio=float(profile.aspect_ratio), return_status=True
    )
    shortcut = float(shortcut)  # NaN (printed 'undefined') where the parabola cannot
    rows = [
        row("ecof", args.ecof, "(reported)"),
        row("amplitude", args.amplitude),
        row("load", args.load),
        row("stiffness", args.stiffness),
        *profile_rows(args, profile),
        None,
        two_columns_header(),
        two_values("mu", mu, shortcut),
        two_values("correction_factor", mu / args.ecof, shortcut / args.ecof),
    ]
    print_rows(
        f"ecofmaps {__version__}: reported ECoF corrected to the contact CoF on a measured "
        f"scar profile ({'X = x' if args.mapping == 'physical' else 'X = x W/Δ*, eq. 11'})",
        rows,
    )
    return 0
