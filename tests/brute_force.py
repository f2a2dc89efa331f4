"""Brute-force steady-loop quantities, independent of ecofmaps: root finding and quadrature.

Used by the tests and by ``tests/benchmarks/bench_maps.py`` as the reference the closed forms
must reproduce. Plain Python floats, SciPy only, with the groove half-width x_o = Δ*.
"""

from __future__ import annotations

import math

from scipy.integrate import quad
from scipy.optimize import brentq


def forward_traction(x, load, mu, slope_per_length):
    """Q_+(x) = P (μ + k x)/(1 − μ k x), eq. 9. [N]"""
    slope = slope_per_length * x
    return load * (mu + slope) / (1.0 - mu * slope)


def steady_loop(amplitude, load, stiffness, mu, aspect_ratio):
    """δ*, Q*, E_d and μ_E by brentq on eq. 16 and quad of eq. 12.

    Parameters are SI (m, N, N/m, 1, 1); stiffness may be ``math.inf``. Returns a dict with
    ``slip_amplitude`` [m], ``max_force`` [N], ``dissipated_energy`` [J] and ``ecof`` [1]
    (NaN with no gross slip); ``None`` when a rigid rig self-locks.
    """
    k = 2.0 * aspect_ratio / amplitude  # eq. 7 with x_o = Δ*
    if mu * load / stiffness >= amplitude:  # no gross slip: the rig takes the whole stroke
        return {
            "slip_amplitude": 0.0,
            "max_force": stiffness * amplitude,
            "dissipated_energy": 0.0,
            "ecof": math.nan,
        }
    if math.isinf(stiffness):
        if mu * k * amplitude >= 1.0:
            return None
        slip = amplitude
    else:
        # eq. 16: δ + Q_+(δ)/S = Δ*, bracketed by 0 and the smaller of Δ* and the locking
        # point 1/(μk), where the left side runs to +inf.
        upper = amplitude if mu * k * amplitude < 1.0 else (1.0 - 1e-15) / (mu * k)

        def residual(x):
            return x + forward_traction(x, load, mu, k) / stiffness - amplitude

        slip = brentq(residual, 0.0, upper, xtol=1e-30, rtol=4 * 2.2205e-16, maxiter=500)
    energy, _ = quad(
        forward_traction, -slip, slip, args=(load, mu, k), epsabs=0.0, epsrel=1e-13, limit=200
    )
    energy *= 2.0  # eq. 12
    return {
        "slip_amplitude": slip,
        "max_force": forward_traction(slip, load, mu, k),
        "dissipated_energy": energy,
        "ecof": energy / (4.0 * load * slip),  # eq. 1
    }
