"""``ecofmaps model``: the model's results at one point (default: the paper's Example 2)."""

from __future__ import annotations

import warnings

from ecofmaps import paper
from ecofmaps._codes import RegimeWarning
from ecofmaps._version import __version__
from ecofmaps.cli._common import print_rows, quantity, row

__all__ = ["add", "run"]


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "model",
        help="evaluate the model at one point (default: the paper's Example 2)",
        description=(
            "Evaluate the compliant wear-scar interaction model at one point and print "
            "the slip amplitude, peak force, dissipated energy, energy CoF and regime. "
            "Defaults are the paper's Example 2: amplitude 50um, load 450N, stiffness "
            "35MN/m, mu 0.8, aspect ratio 0.2."
        ),
    )
    parser.add_argument(
        "--amplitude", type=quantity("amplitude"), default=paper.EXAMPLE_2["amplitude"],
        help="displacement amplitude Δ* (default 50um)",
    )  # fmt: skip
    parser.add_argument(
        "--load", type=quantity("load"), default=paper.EXAMPLE_2["load"],
        help="normal load P (default 450N)",
    )  # fmt: skip
    parser.add_argument(
        "--stiffness", type=quantity("stiffness"), default=paper.EXAMPLE_2["stiffness"],
        help="rig stiffness S, 'inf' for a rigid rig (default 35MN/m)",
    )  # fmt: skip
    parser.add_argument(
        "--mu", type=quantity("mu"), default=paper.EXAMPLE_2["mu"],
        help="contact coefficient of friction μ (default 0.8)",
    )  # fmt: skip
    parser.add_argument(
        "--aspect-ratio", type=quantity("aspect_ratio"), default=paper.EXAMPLE_2["aspect_ratio"],
        help="groove depth over half-width z_o/x_o (default 0.2)",
    )  # fmt: skip
    parser.add_argument(
        "--groove-half-width", type=quantity("groove_half_width"), default=None,
        help="groove half-width x_o (default: the amplitude, as in the paper)",
    )  # fmt: skip
    parser.set_defaults(handler=run)


def run(args) -> int:
    from ecofmaps import model
    from ecofmaps.model import Regime

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
