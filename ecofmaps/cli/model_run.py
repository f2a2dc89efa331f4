"""The work of ``ecofmaps model`` (its options are in :mod:`ecofmaps.cli.model`): the
model's results at one point, on the parabola or a measured scar profile."""

from __future__ import annotations

import warnings

from ecofmaps import model, paper
from ecofmaps._codes import RegimeWarning
from ecofmaps._version import __version__
from ecofmaps.cli._common import print_rows, row
from ecofmaps.cli._profile import (
    profile_rows,
    read_profile,
    two_columns_header,
    two_values,
)
from ecofmaps.model import Regime

__all__ = ["run"]


def run(args) -> int:
    """Run ``ecofmaps model`` with the parsed ``args``; the exit status."""
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
    rig = dict(amplitude=args.amplitude, load=args.load, stiffness=args.stiffness, mu=args.mu)
    on_profile = dict(rig, groove_half_width=args.groove_half_width, profile=profile,
                      mapping=args.mapping)  # fmt: skip
    # The shortcut: the paper's parabola z_o/x_o = D/W (eq. 11), with x_o as given (default
    # Δ*) whatever the mapping on the profile.
    parabola = dict(rig, aspect_ratio=float(profile.aspect_ratio),
                    groove_half_width=args.groove_half_width)  # fmt: skip
    names = ("slip_amplitude", "max_force", "dissipated_energy", "energy_cof")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RegimeWarning)
        codes = [Regime(int(model.slip_regime(**point))) for point in (on_profile, parabola)]
        values = {name: [float(getattr(model, name)(**point)) for point in (on_profile, parabola)]
                  for name in names}  # fmt: skip
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
