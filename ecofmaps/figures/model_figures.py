r"""The paper's figures of the model's loops and curves (Figures 5-8): each a pure function of a
Dataset of :mod:`ecofmaps.maps` (and of the points it marks), in µm, N, MN/m and mJ.
:mod:`ecofmaps.figures.recipes` builds the Datasets with the paper's parameters."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure

from ecofmaps.figures import style
from ecofmaps.figures.style import MICRO, axis_label, scalar


def rigid_and_compliant_loops(loops: xr.Dataset) -> Figure:
    r"""Figure 5: the steady loop of a rigid rig against that of a compliant one.

    Parameters
    ----------
    loops : xarray.Dataset
        From :func:`ecofmaps.maps.compute_loops` over ``stiffness`` alone (``inf``: rigid).

    Returns
    -------
    figure : matplotlib.figure.Figure
        :math:`Q` [N] and :math:`Q/P` against :math:`\Delta` [µm], each loop's :math:`\delta^*`
        [µm] and :math:`E_d` [mJ] in the legend.
    """
    figure = Figure(figsize=style.FIGSIZE, layout="constrained")
    ax = figure.add_subplot()
    stiffnesses = loops["stiffness"].values
    for stiffness, color in zip(stiffnesses, style.stiffness_colors(stiffnesses), strict=True):
        loop = loops.sel(stiffness=stiffness)
        slip = rf"$\delta^*$ = {float(loop.slip_amplitude) * MICRO:.1f} µm"
        label = f"{style.stiffness_label(stiffness)}: {slip}, "
        label += rf"$E_d$ = {float(loop.dissipated_energy) * style.MILLI:.1f} mJ"
        look = dict(linestyle="--", linewidth=1.8) if np.isinf(stiffness) else dict(linewidth=2.2)
        ax.plot(loop.displacement * MICRO, loop.force, color=color, label=label, **look)
    style.loop_axes(ax, scalar(loops, "load"))
    rig = style.parameters_of(loops, "amplitude", "load", "aspect_ratio", "mu")
    title = f"Fig. 5  Fretting loop: rigid rig against a compliant one\n{rig}"
    ax.set_title(title, fontsize="medium")
    ax.legend(loc="upper left", fontsize="small")
    return figure


def loops_by_aspect_ratio(loops: xr.Dataset) -> Figure:
    r"""Figure 6: loops for several groove aspect ratios, and the line :math:`Q = S\Delta`.

    Parameters
    ----------
    loops : xarray.Dataset
        From :func:`ecofmaps.maps.compute_loops` over ``aspect_ratio`` alone, ``stiffness`` finite.

    Returns
    -------
    figure : matplotlib.figure.Figure
    """
    figure = Figure(figsize=(6.4, 5.6), layout="constrained")
    ax = figure.add_subplot()
    ratios = loops["aspect_ratio"].values
    colors = colormaps["viridis"](np.linspace(0.0, 0.85, len(ratios)))
    for ratio, color in zip(ratios, colors, strict=True):
        loop = loops.sel(aspect_ratio=ratio)
        label = rf"$z_o/x_o$ = {ratio:g}: $\delta^*$ = {float(loop.slip_amplitude) * MICRO:.1f} µm"
        ax.plot(loop.displacement * MICRO, loop.force, color=color, linewidth=2.0, label=label)
    stiffness, load, mu = (scalar(loops, name) for name in ("stiffness", "load", "mu"))
    reach = 1.12 * float(np.abs(loops.force).max())
    ends = np.array([-reach, reach]) / stiffness
    line = dict(color="black", linewidth=1.2, linestyle="--", label=r"$Q = S\Delta$")
    ax.plot(ends * MICRO, ends * stiffness, **line)
    crossings = np.array([-mu * load, mu * load])
    label = rf"common points $Q = \pm\mu P$ = ±{mu * load:g} N (GICoF)"
    dots = dict(color="crimson", markersize=8, zorder=5, label=label)
    ax.plot(crossings / stiffness * MICRO, crossings, "o", **dots)
    style.loop_axes(ax, scalar(loops, "load"))
    rig = style.parameters_of(loops, "amplitude", "load", "stiffness", "mu")
    ax.set_title(f"Fig. 6  Loops for several groove aspect ratios\n{rig}", fontsize="medium")
    figure.legend(loc="outside lower center", fontsize="small", ncols=2)
    return figure


def _stiffness_curves(dataset, variable: str, scale: float, number: str, loc: str, markers=None):
    """One curve of ``dataset[variable] * scale`` against z_o/x_o per rig stiffness, the
    ``markers`` of :func:`ecof_ratio_curves`, a legend at ``loc`` listing the stiffest first."""
    figure = Figure(figsize=style.FIGSIZE, layout="constrained")
    ax = figure.add_subplot()
    load = scalar(dataset, "load")
    stiffnesses = dataset["stiffness_ratio"].values * load
    for index, color in enumerate(style.stiffness_colors(stiffnesses)):
        curve = dataset[variable].isel(stiffness_ratio=index) * scale
        look = dict(linestyle="--" if np.isinf(stiffnesses[index]) else "-")
        label = style.stiffness_label(stiffnesses[index])
        ax.plot(dataset["aspect_ratio"], curve, color=color, linewidth=2.0, label=label, **look)
    ax.set(xlabel=axis_label("aspect_ratio"), ylabel=axis_label(variable))
    ax.set_xlim(float(dataset["aspect_ratio"].min()), float(dataset["aspect_ratio"].max()))
    ax.grid(alpha=0.3)
    rig = style.parameters_of(dataset, "amplitude", "load", "mu")
    ax.set_title(f"Fig. {number}\n{rig}", fontsize="medium")
    for name, point in (markers or {}).items():
        curve = dataset["ecof_ratio"].sel(stiffness_ratio=point["stiffness"] / load)
        value = float(curve.interp(aspect_ratio=point["aspect_ratio"]))
        rig = rf"{style.stiffness_label(point['stiffness'])}, $z_o/x_o$ = {point['aspect_ratio']:g}"
        label = rf"{name} ({rig}): $\mu_E/\mu$ = {value:.3f} (+{(value - 1) * 100:.1f} %)"
        dot = dict(color="crimson", markersize=9, zorder=5, label=label)
        ax.plot(point["aspect_ratio"], value, "o", **dot)
    handles, labels = ax.get_legend_handles_labels()  # the curves as they stack, then the rest
    order = [*reversed(range(stiffnesses.size)), *range(stiffnesses.size, len(labels))]
    ax.legend([handles[i] for i in order], [labels[i] for i in order], loc=loc, fontsize="small")
    return figure


def slip_amplitude_curves(dataset: xr.Dataset) -> Figure:
    r"""Figure 7a: slip amplitude :math:`\delta^*` [µm] against :math:`z_o/x_o` for several rigs.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`ecofmaps.compute_map` with a load, over ``stiffness_ratio``, ``aspect_ratio``.

    Returns
    -------
    figure : matplotlib.figure.Figure
    """
    title = "7a  Slip amplitude against the groove aspect ratio"
    return _stiffness_curves(dataset, "slip_amplitude", MICRO, title, "lower left")


def dissipated_energy_curves(dataset: xr.Dataset) -> Figure:
    r"""Figure 7b: dissipated energy per cycle :math:`E_d` [mJ] against :math:`z_o/x_o`.

    Parameters
    ----------
    dataset : xarray.Dataset
        As for :func:`slip_amplitude_curves`; needs ``dissipated_energy`` (a load).

    Returns
    -------
    figure : matplotlib.figure.Figure
    """
    title = "7b  Dissipated energy against the groove aspect ratio"
    return _stiffness_curves(dataset, "dissipated_energy", style.MILLI, title, "upper left")


def ecof_ratio_curves(dataset: xr.Dataset, markers: Mapping[str, Mapping] | None = None) -> Figure:
    r"""Figure 8: :math:`\mu_E/\mu` against :math:`z_o/x_o` for several rigs, points marked.

    Parameters
    ----------
    dataset : xarray.Dataset
        As for :func:`slip_amplitude_curves`.
    markers : mapping of str to mapping, optional
        Points to mark, by legend name: each with ``stiffness`` [N/m] (one of the
        Dataset's rigs) and ``aspect_ratio`` [1] (e.g. :data:`ecofmaps.paper.EXAMPLE_2`).

    Returns
    -------
    figure : matplotlib.figure.Figure
        The curves, each marked point with its :math:`\mu_E/\mu` read off the Dataset.
    """
    title = "8  ECoF over the contact CoF against the groove aspect ratio"
    return _stiffness_curves(dataset, "ecof_ratio", 1.0, title, "upper left", markers)
