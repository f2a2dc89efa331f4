"""ecofmaps: friction from fretting loops, corrected for rig compliance and wear-scar shape.

The public API in SI units (m, N, N/m, J), or pint Quantities. See the README for an
overview and the paper this package implements (:mod:`ecofmaps.paper`).

The names below are imported on first use, so ``import ecofmaps`` is quick and the command
line starts (and answers Ctrl-C) before JAX, xarray or matplotlib are loaded.
"""

import importlib

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
_HOME = {name: module for module, names in _PUBLIC.items() for name in names}
#: Subpackages reachable as attributes (``ecofmaps.figures`` needs matplotlib).
_SUBMODULES = ("cli", "correction", "figures", "io", "maps", "measured", "model", "paper")


def __getattr__(name: str):
    if name in _HOME:
        value = getattr(importlib.import_module(_HOME[name]), name)
        globals()[name] = value  # imported once
        return value
    if name in _SUBMODULES:
        return importlib.import_module(f"ecofmaps.{name}")
    raise AttributeError(f"module 'ecofmaps' has no attribute {name!r}")


def __dir__():
    return sorted({*globals(), *__all__})


__all__ = sorted([*_HOME, *_SUBMODULES, "__version__"])
