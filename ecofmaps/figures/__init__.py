"""Figures (needs matplotlib): the paper's, drawn from Datasets, and those of measured loops.

The model's loops and curves (:mod:`~ecofmaps.figures.model_figures`), its maps
(:mod:`~ecofmaps.figures.map_figures`), measured loops (:mod:`~ecofmaps.figures.measured_figures`),
scar profiles (:mod:`~ecofmaps.figures.profile_figures`), a campaign's running-condition map
and a test's loop-scar closure (:mod:`~ecofmaps.figures.lab_figures`), the set
``ecofmaps figures`` writes (:mod:`~ecofmaps.figures.recipes`) and their shared look
(:mod:`~ecofmaps.figures.style`).
The names are imported on first use: the registry of figures reads without matplotlib.
"""

from ecofmaps._lazy import lazy_names

#: Each public name, by the module that defines it.
_PUBLIC = {
    "ecofmaps.figures.measured_figures": (
        "cof_evolution",
        "measured_and_fitted_loops",
        "measured_loops",
        "resolved_loops",
    ),
    "ecofmaps.figures.lab_figures": ("loop_scar_closure_figure", "running_condition_map"),
    "ecofmaps.figures.map_figures": ("ecof_ratio_contours", "universal_ecof_ratio_map"),
    "ecofmaps.figures.model_figures": (
        "dissipated_energy_curves",
        "ecof_ratio_curves",
        "loops_by_aspect_ratio",
        "rigid_and_compliant_loops",
        "slip_amplitude_curves",
    ),
    "ecofmaps.figures.profile_figures": ("scar_profile_figure", "scar_shape_comparison"),
    "ecofmaps.figures.recipes": (
        "FIGURES",
        "FigureRecipe",
        "figure_groups",
        "figure_parts",
        "make_figure",
        "make_figures",
    ),
    "ecofmaps.figures.style": ("ECOF_RATIO_LEVELS", "RECORDING_DPI", "save_figure"),
}
__getattr__, __dir__, __all__ = lazy_names(__name__, _PUBLIC)
