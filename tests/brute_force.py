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


# --- grooves of any shape -----------------------------------------------------------------


class ProfileBruteForce:
    """The steady loop on a sampled profile by brute force, independent of ecofmaps.

    The slope is ``numpy.interp`` of the samples (piecewise linear, as the model takes it).
    Positions are in units of the amplitude, ξ = x/Δ*, and the pad sees the profile at
    X = ξ·length (length = Δ*·W/x_o, or Δ* for the physical mapping). The slip branches
    F±(ξ) = ξ + λ q±(ξ), λ = P/(SΔ*), are tabulated on a grid of ``refine`` points per
    sample interval; a first passage is the first grid point whose running extremum
    reaches the level, refined by brentq. The return map is iterated from rest at ξ = 0
    until the loop repeats, and E_d = S Δ*² ∫ (ξ_back(D) − ξ_forward(D)) dD over the
    actuator position D = Δ/Δ* by quad, split at the levels where the pad jumps.
    """

    def __init__(self, position, slope, amplitude, load, stiffness, mu, length, refine=16):
        import numpy as np

        self.np = np
        self.position = np.asarray(position, float)
        self.slope_samples = np.asarray(slope, float)
        self.length = float(length)
        self.mu = float(mu)
        self.lam = 0.0 if math.isinf(stiffness) else load / (stiffness * amplitude)
        fractions = np.arange(refine) / refine
        steps = np.diff(self.position)
        grid = (self.position[:-1, None] + fractions[None, :] * steps[:, None]).ravel()
        self.grid = np.append(grid, self.position[-1]) / self.length
        self.amplitude, self.load, self.stiffness = amplitude, load, stiffness

    def slope(self, xi):
        return self.np.interp(self.np.asarray(xi) * self.length, self.position, self.slope_samples)

    def forward_branch(self, xi):
        """F+(ξ) = ξ + λ (μ + g)/(1 − μ g) (eq. 9, 10); +inf at and beyond locking."""
        g = self.slope(xi)
        w = 1.0 - self.mu * g
        with self.np.errstate(divide="ignore", invalid="ignore"):
            q = self.np.where(w > 0, (self.mu + g) / w, self.np.inf)
        return xi + (self.lam * q if self.lam > 0 else 0.0)

    def backward_branch(self, xi):
        """F−(ξ) = ξ + λ (g − μ)/(1 + μ g); −inf at and beyond locking."""
        g = self.slope(xi)
        w = 1.0 + self.mu * g
        with self.np.errstate(divide="ignore", invalid="ignore"):
            q = self.np.where(w > 0, (g - self.mu) / w, -self.np.inf)
        return xi + (self.lam * q if self.lam > 0 else 0.0)

    def forward(self, start, level):
        """First ξ >= start with F+(ξ) >= level; None if the trace ends first."""
        f = self.forward_branch
        if f(start) >= level:
            return start
        points = self.grid[self.grid > start]
        reached = f(points) >= level
        if not reached.any():
            return None
        i = int(self.np.argmax(reached))
        low = start if i == 0 else points[i - 1]
        if self.lam == 0.0:
            return level
        return brentq(lambda x: f(x) - level, low, points[i], xtol=1e-16, rtol=8.9e-16)

    def backward(self, start, level):
        """Last ξ <= start with F−(ξ) <= level; None if the trace ends first."""
        f = self.backward_branch
        if f(start) <= level:
            return start
        points = self.grid[self.grid < start][::-1]
        reached = f(points) <= level
        if not reached.any():
            return None
        i = int(self.np.argmax(reached))
        high = start if i == 0 else points[i - 1]
        if self.lam == 0.0:
            return level
        return brentq(lambda x: f(x) - level, points[i], high, xtol=1e-16, rtol=8.9e-16)

    def loop(self, cycles=8):
        """The loop's ends (ξ−, ξ+) after iterating the return map; None if off the trace."""
        x, ends = 0.0, []
        for _ in range(cycles):
            plus = self.forward(x, 1.0)
            if plus is None:
                return None
            minus = self.backward(plus, -1.0)
            if minus is None:
                return None
            ends.append((minus, plus))
            x = minus
        assert ends[-1] == ends[-2], "the return map has not settled"
        return ends[-1]

    def steady_loop(self):
        """δ*, E_d and μ_E (eq. 1), or None when the pad runs off the trace.

        E_d = ∮ Q dx = S Δ*² ∫ (M+ − M−) dξ over the slip, where M+ is the running maximum
        of F+ from ξ− (the actuator position while the pad slips or jumps forward) and M− the
        running minimum of F− from ξ+; with Q±/P = q±, the integrand is
        λ (q+ − q−) + (M+ − F+) − (M− − F−). The running extrema come from the grid (and
        the point itself); quad is split at every sample.
        """
        np = self.np
        ends = self.loop()
        if ends is None:
            return None
        minus, plus = ends
        slip = 0.5 * (plus - minus)
        inside = (self.grid > minus) & (self.grid < plus)
        points = self.grid[inside]
        rising = np.maximum.accumulate(
            np.concatenate([[self.forward_branch(minus)], self.forward_branch(points)])
        )
        falling = np.minimum.accumulate(
            np.concatenate([[self.backward_branch(plus)], self.backward_branch(points[::-1])])
        )[::-1]  # falling[i]: min of F− over [points[i], plus]; its last entry is F−(plus)

        def jumps(x):
            i = int(np.searchsorted(points, x, side="right"))  # grid points in (minus, x]
            ahead = max(rising[i], self.forward_branch(x)) - self.forward_branch(x)
            j = int(np.searchsorted(points, x, side="left"))  # grid points in [x, plus)
            behind = min(falling[j], self.backward_branch(x)) - self.backward_branch(x)
            return ahead - behind

        samples = self.position / self.length
        breaks = list(samples[(samples > minus) & (samples < plus)])
        traction, _ = quad(
            lambda x: self.forward_traction(x) - self.backward_traction(x), minus, plus,
            points=breaks or None, epsabs=0.0, epsrel=1e-13, limit=4 * len(breaks) + 100,
        )  # fmt: skip
        jump = 0.0
        if self.lam > 0.0:
            jump, _ = quad(
                jumps, minus, plus, points=breaks or None, epsabs=1e-15, epsrel=1e-12,
                limit=4 * len(breaks) + 100,
            )  # fmt: skip
            jump /= self.lam
        integral = traction + jump  # ∫ (M+ − M−) dξ / λ
        return {
            "slip_amplitude": slip * self.amplitude,
            "dissipated_energy": self.load * self.amplitude * integral,
            "ecof": integral / (4.0 * slip) if slip > 0 else math.nan,
            "minus": minus,
            "plus": plus,
            "jumps": bool(jump > 0.0),
        }

    def forward_traction(self, xi):
        """Q+/P = (μ + g)/(1 − μ g), eq. 9."""
        g = self.slope(xi)
        return (self.mu + g) / (1.0 - self.mu * g)

    def backward_traction(self, xi):
        """Q−/P = (g − μ)/(1 + μ g), eq. 9."""
        g = self.slope(xi)
        return (g - self.mu) / (1.0 + self.mu * g)
