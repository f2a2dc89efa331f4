r"""The maps of μ_E/μ over the rig (S/P, or λ = P/(SΔ*)) and z_o/x_o: the paper's Figure 11 and
the universal map, each a pure function of the Dataset that holds its numbers (docs/model.md)."""

from __future__ import annotations

import itertools
from collections.abc import Mapping

import numpy as np
import xarray as xr
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from ecofmaps.figures import style
from ecofmaps.figures.style import MICRO, axis_label, scalar
from ecofmaps.model import NO_GROSS_SLIP, compliance_ratio, energy_cof


def _ecof_ratio_contours(ax, x, ratio: xr.DataArray, regime: xr.DataArray) -> list:
    """Filled and labelled contours of μ_E/μ over (x, z_o/x_o), no-gross-slip area hatched."""
    y = ratio["aspect_ratio"].values
    values = ratio.transpose(..., "aspect_ratio").values.T
    top = np.nanmax(values)
    levels = [level for level in style.ECOF_RATIO_LEVELS if level <= top]
    above = [level for level in style.ECOF_RATIO_LEVELS if level > top]
    fill_levels = [1.0, *levels, above[0] if above else top]
    cmap, norm = style.ecof_ratio_colors()
    filled = ax.contourf(x, y, values, levels=fill_levels, cmap=cmap, norm=norm, alpha=0.85)
    widths = [2.4 if level == style.HIGHLIGHT_LEVEL else 0.9 for level in levels]
    lines = ax.contour(x, y, values, levels=levels, colors="black", linewidths=widths)
    ax.clabel(lines, fmt="%.2f", fontsize="small", inline_spacing=3)
    colorbar = ax.figure.colorbar(filled, ax=ax, ticks=fill_levels, format="%.2f")
    colorbar.set_label(r"$\mu_E/\mu$ [1]")
    ax.set_ylabel(axis_label("aspect_ratio"))
    label = r"$\mu_E/\mu$ = 1.05 (5 % above $\mu$)"
    handles = [Line2D([], [], color="black", linewidth=2.4, label=label)]
    stuck = (regime == NO_GROSS_SLIP).transpose(..., "aspect_ratio").values.T.astype(float)
    if stuck.any():
        ax.contourf(x, y, stuck, levels=[0.5, 1.5], colors="none", hatches=["//"])
        ax.contour(x, y, stuck, levels=[0.5], colors="0.3", linewidths=1.0)
        label = r"no gross slip ($\mu P/S \geq \Delta^*$)"
        handles.append(Patch(facecolor="none", edgecolor="0.3", hatch="//", label=label))
    return handles


def ecof_ratio_contours(
    dataset: xr.Dataset, number: str = "11", markers: Mapping[str, Mapping] | None = None
) -> Figure:
    r"""Figure 11: labelled contours of :math:`\mu_E/\mu` over :math:`S/P` and :math:`z_o/x_o`.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`ecofmaps.compute_map` over ``stiffness_ratio`` and ``aspect_ratio`` alone.
    number : str
        The figure's number in its title (``'11a'``).
    markers : mapping of str to mapping, optional
        Test conditions to mark, by legend name: each with ``stiffness`` [N/m], ``load`` [N]
        and ``aspect_ratio`` [1] (e.g. :data:`ecofmaps.paper.EXAMPLE_2`).

    Returns
    -------
    figure : matplotlib.figure.Figure
        Contours at :data:`ECOF_RATIO_LEVELS` over :math:`S/P` [(MN/m)/kN], no gross slip hatched.
    """
    figure = Figure(figsize=style.FIGSIZE, layout="constrained")
    ax = figure.add_subplot()
    x = dataset["stiffness_ratio"].values * style.PER_MM
    handles = _ecof_ratio_contours(ax, x, dataset["ecof_ratio"], dataset["regime"])
    ax.set_xlabel(axis_label("stiffness_ratio"))
    for name, point in (markers or {}).items():
        rig = style.stiffness_label(point["stiffness"]), style.load_label(point["load"])
        label = f"{name} ({', '.join(rig)})"
        dot = dict(color="navy", markersize=8, markeredgecolor="white", label=label)
        at = point["stiffness"] / point["load"] * style.PER_MM
        handles += ax.plot(at, point["aspect_ratio"], "o", **dot)
    ax.legend(handles=handles, loc="lower right", fontsize="small", framealpha=0.9)
    rig = style.parameters_of(dataset, "amplitude", "mu")
    title = rf"Fig. {number}  $\mu_E/\mu$ over rig stiffness and groove shape" + "\n" + rig
    ax.set_title(title, fontsize="medium")
    return figure


