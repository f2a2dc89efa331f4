r"""Slip branches resampled at given contact positions, and the weight of each sample.

Each branch is a row of slip samples sorted by contact position :math:`\xi` (padded with
+inf). :func:`resample` reads it at positions by the linear fraction through three
samples, which is eq. 9 on a parabolic groove; :func:`read_branches` reads both branches
and turns them into :math:`\mu(\xi)` and :math:`g(\xi)`; :func:`branch_noise` and
:func:`sample_weights` give what the standard errors need. The method is described in
:mod:`ecofmaps.measured.resolved`.
"""

from __future__ import annotations

import numpy as np

from ecofmaps.measured.stick_slip import masked_sum

__all__ = ["branch_noise", "read_branches", "resample", "sample_weights"]


def resample(xs, qs, count, grid, scale, inside):
    r"""``qs(xs)`` at the positions ``scale * grid`` (one row per cycle), by 3-point fractions.

    ``xs`` rows are sorted, padded with +inf beyond ``count``; ``grid`` is increasing and
    common to the rows, ``scale`` (one per row) stretches it; positions outside
    ``inside`` give NaN. The fraction through three samples around a position (the two
    that bracket it and the one before, or the first three),
    :math:`Q - Q_1 = m d/(1 + c d)` with :math:`d = \xi - \xi_1`, is used where its
    denominator stays above 1/2 over the three samples; elsewhere the line through the
    two samples that bracket the position.

    Returns the values, and the index of the sample before each position and the
    position's share of the way to the next sample (the weights of the straight line).
    """
    cycles, width = xs.shape
    points = grid.size
    at = scale[:, None] * grid[None, :]
    # How many samples lie at or below each position: each sample counts from the first
    # grid point at or above it on (a histogram over the grid, summed).
    with np.errstate(invalid="ignore", divide="ignore"):
        bins = np.searchsorted(grid, xs / scale[:, None], side="left")
    rows = (points + 1) * np.arange(cycles)[:, None]
    histogram = np.bincount((rows + bins).ravel(), minlength=cycles * (points + 1))
    right = np.cumsum(histogram.reshape(cycles, points + 1)[:, :points], axis=1)
    base = width * np.arange(cycles)[:, None]
    left = np.clip(right - 1, 0, np.maximum(count - 2, 0)[:, None])
    # The three samples around the position: left - 1, left, left + 1, or 0, 1, 2 at the start.
    middle = np.clip(left, 1, np.maximum(count - 2, 1)[:, None])
    last = np.maximum(count - 1, 0)[:, None]
    flat_x, flat_q = xs.ravel(), qs.ravel()
    index = [base + np.minimum(middle + k, last) for k in (-1, 0, 1)]
    xa, xb, xc = (flat_x[i] for i in index)
    qa, qb, qc = (flat_q[i] for i in index)
    first = left == middle
    x0, x1 = np.where(first, xb, xa), np.where(first, xc, xb)
    q0, q1 = np.where(first, qb, qa), np.where(first, qc, qb)
    share = np.divide(at - x0, x1 - x0, out=np.zeros_like(x0), where=x1 > x0)
    linear = q0 + share * (q1 - q0)
    # The linear fraction through the three samples.
    da, dc = xa - xb, xc - xb
    fa, fc = qa - qb, qc - qb
    slope_a, slope_c = fa / da, fc / dc
    pole = (slope_c - slope_a) / (fa - fc)
    d = at - xb
    fraction = qb + (slope_a + pole * fa) * d / (1.0 + pole * d)
    safe = (
        (count[:, None] >= 3)
        & (np.minimum(1.0 + pole * da, 1.0 + pole * dc) >= 0.5)
        & np.isfinite(fraction)
    )
    value = np.where(safe, fraction, linear)
    return np.where(inside & (count[:, None] >= 2), value, np.nan), left, share


def read_branches(forward, backward, grid, scale, inside, load):
    """Q+, Q-, μ and g at the positions ``scale * grid``, and the line weights of each branch."""
    q_forward, *line_forward = resample(*forward, grid, scale, inside)
    q_backward, *line_backward = resample(*backward, grid, scale, inside)
    up = np.arctan(q_forward / load)
    down = np.arctan(q_backward / load)
    mu = np.tan(0.5 * (up - down))
    slope = np.tan(0.5 * (up + down))
    return q_forward, q_backward, mu, slope, (line_forward, line_backward)


def branch_noise(xs, qs, count, central):
    """Standard deviation of a branch's samples about the branch, in its central part.

    Each sample is compared with the line through its two neighbours; the residual's
    variance is σ² (1 + u² + (1 - u)²) for white noise of σ, u the sample's share of the
    way between them.
    """
    x0, x1, x2 = xs[:, :-2], xs[:, 1:-1], xs[:, 2:]
    q0, q1, q2 = qs[:, :-2], qs[:, 1:-1], qs[:, 2:]
    u = np.divide(x1 - x0, x2 - x0, out=np.full_like(x0, 0.5), where=x2 > x0)
    residual = q1 - q0 - u * (q2 - q0)
    use = (np.arange(1, xs.shape[1] - 1)[None, :] < (count - 1)[:, None]) & (
        np.abs(x1) <= central[:, None]
    )
    return np.sqrt(masked_sum(residual**2, use) / masked_sum(1.0 + u**2 + (1.0 - u) ** 2, use))


def sample_weights(left, share, gain, width):
    """Weight of each sample of a branch in a sum over grid points of ``gain`` times its value.

    The grid value is read as the straight line between samples ``left`` and ``left + 1``.
    """
    cycles = left.shape[0]
    base = (width * np.arange(cycles))[:, None]
    gain = np.where(np.isfinite(gain), gain, 0.0)
    index = np.concatenate([(base + left).ravel(), (base + left + 1).ravel()])
    weight = np.concatenate([(gain * (1.0 - share)).ravel(), (gain * share).ravel()])
    return np.bincount(index, weight, minlength=cycles * width + 1)[: cycles * width].reshape(
        cycles, width
    )
