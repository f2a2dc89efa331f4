"""The compliant wear-scar interaction model (the paper's Sections 2 and 3).

:mod:`~ecofmaps.model.core` holds the dimensionless core on (μ, κ, λ),
:mod:`~ecofmaps.model.steady_state` the steady loop's quantities in SI units,
:mod:`~ecofmaps.model.simulation` the steady loop and the time-domain return map, and
:mod:`~ecofmaps.model.regimes` the regime codes.
"""

from ecofmaps.model.core import (
    compliance_ratio,
    curvature_number,
    ecof_ratio,
    locking_margin,
    normalized_energy,
    normalized_max_force,
    regime_code,
    slip_position,
    slip_ratio,
    traction_ratio,
)
from ecofmaps.model.profile_families import (
    flat_bottomed_profile,
    parabolic_profile,
    ridged_profile,
    w_shaped_profile,
)
from ecofmaps.model.profiles import ScarProfile, scar_profile
from ecofmaps.model.regimes import (
    BEYOND_PROFILE,
    GROSS_SLIP,
    INVALID,
    NO_GROSS_SLIP,
    SELF_LOCKING,
    Regime,
)
from ecofmaps.model.simulation import fretting_loop, simulate
from ecofmaps.model.steady_state import (
    dissipated_energy,
    energy_cof,
    max_force,
    slip_amplitude,
    slip_regime,
)

__all__ = [
    "BEYOND_PROFILE",
    "GROSS_SLIP",
    "INVALID",
    "NO_GROSS_SLIP",
    "SELF_LOCKING",
    "Regime",
    "ScarProfile",
    "compliance_ratio",
    "curvature_number",
    "dissipated_energy",
    "ecof_ratio",
    "energy_cof",
    "flat_bottomed_profile",
    "fretting_loop",
    "locking_margin",
    "max_force",
    "normalized_energy",
    "normalized_max_force",
    "parabolic_profile",
    "regime_code",
    "ridged_profile",
    "scar_profile",
    "simulate",
    "slip_amplitude",
    "slip_position",
    "slip_ratio",
    "slip_regime",
    "traction_ratio",
    "w_shaped_profile",
]
