"""A quasi-static stick/slip return map for a groove of any slope, independent of ecofmaps.

Used by the tests of the stroke-resolved reading (``ecofmaps.resolve_loops``) to make the
loops of shaped grooves (flat-bottomed, W-shaped, ridged, tilted). Plain NumPy and SciPy,
one time step at a time: slow, and simple enough to trust.

At slip position x the pad feels the local slope g(x); eq. 9 holds pointwise,
Q±(x) = P (±μ + g)/(1 ∓ μ g). While Q₋(x) <= S (Δ − x) <= Q₊(x) the contact sticks;
otherwise it slips to the first equilibrium x' + Q±(x')/S = Δ met on the way (first
passage: a fine scan from x, then brentq in the cell where the sign changes).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq


def traction(x, slope, load, mu, direction):
    """Q±(x) = P (±μ + g(x)) / (1 ∓ μ g(x)), eq. 9 at the local slope. [N]"""
    g = slope(x)
    return load * (direction * mu + g) / (1.0 - direction * mu * g)


def _first_passage(x, target, slope, load, stiffness, mu, direction, step):
    """First x' beyond x (in ``direction``) with x' + Q±(x')/S = target."""

    def residual(position):
        return direction * (
            position + traction(position, slope, load, mu, direction) / stiffness - target
        )

    # residual(x) < 0 when the rig pulls harder than the contact holds.
    here = x
    while True:
        ahead = here + direction * step * np.arange(1, 1025)
        values = residual(ahead)
        crossed = np.flatnonzero(values >= 0.0)
        if crossed.size:
            first = crossed[0]
            before = here if first == 0 else ahead[first - 1]
            low, high = sorted((before, ahead[first]))
            return brentq(residual, low, high, xtol=1e-22, rtol=8.9e-16, maxiter=200)
        here = ahead[-1]


def return_map(displacement, load, stiffness, mu, slope, step=1e-9):
    """Tangential force for an actuator displacement history over a groove of slope g(x).

    Parameters
    ----------
    displacement : array_like
        Actuator displacement Δ at successive instants. [m]
    load, stiffness, mu : float
        Normal load P [N], rig stiffness S [N/m], contact coefficient of friction [1].
    slope : callable
        The groove slope g(x) at contact position x [m], vectorised over NumPy arrays.
    step : float
        Scan step of the first-passage search. [m]

    Returns
    -------
    force, position : numpy.ndarray
        The tangential force Q [N] and the contact position x [m] at each instant, from
        rest at x = 0, Q = 0.
    """
    x = 0.0
    force = np.empty(len(displacement))
    position = np.empty(len(displacement))
    for i, target in enumerate(np.asarray(displacement, dtype=float)):
        trial = stiffness * (target - x)
        if trial > traction(x, slope, load, mu, 1.0):
            x = _first_passage(x, target, slope, load, stiffness, mu, 1.0, step)
            trial = traction(x, slope, load, mu, 1.0)
        elif trial < traction(x, slope, load, mu, -1.0):
            x = _first_passage(x, target, slope, load, stiffness, mu, -1.0, step)
            trial = traction(x, slope, load, mu, -1.0)
        force[i] = trial
        position[i] = x
    return force, position
