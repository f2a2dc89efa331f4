"""``ecofmaps model``: the model's results at one point (default: the paper's Example 2)."""

from __future__ import annotations

from ecofmaps import paper
from ecofmaps.cli._common import quantity
from ecofmaps.cli._profile import (
    add_profile_options,
)

__all__ = ["add"]


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
        "--aspect-ratio", type=quantity("aspect_ratio"), default=None,
        help="groove depth over half-width z_o/x_o of the parabolic groove (default 0.2)",
    )  # fmt: skip
    parser.add_argument(
        "--groove-half-width", type=quantity("groove_half_width"), default=None,
        help="groove half-width x_o (default: the amplitude, as in the paper); with a "
        "profile, the x_o of the mapping X = x W/x_o",
    )  # fmt: skip
    add_profile_options(parser)
    parser.set_defaults(handler="ecofmaps.cli.model_run:run")  # imported when it runs
