"""Figures (needs matplotlib): the paper's, drawn from Datasets, and those of measured loops.

:mod:`~ecofmaps.figures.model_figures` draws the model's loops and curves (the paper's
Figures 5-8), :mod:`~ecofmaps.figures.map_figures` its maps (Figure 11 and the universal
map), :mod:`~ecofmaps.figures.measured_figures` those of measured
loops (Figures 9 and 10, the loops read along the stroke),
:mod:`~ecofmaps.figures.profile_figures` those of wear-scar profiles (a measured profile,
and scars of several shapes), :mod:`~ecofmaps.figures.recipes` the set ``ecofmaps figures``
writes, and :mod:`~ecofmaps.figures.style` what they share. The names are imported on
first use: the registry of figures reads without matplotlib.
"""

import importlib

#: Each public name, by the module of ecofmaps.figures that defines it.
_PUBLIC = {
    "measured_figures": (
        "cof_evolution",
        "measured_and_fitted_loops",
        "measured_loops",
        "resolved_loops",
    ),
    "map_figures": ("ecof_ratio_contours", "universal_ecof_ratio_map"),
    "model_figures": (
        "dissipated_energy_curves",
        "ecof_ratio_curves",
        "loops_by_aspect_ratio",
        "rigid_and_compliant_loops",
        "slip_amplitude_curves",
    ),
    "profile_figures": ("scar_profile_figure", "scar_shape_comparison"),
    "recipes": ("FIGURES", "FigureRecipe", "make_figure", "make_figures"),
    "style": ("ECOF_RATIO_LEVELS", "save_figure"),
}
_HOME = {name: module for module, names in _PUBLIC.items() for name in names}


def __getattr__(name: str):
    if name in _HOME:
        value = getattr(importlib.import_module(f"ecofmaps.figures.{_HOME[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'ecofmaps.figures' has no attribute {name!r}")


def __dir__():
    return sorted({*globals(), *__all__})


__all__ = sorted(_HOME)
