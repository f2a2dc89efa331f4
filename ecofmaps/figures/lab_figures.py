"""The campaign figure of a fretting lab: the running-condition fretting map (docs/lab.md)."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ecofmaps.figures.style import FIGSIZE, MICRO, axis_label, parameters, stiffness_label
from ecofmaps.lab import per_cycle, sliding_condition

__all__ = ["running_condition_map"]

#: How each sliding condition is marked on the running-condition map: marker, face colour.
_CONDITION_MARKERS = {
    "partial slip": ("o", "white"),
    "mixed slip": ("D", "0.6"),
    "gross slip": ("s", "black"),
}


def running_condition_map(results, transition: xr.Dataset, rig_stiffness: float) -> Figure:
    r"""The running-condition fretting map of a campaign, with the transition line.

    Parameters
    ----------
    results : list of xarray.Dataset
        Each test's results from :func:`ecofmaps.analyze_loops`.
    transition : xarray.Dataset
        From :func:`ecofmaps.transition`: the contact's transition amplitude
        :math:`\delta_t` and :math:`\mu_t`.
    rig_stiffness : float
        The rig's own stiffness :math:`S`. [N/m]

    Returns
    -------
    figure : matplotlib.figure.Figure
        Each test at its median amplitude :math:`\Delta^*` [µm] and load :math:`P` [N],
        marked by its sliding condition (:func:`ecofmaps.sliding_condition`), and the line
        :math:`\Delta_t(P) = \delta_t + \mu_t P/S` between partial and gross slip.

    References
    ----------
    L. Vincent, Y. Berthier, M. Godet (1992), Testing methods in fretting fatigue: a
    critical appraisal, ASTM STP 1159, 33-48.
    """
    figure = Figure(figsize=FIGSIZE, layout="constrained")
    ax = figure.add_subplot()
    drawn = set()
    for test in results:
        cycles = per_cycle(test, ("amplitude",))
        condition = sliding_condition(test, rig_stiffness).attrs["sliding_condition"]
        marker, face = _CONDITION_MARKERS[condition]
        ax.plot(
            np.nanmedian(cycles["amplitude"]) * MICRO,
            np.nanmedian(cycles["load"]),
            marker=marker,
            markerfacecolor=face,
            markeredgecolor="black",
            linestyle="",
            label=None if condition in drawn else condition,
        )
        drawn.add(condition)
    top = 1.15 * ax.get_ylim()[1]
    load = np.linspace(0.0, top, 50)
    line = float(transition.contact_amplitude) + float(transition.mu) * load / rig_stiffness
    ax.plot(
        line * MICRO, load, color="tab:red", label=r"transition $\Delta_t = \delta_t + \mu_t P/S$"
    )
    ax.set_xlim(0.0, None)
    ax.set_ylim(0.0, top)
    ax.set_xlabel(axis_label("amplitude"))
    ax.set_ylabel(axis_label("load"))
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize="small")
    ax.set_title(
        "Running-condition fretting map\n"
        + parameters(
            rf"$\delta_t$ = {float(transition.contact_amplitude) * MICRO:.3g} µm",
            rf"$\mu_t$ = {float(transition.mu):.3g}",
            stiffness_label(rig_stiffness),
        ),
        fontsize="medium",
    )
    return figure
