"""Figures (needs matplotlib): the paper's, drawn from Datasets, and those of measured loops.

:mod:`~ecofmaps.figures.model_figures` draws the model's figures (the paper's Figures 5-8
and 11, and the universal map), :mod:`~ecofmaps.figures.measured_figures` those of measured
loops (Figures 9 and 10), :mod:`~ecofmaps.figures.recipes` the set ``ecofmaps figures``
writes, and :mod:`~ecofmaps.figures.style` what they share.
"""

from ecofmaps.figures.measured_figures import (
    cof_evolution,
    measured_and_fitted_loops,
    measured_loops,
    resolved_loops,
)
from ecofmaps.figures.model_figures import (
    dissipated_energy_curves,
    ecof_ratio_contours,
    ecof_ratio_curves,
    loops_by_aspect_ratio,
    rigid_and_compliant_loops,
    slip_amplitude_curves,
    universal_ecof_ratio_map,
)
from ecofmaps.figures.recipes import FIGURES, FigureRecipe, make_figure, make_figures
from ecofmaps.figures.style import ECOF_RATIO_LEVELS, save_figure

__all__ = [
    "ECOF_RATIO_LEVELS",
    "FIGURES",
    "FigureRecipe",
    "cof_evolution",
    "dissipated_energy_curves",
    "ecof_ratio_contours",
    "ecof_ratio_curves",
    "loops_by_aspect_ratio",
    "make_figure",
    "make_figures",
    "measured_and_fitted_loops",
    "measured_loops",
    "resolved_loops",
    "rigid_and_compliant_loops",
    "save_figure",
    "slip_amplitude_curves",
    "universal_ecof_ratio_map",
]
