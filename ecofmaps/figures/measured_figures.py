r"""Figures of measured loops: the loops with :math:`Q = S\Delta`, Figure 9 and Figure 10.

Each function takes the results of :func:`ecofmaps.analyze_loops` or
:func:`ecofmaps.fit_loop` and returns a :class:`matplotlib.figure.Figure`.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure

from ecofmaps.figures.style import (
    MICRO,
    axis_label,
    force_ratio_axis,
    parameters,
    scalar,
    stiffness_label,
)
from ecofmaps.model.regimes import GROSS_SLIP, Regime

__all__ = ["cof_evolution", "measured_and_fitted_loops", "measured_loops", "resolved_loops"]


def _evenly_spread(labels, count: int) -> list:
    """Up to ``count`` of ``labels`` spread evenly, the first and the last included."""
    picks = np.unique(np.linspace(0, len(labels) - 1, min(count, len(labels))).round().astype(int))
    return [labels[i] for i in picks]


def measured_loops(
    results: xr.Dataset, cycles=None, columns: int = 3, resolved: xr.Dataset | None = None
) -> Figure:
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
    resolved : xarray.Dataset, optional
        From :func:`ecofmaps.resolve_analyzed_loops` of the same ``results``: the part of
        the stroke it read is shaded.

    Returns
    -------
    figure : matplotlib.figure.Figure
        One panel per cycle: the centred loop, :math:`Q` [N] against :math:`\Delta` [µm],
        the line :math:`Q = S\Delta` with the cycle's stiffness, the crossings whose
        :math:`Q/P` is the GICoF, and, with ``resolved``, the band of contact positions
        :math:`\xi_{min} \le \Delta - Q/S \le \xi_{max}` where both branches were read.
        The title gives the cycle's GICoF and ECoF (a dash where they are NaN) and its
        ``quality`` when not ``'ok'``.

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
    load = scalar(results, "load")
    for ax, label in zip(axes.flat, chosen, strict=False):
        cycle = results.sel(cycle=label)
        x = cycle["loop_displacement"].values * MICRO
        q = cycle["loop_force"].values
        ax.plot(x, q, color="tab:blue", linewidth=1.2, label="measured loop")
        stiffness = float(cycle["stiffness"])
        if np.isfinite(stiffness) and stiffness > 0:
            # The line across the loop's height, within its width. [µm]
            reach = np.nanmax(np.abs(q)) / stiffness * MICRO
            ends = np.array([max(np.nanmin(x), -reach), min(np.nanmax(x), reach)])
            ax.plot(
                ends,
                stiffness * ends / MICRO,
                color="0.35",
                linestyle="--",
                linewidth=1.0,
                label=r"$Q = S\Delta$",
            )
        if resolved is not None:
            _resolved_band(ax, resolved.sel(cycle=label), q)
        crossings = np.array(
            [
                float(cycle["crossing_displacement_forward"]),
                float(cycle["crossing_displacement_backward"]),
            ]
        )
        ratios = np.array([float(cycle["gicof_forward"]), -float(cycle["gicof_backward"])])
        ax.plot(
            crossings * MICRO,
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
            f"GICoF {_number(cycle['gicof'])}, ECoF {_number(cycle['ecof'])}"
            if int(cycle["regime"]) == GROSS_SLIP
            else "no GICoF or ECoF"
        )
        quality = str(cycle["quality"].values) if "quality" in cycle else "ok"
        state = Regime(int(cycle["regime"])).label + ("" if quality == "ok" else f"; {quality}")
        ax.set_title(
            f"cycle {label}: {reading}\n{stiffness_label(stiffness)}, {state}",
            fontsize="small",
        )
    for ax in axes.flat[len(chosen) :]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel(axis_label("displacement"))
    for ax in axes[:, 0]:
        ax.set_ylabel(axis_label("force"))
    axes.flat[0].legend(loc="upper left", fontsize="x-small")
    figure.suptitle(
        # Two lines: the figure of a single cycle is only one panel wide.
        rf"Measured loops and the line $Q = S\Delta$ (P = {load:g} N):"
        "\nthe GICoF is Q/P at the crossings",
        fontsize="medium",
    )
    return figure


def _number(value, form: str = ".3f") -> str:
    """``value`` formatted, or a dash where it is NaN."""
    value = float(value)
    return format(value, form) if np.isfinite(value) else "–"


def _resolved_band(ax, cycle: xr.Dataset, q) -> None:
    """Shade the contact positions ξ_min <= Δ - Q/S <= ξ_max that were read along the stroke."""
    low, high = float(cycle["position_min"]), float(cycle["position_max"])
    if not (np.isfinite(low) and np.isfinite(high)):
        return
    force = np.linspace(np.nanmin(q), np.nanmax(q), 2)
    compliance = 1.0 / float(cycle["stiffness"])
    ax.fill_betweenx(
        force,
        (low + compliance * force) * MICRO,
        (high + compliance * force) * MICRO,
        color="tab:green",
        alpha=0.12,
        linewidth=0,
        label="read along the stroke",
    )


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
    amplitude = float(results["amplitude"].median()) * MICRO
    figure.suptitle(
        "Fig. 9  Evolution of the ECoF and the GICoF\n"
        + parameters(f"P = {scalar(results, 'load'):g} N", rf"$\Delta^*$ ≈ {amplitude:.1f} µm"),
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
        ax.plot(fit.displacement * MICRO, fit.force, "o", color="0.15", markersize=2.5,
                alpha=0.7, zorder=3, label="measured")  # fmt: skip
        ax.plot(
            displacement * MICRO,
            force,
            color="crimson",
            linewidth=1.8,
            label="fitted model",
        )
        ax.axhline(fit.force_offset, color="0.6", linewidth=0.6)
        ax.axvline(fit.displacement_offset * MICRO, color="0.6", linewidth=0.6)
        ax.set_xlabel(axis_label("displacement"))
        ax.set_ylabel(axis_label("force"))
        ax.grid(alpha=0.3)
        force_ratio_axis(ax, fit.load)
        panel = f"({chr(ord('a') + index)}) " if len(panels) > 1 else ""
        panel += f"{name}: " if name else ""
        ax.set_title(
            f"{panel}P = {fit.load:g} N, "
            rf"$x_o = \Delta^*$ = {fit.amplitude * MICRO:.1f} µm"
            "\n"
            + parameters(
                rf"fit: $\mu$ = {fit.mu:.3f}",
                stiffness_label(fit.stiffness),
                rf"$z_o$ = {fit.groove_depth * MICRO:.2f} µm",
                f"RMS residual {fit.rms_residual:.2g} N",
            ),
            fontsize="medium",
        )
        ax.legend(loc="best", fontsize="small")
    figure.suptitle("Fig. 10  Measured fretting loops and the fitted model", fontsize="medium")
    return figure


# --- the loops read along the stroke: ecofmaps.resolve_loops --------------------------------


def resolved_loops(resolved: xr.Dataset, results: xr.Dataset | None = None, cycles=None) -> Figure:
    r"""Friction and felt groove read along the stroke, cycle by cycle, and over the test.

    Parameters
    ----------
    resolved : xarray.Dataset
        From :func:`ecofmaps.resolve_loops` (with its ``position`` dimension).
    results : xarray.Dataset, optional
        From :func:`ecofmaps.analyze_loops` for the same recording: its ECoF and GICoF are
        drawn beside the resolved :math:`\mu` for comparison.
    cycles : sequence of int, optional
        Cycle numbers drawn along the stroke; by default up to five cycles whose quality is
        ``'ok'``, spread evenly over the test, the first and the last included.

    Returns
    -------
    figure : matplotlib.figure.Figure
        (a) :math:`\mu(\xi)` against the contact position :math:`\xi` [µm], each cycle's
        ``mu_resolved`` dashed and the central part it averages shaded; (b) the felt
        profile :math:`h(\xi)` [µm] with each cycle's equivalent parabola
        :math:`k\xi^2/2` dotted; (c) :math:`h` over (position, cycle), the groove deepening
        as the test runs; (d) ``mu_resolved`` :math:`\pm 2` standard errors over the cycles
        (with the ECoF and GICoF when ``results`` is given) and the equivalent
        ``aspect_ratio`` on a right-hand axis; cycles with no resolved value are marked
        along the bottom with their quality.

    Notes
    -----
    :math:`\mu(\xi) = \tan((\arctan q_+ - \arctan q_-)/2)` and
    :math:`g(\xi) = \tan((\arctan q_+ + \arctan q_-)/2)` with :math:`q_\pm = Q_\pm/P` on the
    two slip branches at the same :math:`\xi = \Delta - Q/S` (eq. 9, 10); the GICoF
    (eq. 17-18) is :math:`\mu(0)`.
    """
    if "position" not in resolved.dims:
        raise ValueError("resolved holds no positions: call resolve_loops(..., positions=201)")
    labels = list(resolved["cycle"].values)
    ok = [label for label, quality in zip(labels, resolved["quality"].values, strict=True)
          if quality == "ok"]  # fmt: skip
    chosen = _evenly_spread(ok, 5) if cycles is None else list(cycles)
    figure = Figure(figsize=(11.0, 8.2), layout="constrained")
    (stroke, felt), (image, test) = figure.subplots(2, 2)
    xi = resolved["position"].values * MICRO
    colors = colormaps["viridis"](np.linspace(0.0, 0.85, max(len(chosen), 1)))
    central = float(resolved.attrs.get("central", np.nan))
    for label, color in zip(chosen, colors, strict=False):
        cycle = resolved.sel(cycle=label)
        mu = float(cycle["mu_resolved"])
        stroke.plot(xi, cycle["mu"], color=color, linewidth=1.2, label=f"cycle {label}")
        stroke.axhline(mu, color=color, linestyle="--", linewidth=0.9)
        felt.plot(
            xi, cycle["felt_profile"] * MICRO, color=color, linewidth=1.4, label=f"cycle {label}"
        )
        k = 2.0 * float(cycle["aspect_ratio"]) / float(cycle["amplitude"])  # z_o/x_o = kΔ*/2
        parabola = 0.5 * k * (xi / MICRO) ** 2 * MICRO
        felt.plot(xi, parabola, color=color, linestyle=":", linewidth=1.0)
    if chosen and np.isfinite(central):
        reach = central * min(
            -float(resolved.sel(cycle=chosen)["position_min"].max()),
            float(resolved.sel(cycle=chosen)["position_max"].min()),
        )
        stroke.axvspan(-reach * MICRO, reach * MICRO, color="0.9", zorder=0,
                       label="central part averaged")  # fmt: skip
    stroke.set_xlabel(axis_label("position"))
    stroke.set_ylabel(r"Coefficient of friction $\mu(\xi)$ [1]")
    stroke.set_title(r"(a) $\mu$ along the stroke (dashed: its average)", fontsize="medium")
    if chosen:
        stroke.legend(loc="lower center", fontsize="x-small", ncols=2)
    else:
        stroke.text(0.5, 0.5, "no cycle was read along the stroke\n(none has quality 'ok')",
                    transform=stroke.transAxes, ha="center", va="center", color="0.3")  # fmt: skip
    felt.plot([], [], color="0.4", linestyle=":", label=r"equivalent parabola $k\xi^2/2$")
    felt.set_xlabel(axis_label("position"))
    felt.set_ylabel(r"Felt groove profile $h(\xi)$ [µm]")
    felt.set_title("(b) the scar as the contact feels it", fontsize="medium")
    felt.legend(loc="upper center", fontsize="x-small", ncols=2)
    for ax in (stroke, felt, test):
        ax.grid(alpha=0.3)
    profile = resolved["felt_profile"].transpose("cycle", "position").values * MICRO
    mesh = image.pcolormesh(xi, np.arange(len(labels)), profile, shading="nearest",
                            cmap="cividis")  # fmt: skip
    ticks = np.unique(np.linspace(0, len(labels) - 1, min(len(labels), 6)).round().astype(int))
    image.set_yticks(ticks, [str(labels[i]) for i in ticks])
    image.set_xlabel(axis_label("position"))
    image.set_ylabel("Cycle")
    image.set_title("(c) felt profile over the test", fontsize="medium")
    figure.colorbar(mesh, ax=image, label=r"$h(\xi)$ [µm]")
    number = resolved["cycle"].values
    mu = resolved["mu_resolved"].values
    error = 2.0 * resolved["mu_resolved_se"].values
    test.fill_between(number, mu - error, mu + error, color="tab:green", alpha=0.25,
                      label=r"$\pm$2 standard errors")  # fmt: skip
    test.plot(number, mu, color="tab:green", linewidth=1.4, label=r"$\mu$ read along the stroke")
    if results is not None:
        test.plot(number, results["ecof"], color="tab:orange", linewidth=1.0,
                  label=r"ECoF $\mu_E$")  # fmt: skip
        test.plot(number, results["gicof"], color="tab:blue", linewidth=1.0, label="GICoF")
    missing = resolved["quality"].values != "ok"
    if missing.any():
        bottom = np.nanmin(mu - error) if np.isfinite(mu).any() else 0.0
        test.plot(number[missing], np.full(missing.sum(), bottom), "x", color="crimson",
                  label="no resolved value: " + ", ".join(
                      sorted(set(resolved["quality"].values[missing]))))  # fmt: skip
    test.set_xlabel("Cycle")
    test.set_ylabel("Coefficient of friction [1]")
    ratio = test.twinx()
    ratio.plot(number, resolved["aspect_ratio"], color="0.3", linestyle="--", linewidth=1.0)
    ratio.set_ylabel(axis_label("aspect_ratio") + " (dashed)")
    test.set_title(r"(d) $\mu$ over the test, and the equivalent groove", fontsize="medium")
    test.legend(loc="best", fontsize="x-small")
    figure.suptitle(
        rf"Loops read along the stroke (P = {scalar(resolved, 'load'):g} N): "
        r"$\mu(\xi)$ and $g(\xi)$ from the two slip branches at the same $\xi = \Delta - Q/S$",
        fontsize="medium",
    )
    return figure
