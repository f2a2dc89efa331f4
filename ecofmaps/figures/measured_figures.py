r"""Figures of measured loops: the loops with :math:`Q = S\Delta`, the friction over the test (as
the paper's Figure 9), the fitted model (as its Figure 10) and the loops read along the stroke.

Each function takes the results of :func:`ecofmaps.analyze_loops` or
:func:`ecofmaps.fit_loop` and returns a :class:`matplotlib.figure.Figure`, titled by the
recording's name (``source``) and what it shows; legends never cover what is drawn.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure
from matplotlib.path import Path
from matplotlib.ticker import MaxNLocator

from ecofmaps.figures.style import (
    MICRO,
    axis_label,
    force_ratio_axis,
    parameters,
    scalar,
    stiffness_text,
)
from ecofmaps.measured.quality import SEPARATOR
from ecofmaps.model.regimes import GROSS_SLIP, Regime

__all__ = ["cof_evolution", "measured_and_fitted_loops", "measured_loops", "resolved_loops"]


def _title(what: str, source: str | None) -> str:
    """A figure's title: the recording's name ``source``, when given, and ``what`` it shows."""
    return f"{source}: {what}" if source else what[:1].upper() + what[1:]


def _stiffness(stiffness: float) -> str:
    """A rig stiffness [N/m] for a title, its symbol italic: ``'$S$ = 35 MN/m'``."""
    return r"rigid ($S = \infty$)" if np.isinf(stiffness) else f"$S$ = {stiffness_text(stiffness)}"


def _load(load: float) -> str:
    """The normal load [N] for a title, its symbol italic: ``'$P$ = 450 N'``."""
    return f"$P$ = {load:g} N"


#: Room kept between a legend and what is drawn, as a fraction of the panel's height. [1]
_LEGEND_ROOM = 0.03

#: Where a legend may go inside a panel, in the order tried.
_CORNERS = (
    "upper left",
    "upper right",
    "lower left",
    "lower right",
    "upper center",
    "lower center",
)


def _legend_clear_of_data(ax, handles=None, labels=None, *, twins=(), **options):
    """A legend in the first corner of ``ax`` where it covers nothing drawn in ``ax`` or in
    ``twins`` (its twin axes); with no such corner, the value axes are stretched upwards to
    make room above everything drawn, and the legend goes in the upper left."""
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    legend = ax.legend(handles, labels, loc=_CORNERS[0], **options)
    ax.figure.draw_without_rendering()  # the layout done: the legend's and the data's places
    panels = (ax, *twins)
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
    """Whether anything drawn in ``ax`` (lines, their markers, filled areas, texts) meets the
    display-space ``box``; spans of the whole panel's height (a shaded background) do not."""
    for line in ax.get_lines():
        path = line.get_transform().transform_path(line.get_path()).cleaned(remove_nans=True)
        points = path.vertices[np.isin(path.codes, (Path.MOVETO, Path.LINETO))]
        if line.get_marker() not in (None, "None", "", " ") and box.count_contains(points):
            return True
        if line.get_linestyle() not in ("None", "", " ") and path.intersects_bbox(
            box, filled=False
        ):
            return True
    for collection in ax.collections:
        transform = collection.get_transform()
        if any(
            transform.transform_path(path).intersects_bbox(box) for path in collection.get_paths()
        ):
            return True
    return any(text.get_window_extent().overlaps(box) for text in ax.texts)


def _evenly_spread(labels, count: int) -> list:
    """Up to ``count`` of ``labels`` spread evenly, the first and the last included."""
    picks = np.unique(np.linspace(0, len(labels) - 1, min(count, len(labels))).round().astype(int))
    return [labels[i] for i in picks]


