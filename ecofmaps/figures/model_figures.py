r"""The paper's figures, each drawn from a Dataset of :mod:`ecofmaps.maps`.

One function per figure takes the Dataset that holds its numbers and returns a
:class:`matplotlib.figure.Figure` (no pyplot state, so figures can be made in a loop or a
server). Axes speak the tribologist's units: µm, N, MN/m, mJ.

:data:`FIGURES` is the registry used by ``ecofmaps figures``: for each figure name, the
function that builds its Dataset with the paper's parameters (through the cached map
functions) and the function that draws it. :func:`make_figure` does both for one figure,
:func:`make_figures` for several (building each shared Dataset once), and
:func:`save_figure` writes a figure atomically.

The paper's parameters (Section 3): :math:`\Delta^* = x_o = 50` µm, :math:`P = 450` N,
:math:`S = 35` MN/m, :math:`\mu = 0.8`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.colors import BoundaryNorm
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from ecofmaps.io.files import atomic_path
from ecofmaps.maps.grid import compute_loops, compute_map, compute_universal_map
from ecofmaps.model import NO_GROSS_SLIP, compliance_ratio, energy_cof

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
    "rigid_and_compliant_loops",
    "save_figure",
    "slip_amplitude_curves",
    "universal_ecof_ratio_map",
]

# --- the paper's parameters (Section 3) and examples (Section 4, Figure 10) ----------------

AMPLITUDE = 50e-6  # displacement amplitude Δ* = x_o [m]
LOAD = 450.0  # normal load P [N]
STIFFNESS = 35e6  # rig stiffness S [N/m]
MU = 0.8  # contact coefficient of friction μ [1]

#: The worked examples of the paper, in SI units. Example 2 appears twice: Section 3 uses
#: z_o/x_o = 0.2 and μ = 0.8; the fit of Figure 10 uses z_o = 8.0 µm and μ = 0.825.
EXAMPLES = {
    "Example 1": dict(stiffness=45e6, aspect_ratio=1.8e-6 / AMPLITUDE, mu=0.825),
    "Example 2": dict(stiffness=35e6, aspect_ratio=8.0e-6 / AMPLITUDE, mu=0.825),
    "Example 2 (Section 3)": dict(stiffness=STIFFNESS, aspect_ratio=0.2, mu=MU),
}

#: Contour levels of μ_E/μ shared by Figure 11 and the universal map, so they read alike.
ECOF_RATIO_LEVELS = (1.01, 1.02, 1.03, 1.04, 1.05, 1.06, 1.08, 1.10, 1.12, 1.14, 1.17, 1.20, 1.25)

#: The level drawn heavier: the paper's "most tests are within 5 %".
_HIGHLIGHT_LEVEL = 1.05

_MICRO = 1e6  # m -> µm
_MEGA = 1e-6  # N/m -> MN/m
_MILLI = 1e3  # J -> mJ
_PER_MM = 1e-3  # 1/m -> 1/mm = (MN/m)/kN

_FIGSIZE = (6.4, 4.6)
_LABELS = {
    "displacement": r"Applied displacement $\Delta$ [µm]",
    "force": r"Tangential force $Q$ [N]",
    "force_ratio": r"$Q/P$ [1]",
    "aspect_ratio": r"Groove aspect ratio $z_o/x_o$ [1]",
    "slip_amplitude": r"Slip amplitude $\delta^*$ [µm]",
    "dissipated_energy": r"Dissipated energy per cycle $E_d$ [mJ]",
    "ecof_ratio": r"$\mu_E/\mu$ [1]",
    "stiffness_ratio": r"Stiffness over load $S/P$ [(MN/m)/kN = 1/mm]",
    "compliance_ratio": r"Compliance ratio $\lambda = P/(S\Delta^*)$ [1]",
}


# --- helpers -------------------------------------------------------------------------------


def _scalar(dataset: xr.Dataset, name: str) -> float:
    """A parameter held as a scalar coordinate of ``dataset``, as a float."""
    return float(dataset[name].values)


def _stiffness_label(stiffness: float) -> str:
    """Legend text for a rig stiffness [N/m]."""
    if np.isinf(stiffness):
        return r"rigid ($S = \infty$)"
    return f"S = {stiffness * _MEGA:g} MN/m"


def _stiffness_colors(stiffnesses) -> list:
    """One colour per stiffness: a sequential map for finite rigs, black for the rigid one."""
    finite = [s for s in stiffnesses if np.isfinite(s)]
    cmap = colormaps["plasma"]
    shades = dict(zip(finite, cmap(np.linspace(0.05, 0.8, len(finite))), strict=True))
    return [shades.get(s, "black") for s in stiffnesses]


def _parameters(*items: str) -> str:
    """A figure subtitle listing the fixed parameters."""
    return ",  ".join(items)


def _force_ratio_axis(ax, load: float) -> None:
    """A right-hand axis reading the force axis [N] as :math:`Q/P`."""
    secondary = ax.secondary_yaxis("right", functions=(lambda q: q / load, lambda r: r * load))
    secondary.set_ylabel(_LABELS["force_ratio"])


# --- Figures 5 and 6: fretting loops --------------------------------------------------------


def rigid_and_compliant_loops(loops: xr.Dataset) -> Figure:
    r"""Figure 5: the steady loop of a rigid rig against that of a compliant one.

    Parameters
    ----------
    loops : xarray.Dataset
        From :func:`ecofmaps.maps.compute_loops` with a 1-D ``stiffness`` dimension (one
        entry may be ``inf``) and scalar ``aspect_ratio``, ``amplitude``, ``load``, ``mu``.

    Returns
    -------
    figure : matplotlib.figure.Figure
        :math:`Q` [N] (left) and :math:`Q/P` (right) against :math:`\Delta` [µm]; the
        legend gives each loop's :math:`\delta^*` [µm] and :math:`E_d` [mJ].

    Notes
    -----
    Figure 5 of the paper (:math:`x_o = \Delta^* = 50` µm, :math:`P = 450` N,
    :math:`z_o/x_o = 0.2`, :math:`\mu = 0.8`, :math:`S = \infty` and 35 MN/m). The
    compliant loop's sides have slope :math:`S` (eq. 10); its slip branches follow eq. 9.
    """
    figure = Figure(figsize=_FIGSIZE, layout="constrained")
    ax = figure.add_subplot()
    stiffnesses = loops["stiffness"].values
    styles = {True: dict(linestyle="--", linewidth=1.8), False: dict(linewidth=2.2)}
    for stiffness, color in zip(stiffnesses, _stiffness_colors(stiffnesses), strict=True):
        loop = loops.sel(stiffness=stiffness)
        label = (
            f"{_stiffness_label(stiffness)}: "
            rf"$\delta^*$ = {float(loop.slip_amplitude) * _MICRO:.1f} µm, "
            rf"$E_d$ = {float(loop.dissipated_energy) * _MILLI:.1f} mJ"
        )
        ax.plot(
            loop.displacement * _MICRO,
            loop.force,
            color=color,
            label=label,
            **styles[bool(np.isinf(stiffness))],
        )
    _loop_axes(ax, loops)
    ax.set_title(
        "Fig. 5  Fretting loop: rigid rig against a compliant one\n"
        + _parameters(
            rf"$x_o = \Delta^*$ = {_scalar(loops, 'amplitude') * _MICRO:g} µm",
            f"P = {_scalar(loops, 'load'):g} N",
            rf"$z_o/x_o$ = {_scalar(loops, 'aspect_ratio'):g}",
            rf"$\mu$ = {_scalar(loops, 'mu'):g}",
        ),
        fontsize="medium",
    )
    ax.legend(loc="upper left", fontsize="small")
    return figure


def _loop_axes(ax, loops: xr.Dataset) -> None:
    """Labels, zero lines and the Q/P axis shared by the loop figures."""
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    ax.axvline(0.0, color="0.6", linewidth=0.6)
    ax.set_xlabel(_LABELS["displacement"])
    ax.set_ylabel(_LABELS["force"])
    ax.grid(alpha=0.3)
    _force_ratio_axis(ax, _scalar(loops, "load"))


def loops_by_aspect_ratio(loops: xr.Dataset) -> Figure:
    r"""Figure 6: loops for several groove aspect ratios, and the line :math:`Q = S\Delta`.

    Parameters
    ----------
    loops : xarray.Dataset
        From :func:`ecofmaps.maps.compute_loops` with a 1-D ``aspect_ratio`` dimension and
        scalar ``stiffness`` (finite), ``amplitude``, ``load``, ``mu``.

    Returns
    -------
    figure : matplotlib.figure.Figure
        One loop per :math:`z_o/x_o`, the line :math:`Q = S\Delta` and its two crossings
        :math:`Q = \pm\mu P` marked (the GICoF points).

    Notes
    -----
    Figure 6 of the paper. Every loop crosses :math:`Q = S\Delta` where the contact is at
    the groove centre, :math:`x = 0`, so :math:`Q = \pm\mu P` there whatever the groove
    (eq. 17-18): the geometry-independent coefficient of friction is read off these points.
    """
    figure = Figure(figsize=(6.4, 5.6), layout="constrained")
    ax = figure.add_subplot()
    ratios = loops["aspect_ratio"].values
    colors = colormaps["viridis"](np.linspace(0.0, 0.85, len(ratios)))
    for ratio, color in zip(ratios, colors, strict=True):
        loop = loops.sel(aspect_ratio=ratio)
        ax.plot(
            loop.displacement * _MICRO,
            loop.force,
            color=color,
            linewidth=2.0,
            label=(
                rf"$z_o/x_o$ = {ratio:g}: "
                rf"$\delta^*$ = {float(loop.slip_amplitude) * _MICRO:.1f} µm"
            ),
        )
    stiffness = _scalar(loops, "stiffness")
    load = _scalar(loops, "load")
    mu = _scalar(loops, "mu")
    reach = 1.12 * float(np.abs(loops.force).max())
    ends = np.array([-reach, reach]) / stiffness
    ax.plot(
        ends * _MICRO,
        ends * stiffness,
        color="black",
        linewidth=1.2,
        linestyle="--",
        label=r"$Q = S\Delta$",
    )
    crossings = np.array([-mu * load, mu * load])
    ax.plot(
        crossings / stiffness * _MICRO,
        crossings,
        "o",
        color="crimson",
        markersize=8,
        zorder=5,
        label=rf"common points $Q = \pm\mu P$ = ±{mu * load:g} N (GICoF)",
    )
    _loop_axes(ax, loops)
    ax.set_title(
        "Fig. 6  Loops for several groove aspect ratios\n"
        + _parameters(
            rf"$x_o = \Delta^*$ = {_scalar(loops, 'amplitude') * _MICRO:g} µm",
            f"P = {load:g} N",
            f"S = {stiffness * _MEGA:g} MN/m",
            rf"$\mu$ = {mu:g}",
        ),
        fontsize="medium",
    )
    figure.legend(loc="outside lower center", fontsize="small", ncols=2)
    return figure


# --- Figures 7 and 8: curves against the aspect ratio for several rigs ------------------------


def _stiffness_curves(dataset: xr.Dataset, variable: str, scale: float, number: str) -> Figure:
    """One curve of ``dataset[variable] * scale`` against z_o/x_o per rig stiffness."""
    figure = Figure(figsize=_FIGSIZE, layout="constrained")
    ax = figure.add_subplot()
    load = _scalar(dataset, "load")
    stiffnesses = dataset["stiffness_ratio"].values * load
    for index, color in enumerate(_stiffness_colors(stiffnesses)):
        curve = dataset[variable].isel(stiffness_ratio=index)
        ax.plot(
            dataset["aspect_ratio"],
            curve * scale,
            color=color,
            linewidth=2.0,
            linestyle="--" if np.isinf(stiffnesses[index]) else "-",
            label=_stiffness_label(stiffnesses[index]),
        )
    ax.set_xlabel(_LABELS["aspect_ratio"])
    ax.set_ylabel(_LABELS[variable])
    ax.set_xlim(float(dataset["aspect_ratio"].min()), float(dataset["aspect_ratio"].max()))
    ax.grid(alpha=0.3)
    ax.set_title(
        f"Fig. {number}\n"
        + _parameters(
            rf"$x_o = \Delta^*$ = {_scalar(dataset, 'amplitude') * _MICRO:g} µm",
            f"P = {load:g} N",
            rf"$\mu$ = {_scalar(dataset, 'mu'):g}",
        ),
        fontsize="medium",
    )
    return figure


def _legend_top_down(ax, rigs: int, loc: str) -> None:
    """A legend listing the ``rigs`` curves stiffest first, as they stack, then the rest."""
    handles, labels = ax.get_legend_handles_labels()
    order = [*reversed(range(rigs)), *range(rigs, len(labels))]
    ax.legend([handles[i] for i in order], [labels[i] for i in order], loc=loc, fontsize="small")


def slip_amplitude_curves(dataset: xr.Dataset) -> Figure:
    r"""Figure 7a: slip amplitude :math:`\delta^*` [µm] against :math:`z_o/x_o` for several rigs.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`ecofmaps.maps.compute_map` with a load, a 1-D ``stiffness_ratio`` and
        ``aspect_ratio`` and scalar ``amplitude`` and ``mu``.

    Returns
    -------
    figure : matplotlib.figure.Figure

    Notes
    -----
    Figure 7a of the paper: the rigid rig keeps :math:`\delta^* = \Delta^*`; a compliant
    rig loses more of the stroke to its own deflection as the groove deepens (eq. 16).
    """
    figure = _stiffness_curves(
        dataset, "slip_amplitude", _MICRO, "7a  Slip amplitude against the groove aspect ratio"
    )
    _legend_top_down(figure.axes[0], dataset.sizes["stiffness_ratio"], loc="lower left")
    return figure


def dissipated_energy_curves(dataset: xr.Dataset) -> Figure:
    r"""Figure 7b: dissipated energy per cycle :math:`E_d` [mJ] against :math:`z_o/x_o`.

    Parameters
    ----------
    dataset : xarray.Dataset
        As for :func:`slip_amplitude_curves`; needs ``dissipated_energy`` (a load).

    Returns
    -------
    figure : matplotlib.figure.Figure

    Notes
    -----
    Figure 7b of the paper (eq. 12): a stiffer rig always dissipates more; :math:`E_d`
    rises with :math:`z_o/x_o` for stiff rigs and falls for compliant ones.
    """
    figure = _stiffness_curves(
        dataset,
        "dissipated_energy",
        _MILLI,
        "7b  Dissipated energy against the groove aspect ratio",
    )
    _legend_top_down(figure.axes[0], dataset.sizes["stiffness_ratio"], loc="upper left")
    return figure


def ecof_ratio_curves(dataset: xr.Dataset) -> Figure:
    r"""Figure 8: :math:`\mu_E/\mu` against :math:`z_o/x_o` for several rigs, Example 2 marked.

    Parameters
    ----------
    dataset : xarray.Dataset
        As for :func:`slip_amplitude_curves`, with :math:`S/P` = 35 MN/m / 450 N among
        its ``stiffness_ratio`` values.

    Returns
    -------
    figure : matplotlib.figure.Figure
        The curves, and the paper's Example 2 (:math:`S = 35` MN/m, :math:`z_o/x_o = 0.2`)
        marked with its value read off the Dataset.

    Notes
    -----
    Figure 8 of the paper (eq. 1, 12-16, with the corrected eq. 13-15): Example 2's
    :math:`\mu_E` is about 4 % above :math:`\mu`.
    """
    figure = _stiffness_curves(
        dataset, "ecof_ratio", 1.0, "8  ECoF over the contact CoF against the groove aspect ratio"
    )
    ax = figure.axes[0]
    example = EXAMPLES["Example 2 (Section 3)"]
    value = float(
        dataset["ecof_ratio"]
        .sel(stiffness_ratio=example["stiffness"] / _scalar(dataset, "load"))
        .interp(aspect_ratio=example["aspect_ratio"])
    )
    ax.plot(
        example["aspect_ratio"],
        value,
        "o",
        color="crimson",
        markersize=9,
        zorder=5,
        label=(
            rf"Example 2 ($S$ = {example['stiffness'] * _MEGA:g} MN/m, "
            rf"$z_o/x_o$ = {example['aspect_ratio']:g}): $\mu_E/\mu$ = {value:.3f} "
            rf"(+{(value - 1) * 100:.1f} %)"
        ),
    )
    _legend_top_down(ax, dataset.sizes["stiffness_ratio"], loc="upper left")
    return figure


# --- Figure 11 and the universal map: contours of μ_E/μ -------------------------------------


def _ecof_ratio_contours(ax, x, ratio: xr.DataArray, regime: xr.DataArray) -> list:
    """Filled and labelled contours of μ_E/μ over (x, z_o/x_o), no-gross-slip area hatched.

    ``ratio`` and ``regime`` have the dims (x dimension, aspect_ratio); ``x`` holds the
    x values. Returns the legend handles of what was drawn besides the contours.
    """
    y = ratio["aspect_ratio"].values
    values = ratio.transpose(..., "aspect_ratio").values.T
    top = np.nanmax(values)
    levels = [level for level in ECOF_RATIO_LEVELS if level <= top]
    above = [level for level in ECOF_RATIO_LEVELS if level > top]
    fill_levels = [1.0, *levels, above[0] if above else top]
    # One colour per band of ECOF_RATIO_LEVELS, whatever the figure's range, so the same
    # μ_E/μ has the same colour in Figures 11a, 11b and the universal map.
    cmap = colormaps["YlOrRd"]
    norm = BoundaryNorm([1.0, *ECOF_RATIO_LEVELS], cmap.N, clip=True)
    filled = ax.contourf(x, y, values, levels=fill_levels, cmap=cmap, norm=norm, alpha=0.85)
    widths = [2.4 if level == _HIGHLIGHT_LEVEL else 0.9 for level in levels]
    lines = ax.contour(x, y, values, levels=levels, colors="black", linewidths=widths)
    ax.clabel(lines, fmt="%.2f", fontsize="small", inline_spacing=3)
    colorbar = ax.figure.colorbar(filled, ax=ax, ticks=fill_levels, format="%.2f")
    colorbar.set_label(r"$\mu_E/\mu$ [1]")
    ax.set_ylabel(_LABELS["aspect_ratio"])
    handles = [
        Line2D([], [], color="black", linewidth=2.4, label=r"$\mu_E/\mu$ = 1.05 (5 % above $\mu$)")
    ]
    stuck = (regime == NO_GROSS_SLIP).transpose(..., "aspect_ratio").values.T.astype(float)
    if stuck.any():
        ax.contourf(x, y, stuck, levels=[0.5, 1.5], colors="none", hatches=["//"])
        ax.contour(x, y, stuck, levels=[0.5], colors="0.3", linewidths=1.0)
        handles.append(
            Patch(
                facecolor="none",
                edgecolor="0.3",
                hatch="//",
                label=r"no gross slip ($\mu P/S \geq \Delta^*$)",
            )
        )
    return handles


def ecof_ratio_contours(dataset: xr.Dataset) -> Figure:
    r"""Figure 11: labelled contours of :math:`\mu_E/\mu` over :math:`S/P` and :math:`z_o/x_o`.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`ecofmaps.maps.compute_map` with 1-D ``stiffness_ratio`` and
        ``aspect_ratio`` and scalar ``amplitude`` and ``mu``.

    Returns
    -------
    figure : matplotlib.figure.Figure
        Filled contours with labelled lines at :data:`ECOF_RATIO_LEVELS` (the 5 % line
        heavier), :math:`S/P` in (MN/m)/kN (= 1/mm); the area with no gross slip hatched;
        the paper's Example 2 marked when :math:`\Delta^*` = 50 µm.

    Notes
    -----
    Figure 11 of the paper (a: :math:`\Delta^*` = 25 µm, b: 50 µm, :math:`\mu = 0.8`).
    :math:`\mu_E/\mu` depends on :math:`S/P` and :math:`\Delta^*` only through
    :math:`\lambda = P/(S\Delta^*)` (eq. 16), so the two panels are one surface read on two
    scales of :math:`S/P`: see :func:`universal_ecof_ratio_map`.
    """
    figure = Figure(figsize=_FIGSIZE, layout="constrained")
    ax = figure.add_subplot()
    amplitude = _scalar(dataset, "amplitude")
    x = dataset["stiffness_ratio"].values * _PER_MM
    handles = _ecof_ratio_contours(ax, x, dataset["ecof_ratio"], dataset["regime"])
    ax.set_xlabel(_LABELS["stiffness_ratio"])
    if np.isclose(amplitude, AMPLITUDE):
        example = EXAMPLES["Example 2 (Section 3)"]
        handles += ax.plot(
            example["stiffness"] / LOAD * _PER_MM,
            example["aspect_ratio"],
            "o",
            color="navy",
            markersize=8,
            markeredgecolor="white",
            label=r"Example 2 ($S$ = 35 MN/m, $P$ = 450 N)",
        )
    ax.legend(handles=handles, loc="lower right", fontsize="small", framealpha=0.9)
    panel = (
        "11a" if np.isclose(amplitude, 25e-6) else "11b" if np.isclose(amplitude, 50e-6) else "11"
    )
    ax.set_title(
        rf"Fig. {panel}  $\mu_E/\mu$ over rig stiffness and groove shape"
        + "\n"
        + _parameters(
            rf"$x_o = \Delta^*$ = {amplitude * _MICRO:g} µm", rf"$\mu$ = {_scalar(dataset, 'mu'):g}"
        ),
        fontsize="medium",
    )
    return figure


def universal_ecof_ratio_map(dataset: xr.Dataset) -> Figure:
    r"""The universal map: :math:`\mu_E/\mu` over :math:`\lambda = P/(S\Delta^*)` and z_o/x_o.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`ecofmaps.maps.compute_universal_map` with 1-D ``compliance_ratio``
        (positive: the axis is logarithmic) and ``aspect_ratio`` and a scalar ``mu``.

    Returns
    -------
    figure : matplotlib.figure.Figure
        Labelled contours at :data:`ECOF_RATIO_LEVELS` on a logarithmic :math:`\lambda`
        axis, the spans of :math:`\lambda` that Figures 11a and 11b cover, and the paper's
        Examples 1 and 2 marked, each with its own :math:`\mu_E/\mu` (at its own :math:`\mu`).

    Notes
    -----
    With :math:`x_o = \Delta^*` the slip ratio (eq. 16) and :math:`\mu_E/\mu` (eq. 15,
    corrected) depend on :math:`\mu`, :math:`z_o/x_o` and :math:`\lambda` only, so every
    pair (:math:`\Delta^*`, :math:`S/P`) with the same :math:`\lambda` gives the same
    :math:`\mu_E/\mu`: this one chart holds both panels of Figure 11, which on the
    logarithmic axis are the same window shifted by a factor 2. Not in the paper.
    """
    figure = Figure(figsize=(6.8, 5.6), layout="constrained")
    ax = figure.add_subplot()
    mu = _scalar(dataset, "mu")
    x = dataset["compliance_ratio"].values
    handles = _ecof_ratio_contours(ax, x, dataset["ecof_ratio"], dataset["regime"])
    ax.set_xscale("log")
    ticks = [tick for tick in (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0) if x[0] <= tick <= x[-1]]
    ax.set_xticks(ticks, [f"{tick:g}" for tick in ticks])
    ax.set_xticks([], minor=True)
    ax.set_xlabel(_LABELS["compliance_ratio"] + r"   ($\lambda \to 0$: rigid rig)")
    # The spans of λ that Figure 11's S/P axis covers at its two amplitudes.
    windows = ((0.022, "11a", 25e-6), (0.008, "11b", 50e-6))
    for height, panel, amplitude in windows:
        span = compliance_ratio(amplitude, 1.0, STIFFNESS_RATIOS[[-1, 0]])
        ax.annotate(
            "",
            (float(span[0]), height),
            (float(span[1]), height),
            arrowprops=dict(arrowstyle="|-|", color="0.25", shrinkA=0, shrinkB=0),
        )
        ax.text(
            0.92 * float(span[0]),
            height,
            rf"Fig. {panel} ($\Delta^*$ = {amplitude * _MICRO:g} µm)",
            ha="right",
            va="center",
            fontsize="x-small",
            color="0.15",
        )
    short = {"Example 1": "Ex. 1", "Example 2": "Ex. 2", "Example 2 (Section 3)": "Ex. 2 (§3)"}
    for (name, example), marker in zip(EXAMPLES.items(), ("s", "o", "D"), strict=True):
        lam = float(compliance_ratio(AMPLITUDE, LOAD, example["stiffness"]))
        value = float(energy_cof(AMPLITUDE, LOAD, **example) / example["mu"])
        handles += ax.plot(
            lam,
            example["aspect_ratio"],
            marker,
            color="navy",
            markersize=8,
            markeredgecolor="white",
            zorder=5,
            label=(
                rf"{name}: $S$ = {example['stiffness'] * _MEGA:g} MN/m, "
                rf"$z_o/x_o$ = {example['aspect_ratio']:.3g}, "
                rf"$\mu$ = {example['mu']:g}: $\mu_E/\mu$ = {value:.3f}"
            ),
        )
        ax.annotate(
            short[name],
            (lam, example["aspect_ratio"]),
            xytext=(7, -3),
            textcoords="offset points",
            fontsize="x-small",
            color="navy",
        )
    figure.legend(handles=handles, loc="outside lower center", fontsize="x-small", ncols=1)
    ax.set_title(
        rf"Universal map of $\mu_E/\mu$ ($x_o = \Delta^*$, $\mu$ = {mu:g}, $P$ = {LOAD:g} N)"
        + "\n"
        + r"Any $\Delta^*$ and $S/P$ with the same $\lambda = P/(S\Delta^*)$ give the same "
        + r"$\mu_E/\mu$:"
        + "\n"
        + r"Fig. 11a ($\Delta^*$ = 25 µm) and 11b (50 µm) are two windows of this one chart",
        fontsize="medium",
    )
    return figure


# --- Figure 9 and measured loops: results of ecofmaps.analyze_loops -------------------------


def _evenly_spread(labels, count: int) -> list:
    """Up to ``count`` of ``labels`` spread evenly, the first and the last included."""
    picks = np.unique(np.linspace(0, len(labels) - 1, min(count, len(labels))).round().astype(int))
    return [labels[i] for i in picks]


def measured_loops(results: xr.Dataset, cycles=None, columns: int = 3) -> Figure:
    r"""Measured loops, each with the line :math:`Q = S\Delta` and its two GICoF crossings.

    Parameters
    ----------
    results : xarray.Dataset
        From :func:`ecofmaps.analyze_loops` with ``keep_loops=True``.
    cycles : sequence of int, optional
        Cycle numbers to draw, one panel each; by default six spread evenly over the
        recording, the first and the last included.
    columns : int
        Panels per row.

    Returns
    -------
    figure : matplotlib.figure.Figure
        One panel per cycle: the centred loop, :math:`Q` [N] against :math:`\Delta` [µm],
        the line :math:`Q = S\Delta` with the cycle's stiffness, and the crossings whose
        :math:`Q/P` is the GICoF.

    Notes
    -----
    The paper's Section 5 and Figure 6 (eq. 17-18): where the loop meets
    :math:`Q = S\Delta` the contact is at the bottom of the groove, and :math:`Q/P = \mu`.
    """
    if "loop_displacement" not in results:
        raise ValueError("results hold no loops: call analyze_loops(..., keep_loops=True)")
    labels = list(results["cycle"].values)
    chosen = _evenly_spread(labels, 6) if cycles is None else list(cycles)
    rows = -(-len(chosen) // columns)
    width = min(columns, len(chosen))
    figure = Figure(figsize=(3.6 * width + 0.6, 3.1 * rows + 0.9), layout="constrained")
    axes = figure.subplots(rows, width, squeeze=False, sharex=True, sharey=True)
    load = _scalar(results, "load")
    for ax, label in zip(axes.flat, chosen, strict=False):
        cycle = results.sel(cycle=label)
        x = cycle["loop_displacement"].values * _MICRO
        q = cycle["loop_force"].values
        ax.plot(x, q, color="tab:blue", linewidth=1.2, label="measured loop")
        stiffness = float(cycle["stiffness"])
        # The line across the loop's height, within its width. [µm]
        reach = np.nanmax(np.abs(q)) / stiffness * _MICRO
        ends = np.array([max(np.nanmin(x), -reach), min(np.nanmax(x), reach)])
        ax.plot(
            ends,
            stiffness * ends / _MICRO,
            color="0.35",
            linestyle="--",
            linewidth=1.0,
            label=r"$Q = S\Delta$",
        )
        crossings = np.array(
            [
                float(cycle["crossing_displacement_forward"]),
                float(cycle["crossing_displacement_backward"]),
            ]
        )
        ratios = np.array([float(cycle["gicof_forward"]), -float(cycle["gicof_backward"])])
        ax.plot(
            crossings * _MICRO,
            ratios * load,
            linestyle="none",
            marker="o",
            markersize=6,
            markerfacecolor="tab:red",
            markeredgecolor="black",
            label="GICoF crossings",
        )
        ax.axhline(0.0, color="0.7", linewidth=0.6)
        ax.axvline(0.0, color="0.7", linewidth=0.6)
        ax.grid(alpha=0.3)
        reading = (
            f"GICoF {float(cycle['gicof']):.3f}, ECoF {float(cycle['ecof']):.3f}"
            if cycle["regime"] == "gross slip"
            else "no GICoF or ECoF"
        )
        ax.set_title(
            f"cycle {label}: {reading}\n"
            f"S = {stiffness * _MEGA:.1f} MN/m, {cycle['regime'].values!s}",
            fontsize="small",
        )
    for ax in axes.flat[len(chosen) :]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel(_LABELS["displacement"])
    for ax in axes[:, 0]:
        ax.set_ylabel(_LABELS["force"])
    axes.flat[0].legend(loc="upper left", fontsize="x-small")
    figure.suptitle(
        rf"Measured loops and the line $Q = S\Delta$ (P = {load:g} N): "
        "the GICoF is Q/P at the crossings",
        fontsize="medium",
    )
    return figure


def cof_evolution(results: xr.Dataset) -> Figure:
    r"""Figure 9: the ECoF and the GICoF over the cycles of a test.

    Parameters
    ----------
    results : xarray.Dataset
        From :func:`ecofmaps.analyze_loops`.

    Returns
    -------
    figure : matplotlib.figure.Figure
        Top: :math:`\mu_E` (eq. 1) and the GICoF against the cycle number.
        Bottom: how far the ECoF is above the GICoF, :math:`\mu_E/\text{GICoF} - 1` [%].

    Notes
    -----
    The paper's Figure 9: with a flat scar the two coefficients agree; as the scar deepens
    into a groove the ECoF rises above the GICoF, which stays at the contact :math:`\mu`.
    Cycles in partial slip have neither and leave gaps.
    """
    figure = Figure(figsize=(7.0, 5.6), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.3]})
    cycle = results["cycle"].values
    marker = dict(marker="o", markersize=2.5) if cycle.size <= 400 else {}
    top.plot(
        cycle,
        results["ecof"],
        color="tab:orange",
        linewidth=1.3,
        label=r"ECoF $\mu_E = E_d/(4P\delta^*)$",
        **marker,
    )
    top.plot(
        cycle,
        results["gicof"],
        color="tab:blue",
        linewidth=1.3,
        label=r"GICoF ($Q/P$ on $Q = S\Delta$)",
        **marker,
    )
    top.set_ylabel("Coefficient of friction [1]")
    top.grid(alpha=0.3)
    top.legend(loc="best", fontsize="small")
    excess = (results["ecof"] / results["gicof"] - 1.0) * 100.0
    bottom.plot(cycle, excess, color="tab:purple", linewidth=1.2, **marker)
    bottom.axhline(0.0, color="0.5", linewidth=0.8)
    bottom.set_ylabel("ECoF / GICoF − 1 [%]")
    bottom.set_xlabel("Cycle")
    bottom.grid(alpha=0.3)
    amplitude = float(results["amplitude"].median()) * _MICRO
    figure.suptitle(
        "Fig. 9  Evolution of the ECoF and the GICoF\n"
        + _parameters(f"P = {_scalar(results, 'load'):g} N", rf"$\Delta^*$ ≈ {amplitude:.1f} µm"),
        fontsize="medium",
    )
    return figure


# --- Figure 10: measured loops and the fitted model ----------------------------------------


def measured_and_fitted_loops(fits) -> Figure:
    r"""Figure 10: measured fretting loops overlaid with the model fitted to them.

    Parameters
    ----------
    fits : LoopFit or mapping of str to LoopFit
        From :func:`ecofmaps.fit_loop`. A mapping draws one panel per entry, titled by
        its key, side by side (the paper's Figure 10 has Example 1 and Example 2).

    Returns
    -------
    figure : matplotlib.figure.Figure
        In each panel the measured samples (dots) and the fitted model loop (line), Q [N]
        (left) and Q/P (right) against Δ [µm]; the title gives the fitted μ, S [MN/m],
        z_o [µm] and the RMS force residual [N].

    Notes
    -----
    Figure 10 of the paper overlays the final measured loops of its two tests and the
    model with :math:`x_o = \Delta^* = 50` µm, :math:`\mu` = GICoF = 0.825, S = 45 and
    35 MN/m, :math:`z_o` = 1.8 and 8.0 µm (Section 4.2); here the model's parameters are
    the least-squares fit.
    """
    panels = dict(fits) if isinstance(fits, Mapping) else {"": fits}
    figure = Figure(figsize=(5.6 * len(panels), 5.2), layout="constrained")
    axes = figure.subplots(1, len(panels), squeeze=False)[0]
    for index, (ax, (name, fit)) in enumerate(zip(axes, panels.items(), strict=True)):
        displacement, force = fit.model_loop()
        ax.plot(fit.displacement * _MICRO, fit.force, "o", color="0.15", markersize=2.5,
                alpha=0.7, zorder=3, label="measured")  # fmt: skip
        ax.plot(
            displacement * _MICRO,
            force,
            color="crimson",
            linewidth=1.8,
            label="fitted model",
        )
        ax.axhline(fit.force_offset, color="0.6", linewidth=0.6)
        ax.axvline(fit.displacement_offset * _MICRO, color="0.6", linewidth=0.6)
        ax.set_xlabel(_LABELS["displacement"])
        ax.set_ylabel(_LABELS["force"])
        ax.grid(alpha=0.3)
        _force_ratio_axis(ax, fit.load)
        panel = f"({chr(ord('a') + index)}) " if len(panels) > 1 else ""
        panel += f"{name}: " if name else ""
        ax.set_title(
            f"{panel}P = {fit.load:g} N, "
            rf"$x_o = \Delta^*$ = {fit.amplitude * _MICRO:.1f} µm"
            "\n"
            + _parameters(
                rf"fit: $\mu$ = {fit.mu:.3f}",
                f"S = {fit.stiffness * _MEGA:.1f} MN/m",
                rf"$z_o$ = {fit.groove_depth * _MICRO:.2f} µm",
                f"RMS residual {fit.rms_residual:.2g} N",
            ),
            fontsize="medium",
        )
        ax.legend(loc="best", fontsize="small")
    figure.suptitle("Fig. 10  Measured fretting loops and the fitted model", fontsize="medium")
    return figure


# --- the registry --------------------------------------------------------------------------


@dataclass(frozen=True)
class FigureRecipe:
    """How to make one figure: its Dataset (paper's parameters) and its drawing function.

    Attributes
    ----------
    name : str
        File stem, e.g. ``'fig7a'``.
    description : str
        One line saying what the figure shows.
    data : callable
        ``data() -> xarray.Dataset``, built through the cached map functions. Recipes that
        share a ``data`` function share its Dataset (see :func:`make_figures`).
    draw : callable
        ``draw(dataset) -> matplotlib.figure.Figure``.
    selection : dict
        Coordinate values picked from the Dataset with ``.sel`` before drawing.
    """

    name: str
    description: str
    data: Callable[[], xr.Dataset]
    draw: Callable[[xr.Dataset], Figure]
    selection: dict = field(default_factory=dict)

    def dataset(self) -> xr.Dataset:
        """The Dataset this figure draws."""
        return self.data().sel(self.selection)


def _loops() -> xr.Dataset:
    """The loops of Figures 5 and 6: rigid and 35 MN/m rigs, z_o/x_o = 0, 0.1, 0.2, 0.3."""
    return compute_loops(
        stiffness=np.array([np.inf, STIFFNESS]),
        aspect_ratio=np.array([0.0, 0.1, 0.2, 0.3]),
        amplitude=AMPLITUDE,
        load=LOAD,
        mu=MU,
    )


#: Rig stiffnesses of Figures 7 and 8 [N/m], rigid included.
STIFFNESSES = (20e6, 35e6, 50e6, 100e6, np.inf)
#: Groove aspect ratios z_o/x_o of Figures 7, 8, 11 and the universal map.
ASPECT_RATIOS = np.linspace(0.0, 0.3, 61)
#: S/P of Figure 11: 20 to 200 (MN/m)/kN [1/m].
STIFFNESS_RATIOS = np.linspace(20e3, 200e3, 91)
#: λ of the universal map, on a logarithmic scale: near-rigid rigs to well past the end of
#: gross slip at μλ = 1, covering Figure 11 at both amplitudes.
COMPLIANCE_RATIOS = np.geomspace(0.01, 2.0, 161)


def _stiffness_curves_data() -> xr.Dataset:
    return compute_map(
        stiffness_ratio=np.array(STIFFNESSES) / LOAD,
        aspect_ratio=ASPECT_RATIOS,
        amplitude=AMPLITUDE,
        mu=MU,
        load=LOAD,
    )


def _ecof_ratio_map_25um() -> xr.Dataset:
    return compute_map(STIFFNESS_RATIOS, ASPECT_RATIOS, 25e-6, MU)


def _ecof_ratio_map_50um() -> xr.Dataset:
    return compute_map(STIFFNESS_RATIOS, ASPECT_RATIOS, 50e-6, MU)


def _universal_map() -> xr.Dataset:
    return compute_universal_map(COMPLIANCE_RATIOS, ASPECT_RATIOS, MU)


FIGURES: dict[str, FigureRecipe] = {
    recipe.name: recipe
    for recipe in (
        FigureRecipe(
            "fig5",
            "loop of a rigid rig against S = 35 MN/m, z_o/x_o = 0.2",
            _loops,
            rigid_and_compliant_loops,
            {"aspect_ratio": 0.2},
        ),
        FigureRecipe(
            "fig6",
            "loops for z_o/x_o = 0, 0.1, 0.2, 0.3 at S = 35 MN/m, with Q = SΔ",
            _loops,
            loops_by_aspect_ratio,
            {"stiffness": STIFFNESS},
        ),
        FigureRecipe(
            "fig7a",
            "slip amplitude against z_o/x_o for S = 20, 35, 50, 100 MN/m and rigid",
            _stiffness_curves_data,
            slip_amplitude_curves,
        ),
        FigureRecipe(
            "fig7b",
            "dissipated energy against z_o/x_o for S = 20, 35, 50, 100 MN/m and rigid",
            _stiffness_curves_data,
            dissipated_energy_curves,
        ),
        FigureRecipe(
            "fig8",
            "μ_E/μ against z_o/x_o for S = 20, 35, 50, 100 MN/m and rigid, Example 2 marked",
            _stiffness_curves_data,
            ecof_ratio_curves,
        ),
        FigureRecipe(
            "fig11a",
            "contours of μ_E/μ over S/P and z_o/x_o at Δ* = 25 µm",
            _ecof_ratio_map_25um,
            ecof_ratio_contours,
        ),
        FigureRecipe(
            "fig11b",
            "contours of μ_E/μ over S/P and z_o/x_o at Δ* = 50 µm",
            _ecof_ratio_map_50um,
            ecof_ratio_contours,
        ),
        FigureRecipe(
            "universal",
            "μ_E/μ over λ = P/(SΔ*) and z_o/x_o: Fig. 11a and 11b in one chart",
            _universal_map,
            universal_ecof_ratio_map,
        ),
    )
}


def _recipe(name: str) -> FigureRecipe:
    if name not in FIGURES:
        raise ValueError(f"unknown figure {name!r}; valid names: {', '.join(FIGURES)}")
    return FIGURES[name]


def make_figure(name: str) -> Figure:
    """Build the Dataset of figure ``name`` (from the cache when there) and draw it.

    Parameters
    ----------
    name : str
        A key of :data:`FIGURES`.

    Returns
    -------
    figure : matplotlib.figure.Figure

    Raises
    ------
    ValueError
        If ``name`` is not a key of :data:`FIGURES`.
    """
    recipe = _recipe(name)
    return recipe.draw(recipe.dataset())


def make_figures(names=None) -> Iterator[tuple[str, Figure]]:
    """Draw several figures, building each Dataset only once.

    Parameters
    ----------
    names : iterable of str, optional
        Keys of :data:`FIGURES`; default all of them, in order.

    Yields
    ------
    name : str
    figure : matplotlib.figure.Figure
        Drawn lazily, so a caller can time each one.

    Raises
    ------
    ValueError
        If a name is not a key of :data:`FIGURES` (before anything is computed).
    """
    recipes = [_recipe(name) for name in (FIGURES if names is None else names)]
    datasets: dict = {}
    for recipe in recipes:
        if recipe.data not in datasets:
            datasets[recipe.data] = recipe.data()
        yield recipe.name, recipe.draw(datasets[recipe.data].sel(recipe.selection))


# No time stamps in the files, so regenerating an unchanged figure gives the same bytes.
_METADATA = {"pdf": {"CreationDate": None}, "svg": {"Date": None}}


def save_figure(figure: Figure, path, dpi: int = 150) -> Path:
    """Write ``figure`` to ``path`` atomically; the format follows the file's suffix.

    The figure is written to a temporary file in the same directory and renamed over
    ``path``, so an existing file is never left half written.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
    path : str or os.PathLike
        Destination, ending in ``.png``, ``.pdf`` or ``.svg``. Its directory must exist.
    dpi : int
        Resolution of raster output. [1/inch]

    Returns
    -------
    path : pathlib.Path
    """
    path = Path(path)
    file_format = path.suffix.lstrip(".").lower()
    with atomic_path(path) as temporary:
        figure.savefig(temporary, format=file_format, dpi=dpi, metadata=_METADATA.get(file_format))
    return path
