r"""Figures of measured loops: the loops with :math:`Q = S\Delta`, the friction over the test (as
the paper's Figure 9), the fitted model (its Figure 10) and the loops read along the stroke
(docs/method-loops.md)."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ecofmaps.figures import style
from ecofmaps.figures.style import MICRO, axis_label, load_label, scalar, stiffness_label
from ecofmaps.measured.quality import SEPARATOR
from ecofmaps.model.regimes import GROSS_SLIP, Regime

#: The colour of the ECoF and of the GICoF over the cycles.
_COLORS = {"ecof": "tab:orange", "gicof": "tab:blue"}


def _title(what: str, source: str | None) -> str:
    """A figure's title: the recording's name ``source``, when given, and ``what`` it shows."""
    return f"{source}: {what}" if source else what[:1].upper() + what[1:]


def _evenly_spread(labels, count: int) -> list:
    """Up to ``count`` of ``labels`` spread evenly, the first and the last included."""
    picks = np.unique(np.linspace(0, len(labels) - 1, min(count, len(labels))).round().astype(int))
    return [labels[i] for i in picks]


def _number(value) -> str:
    """``value`` to three decimals, or a dash where it is NaN."""
    value = float(value)
    return f"{value:.3f}" if np.isfinite(value) else "–"


def _reasons(qualities) -> list[str]:
    """Each reason of ``qualities`` (flags joined by the separator), as often as it occurs."""
    return [reason for text in np.ravel(qualities) for reason in str(text).split(SEPARATOR)]


def _why_none(results: xr.Dataset) -> str:
    if "quality" not in results or (results["quality"].values == "ok").any():
        return "no cycle in gross slip"
    counts = Counter(_reasons(results["quality"].values))
    return "every cycle flagged:\n" + ", ".join(f"{reason} {n}" for reason, n in counts.items())


def _note(ax, text: str, clear: str = "", height: float = 0.5, fontsize="small") -> None:
    """Write ``text`` across ``ax``, ``height`` up; no ticks on its axes ``clear`` (``'xy'``)."""
    where = dict(transform=ax.transAxes, ha="center", va="center")
    ax.text(0.5, height, text, color="0.3", fontsize=fontsize, **where)
    ax.set(**{f"{axis}ticks": [] for axis in clear})


def _cycle_axis(ax, cycle) -> None:
    """At most six integer ticks on the cycle axis of ``ax``, its limits the cycles' range."""
    ax.xaxis.set_major_locator(MaxNLocator(nbins=6, integer=True, min_n_ticks=1))
    if cycle.size:
        first, last = float(np.min(cycle)), float(np.max(cycle))
        margin = 0.5 if first == last else 0.02 * (last - first)
        ax.set_xlim(first - margin, last + margin)


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
        Cycles to draw, a panel each; by default six spread evenly, the first and last included.
    columns : int
        Panels per row.
    resolved : xarray.Dataset, optional
        From :func:`ecofmaps.resolve_analyzed_loops` of ``results``: the part read is shaded.
    source : str, optional
        The recording's name (its file's), which the title begins with.

    Returns
    -------
    figure : matplotlib.figure.Figure
        A panel per cycle titled by its GICoF, ECoF and flags: :math:`Q` [N] against
        :math:`\Delta` [µm]; the GICoF is :math:`Q/P` at the crossings (eq. 17-18).
    """
    if "loop_displacement" not in results:
        raise ValueError("results hold no loops: call analyze_loops(..., keep_loops=True)")
    chosen = _evenly_spread(results["cycle"].values, 6) if cycles is None else list(cycles)
    rows, width = -(-len(chosen) // columns), min(columns, len(chosen))
    figure = Figure(figsize=(3.6 * width + 0.6, 3.1 * rows + 0.9), layout="constrained")
    axes = figure.subplots(rows, width, squeeze=False, sharex=True, sharey=True)
    load = scalar(results, "load")
    for ax, label in zip(axes.flat, chosen, strict=False):
        cycle = results.sel(cycle=label)
        x, q = cycle["loop_displacement"].values * MICRO, cycle["loop_force"].values
        ax.plot(x, q, color="tab:blue", linewidth=1.2, label="measured loop")
        stiffness = float(cycle["stiffness"])
        if np.isfinite(stiffness) and stiffness > 0:  # across the loop's height, within its width
            reach = np.nanmax(np.abs(q)) / stiffness * MICRO
            ends = np.array([max(np.nanmin(x), -reach), min(np.nanmax(x), reach)])
            line = dict(color="0.35", linestyle="--", linewidth=1.0, label=r"$Q = S\Delta$")
            ax.plot(ends, stiffness * ends / MICRO, **line)
        if resolved is not None:
            _resolved_band(ax, resolved.sel(cycle=label), q)
        sides = ("forward", "backward")  # the two crossings of the loop with Q = SΔ, if any
        crossings = np.array([float(cycle[f"crossing_displacement_{side}"]) for side in sides])
        ratios = np.array([float(cycle["gicof_forward"]), -float(cycle["gicof_backward"])])
        if np.isfinite(crossings * ratios).any():
            dots = dict(marker="o", markersize=6, linestyle="none", label="GICoF crossings")
            face = dict(markerfacecolor="tab:red", markeredgecolor="black")
            ax.plot(crossings * MICRO, ratios * load, **dots, **face)
        style.zero_lines(ax, "0.7")
        ax.grid(alpha=0.3)
        regime = Regime(int(cycle["regime"]))
        reading = f"GICoF {_number(cycle['gicof'])}, ECoF {_number(cycle['ecof'])}"
        reading = reading if regime == GROSS_SLIP else "no GICoF or ECoF"
        reasons = str(cycle["quality"].values).split(SEPARATOR) if "quality" in cycle else ["ok"]
        flags = ", ".join(reasons)  # or the first and how many more beyond 50 characters
        if len(flags) > 50 and len(reasons) > 1:
            flags = f"{reasons[0]} and {len(reasons) - 1} more"
        flags = "" if reasons == ["ok"] else "\nflagged: " + flags
        title = f"cycle {label}: {reading}\n{stiffness_label(stiffness)}, {regime.label}{flags}"
        ax.set_title(title, fontsize="small")
    for ax in axes.flat[len(chosen) :]:
        ax.set_visible(False)
    for column in axes.T:  # the lowest panel drawn in each column, above a hidden one or not
        lowest = [ax for ax in column if ax.get_visible()][-1]
        lowest.xaxis.set_tick_params(labelbottom=True)
        lowest.set_xlabel(axis_label("displacement"))
    for ax in axes[:, 0]:
        ax.set_ylabel(axis_label("force"))
    title = _title(rf"measured loops and the line $Q = S\Delta$ ({load_label(load)}):", source)
    # Two lines: the figure of a single cycle is only one panel wide.
    figure.suptitle(title + "\nthe GICoF is $Q/P$ at the crossings", fontsize="medium")
    entries = {}  # one legend of every labelled artist of the panels drawn, below them
    for ax in axes.flat[: len(chosen)]:
        for handle, name in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(name, handle)
    ncols = min(len(entries), 2 if len(chosen) == 1 else 4)
    options = dict(loc="outside lower center", ncols=ncols, fontsize="x-small")
    figure.legend(list(entries.values()), list(entries), **options)
    return figure


def _resolved_band(ax, cycle: xr.Dataset, q) -> None:
    """Shade the contact positions ξ_min <= Δ - Q/S <= ξ_max that were read along the stroke."""
    low, high = float(cycle["position_min"]), float(cycle["position_max"])
    if np.isfinite(low) and np.isfinite(high):
        force = np.linspace(np.nanmin(q), np.nanmax(q), 2)
        compliance = 1.0 / float(cycle["stiffness"])
        low, high = (low + compliance * force) * MICRO, (high + compliance * force) * MICRO
        band = dict(color="tab:green", alpha=0.12, linewidth=0, label="read along the stroke")
        ax.fill_betweenx(force, low, high, **band)


def cof_evolution(results: xr.Dataset, *, source: str | None = None) -> Figure:
    r"""The ECoF and the GICoF over the cycles of a test, as the paper's Figure 9.

    Parameters
    ----------
    results : xarray.Dataset
        From :func:`ecofmaps.analyze_loops`.
    source : str, optional
        As for :func:`measured_loops`.

    Returns
    -------
    figure : matplotlib.figure.Figure
        Top: :math:`\mu_E` (eq. 1) and the GICoF against the cycle. Bottom:
        :math:`\mu_E/\text{GICoF} - 1` [%]. A panel with nothing to draw says why.
    """
    figure = Figure(figsize=(7.0, 5.6), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.3]})
    cycle = results["cycle"].values
    marker = dict(marker="o", markersize=2.5) if cycle.size <= 400 else {}
    labels = (r"ECoF $\mu_E = E_d/(4P\delta^*)$", r"GICoF ($Q/P$ on $Q = S\Delta$)")
    for (name, color), label in zip(_COLORS.items(), labels, strict=True):
        if np.isfinite(results[name].values).any():
            top.plot(cycle, results[name].values, color=color, linewidth=1.3, label=label, **marker)
    top.set_ylabel("Coefficient of friction [1]")
    top.grid(alpha=0.3)
    if not top.get_lines():
        _note(top, "no ECoF or GICoF in any cycle:\n" + _why_none(results), "y")
    excess = (results["ecof"] / results["gicof"] - 1.0).values * 100.0
    if np.isfinite(excess).any():
        bottom.plot(cycle, excess, color="tab:purple", linewidth=1.2, **marker)
        bottom.axhline(0.0, color="0.5", linewidth=0.8)
    else:
        _note(bottom, "no cycle with both an ECoF and a GICoF", "y")
    bottom.set(ylabel="ECoF / GICoF − 1 [%]", xlabel=axis_label("cycle"))
    bottom.grid(alpha=0.3)
    _cycle_axis(bottom, cycle)
    amplitude = float(results["amplitude"].median()) * MICRO
    load = load_label(scalar(results, "load"))
    test = style.parameters(load, rf"$\Delta^*$ ≈ {amplitude:.1f} µm")
    title = _title("the ECoF and the GICoF over the cycles", source)
    figure.suptitle(f"{title}\n{test}", fontsize="medium")
    if top.get_lines():  # the layout done with the title: the legend's place
        style.legend_clear_of_data(top, fontsize="small")
    return figure


def measured_and_fitted_loops(fits, *, source: str | None = None) -> Figure:
    r"""Measured fretting loops overlaid with the model fitted to them, as the paper's Figure 10.

    Parameters
    ----------
    fits : LoopFit or mapping of str to LoopFit
        From :func:`ecofmaps.fit_loop`; a mapping draws a panel per entry, titled by its key.
    source : str, optional
        As for :func:`measured_loops`.

    Returns
    -------
    figure : matplotlib.figure.Figure
        Q [N] and Q/P against Δ [µm], titled by the fitted μ, S, z_o and RMS residual.
    """
    panels = dict(fits) if isinstance(fits, Mapping) else {"": fits}
    figure = Figure(figsize=(5.6 * len(panels), 5.2), layout="constrained")
    axes = figure.subplots(1, len(panels), squeeze=False)[0]
    dots = dict(color="0.15", markersize=2.5, alpha=0.7, zorder=3, label="measured")
    for index, (ax, (name, fit)) in enumerate(zip(axes, panels.items(), strict=True)):
        displacement, force = fit.model_loop()
        ax.plot(fit.displacement * MICRO, fit.force, "o", **dots)
        ax.plot(displacement * MICRO, force, color="crimson", linewidth=1.8, label="fitted model")
        style.loop_axes(ax, fit.load, fit.displacement_offset * MICRO, fit.force_offset)
        panel = f"({chr(ord('a') + index)}) " if len(panels) > 1 else ""
        panel += f"{name}: " if name else ""
        test = rf"{panel}{load_label(fit.load)}, $x_o = \Delta^*$ = {fit.amplitude * MICRO:.1f} µm"
        depth = rf"$z_o$ = {fit.groove_depth * MICRO:.2f} µm"
        fitted = [rf"fit: $\mu$ = {fit.mu:.3f}", stiffness_label(fit.stiffness), depth]
        fitted = style.parameters(*fitted, f"RMS residual {fit.rms_residual:.2g} N")
        ax.set_title(f"{test}\n{fitted}", fontsize="medium")
    title = _title("measured fretting loops and the fitted model", source)
    figure.suptitle(title, fontsize="medium")
    for ax in axes:  # the layout done with the titles: the legends' places
        style.legend_clear_of_data(ax, fontsize="small")
    return figure


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
        From :func:`ecofmaps.analyze_loops` of the recording: its ECoF and GICoF drawn too.
    cycles : sequence of int, optional
        Cycles drawn along the stroke; by default up to five of quality ``'ok'``, as above.
    source : str, optional
        As for :func:`measured_loops`.

    Returns
    -------
    figure : matplotlib.figure.Figure
        (a) :math:`\mu(\xi)` against :math:`\xi` [µm], ``mu_resolved`` dashed; (b) the felt
        profile :math:`h(\xi)` [µm] and its parabola; (c) :math:`h` over (position, cycle);
        (d) ``mu_resolved`` :math:`\pm 2` standard errors, ECoF, GICoF and ``aspect_ratio``
        over the cycles, those without a value marked with their quality.
    """
    if "position" not in resolved.dims:
        raise ValueError("resolved holds no positions: call resolve_loops(..., positions=201)")
    ok = resolved["cycle"].values[resolved["quality"].values == "ok"]
    chosen = _evenly_spread(ok, 5) if cycles is None else list(cycles)
    figure = Figure(figsize=(11.0, 8.2), layout="constrained")
    (stroke, felt), (image, test) = figure.subplots(2, 2)
    xi = resolved["position"].values * MICRO
    colors = colormaps["viridis"](np.linspace(0.0, 0.85, max(len(chosen), 1)))
    for label, color in zip(chosen, colors, strict=False):
        cycle = resolved.sel(cycle=label)
        line = dict(color=color, label=f"cycle {label}")
        stroke.plot(xi, cycle["mu"], linewidth=1.2, **line)
        stroke.axhline(float(cycle["mu_resolved"]), color=color, linestyle="--", linewidth=0.9)
        felt.plot(xi, cycle["felt_profile"] * MICRO, linewidth=1.4, **line)
        k = 2.0 * float(cycle["aspect_ratio"]) / float(cycle["amplitude"])  # z_o/x_o = kΔ*/2
        felt.plot(xi, 0.5 * k * (xi / MICRO) ** 2 * MICRO, color=color, linestyle=":", linewidth=1)
    central = float(resolved.attrs.get("central", np.nan))
    if chosen and np.isfinite(central):
        picked = resolved.sel(cycle=chosen)
        low, high = -float(picked["position_min"].max()), float(picked["position_max"].min())
        reach = central * min(low, high)
        averaged = dict(color="0.9", zorder=0, label="central part averaged")
        stroke.axvspan(-reach * MICRO, reach * MICRO, **averaged)
    stroke.set(xlabel=axis_label("position"), ylabel=r"Coefficient of friction $\mu(\xi)$ [1]")
    stroke.set_title(r"(a) $\mu$ along the stroke (dashed: its average)", fontsize="medium")
    felt.set(xlabel=axis_label("position"), ylabel=r"Felt groove profile $h(\xi)$ [µm]")
    felt.set_title("(b) the scar as the contact feels it", fontsize="medium")
    if chosen:
        felt.plot([], [], color="0.4", linestyle=":", label=r"equivalent parabola $k\xi^2/2$")
    else:
        unread = "no cycle was read along the stroke"
        _note(stroke, f"{unread}\n(none has quality 'ok')", "xy", fontsize=None)
        _note(felt, f"no felt profile: {unread}", "xy")
    for ax in (stroke, felt, test):
        ax.grid(alpha=0.3)
    _profile_over_test(figure, image, resolved)
    twins = _mu_over_test(test, resolved, results)
    load = load_label(scalar(resolved, "load"))
    title = _title(f"loops read along the stroke ({load}): ", source)
    title += r"$\mu(\xi)$ and $g(\xi)$ from the two slip branches at the same $\xi = \Delta - Q/S$"
    figure.suptitle(title, fontsize="medium")
    # The layout done with the titles: each legend's place, clear of its panel's data.
    for ax in (stroke, felt) if chosen else ():
        style.legend_clear_of_data(ax, fontsize="x-small", ncols=2)
    style.legend_clear_of_data(test, twins=twins, fontsize="x-small")
    return figure