def measured_loops(
    results: xr.Dataset,
    cycles=None,
    columns: int = 3,
    resolved: xr.Dataset | None = None,
    *,
    source: str | None = None,
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
    source : str, optional
        The recording's name (its file's), which the title begins with.

    Returns
    -------
    figure : matplotlib.figure.Figure
        One panel per cycle: the centred loop, :math:`Q` [N] against :math:`\Delta` [µm],
        the line :math:`Q = S\Delta` with the cycle's stiffness, the crossings whose
        :math:`Q/P` is the GICoF, and, with ``resolved``, the band of contact positions
        :math:`\xi_{min} \le \Delta - Q/S \le \xi_{max}` where both branches were read.
        The title gives the cycle's GICoF and ECoF (a dash where they are NaN) and, on a
        line of its own, its flags when its ``quality`` is not ``'ok'`` (the first and how
        many more when they are too long for the panel). One legend, below the panels,
        lists what is drawn: crossings only where there are any.

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
        _crossings(ax, cycle, load)
        ax.axhline(0.0, color="0.7", linewidth=0.6)
        ax.axvline(0.0, color="0.7", linewidth=0.6)
        ax.grid(alpha=0.3)
        reading = (
            f"GICoF {_number(cycle['gicof'])}, ECoF {_number(cycle['ecof'])}"
            if int(cycle["regime"]) == GROSS_SLIP
            else "no GICoF or ECoF"
        )
        quality = str(cycle["quality"].values) if "quality" in cycle else "ok"
        state = Regime(int(cycle["regime"])).label
        flags = "" if quality == "ok" else "\nflagged: " + _flags_text(quality)
        ax.set_title(
            f"cycle {label}: {reading}\n{_stiffness(stiffness)}, {state}{flags}",
            fontsize="small",
        )
    for ax in axes.flat[len(chosen) :]:
        ax.set_visible(False)
    for column in axes.T:  # the lowest panel drawn in each column, above a hidden one or not
        lowest = [ax for ax in column if ax.get_visible()][-1]
        lowest.xaxis.set_tick_params(labelbottom=True)
        lowest.set_xlabel(axis_label("displacement"))
    for ax in axes[:, 0]:
        ax.set_ylabel(axis_label("force"))
    figure.suptitle(
        # Two lines: the figure of a single cycle is only one panel wide.
        _title(rf"measured loops and the line $Q = S\Delta$ ({_load(load)}):", source)
        + "\nthe GICoF is $Q/P$ at the crossings",
        fontsize="medium",
    )
    _shared_legend(figure, axes.flat[: len(chosen)])
    return figure


def _crossings(ax, cycle: xr.Dataset, load: float) -> None:
    """Mark the cycle's two crossings of the loop with Q = SΔ, where there are any."""
    crossings = np.array(
        [
            float(cycle["crossing_displacement_forward"]),
            float(cycle["crossing_displacement_backward"]),
        ]
    )
    ratios = np.array([float(cycle["gicof_forward"]), -float(cycle["gicof_backward"])])
    if np.isfinite(crossings * ratios).any():
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


def _flags_text(quality: str, width: int = 50) -> str:
    """A cycle's flags, comma separated, or the first and how many more when they are longer than
    ``width`` characters."""
    reasons = quality.split(SEPARATOR)
    text = ", ".join(reasons)
    if len(text) <= width or len(reasons) == 1:
        return text
    return f"{reasons[0]} and {len(reasons) - 1} more"


def _reasons(qualities) -> list[str]:
    """The distinct reasons in ``qualities``, sorted."""
    return sorted({reason for text in qualities for reason in str(text).split(SEPARATOR)})


def _shared_legend(figure: Figure, panels) -> None:
    """One legend of ``figure``, below its panels, for every labelled artist drawn in any of
    ``panels``."""
    entries = {}
    for panel in panels:
        for handle, name in zip(*panel.get_legend_handles_labels(), strict=True):
            entries.setdefault(name, handle)
    if entries:
        figure.legend(
            list(entries.values()),
            list(entries),
            loc="outside lower center",
            ncols=min(len(entries), 2 if len(panels) == 1 else 4),
            fontsize="x-small",
        )


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


