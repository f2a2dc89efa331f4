"""The look shared by every figure: sizes, labels from the nomenclature, colours, legends
clear of the data, saving. Figures are :class:`matplotlib.figure.Figure` objects built without
pyplot state, so they can be made in a loop or a server."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.colors import BoundaryNorm
from matplotlib.figure import Figure
from matplotlib.path import Path as DrawnPath

from ecofmaps._nomenclature import QUANTITIES, axis_label
from ecofmaps.io.files import atomic_path

#: Contour levels of μ_E/μ shared by Figure 11 and the universal map, so they read alike.
ECOF_RATIO_LEVELS = (1.01, 1.02, 1.03, 1.04, 1.05, 1.06, 1.08, 1.10, 1.12, 1.14, 1.17, 1.20, 1.25)
#: The level drawn heavier: the paper's "most tests are within 5 %".
HIGHLIGHT_LEVEL = 1.05
#: Resolution of the paper's figures (``ecofmaps figures``) written as PNG. [1/inch]
PAPER_DPI = 300
#: Resolution of the plots of a user's recording (``ecofmaps loops --plots``). [1/inch]
RECORDING_DPI = 300


def ecof_ratio_colors() -> tuple:
    """The colour map of μ_E/μ and its norm: a colour per band of :data:`ECOF_RATIO_LEVELS`."""
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
    return float(dataset[name].values)


def number_text(value: float, digits: int = 3) -> str:
    """``value`` for a label: at most ``digits`` significant digits (a whole number keeps all its
    own), no exponent, no trailing zeros; a dash for NaN, ``∞`` for an infinite value."""
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


def stiffness_label(stiffness: float) -> str:
    r"""Legend text for a rig stiffness [N/m]: ``'$S$ = 35 MN/m'``, ``'rigid ($S = \infty$)'``."""
    if np.isinf(stiffness):
        return r"rigid ($S = \infty$)"
    return f"$S$ = {number_text(stiffness * MEGA)} MN/m"


def load_label(load: float) -> str:
    """The normal load [N] for a title or legend, its symbol italic: ``'$P$ = 450 N'``."""
    return f"$P$ = {load:g} N"


def stiffness_colors(stiffnesses) -> list:
    """One colour per stiffness: a sequential map for finite rigs, black for the rigid one."""
    finite = [s for s in stiffnesses if np.isfinite(s)]
    cmap = colormaps["plasma"]
    shades = dict(zip(finite, cmap(np.linspace(0.05, 0.8, len(finite))), strict=True))
    return [shades.get(s, "black") for s in stiffnesses]


def parameters(*items: str) -> str:
    """A figure subtitle listing the fixed parameters."""
    return ",  ".join(items)


#: The paper's parameters in a subtitle: text, and the factor to its unit.
_PARAMETERS = {
    "amplitude": (r"$x_o = \Delta^*$ = {:g} µm", MICRO),
    "aspect_ratio": (r"$z_o/x_o$ = {:g}", 1.0),
    "mu": (r"$\mu$ = {:g}", 1.0),
}
#: The parameters a subtitle gives through their own label.
_LABELS = {"stiffness": stiffness_label, "load": load_label}


def parameters_of(dataset: xr.Dataset, *names: str) -> str:
    """:func:`parameters` of the scalars ``names`` of ``dataset``, the rig by its stiffness."""
    texts = []
    for name in names:
        value = scalar(dataset, name)
        if name in _LABELS:
            texts.append(_LABELS[name](value))
        else:
            text, factor = _PARAMETERS[name]
            texts.append(text.format(value * factor))
    return parameters(*texts)


def force_ratio_axis(ax, load: float) -> None:
    """A right-hand axis reading the force axis [N] as :math:`Q/P`."""
    secondary = ax.secondary_yaxis("right", functions=(lambda q: q / load, lambda r: r * load))
    secondary.set_ylabel(axis_label("force_ratio"))


def zero_lines(ax, color: str = "0.6", x: float = 0.0, y: float = 0.0) -> None:
    """Thin lines across ``ax`` at ``y`` and ``x`` (in its data's units)."""
    ax.axhline(y, color=color, linewidth=0.6)
    ax.axvline(x, color=color, linewidth=0.6)


def loop_axes(ax, load: float, x: float = 0.0, y: float = 0.0) -> None:
    """The axes of a loop: :func:`zero_lines` at ``x`` [µm] and ``y`` [N], labels, grid, Q/P."""
    zero_lines(ax, x=x, y=y)
    ax.set(xlabel=axis_label("displacement"), ylabel=axis_label("force"))
    ax.grid(alpha=0.3)
    force_ratio_axis(ax, load)


#: Room kept between a legend and what is drawn, as a fraction of the panel's height. [1]
_LEGEND_ROOM = 0.03
#: Where a legend may go inside a panel, in the order tried: the corners, then the middles.
_CORNERS = ("upper left", "upper right", "lower left", "lower right")
_CORNERS += ("upper center", "lower center")


def legend_clear_of_data(ax, *, twins=(), **options):
    """A legend of ``ax`` and its twin axes ``twins`` in the first corner of ``ax`` where it
    covers nothing drawn in them; with no such corner, the value axes are stretched upwards to
    make room above everything drawn, and the legend goes in the upper left."""
    panels = (ax, *twins)
    entries = [panel.get_legend_handles_labels() for panel in panels]
    handles = [handle for more, _ in entries for handle in more]
    labels = [label for _, more in entries for label in more]
    legend = ax.legend(handles, labels, loc=_CORNERS[0], **options)
    ax.figure.draw_without_rendering()  # the layout done: the legend's and the data's places
    for corner in _CORNERS:
        legend.set_loc(corner)
        box = legend.get_window_extent().padded(_LEGEND_ROOM * ax.bbox.height)
        if not any(_covers(panel, box) for panel in panels):
            return legend
    legend.set_loc(_CORNERS[0])
    share = legend.get_window_extent().height / ax.bbox.height + 2.0 * _LEGEND_ROOM
    for panel in panels:
        low, high = panel.get_ylim()
        panel.set_ylim(low, low + (high - low) / max(1.0 - share, 0.2))
    return legend


def _covers(ax, box) -> bool:
    """Whether anything drawn in ``ax`` (not a shaded background) meets the display ``box``."""
    for line in ax.get_lines():
        path = line.get_transform().transform_path(line.get_path()).cleaned(remove_nans=True)
        points = path.vertices[np.isin(path.codes, (DrawnPath.MOVETO, DrawnPath.LINETO))]
        marked = line.get_marker() not in (None, "None", "", " ") and box.count_contains(points)
        lined = line.get_linestyle() not in ("None", "", " ")
        if marked or (lined and path.intersects_bbox(box, filled=False)):
            return True
    for collection in ax.collections:
        transform = collection.get_transform()
        if any(transform.transform_path(p).intersects_bbox(box) for p in collection.get_paths()):
            return True
    return any(text.get_window_extent().overlaps(box) for text in ax.texts)


# No time stamps in the files, so regenerating an unchanged figure gives the same bytes.
_METADATA = {"pdf": {"CreationDate": None}, "svg": {"Date": None}}


def save_figure(figure: Figure, path, dpi: int = PAPER_DPI) -> Path:
    """Write ``figure`` to ``path`` atomically (never half written), in its suffix's format.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
    path : str or os.PathLike
        Ending in ``.png``, ``.pdf`` or ``.svg``; its directory must exist.
    dpi : int
        Raster resolution: :data:`PAPER_DPI`, or :data:`RECORDING_DPI` for a recording. [1/inch]

    Returns
    -------
    path : pathlib.Path
    """
    path = Path(path)
    file_format = path.suffix.lstrip(".").lower()
    with atomic_path(path) as temporary:
        figure.savefig(temporary, format=file_format, dpi=dpi, metadata=_METADATA.get(file_format))
    return path
