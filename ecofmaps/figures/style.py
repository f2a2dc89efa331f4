"""The look shared by every figure: sizes, labels from the nomenclature, colours, saving.

Figures are :class:`matplotlib.figure.Figure` objects built without pyplot state, so they
can be made in a loop or a server; :func:`save_figure` writes one atomically.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.colors import BoundaryNorm
from matplotlib.figure import Figure

from ecofmaps._nomenclature import QUANTITIES, axis_label
from ecofmaps.io.files import atomic_path

__all__ = [
    "ECOF_RATIO_LEVELS",
    "FIGSIZE",
    "PAPER_DPI",
    "RECORDING_DPI",
    "axis_label",
    "number_text",
    "save_figure",
    "stiffness_label",
    "stiffness_text",
]

#: Contour levels of μ_E/μ shared by Figure 11 and the universal map, so they read alike.
ECOF_RATIO_LEVELS = (1.01, 1.02, 1.03, 1.04, 1.05, 1.06, 1.08, 1.10, 1.12, 1.14, 1.17, 1.20, 1.25)

#: The level drawn heavier: the paper's "most tests are within 5 %".
HIGHLIGHT_LEVEL = 1.05

#: Resolution of the paper's figures (``ecofmaps figures``) written as PNG. [1/inch]
PAPER_DPI = 150

#: Resolution of the plots of a user's recording (``ecofmaps loops --plots``). [1/inch]
RECORDING_DPI = 300


def ecof_ratio_colors() -> tuple:
    """The colour map of μ_E/μ and its norm: one colour per band between 1 and the
    :data:`ECOF_RATIO_LEVELS`, whatever a map's range, so the same μ_E/μ has the same colour in
    Figures 11a and 11b, the universal map and the explorer's map."""
    cmap = colormaps["YlOrRd"]
    return cmap, BoundaryNorm([1.0, *ECOF_RATIO_LEVELS], cmap.N, clip=True)


#: Size of a one-panel figure. [inch]
FIGSIZE = (6.4, 4.6)

#: Factors from SI to the units the figures speak.
MICRO = QUANTITIES["displacement"].display_factor  # m -> µm
MEGA = QUANTITIES["stiffness"].display_factor  # N/m -> MN/m
MILLI = QUANTITIES["dissipated_energy"].display_factor  # J -> mJ
PER_MM = QUANTITIES["stiffness_ratio"].display_factor  # 1/m -> 1/mm = (MN/m)/kN


def scalar(dataset: xr.Dataset, name: str) -> float:
    """A parameter held as a scalar coordinate of ``dataset``, as a float."""
    return float(dataset[name].values)


def number_text(value: float, digits: int = 3) -> str:
    """``value`` for a label: ``digits`` significant digits, no exponent, no trailing zeros.

    Parameters
    ----------
    value : float
    digits : int
        Significant digits at most; whole numbers keep all theirs. [1]

    Returns
    -------
    text : str
        A dash for NaN, ``∞`` for an infinite value.

    Examples
    --------
    >>> [number_text(v) for v in (35.0, 0.02, 35.04, 12345.6, 0.0, float("nan"))]
    ['35', '0.02', '35', '12346', '0', '–']
    """
    value = float(value)
    if np.isnan(value):
        return "–"
    if np.isinf(value):
        return "∞" if value > 0 else "−∞"
    if value == 0.0:
        return "0"
    decimals = max(0, digits - 1 - int(np.floor(np.log10(abs(value)))))
    text = f"{value:.{decimals}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def stiffness_text(stiffness: float) -> str:
    """A rig stiffness [N/m] in MN/m for a label: ``'35 MN/m'``, ``'0.02 MN/m'``, ``'rigid'``.

    Examples
    --------
    >>> [stiffness_text(s) for s in (35e6, 0.02e6, 35.04e6, float("inf"))]
    ['35 MN/m', '0.02 MN/m', '35 MN/m', 'rigid']
    """
    if np.isinf(stiffness):
        return "rigid"
    return f"{number_text(stiffness * MEGA)} MN/m"


def stiffness_label(stiffness: float) -> str:
    """Legend text for a rig stiffness [N/m]: ``'S = 35 MN/m'``, or ``'rigid (S = ∞)'``."""
    if np.isinf(stiffness):
        return r"rigid ($S = \infty$)"
    return f"S = {stiffness_text(stiffness)}"


def stiffness_colors(stiffnesses) -> list:
    """One colour per stiffness: a sequential map for finite rigs, black for the rigid one."""
    finite = [s for s in stiffnesses if np.isfinite(s)]
    cmap = colormaps["plasma"]
    shades = dict(zip(finite, cmap(np.linspace(0.05, 0.8, len(finite))), strict=True))
    return [shades.get(s, "black") for s in stiffnesses]


def parameters(*items: str) -> str:
    """A figure subtitle listing the fixed parameters."""
    return ",  ".join(items)


def force_ratio_axis(ax, load: float) -> None:
    """A right-hand axis reading the force axis [N] as :math:`Q/P`."""
    secondary = ax.secondary_yaxis("right", functions=(lambda q: q / load, lambda r: r * load))
    secondary.set_ylabel(axis_label("force_ratio"))


# No time stamps in the files, so regenerating an unchanged figure gives the same bytes.
_METADATA = {"pdf": {"CreationDate": None}, "svg": {"Date": None}}


def save_figure(figure: Figure, path, dpi: int = PAPER_DPI) -> Path:
    """Write ``figure`` to ``path`` atomically; the format follows the file's suffix.

    The figure is written to a temporary file in the same directory and renamed over
    ``path``, so an existing file is never left half written.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
    path : str or os.PathLike
        Destination, ending in ``.png``, ``.pdf`` or ``.svg``. Its directory must exist.
    dpi : int
        Resolution of raster output: :data:`PAPER_DPI` by default, :data:`RECORDING_DPI`
        for the plots of a recording. [1/inch]

    Returns
    -------
    path : pathlib.Path
    """
    path = Path(path)
    file_format = path.suffix.lstrip(".").lower()
    with atomic_path(path) as temporary:
        figure.savefig(temporary, format=file_format, dpi=dpi, metadata=_METADATA.get(file_format))
    return path