def cof_evolution(results: xr.Dataset, *, source: str | None = None) -> Figure:
    r"""The ECoF and the GICoF over the cycles of a test, as the paper's Figure 9.

    Parameters
    ----------
    results : xarray.Dataset
        From :func:`ecofmaps.analyze_loops`.
    source : str, optional
        The recording's name (its file's), which the title begins with.

    Returns
    -------
    figure : matplotlib.figure.Figure
        Top: :math:`\mu_E` (eq. 1) and the GICoF against the cycle number.
        Bottom: how far the ECoF is above the GICoF, :math:`\mu_E/\text{GICoF} - 1` [%].
        The cycle axis spans the test with integer ticks; a panel with nothing to draw
        says why (every cycle flagged, with the count of each reason, or none in gross
        slip) and has no ticks on its value axis.

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
    series = {
        r"ECoF $\mu_E = E_d/(4P\delta^*)$": (results["ecof"].values, "tab:orange"),
        r"GICoF ($Q/P$ on $Q = S\Delta$)": (results["gicof"].values, "tab:blue"),
    }
    for name, (values, color) in series.items():
        if np.isfinite(values).any():
            top.plot(cycle, values, color=color, linewidth=1.3, label=name, **marker)
    top.set_ylabel("Coefficient of friction [1]")
    top.grid(alpha=0.3)
    if not top.get_lines():
        _note(top, "no ECoF or GICoF in any cycle:\n" + _why_none(results))
        top.set_yticks([])
    excess = (results["ecof"] / results["gicof"] - 1.0).values * 100.0
    if np.isfinite(excess).any():
        bottom.plot(cycle, excess, color="tab:purple", linewidth=1.2, **marker)
        bottom.axhline(0.0, color="0.5", linewidth=0.8)
    else:
        _note(bottom, "no cycle with both an ECoF and a GICoF")
        bottom.set_yticks([])
    bottom.set_ylabel("ECoF / GICoF − 1 [%]")
    bottom.set_xlabel("Cycle")
    bottom.grid(alpha=0.3)
    _cycle_axis(bottom, cycle)
    amplitude = float(results["amplitude"].median()) * MICRO
    figure.suptitle(
        _title("the ECoF and the GICoF over the cycles", source)
        + "\n"
        + parameters(_load(scalar(results, "load")), rf"$\Delta^*$ ≈ {amplitude:.1f} µm"),
        fontsize="medium",
    )
    if top.get_lines():  # the layout done with the title: the legend's place
        _legend_clear_of_data(top, fontsize="small")
    return figure


def _note(ax, text: str, height: float = 0.5) -> None:
    """Write ``text`` across the panel ``ax``, which has nothing else to show, at ``height`` (a
    fraction of the panel's, from the bottom)."""
    ax.text(
        0.5,
        height,
        text,
        transform=ax.transAxes,
        ha="center",
        va="center",
        color="0.3",
        fontsize="small",
    )


def _no_ticks(ax) -> None:
    """No ticks or tick labels on either axis of ``ax``, on which nothing was drawn (the axis labels
    stay."""
    ax.set_xticks([])
    ax.set_yticks([])


def _why_none(results: xr.Dataset) -> str:
    """Why no cycle of ``results`` has a value."""
    if "quality" not in results or (results["quality"].values == "ok").any():
        return "no cycle in gross slip"
    counts = {}
    for text in np.ravel(results["quality"].values):
        for reason in str(text).split(SEPARATOR):
            counts[reason] = counts.get(reason, 0) + 1
    return "every cycle flagged:\n" + ", ".join(f"{reason} {n}" for reason, n in counts.items())


def _cycle_axis(ax, cycle) -> None:
    """Integer ticks on the cycle axis of ``ax``, its limits the cycles' range (with a half-cycle
    margin), whether or not anything was drawn."""
    ax.xaxis.set_major_locator(MaxNLocator(nbins=6, integer=True, min_n_ticks=1))
    if cycle.size:
        first, last = float(np.min(cycle)), float(np.max(cycle))
        margin = 0.5 if first == last else 0.02 * (last - first)
        ax.set_xlim(first - margin, last + margin)


# --- measured loops and the fitted model, as the paper's Figure 10 -------------------------


def measured_and_fitted_loops(fits, *, source: str | None = None) -> Figure:
    r"""Measured fretting loops overlaid with the model fitted to them, as the paper's Figure 10.

    Parameters
    ----------
    fits : LoopFit or mapping of str to LoopFit
        From :func:`ecofmaps.fit_loop`. A mapping draws one panel per entry, titled by
        its key, side by side (the paper's Figure 10 has Example 1 and Example 2).
    source : str, optional
        The recording's name (its file's), which the title begins with.

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
        ax.plot(
            fit.displacement * MICRO,
            fit.force,
            "o",
            color="0.15",
            markersize=2.5,
            alpha=0.7,
            zorder=3,
            label="measured",
        )
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
            f"{panel}{_load(fit.load)}, "
            rf"$x_o = \Delta^*$ = {fit.amplitude * MICRO:.1f} µm"
            "\n"
            + parameters(
                rf"fit: $\mu$ = {fit.mu:.3f}",
                _stiffness(fit.stiffness),
                rf"$z_o$ = {fit.groove_depth * MICRO:.2f} µm",
                f"RMS residual {fit.rms_residual:.2g} N",
            ),
            fontsize="medium",
        )
    figure.suptitle(
        _title("measured fretting loops and the fitted model", source), fontsize="medium"
    )
    for ax in axes:  # the layout done with the titles: the legends' places
        _legend_clear_of_data(ax, fontsize="small")
    return figure


# --- the loops read along the stroke: ecofmaps.resolve_loops --------------------------------


def resolved_loops(
    resolved: xr.Dataset,
    results: xr.Dataset | None = None,
    cycles=None,
    *,
    source: str | None = None,
) -> Figure:
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
    source : str, optional
        The recording's name (its file's), which the title begins with.

    Returns
    -------
    figure : matplotlib.figure.Figure
        (a) :math:`\mu(\xi)` against the contact position :math:`\xi` [µm], each cycle's
        ``mu_resolved`` dashed and the central part it averages shaded; (b) the felt
        profile :math:`h(\xi)` [µm] with each cycle's equivalent parabola
        :math:`k\xi^2/2` dotted; (c) :math:`h` over (position, cycle), the groove deepening
        as the test runs; (d) ``mu_resolved`` :math:`\pm 2` standard errors over the cycles
        (with the ECoF and GICoF when ``results`` is given) and the equivalent
        ``aspect_ratio`` on a right-hand axis, dashed and in the legend (no axis where no
        cycle has one); cycles with
        no resolved value are marked along the bottom with their quality (halfway up when
        nothing has a value). A single cycle is a band in (c) and an error bar in (d); a
        panel with nothing to draw says why and has no ticks on its value axes. Each legend
        sits in a corner clear of the panel's data, made above the data when none is.

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
    ok = [
        label
        for label, quality in zip(labels, resolved["quality"].values, strict=True)
        if quality == "ok"
    ]
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
        stroke.axvspan(
            -reach * MICRO, reach * MICRO, color="0.9", zorder=0, label="central part averaged"
        )
    stroke.set_xlabel(axis_label("position"))
    stroke.set_ylabel(r"Coefficient of friction $\mu(\xi)$ [1]")
    stroke.set_title(r"(a) $\mu$ along the stroke (dashed: its average)", fontsize="medium")
    if not chosen:
        stroke.text(
            0.5,
            0.5,
            "no cycle was read along the stroke\n(none has quality 'ok')",
            transform=stroke.transAxes,
            ha="center",
            va="center",
            color="0.3",
        )
        _no_ticks(stroke)
    felt.set_xlabel(axis_label("position"))
    felt.set_ylabel(r"Felt groove profile $h(\xi)$ [µm]")
    felt.set_title("(b) the scar as the contact feels it", fontsize="medium")
    if chosen:
        felt.plot([], [], color="0.4", linestyle=":", label=r"equivalent parabola $k\xi^2/2$")
    else:
        _note(felt, "no felt profile: no cycle was read along the stroke")
        _no_ticks(felt)
    for ax in (stroke, felt, test):
        ax.grid(alpha=0.3)
    _profile_over_test(figure, image, resolved)
    twins = _mu_over_test(test, resolved, results)
    figure.suptitle(
        _title(f"loops read along the stroke ({_load(scalar(resolved, 'load'))}): ", source)
        + r"$\mu(\xi)$ and $g(\xi)$ from the two slip branches at the same $\xi = \Delta - Q/S$",
        fontsize="medium",
    )
    # The layout done with the titles: each legend's place, clear of its panel's data.
    if chosen:
        _legend_clear_of_data(stroke, fontsize="x-small", ncols=2)
        _legend_clear_of_data(felt, fontsize="x-small", ncols=2)
    handles, labels = test.get_legend_handles_labels()
    for twin in twins:
        more = twin.get_legend_handles_labels()
        handles, labels = handles + more[0], labels + more[1]
    _legend_clear_of_data(test, handles, labels, twins=twins, fontsize="x-small")
    return figure


def _profile_over_test(figure: Figure, image, resolved: xr.Dataset) -> None:
    """Panel (c): the felt profile h [µm] over (position, cycle), one row per cycle."""
    labels = resolved["cycle"].values
    xi = resolved["position"].values * MICRO
    profile = resolved["felt_profile"].transpose("cycle", "position").values * MICRO
    image.set_xlabel(axis_label("position"))
    image.set_ylabel("Cycle")
    image.set_title("(c) felt profile over the test", fontsize="medium")
    # One row per cycle, labelled by its number, whether or not any has a profile.
    rows = np.arange(len(labels) + 1) - 0.5
    ticks = np.arange(0, len(labels), max(1, -(-len(labels) // 6)))  # evenly, at most 6
    image.set_yticks(ticks, [str(labels[i]) for i in ticks])
    image.set_ylim(rows[0], rows[-1])
    if not np.isfinite(profile).any():
        _note(image, "no felt profile:\n" + _why_none(resolved))
        image.set_xticks([])  # no position was read
        return
    # Cell edges halfway between the positions, and between the rows: one cycle is a band.
    middle = (xi[1:] + xi[:-1]) / 2.0
    edges = np.concatenate([[2.0 * xi[0] - middle[0]], middle, [2.0 * xi[-1] - middle[-1]]])
    mesh = image.pcolormesh(edges, rows, profile, shading="flat", cmap="cividis")
    figure.colorbar(mesh, ax=image, label=r"$h(\xi)$ [µm]")


def _mu_over_test(test, resolved: xr.Dataset, results: xr.Dataset | None) -> tuple:
    """Panel (d), without its legend; its right-hand axis, if any, in a tuple."""
    number = resolved["cycle"].values
    mu = resolved["mu_resolved"].values
    error = 2.0 * resolved["mu_resolved_se"].values
    marker = dict(marker="o", markersize=3) if number.size <= 400 else {}
    if number.size > 1 and np.isfinite(error).any():
        test.fill_between(
            number,
            mu - error,
            mu + error,
            color="tab:green",
            alpha=0.25,
            label=r"$\pm$2 standard errors",
        )
    elif np.isfinite(error).any():  # a band over one cycle has no width
        test.errorbar(
            number,
            mu,
            yerr=error,
            fmt="none",
            ecolor="tab:green",
            capsize=4,
            label=r"$\pm$2 standard errors",
        )
    if np.isfinite(mu).any():
        test.plot(
            number,
            mu,
            color="tab:green",
            linewidth=1.4,
            label=r"$\mu$ read along the stroke",
            **marker,
        )
    if results is not None:
        for name, label, color in (
            ("ecof", r"ECoF $\mu_E$", "tab:orange"),
            ("gicof", "GICoF", "tab:blue"),
        ):
            values = results[name].values
            if np.isfinite(values).any():
                test.plot(number, values, color=color, linewidth=1.0, label=label, **marker)
    missing = resolved["quality"].values != "ok"
    drawn = [mu - error]
    if results is not None:
        drawn += [results[name].values for name in ("ecof", "gicof")]
    drawn = np.concatenate([values[np.isfinite(values)] for values in drawn])
    if missing.any():
        reasons = ", ".join(_reasons(resolved["quality"].values[missing]))
        # Along the lowest value drawn; with none, halfway up the panel: no friction scale.
        height, where = (
            (drawn.min(), test.transData) if drawn.size else (0.5, test.get_xaxis_transform())
        )
        test.plot(
            number[missing],
            np.full(missing.sum(), height),
            "x",
            color="crimson",
            transform=where,
            label=f"no resolved value: {reasons}",
        )
    if not drawn.size:  # the marks have no height: no scale of friction to read
        test.set_yticks([])
    if missing.all():  # below the marks, which are at the middle
        _note(test, "no cycle read along the stroke:\n" + _why_none(resolved), height=0.3)
    test.set_xlabel("Cycle")
    test.set_ylabel("Coefficient of friction [1]")
    twins = ()
    if np.isfinite(resolved["aspect_ratio"].values).any():  # no right-hand axis without a line
        ratio = test.twinx()
        ratio.plot(
            number,
            resolved["aspect_ratio"],
            color="0.3",
            linestyle="--",
            linewidth=1.0,
            label=r"equivalent groove $z_o/x_o$ (right axis)",
            **marker,
        )
        ratio.set_ylabel(axis_label("aspect_ratio"))
        twins = (ratio,)
    _cycle_axis(test, number)  # after twinx, which shares the cycle axis's ticker
    test.set_title(r"(d) $\mu$ over the test, and the equivalent groove", fontsize="medium")
    return twins
