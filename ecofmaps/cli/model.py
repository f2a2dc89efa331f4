"""``ecofmaps model``: the model's results at one point (default: the paper's Example 2), on the
parabolic groove or a measured scar profile."""

from __future__ import annotations

import warnings

from ecofmaps import paper
from ecofmaps._version import __version__
from ecofmaps.cli._common import print_rows, quantity, row
from ecofmaps.cli._profile import (
    add_profile_options,
    profile_rows,
    read_profile,
    two_columns_header,
    two_values,
)

__all__ = ["add", "run"]


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "model",
        help="evaluate the model at one point (default: the paper's Example 2)",
        description=(
            "Evaluate the compliant wear-scar interaction model at one point and print "
            "the slip amplitude, peak force, dissipated energy, energy CoF and regime. "
            "Defaults are the paper's Example 2: amplitude 50um, load 450N, stiffness "
            "35MN/m, mu 0.8, aspect ratio 0.2. With --scar-profile FILE the groove is a "
            "measured wear-scar profile instead, and the parabola of the same depth over "
            "half-width D/W is printed beside it."
        ),
    )
    parser.add_argument(
        "--amplitude",
        type=quantity("amplitude"),
        default=paper.EXAMPLE_2["amplitude"],
        help="displacement amplitude Δ* (default 50um)",
    )
    parser.add_argument(
        "--load",
        type=quantity("load"),
        default=paper.EXAMPLE_2["load"],
        help="normal load P (default 450N)",
    )
    parser.add_argument(
        "--stiffness",
        type=quantity("stiffness"),
        default=paper.EXAMPLE_2["stiffness"],
        help="rig stiffness S, 'inf' for a rigid rig (default 35MN/m)",
    )
    parser.add_argument(
        "--mu",
        type=quantity("mu"),
        default=paper.EXAMPLE_2["mu"],
        help="contact coefficient of friction μ (default 0.8)",
    )
    parser.add_argument(
        "--aspect-ratio",
        type=quantity("aspect_ratio"),
        help="groove depth over half-width z_o/x_o of the parabolic groove (default 0.2)",
    )
    parser.add_argument(
        "--groove-half-width",
        type=quantity("groove_half_width"),
        help="groove half-width x_o (default: the amplitude, as in the paper); with a "
        "profile, the x_o of the mapping X = x W/x_o",
    )
    add_profile_options(parser)


def run(args) -> int:
    """Run ``ecofmaps model`` with the parsed ``args``; the exit status."""
    from ecofmaps import model
    from ecofmaps._codes import RegimeWarning
    from ecofmaps.model import Regime

    profile = read_profile(args, conflicting=("aspect_ratio",))
    if profile is not None:
        return _run_on_profile(args, profile)
    if args.aspect_ratio is None:
        args.aspect_ratio = paper.EXAMPLE_2["aspect_ratio"]
    point = dict(
        amplitude=args.amplitude,
        load=args.load,
        stiffness=args.stiffness,
        mu=args.mu,
        aspect_ratio=args.aspect_ratio,
        groove_half_width=args.groove_half_width,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RegimeWarning)
        code = Regime(int(model.slip_regime(**point)))
        ecof = float(model.energy_cof(**point))
        rows = [
            row("amplitude", args.amplitude),
            row("load", args.load),
            row("stiffness", args.stiffness),
            row("mu", args.mu),
            row("aspect_ratio", args.aspect_ratio),
            row("groove_half_width", args.groove_half_width or args.amplitude),
            None,
            row("regime", code.label),
            row("slip_amplitude", float(model.slip_amplitude(**point))),
            row("max_force", float(model.max_force(**point))),
            row("dissipated_energy", float(model.dissipated_energy(**point))),
            row("ecof", ecof),
            row("ecof_ratio", ecof / args.mu),
        ]
    print_rows(f"ecofmaps {__version__}: compliant wear-scar interaction model", rows)
    return 0


def _run_on_profile(args, profile) -> int:
    """The model on the measured profile, beside the parabola of the same D/W (eq. 11)."""
    from ecofmaps import model
    from ecofmaps._codes import RegimeWarning
    from ecofmaps.model import Regime

    rig = dict(amplitude=args.amplitude, load=args.load, stiffness=args.stiffness, mu=args.mu)
    on_profile = dict(
        rig, groove_half_width=args.groove_half_width, profile=profile, mapping=args.mapping
    )
    # The shortcut: the paper's parabola z_o/x_o = D/W (eq. 11), with x_o as given (default
    # Δ*) whatever the mapping on the profile.
    parabola = dict(
        rig, aspect_ratio=float(profile.aspect_ratio), groove_half_width=args.groove_half_width
    )
    names = ("slip_amplitude", "max_force", "dissipated_energy", "energy_cof")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RegimeWarning)
        codes = [Regime(int(model.slip_regime(**point))) for point in (on_profile, parabola)]
        values = {
            name: [float(getattr(model, name)(**point)) for point in (on_profile, parabola)]
            for name in names
        }
    if args.mapping == "physical":
        mapping = "X = x (physical)"
    else:
        x_o = args.groove_half_width or args.amplitude
        mapping = f"X = x W/x_o, x_o = {x_o * 1e6:.6g} µm (eq. 11)"
    rows = [
        row("amplitude", args.amplitude),
        row("load", args.load),
        row("stiffness", args.stiffness),
        row("mu", args.mu),
        *profile_rows(args, profile),
        ("position on the profile", "X", mapping),
        None,
        two_columns_header(),
        ("regime", "", f"{codes[0].label:<18} {codes[1].label}"),
        *(two_values(name, *values[name]) for name in names[:3]),
        two_values("ecof", *values["energy_cof"]),
        two_values("ecof_ratio", *(value / args.mu for value in values["energy_cof"])),
    ]
    print_rows(
        f"ecofmaps {__version__}: compliant wear-scar interaction model on a measured scar profile",
        rows,
    )
    return 0
