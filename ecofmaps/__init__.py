"""ecofmaps: friction from fretting loops, corrected for rig compliance and wear-scar shape.

The public API in SI units (m, N, N/m, J) or pint Quantities: the README and the paper
(:mod:`ecofmaps.paper`). Names are imported on first use: the command line starts (and answers
Ctrl-C) before JAX, xarray or matplotlib load."""

from ecofmaps._lazy import lazy_names
from ecofmaps._version import __version__ as __version__

#: Each public name, by the module that defines it.
_PUBLIC = {
    "ecofmaps._codes": ("RegimeWarning",),
    "ecofmaps.correction": (
        "CorrectionStatus",
        "Interval",
        "correct_ecof",
        "correction_factor",
        "lookup_correction",
    ),
    "ecofmaps.io": ("read_recording", "read_scar_profile"),
    "ecofmaps.lab": ("energy_wear", "loop_scar_closure", "sliding_condition", "transition"),
    "ecofmaps.maps": (
        "CacheWarning",
        "cache_entries",
        "clear_cache",
        "compute_loops",
        "compute_map",
        "compute_universal_map",
        "write_map",
    ),
    "ecofmaps.measured": (
        "LoopFit",
        "analyze_loops",
        "fit_loop",
        "long_recording",
        "resolve_loops",
        "scar_example_path",
        "synthetic_recording",
        "write_long_recording",
    ),
    "ecofmaps.model": (
        "BEYOND_PROFILE",
        "GROSS_SLIP",
        "INVALID",
        "NO_GROSS_SLIP",
        "PARTIAL_SLIP",
        "SELF_LOCKING",
        "Regime",
        "ScarProfile",
        "dissipated_energy",
        "energy_cof",
        "flat_bottomed_profile",
        "fretting_loop",
        "max_force",
        "parabolic_profile",
        "slip_regime",
        "ridged_profile",
        "scar_profile",
        "simulate",
        "slip_amplitude",
        "w_shaped_profile",
    ),
}
#: Subpackages reachable as attributes (``ecofmaps.figures`` needs matplotlib).
_SUBMODULES = ("cli", "correction", "figures", "io", "maps", "measured", "model", "paper")

__getattr__, __dir__, __all__ = lazy_names(__name__, _PUBLIC, _SUBMODULES)
__all__ = sorted([*__all__, "__version__"])
