r"""Figures of wear-scar profiles: a measured profile as the model reads it, and the ``shapes``
figure, scars of four shapes at one :math:`D/W` against the parabola (docs/profiles.md)."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ecofmaps.figures import style
from ecofmaps.figures.style import MICRO, axis_label, scalar

#: Colour of each scar shape; the parabola of the same D/W (the shortcut) is black, dashed.
SHAPE_COLORS = {
    "parabolic": "tab:orange",
    "flat-bottomed": "tab:blue",
    "W-shaped": "tab:green",
    "ridged": "tab:red",
}
_SHORTCUT = dict(color="black", linestyle="--", linewidth=1.4)
_EDGE = dict(color="0.45", linestyle=":", linewidth=1.2)


def scar_profile_figure(profile, name: str | None = None) -> Figure:
    r"""A scar profile as the model reads it: heights, edges, and the slope it uses.

    Parameters
    ----------
    profile : ScarProfile
        One profile (:func:`ecofmaps.read_scar_profile`, :func:`ecofmaps.scar_profile`, a
        profile family), not a batch.
    name : str, optional
        What to call it in the title (e.g. the file's name).

    Returns
    -------
    figure : matplotlib.figure.Figure
        Over :math:`X` [µm], edges :math:`\pm W` marked: the height :math:`z` [µm] with the
        unworn surface, :math:`D` and the parabola of the same :math:`D/W`; the slope
        :math:`g = dz/dX` the model uses and the parabola's.
    """
    position = np.asarray(profile.position)
    if position.ndim != 1:
        raise ValueError("scar_profile_figure draws one profile, not a batch")
    x, slope = position * MICRO, np.asarray(profile.slope)
    depth, width = float(profile.depth), float(profile.half_width)
    surface = float(profile.reference_height) + float(profile.reference_slope) * position
    figure = Figure(figsize=(7.4, 6.4), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True, height_ratios=(1.25, 1.0))
    height = np.asarray(profile.height) * MICRO
    top.plot(x, height, color="tab:blue", linewidth=1.6, label="profile $z(X)$")
    unworn = dict(color="0.3", linewidth=1.0, linestyle="--")
    top.plot(x, surface * MICRO, **unworn, label="unworn surface (levelling line)")
    level = float(profile.reference_height) * MICRO
    bottom_of_scar = level - depth * MICRO
    arrow = dict(arrowstyle="<->", color="crimson", linewidth=1.2)
    top.annotate("", xy=(0.0, bottom_of_scar), xytext=(0.0, level), arrowprops=arrow)
    label, where = f"  $D$ = {depth * MICRO:.4g} µm", bottom_of_scar + 0.5 * depth * MICRO
    top.text(0.02 * width * MICRO, where, label, color="crimson", va="center")
    parabola = 2.0 * depth * position / width**2 + float(profile.reference_slope)
    inside = np.abs(position) <= width
    bowl = surface[inside] - depth * (1.0 - (position[inside] / width) ** 2)
    top.plot(x[inside], bowl * MICRO, **_SHORTCUT, label="parabola of the same $D/W$")
    bottom.plot(x, slope, color="tab:blue", linewidth=1.6, label="slope the model uses")
    label = f"parabola of the same $D/W$ = {depth / width:.3g}"
    bottom.plot(x[inside], parabola[inside], **_SHORTCUT, label=label)
    bottom.axhline(0.0, color="0.6", linewidth=0.6)
    for ax in (top, bottom):
        for edge, label in ((-width, "edges $\\pm W$"), (width, None)):
            ax.axvline(edge * MICRO, **_EDGE, label=label)
        ax.grid(alpha=0.3)
        ax.legend(loc="lower left" if ax is top else "upper left", fontsize="small")
    top.set_ylabel(axis_label("scar_height"))
    bottom.set_ylabel(axis_label("scar_slope"))
    bottom.set_xlabel(axis_label("scar_position") + " from the scar centre")
    # The slopes outside the scar can dwarf those inside (steep walls, ridges): the scar's.
    within = np.abs(position) <= 1.5 * width
    reach = max(float(np.max(np.abs(slope[within]))), 2.0 * depth / width)
    bottom.set_ylim(-1.15 * reach, 1.15 * reach)
    title = "Wear-scar profile" + (f": {name}" if name else "")
    sizes = [f"$D$ = {depth * MICRO:.4g} µm", f"$W$ = {width * MICRO:.4g} µm"]
    sizes += [f"$D/W$ = {depth / width:.3g}", f"{position.size} samples"]
    top.set_title(f"{title}\n{style.parameters(*sizes)}", fontsize="medium")
    return figure


def scar_shape_comparison(dataset: xr.Dataset) -> Figure:
    r"""Scars of four shapes at one :math:`D/W` against the parabola of that :math:`D/W`.

    Parameters
    ----------
    dataset : xarray.Dataset
        The ``shapes`` figure's (:data:`ecofmaps.figures.FIGURES`), over ``shape``, ``groove``
        (``'profile'``, ``'parabola'``), ``scar_position``, ``point`` and ``stiffness_ratio``.

    Returns
    -------
    figure : matplotlib.figure.Figure
        Top: the profiles and each scar's steady loop against the parabola's. Bottom:
        :math:`\mu_E/\mu` over :math:`S/P`, and the error :math:`\mu'/\mu - 1` [%] of the
        paper's shortcut (the parabola of the same :math:`D/W`) on each scar's :math:`\mu_E`.
    """
    shapes = list(dataset["shape"].values)
    figure = Figure(figsize=(15.0, 9.0), layout="constrained")
    grid = figure.add_gridspec(2, 2 * len(shapes), height_ratios=(1.0, 1.05))
    ax_shapes = figure.add_subplot(grid[0, 0:2])
    loop_axes = [figure.add_subplot(grid[0, 2 * i : 2 * i + 2]) for i in range(1, len(shapes))]
    for ax in loop_axes[1:]:
        ax.sharey(loop_axes[0])
    half = grid.ncols // 2
    ax_ratio = figure.add_subplot(grid[1, :half])
    ax_error = figure.add_subplot(grid[1, half:])
    _draw_scar_profiles(ax_shapes, dataset)
    _draw_shape_loops(loop_axes, dataset)
    _draw_ratio_and_error(ax_ratio, ax_error, dataset)
    depth, width = scalar(dataset, "scar_depth"), scalar(dataset, "scar_half_width")
    sizes = f"$W$ = {width * MICRO:g} µm, $D$ = {depth * MICRO:g} µm"
    loops = f"{style.stiffness_label(scalar(dataset, 'stiffness'))} (loops)"
    rig = [rf"$x_o = \Delta^*$ = {scalar(dataset, 'amplitude') * MICRO:g} µm", sizes]
    rig += [style.load_label(scalar(dataset, "load")), loops, rf"$\mu$ = {scalar(dataset, 'mu'):g}"]
    title = "Scar shape at equal depth over half-width: how wrong the D/W shortcut is"
    figure.suptitle(f"{title}\n{style.parameters(*rig)}", fontsize="medium")
    return figure


def _draw_scar_profiles(ax, dataset: xr.Dataset) -> None:
    """The profiles of the ``shapes`` figure, with the reach of the pad on the parabola."""
    depth, width = scalar(dataset, "scar_depth"), scalar(dataset, "scar_half_width")
    x = dataset["scar_position"].values * MICRO
    for shape in dataset["shape"].values:  # the parabola on top, thinner: others share parts
        parabola = shape == "parabolic"
        look = dict(linewidth=1.4 if parabola else 2.6, zorder=3 if parabola else 2)
        height = dataset["scar_height"].sel(shape=shape) * MICRO
        ax.plot(x, height, color=SHAPE_COLORS.get(shape), label=shape, **look)
    reach = float(dataset["slip_amplitude"].sel(shape="parabolic", groove="parabola"))
    reach *= width / scalar(dataset, "amplitude")
    label = "reach of the pad,\n" + r"$|X| \leq \delta^* W/\Delta^*$"
    ax.axvspan(-reach * MICRO, reach * MICRO, color="0.85", zorder=0, label=label)
    for edge in (-width, width):
        ax.axvline(edge * MICRO, **_EDGE)
    ax.set(xlabel=axis_label("scar_position"), ylabel=axis_label("scar_height"))
    ax.set_title(f"Scars of equal $D/W$ = {depth / width:g}\n(edges ±W dotted)", fontsize="medium")
    ax.set_ylim(-1.25 * depth * MICRO, 2.1 * depth * MICRO)  # the legend above
    ax.legend(loc="upper center", fontsize="x-small", ncols=2)
    ax.grid(alpha=0.3)


def _draw_shape_loops(loop_axes, dataset: xr.Dataset) -> None:
    """The loop on each non-parabolic scar of the ``shapes`` figure against the parabola's."""
    load = scalar(dataset, "load")
    others = [shape for shape in dataset["shape"].values if shape != "parabolic"]
    for ax, shape in zip(loop_axes, others, strict=True):
        own = dict(color=SHAPE_COLORS.get(shape), linewidth=2.0, zorder=2)
        for groove, look in (("profile", own), ("parabola", dict(_SHORTCUT, zorder=3))):
            point = dataset.sel(shape=shape, groove=groove)
            which = f"{shape} scar" if groove == "profile" else "parabola, same $D/W$"
            slip = rf"$\delta^*$ = {float(point['slip_amplitude']) * MICRO:.1f} µm"
            energy = rf"$E_d$ = {float(point['dissipated_energy']) * style.MILLI:.1f} mJ"
            label = f"{which}\n{slip}, {energy}, $\\mu_E$ = {float(point['ecof']):.3f}"
            ax.plot(point["displacement"] * MICRO, point["force"], **look, label=label)
        loops = dataset["force"].sel(shape=shape).values
        if np.allclose(loops[0], loops[1], rtol=1e-6, atol=1e-9 * load):
            text = "the parabola's loop: this scar differs\nonly beyond the pad's reach"
            where = dict(transform=ax.transAxes, ha="right", va="bottom")
            ax.text(0.97, 0.04, text, fontsize="small", color=SHAPE_COLORS.get(shape), **where)
        style.zero_lines(ax)
        ax.set_xlabel(axis_label("displacement"))
        ax.grid(alpha=0.3)
        ax.set_title(f"{shape} scar", fontsize="medium")
        ax.legend(loc="upper left", fontsize="x-small")
    loop_axes[0].set_ylabel(axis_label("force"))
    for ax in loop_axes[:-1]:
        ax.tick_params(labelleft=ax is loop_axes[0])
    style.force_ratio_axis(loop_axes[-1], load)
    peak = float(np.nanmax(np.abs(dataset["force"].values)))
    loop_axes[0].set_ylim(-1.08 * peak, 1.75 * peak)  # room for the legends above the loops


def _draw_ratio_and_error(ax_ratio, ax_error, dataset: xr.Dataset) -> None:
    """μ_E/μ over S/P for every shape and the parabola, and the D/W shortcut's error."""
    depth, width = scalar(dataset, "scar_depth"), scalar(dataset, "scar_half_width")
    stiffness = scalar(dataset, "stiffness")
    ratios = dataset["stiffness_ratio"].values * style.PER_MM
    shortcut = dataset["ecof_ratio"].sel(shape="parabolic", groove="parabola")
    label = f"parabola, $D/W$ = {depth / width:g}"
    ax_ratio.plot(ratios, shortcut, **_SHORTCUT, zorder=3, label=label)
    ax_error.axhline(0.0, **_SHORTCUT, zorder=3, label="no error (the parabola itself)")
    for shape in dataset["shape"].values:
        look = dict(color=SHAPE_COLORS.get(shape), linewidth=2.0, zorder=2)
        if shape == "parabolic":  # on the parabola's closed form: points, so both show
            dots = dict(marker="o", markersize=4, linestyle="none", markevery=6, zorder=4)
            look = dict(color=SHAPE_COLORS["parabolic"], **dots)
        ratio = dataset["ecof_ratio"].sel(shape=shape, groove="profile")
        ax_ratio.plot(ratios, ratio, label=f"{shape} scar", **look)
        if shape != "parabolic":
            error = dataset["shortcut_error"].sel(shape=shape) * 100.0
            ax_error.plot(ratios, error, label=f"{shape} scar", **look)
    example = stiffness / scalar(dataset, "load") * style.PER_MM
    rig = dict(color="crimson", linewidth=1.0, linestyle="-.")
    for ax in (ax_ratio, ax_error):
        ax.axvline(example, **rig, label=f"Example 2, {style.stiffness_label(stiffness)}")
        ax.set(xlabel=axis_label("stiffness_ratio"), xlim=(ratios[0], ratios[-1]))
        ax.grid(alpha=0.3)
    ax_ratio.set_ylabel(axis_label("ecof_ratio"))
    title = rf"Energy CoF over the contact CoF, $\mu$ = {scalar(dataset, 'mu'):g}"
    ax_ratio.set_title(title, fontsize="medium")
    ax_ratio.legend(loc="upper left", fontsize="small")
    ax_error.set_ylabel(r"Error of $\mu'$ from the D/W shortcut, $\mu'/\mu - 1$ [%]")
    title = r"The D/W shortcut: $\mu_E$ of each scar corrected as if it were the parabola"
    ax_error.set_title(title, fontsize="medium")
    ax_error.legend(loc="upper right", fontsize="small")
