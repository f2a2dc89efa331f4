"""ecofmaps: friction from fretting loops, corrected for rig compliance and wear-scar shape.

The public API in SI units (m, N, N/m, J). See the README for an overview and the
paper this package implements.
"""

import importlib
from importlib.metadata import PackageNotFoundError, version

from ecofmaps._inputs import RegimeWarning
from ecofmaps.correction import (
    CorrectionStatus,
    Interval,
    correct_ecof,
    correction_factor,
    lookup_correction,
)
from ecofmaps.io import read_recording, read_scar_profile
from ecofmaps.maps import (
    CacheWarning,
    cache_entries,
    clear_cache,
    compute_loops,
    compute_map,
    compute_universal_map,
)
from ecofmaps.measured import LoopFit, analyze_loops, fit_loop, synthetic_recording
from ecofmaps.model import (
    BEYOND_PROFILE,
    GROSS_SLIP,
    INVALID,
    NO_GROSS_SLIP,
    SELF_LOCKING,
    Regime,
    ScarProfile,
    dissipated_energy,
    energy_cof,
    flat_bottomed_profile,
    fretting_loop,
    max_force,
    parabolic_profile,
    regime,
    ridged_profile,
    scar_profile,
    simulate,
    slip_amplitude,
    w_shaped_profile,
)


def __getattr__(name: str):
    # ecofmaps.figures (the paper's figures) needs matplotlib: it is imported on first use,
    # ecofmaps.figures.make_figure(...), not with the package.
    if name == "figures":
        return importlib.import_module("ecofmaps.figures")
    raise AttributeError(f"module 'ecofmaps' has no attribute {name!r}")


try:
    __version__ = version("ecofmaps")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"

__all__ = [
    "BEYOND_PROFILE",
    "GROSS_SLIP",
    "INVALID",
    "NO_GROSS_SLIP",
    "SELF_LOCKING",
    "CacheWarning",
    "CorrectionStatus",
    "Interval",
    "LoopFit",
    "Regime",
    "RegimeWarning",
    "ScarProfile",
    "__version__",
    "analyze_loops",
    "cache_entries",
    "clear_cache",
    "compute_loops",
    "compute_map",
    "compute_universal_map",
    "correct_ecof",
    "correction_factor",
    "dissipated_energy",
    "energy_cof",
    "figures",
    "fit_loop",
    "flat_bottomed_profile",
    "fretting_loop",
    "lookup_correction",
    "max_force",
    "parabolic_profile",
    "read_recording",
    "read_scar_profile",
    "regime",
    "ridged_profile",
    "scar_profile",
    "simulate",
    "slip_amplitude",
    "synthetic_recording",
    "w_shaped_profile",
]
