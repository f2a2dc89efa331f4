"""Figures: the paper's, drawn from Datasets, and those of measured loops (needs matplotlib)."""

from ecofmaps.figures.model_figures import *  # noqa: F403
from ecofmaps.figures.model_figures import __all__ as __all__
