"""``ecofmaps model``: the model's results at one point (default: the paper's Example 2), on the
parabolic groove or a measured scar profile."""

from __future__ import annotations

import warnings

from ecofmaps import paper
from ecofmaps._version import __version__
from ecofmaps.cli import common

_HELP = {
    "--amplitude": "displacement amplitude Δ* (default 50um)",
    "--load": "normal load P (default 450N)",
    "--stiffness": "rig stiffness S, 'inf' for a rigid rig (default 35MN/m)",
    "--mu": "contact coefficient of friction μ (default 0.8)",
    "--aspect-ratio": "groove depth over half-width z_o/x_o of the parabolic groove (default 0.2)",
    "--groove-half-width": "groove half-width x_o, also of X = x W/x_o (default: the amplitude)",
}

#: The model's results printed, after the regime, in this order.
_RESULTS = ("slip_amplitude", "max_force", "dissipated_energy", "energy_cof")


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "model",
        help="evaluate the model at one point (default: the paper's Example 2)",
        description="Print the compliant wear-scar interaction model's slip amplitude, peak "
        "force, dissipated energy, energy CoF and regime at one point (default: the paper's "
        "Example 2); with --scar-profile FILE on a measured scar, beside the parabola of its D/W.",
    )
    option = common.option_adder(parser, _HELP)
    for name in ("amplitude", "load", "stiffness", "mu"):
        option(f"--{name}", type=common.quantity(name), default=paper.EXAMPLE_2[name])
    option("--aspect-ratio", type=common.quantity("aspect_ratio"))
    option("--groove-half-width", type=common.quantity("groove_half_width"))
    common.add_profile_options(parser)


def run(args) -> int:
    from ecofmaps import model
    from ecofmaps._codes import RegimeWarning

    profile = common.read_profile(args, conflicting=("aspect_ratio",))
    rig = dict(amplitude=args.amplitude, load=args.load, stiffness=args.stiffness, mu=args.mu)
    rows = [common.row(name, value) for name, value in rig.items()]
    point = dict(rig, groove_half_width=args.groove_half_width)
    x_o = args.groove_half_width or args.amplitude
    if profile is None:
        ratio = paper.EXAMPLE_2["aspect_ratio"] if args.aspect_ratio is None else args.aspect_ratio
        points = [dict(point, aspect_ratio=ratio)]
        rows += [common.row("aspect_ratio", ratio), common.row("groove_half_width", x_o), None]
        show, title = common.row, ""
    else:
        shortcut = dict(point, aspect_ratio=float(profile.aspect_ratio))  # eq. 11, x_o as given
        points = [dict(point, profile=profile, mapping=args.mapping), shortcut]
        mapping = f"X = x W/x_o, x_o = {x_o * 1e6:.6g} µm (eq. 11)"
        if args.mapping == "physical":
            mapping = "X = x (physical)"
        rows += [*common.profile_rows(args, profile), ("position on the profile", "X", mapping)]
        rows += [None, common.TWO_COLUMNS]
        show, title = common.two_values, " on a measured scar profile"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RegimeWarning)
        regimes = [model.Regime(int(model.slip_regime(**p))).label for p in points]
        rows.append(show("regime", *regimes))
        values = {name: [float(getattr(model, name)(**p)) for p in points] for name in _RESULTS}
    ecof = values.pop("energy_cof")
    rows += [show(name, *value) for name, value in values.items()]
    rows += [show("ecof", *ecof), show("ecof_ratio", *(value / args.mu for value in ecof))]
    common.print_rows(f"ecofmaps {__version__}: compliant wear-scar interaction model{title}", rows)
    return 0