def universal_ecof_ratio_map(
    dataset: xr.Dataset,
    markers: Mapping[str, Mapping] | None = None,
    windows: Mapping[str, tuple] | None = None,
) -> Figure:
    r"""The universal map: :math:`\mu_E/\mu` over :math:`\lambda = P/(S\Delta^*)` and z_o/x_o.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`ecofmaps.compute_universal_map` over ``compliance_ratio`` (> 0: a
        logarithmic axis) and ``aspect_ratio`` alone.
    markers : mapping of str to mapping, optional
        Points to mark, by legend name: keyword arguments of :func:`ecofmaps.energy_cof`
        (e.g. :data:`ecofmaps.paper.FIGURE_10_FITS`).
    windows : mapping of str to tuple, optional
        Spans of :math:`\lambda` shown as bars, by figure name: ``(amplitude,
        stiffness_ratios)`` [m], [1/m].

    Returns
    -------
    figure : matplotlib.figure.Figure
        Contours at :data:`ECOF_RATIO_LEVELS` on a logarithmic :math:`\lambda` axis.
    """
    figure = Figure(figsize=(6.8, 5.6), layout="constrained")
    ax = figure.add_subplot()
    mu = scalar(dataset, "mu")
    x = dataset["compliance_ratio"].values
    handles = _ecof_ratio_contours(ax, x, dataset["ecof_ratio"], dataset["regime"])
    ax.set_xscale("log")
    ticks = [tick for tick in (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0) if x[0] <= tick <= x[-1]]
    ax.set_xticks(ticks, [f"{tick:g}" for tick in ticks])
    ax.set_xticks([], minor=True)
    ax.set_xlabel(axis_label("compliance_ratio") + r"   ($\lambda \to 0$: rigid rig)")
    windows = windows or {}
    for index, (name, (amplitude, stiffness_ratios)) in enumerate(windows.items()):
        height = 0.008 + 0.014 * (len(windows) - 1 - index)  # stacked near the bottom
        ratios = np.asarray(stiffness_ratios, dtype=np.float64)
        span = compliance_ratio(amplitude, 1.0, np.array([ratios.max(), ratios.min()]))
        bar = dict(arrowstyle="|-|", color="0.25", shrinkA=0, shrinkB=0)
        ax.annotate("", (float(span[0]), height), (float(span[1]), height), arrowprops=bar)
        label = rf"Fig. {name} ($\Delta^*$ = {amplitude * MICRO:g} µm)"
        words = dict(ha="right", va="center", fontsize="x-small", color="0.15")
        ax.text(0.92 * float(span[0]), height, label, **words)
    legible = dict(boxstyle="round,pad=0.1", facecolor="white", alpha=0.75, edgecolor="none")
    for (name, point), marker in zip((markers or {}).items(), itertools.cycle("soD^v")):
        lam = float(compliance_ratio(point["amplitude"], point["load"], point["stiffness"]))
        value = float(energy_cof(**point) / point["mu"])
        ratio = point["aspect_ratio"]
        rig = f"{style.stiffness_label(point['stiffness'])}, $z_o/x_o$ = {ratio:.3g}"
        label = rf"{name}: {rig}, $\mu$ = {point['mu']:g}: $\mu_E/\mu$ = {value:.3f}"
        dot = dict(color="navy", markersize=8, markeredgecolor="white", zorder=5, label=label)
        handles += ax.plot(lam, ratio, marker, **dot)
        short = name.replace("Example ", "Ex. ").replace("(Section 3)", "(§3)")
        words = dict(textcoords="offset points", fontsize="x-small", color="navy", bbox=legible)
        ax.annotate(short, (lam, ratio), xytext=(7, -3), **words)
    figure.legend(handles=handles, loc="outside lower center", fontsize="x-small", ncols=1)
    title = [
        rf"Universal map of $\mu_E/\mu$ ($x_o = \Delta^*$, $\mu$ = {mu:g})",
        r"Any $\Delta^*$ and $S/P$ with the same $\lambda = P/(S\Delta^*)$ give the same "
        r"$\mu_E/\mu$" + (":" if windows else ""),
    ]
    if windows:
        spans = [f"{name} ({amplitude * MICRO:g} µm)" for name, (amplitude, _) in windows.items()]
        spans[0] = spans[0].replace("(", r"($\Delta^*$ = ", 1)
        title.append(f"Fig. {' and '.join(spans)} are windows of this one chart")
    ax.set_title("\n".join(title), fontsize="medium")
    return figure
