"""A fretting lab's figures: a campaign's running-condition fretting map, and a test's
loop-scar closure (docs/lab.md)."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ecofmaps.figures import style
from ecofmaps.figures.style import MICRO, axis_label, number_text, stiffness_label
from ecofmaps.lab import per_cycle, sliding_condition

#: How each sliding condition is marked on the running-condition map.
_CONDITION_MARKERS = {
    "partial slip": dict(marker="o", markerfacecolor="white"),
    "mixed slip": dict(marker="D", markerfacecolor="0.6"),
    "gross slip": dict(marker="s", markerfacecolor="black"),
}


def running_condition_map(results, transition: xr.Dataset, rig_stiffness: float) -> Figure:
    r"""The running-condition fretting map of a campaign, with the transition line.

    Parameters
    ----------
    results : list of xarray.Dataset
        Each test's results from :func:`ecofmaps.analyze_loops`.
    transition : xarray.Dataset
        From :func:`ecofmaps.transition`: the contact's :math:`\delta_t` and :math:`\mu_t`.
    rig_stiffness : float
        The rig's own stiffness :math:`S`. [N/m]

    Returns
    -------
    figure : matplotlib.figure.Figure
        Each test at its median :math:`\Delta^*` [µm] and :math:`P` [N], marked by its
        sliding condition, and the transition :math:`\Delta_t(P) = \delta_t + \mu_t P/S`.

    References
    ----------
    L. Vincent, Y. Berthier, M. Godet (1992), Testing methods in fretting fatigue: a
    critical appraisal, ASTM STP 1159, 33-48.
    """
    figure = Figure(figsize=style.FIGSIZE, layout="constrained")
    ax = figure.add_subplot()
    drawn = set()
    for test in results:
        cycles = per_cycle(test, ("amplitude",))
        condition = sliding_condition(test, rig_stiffness).attrs["sliding_condition"]
        look = dict(_CONDITION_MARKERS[condition], markeredgecolor="black", linestyle="")
        look["label"] = None if condition in drawn else condition
        ax.plot(np.nanmedian(cycles["amplitude"]) * MICRO, np.nanmedian(cycles["load"]), **look)
        drawn.add(condition)
    top = 1.15 * ax.get_ylim()[1]
    load = np.linspace(0.0, top, 50)
    line = float(transition.contact_amplitude) + float(transition.mu) * load / rig_stiffness
    label = r"transition $\Delta_t = \delta_t + \mu_t P/S$"
    ax.plot(line * MICRO, load, color="tab:red", label=label)
    ax.set(xlim=(0.0, None), ylim=(0.0, top))
    ax.set(xlabel=axis_label("amplitude"), ylabel=axis_label("load"))
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize="small")
    contact = [rf"$\delta_t$ = {float(transition.contact_amplitude) * MICRO:.3g} µm"]
    contact += [rf"$\mu_t$ = {float(transition.mu):.3g}", stiffness_label(rig_stiffness)]
    ax.set_title(f"Running-condition fretting map\n{style.parameters(*contact)}", fontsize="medium")
    return figure


def loop_scar_closure_figure(closure: xr.Dataset) -> Figure:
    r"""The loop-scar closure of a test: its last loop and its scar against the model's.

    Parameters
    ----------
    closure : xarray.Dataset
        From :func:`ecofmaps.loop_scar_closure`.

    Returns
    -------
    figure : matplotlib.figure.Figure
        (a) The measured loop and the model's on the profile (:math:`\mu` = the GICoF),
        :math:`Q` [N] against :math:`\Delta` [µm]; (b) the profile and the scar the loops
        imply, :math:`\int g\,d\xi` [µm]; each titled by its RMS residual.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: Fig. 10.
    """
    figure = Figure(figsize=(2 * style.FIGSIZE[0], style.FIGSIZE[1]), layout="constrained")
    loop, scar = figure.subplots(1, 2)
    measured, model = dict(color="0.55", linewidth=2.5), dict(color="tab:red", linewidth=1.2)
    label = f"measured, cycle {int(closure.cycle)}"
    loop.plot(closure.loop_displacement * MICRO, closure.loop_force, **measured, label=label)
    label = rf"model on the profile, $\mu$ = GICoF = {float(closure.mu):.3g}"
    loop.plot(closure.model_displacement * MICRO, closure.model_force, **model, label=label)
    loop.set(xlabel=axis_label("displacement"), ylabel=axis_label("force"))
    off = f"RMS force off the model {number_text(100 * float(closure.loop_residual), 2)} % of Q*"
    loop.set_title(
        style.parameters(off, stiffness_label(float(closure.stiffness))), fontsize="medium"
    )
    position = closure.position * MICRO
    scar.plot(position, closure.scar_height * MICRO, **measured, label="profile")
    label = r"implied by the loops, $\int g\,d\xi$"
    scar.plot(position, closure.implied_scar * MICRO, **model, label=label)
    scar.set(xlabel=axis_label("scar_position"), ylabel=axis_label("scar_height"))
    off = f"RMS height off the profile {number_text(float(closure.scar_residual) * MICRO, 2)} µm"
    share = number_text(100 * float(closure.scar_relative_residual), 2)
    scar.set_title(f"{off} ({share} % of the depth)", fontsize="medium")
    for ax in (loop, scar):
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    figure.suptitle("Loop-scar closure")
    return figure
