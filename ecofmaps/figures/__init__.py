"""Figures (needs matplotlib): the paper's, drawn from Datasets, and those of measured loops,
scar profiles and a lab's numbers, one module each; ``ecofmaps figures`` writes the set of
:mod:`~ecofmaps.figures.recipes`. Names are imported on first use: the registry of figures
reads without matplotlib."""

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