def _profile_over_test(figure: Figure, image, resolved: xr.Dataset) -> None:
    """Panel (c): the felt profile h [µm] over (position, cycle), one row per cycle."""
    labels, xi = resolved["cycle"].values, resolved["position"].values * MICRO
    profile = resolved["felt_profile"].transpose("cycle", "position").values * MICRO
    image.set(xlabel=axis_label("position"), ylabel=axis_label("cycle"))
    image.set_title("(c) felt profile over the test", fontsize="medium")
    # One row per cycle, labelled by its number, whether or not any has a profile.
    rows = np.arange(len(labels) + 1) - 0.5
    ticks = np.arange(0, len(labels), max(1, -(-len(labels) // 6)))  # evenly, at most 6
    image.set_yticks(ticks, [str(labels[i]) for i in ticks])
    image.set_ylim(rows[0], rows[-1])
    if not np.isfinite(profile).any():
        _note(image, "no felt profile:\n" + _why_none(resolved), "x")  # no position was read
        return
    # Cell edges halfway between the positions, and between the rows: one cycle is a band.
    middle = (xi[1:] + xi[:-1]) / 2.0
    edges = np.concatenate([[2.0 * xi[0] - middle[0]], middle, [2.0 * xi[-1] - middle[-1]]])
    mesh = image.pcolormesh(edges, rows, profile, shading="flat", cmap="cividis")
    figure.colorbar(mesh, ax=image, label=r"$h(\xi)$ [µm]")


def _mu_over_test(test, resolved: xr.Dataset, results: xr.Dataset | None) -> tuple:
    """Panel (d), without its legend; its right-hand axis, if any, in a tuple."""
    number, mu = resolved["cycle"].values, resolved["mu_resolved"].values
    error = 2.0 * resolved["mu_resolved_se"].values
    marker = dict(marker="o", markersize=3) if number.size <= 400 else {}
    band = dict(label=r"$\pm$2 standard errors")
    if number.size > 1 and np.isfinite(error).any():
        test.fill_between(number, mu - error, mu + error, color="tab:green", alpha=0.25, **band)
    elif np.isfinite(error).any():  # a band over one cycle has no width
        test.errorbar(number, mu, yerr=error, fmt="none", ecolor="tab:green", capsize=4, **band)
    if np.isfinite(mu).any():
        label = r"$\mu$ read along the stroke"
        test.plot(number, mu, color="tab:green", linewidth=1.4, label=label, **marker)
    drawn = [mu - error]
    if results is not None:
        for (name, color), label in zip(_COLORS.items(), (r"ECoF $\mu_E$", "GICoF"), strict=True):
            drawn.append(results[name].values)
            if np.isfinite(drawn[-1]).any():
                test.plot(number, drawn[-1], color=color, linewidth=1.0, label=label, **marker)
    drawn = np.concatenate([values[np.isfinite(values)] for values in drawn])
    missing = resolved["quality"].values != "ok"
    if missing.any():
        reasons = ", ".join(sorted(set(_reasons(resolved["quality"].values[missing]))))
        # Along the lowest value drawn; with none, halfway up the panel: no friction scale.
        height, where = (
            (drawn.min(), test.transData) if drawn.size else (0.5, test.get_xaxis_transform())
        )
        crosses = dict(color="crimson", transform=where, label=f"no resolved value: {reasons}")
        test.plot(number[missing], np.full(missing.sum(), height), "x", **crosses)
    if not drawn.size:  # the marks have no height: no scale of friction to read
        test.set_yticks([])
    if missing.all():  # below the marks, which are at the middle
        _note(test, "no cycle read along the stroke:\n" + _why_none(resolved), height=0.3)
    test.set(xlabel=axis_label("cycle"), ylabel="Coefficient of friction [1]")
    twins = ()
    if np.isfinite(resolved["aspect_ratio"].values).any():  # no right-hand axis without a line
        ratio = test.twinx()
        line = dict(color="0.3", linestyle="--", linewidth=1.0, **marker)
        label = r"equivalent groove $z_o/x_o$ (right axis)"
        ratio.plot(number, resolved["aspect_ratio"], label=label, **line)
        ratio.set_ylabel(axis_label("aspect_ratio"))
        twins = (ratio,)
    _cycle_axis(test, number)  # after twinx, which shares the cycle axis's ticker
    test.set_title(r"(d) $\mu$ over the test, and the equivalent groove", fontsize="medium")
    return twins
