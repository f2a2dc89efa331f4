"""The compliant wear-scar interaction model (the paper's Sections 2 and 3).

:mod:`~ecofmaps.model.core` holds the dimensionless core on (μ, κ, λ),
:mod:`~ecofmaps.model.steady_state` the steady loop's quantities in SI units,
:mod:`~ecofmaps.model.simulation` the steady loop and the time-domain return map, and
:mod:`~ecofmaps.model.regimes` the regime codes.
"""

from ecofmaps._lazy import lazy_names

#: Each public name, by the module that defines it (imported on first use).
_PUBLIC = {
    "ecofmaps.model.core": (
        "compliance_ratio",
        "curvature_number",
        "ecof_ratio",
        "locking_margin",
        "normalized_energy",
        "normalized_max_force",
        "regime_code",
        "slip_position",
        "slip_ratio",
        "traction_ratio",
    ),
    "ecofmaps.model.profile_families": (
        "flat_bottomed_profile",
        "parabolic_profile",
        "ridged_profile",
        "w_shaped_profile",
    ),
    "ecofmaps.model.profiles": ("ScarProfile", "scar_profile"),
    "ecofmaps.model.regimes": (
        "BEYOND_PROFILE",
        "GROSS_SLIP",
        "INVALID",
        "NO_GROSS_SLIP",
        "PARTIAL_SLIP",
        "SELF_LOCKING",
        "Regime",
    ),
    "ecofmaps.model.simulation": ("fretting_loop", "simulate"),
    "ecofmaps.model.steady_state": (
        "dissipated_energy",
        "energy_cof",
        "max_force",
        "slip_amplitude",
        "slip_regime",
    ),
}

__getattr__, __dir__, __all__ = lazy_names(__name__, _PUBLIC)
