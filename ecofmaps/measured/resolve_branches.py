"""The numerics of the reading along the stroke: the stiffness and the slip of each branch, the
branches resampled at contact positions, their noise and the weights of their samples in the
standard errors (``docs/method-loops.md``)."""

from __future__ import annotations

import numpy as np

from ecofmaps.measured.measure import SECOND_DIFFERENCE

__all__ = [
    "branch_noise",
    "masked_median",
    "masked_sum",
    "read_branches",
    "sample_weights",
    "slip_branches",
]

#: A given stiffness does not fit when it tilts the stick sets by this many σ.
_TILT_SPREAD = 3.0
#: Fewest samples in a stick set to measure the stiffness, the stick level and the noise.
_STICK_SAMPLES = 3
#: The stick set ends this share of the force swing before the first slip sample.
_STICK_MARGIN = 0.05
#: A sample has moved off the stick level, noise-free, beyond this share of Δ*.
_ROUNDING = 1e-9
#: Slip samples at the end of a branch whose median ξ is compared with the next stick level.
_END_SAMPLES = 4


def masked_sum(values, mask):
    """Sum of each row over ``mask`` (NaN elsewhere is ignored)."""
    return np.sum(np.where(mask, values, 0.0), axis=-1)


def masked_median(values, mask):
    """Median of each row over ``mask`` (NaN for an empty row)."""
    ordered = np.sort(np.where(mask, values, np.inf), axis=-1)
    count = np.count_nonzero(mask, axis=-1)
    low = np.take_along_axis(ordered, np.maximum(count - 1, 0)[:, None] // 2, axis=-1)[:, 0]
    high = np.take_along_axis(ordered, count[:, None] // 2, axis=-1)[:, 0]
    return np.where(count > 0, 0.5 * (low + high), np.nan)


def _branches(x, valid):
    """Masks of the rising branch (start to top) and of the falling one (top to the end)."""
    top = np.argmax(np.where(valid, x, -np.inf), axis=1)
    j = np.arange(x.shape[1])[None, :]
    return valid & (j <= top[:, None]), valid & (j >= top[:, None])


def _span(q, mask):
    """Range of ``q`` over ``mask``, per row."""
    return np.max(np.where(mask, q, -np.inf), axis=1) - np.min(np.where(mask, q, np.inf), axis=1)


def _at_first(values, mask):
    """``values`` at the first sample of ``mask``, per row (a column)."""
    return np.take_along_axis(values, np.argmax(mask, axis=1)[:, None], axis=1)


def _enough(stick):
    """True for the rows of ``stick`` with samples enough to judge."""
    return np.count_nonzero(stick, axis=1) >= _STICK_SAMPLES


def _before(mask, branch):
    """The samples of ``branch`` before the first sample of ``mask``."""
    return branch & ~np.maximum.accumulate(branch & mask, axis=1)


def _compliance(x, q, sticks):
    """Least-squares compliance common to lines Δ = ξ_s + cQ through each stick set."""
    covariance, variance = np.zeros((2, x.shape[0]))
    centred = []
    for mask in sticks:
        count = np.count_nonzero(mask, axis=1)[:, None]
        dq = q - masked_sum(q, mask)[:, None] / count
        dx = x - masked_sum(x, mask)[:, None] / count
        covariance += masked_sum(dq * dx, mask)
        variance += masked_sum(dq * dq, mask)
        centred.append((dq, dx))
    compliance = covariance / variance
    squares = sum(
        masked_sum((dx - compliance[:, None] * dq) ** 2, mask)
        for (dq, dx), mask in zip(centred, sticks, strict=True)
    )
    points = sum(np.count_nonzero(mask, axis=1) for mask in sticks)
    return compliance, np.sqrt(squares / np.maximum(points - 3, 1) / variance)


def _stick_and_slip(xi, branches, sticks, floor, slip_threshold):
    """Noise and the slip of each branch."""
    # σ from the second differences within the stick sets: a smooth trend of ξ (a rounded
    # loop, a wrong stiffness) hardly enters them, white noise does with variance 6σ².
    second = np.abs(xi[:, :-2] - 2.0 * xi[:, 1:-1] + xi[:, 2:])
    triples = np.zeros_like(second, dtype=bool)
    for stick in sticks:
        triples |= stick[:, :-2] & stick[:, 1:-1] & stick[:, 2:]
    sigma = masked_median(second, triples) / SECOND_DIFFERENCE
    sigma = np.where(np.isfinite(sigma), sigma, 0.0)
    threshold = slip_threshold * sigma + floor
    slips, levels = [], []
    for branch, stick, sign in zip(branches, sticks, (1.0, -1.0), strict=True):
        # The stick level: the set's median, or the reversal's ξ where the set has too few
        # samples to judge (a sparse loop, or the model's loop drawn with straight sides).
        level = np.where(_enough(stick), masked_median(xi, stick), _at_first(xi, branch)[:, 0])
        # Slip: beyond the threshold, and every later sample of the branch too.
        beyond = np.where(branch, sign * xi, np.inf)
        least = np.minimum.accumulate(beyond[:, ::-1], axis=1)[:, ::-1]
        slips.append(branch & (least > (sign * level + threshold)[:, None]))
        levels.append(level)
    return sigma, slips, levels


def _branch_shift(xi, slips, levels):
    r"""How far the rising branch's slip lies beyond the falling one's, in ξ, per cycle."""
    gaps = []
    for slip, level in zip(slips, levels[::-1], strict=True):
        # The last slip samples of the branch in time: its slip runs to the reversal.
        last = slip & (np.cumsum(slip[:, ::-1], axis=1)[:, ::-1] <= _END_SAMPLES)
        gaps.append(masked_median(xi, last) - level)
    return 0.5 * (gaps[0] - gaps[1])


def _tilted_alike(xi, q, sticks, tolerance, floor):
    """True where the stick sets tilt alike in ξ beyond ``tolerance`` (a wrong compliance)."""
    span = np.max([_span(q, stick) for stick in sticks], axis=0)
    judged = np.all([_enough(stick) for stick in sticks], axis=0)
    tilt, _ = _compliance(xi, q, sticks)
    alike = judged & ~(np.abs(tilt) * span <= tolerance)  # NaN: does not fit
    for stick in sticks:
        own, _ = _compliance(xi, q, [stick])
        alike &= ~(np.sign(own) * np.sign(tilt) * np.abs(own) * span <= floor)
    return alike


def _sorted_branch(xi, q, slip):
    """The slip samples of a branch sorted by ξ (padded with +inf / NaN), and their count."""
    key = np.where(slip, xi, np.inf)
    order = np.argsort(key, axis=1, kind="stable")
    return (
        np.take_along_axis(key, order, axis=1),
        np.take_along_axis(np.where(slip, q, np.nan), order, axis=1),
        np.count_nonzero(slip, axis=1),
    )


def slip_branches(x, q, valid, stiffness, amplitude, options):
    """The stiffness (given in ``options``, else fitted), the checks of the stick sets, and the
    two slip branches."""
    cycles, given = x.shape[0], options.stiffness is not None
    floor = _ROUNDING * amplitude
    branches = _branches(x, valid)
    # The share of its branch's force swing by which each sample has moved from the reversal.
    moved = [np.abs(q - _at_first(q, branch)) / _span(q, branch)[:, None] for branch in branches]
    (low, high), slip_threshold = options.stick_window, options.slip_threshold
    windows = [
        _before(share > high, branch) & (share >= low)
        for share, branch in zip(moved, branches, strict=True)
    ]
    # First pass, with the given stiffness or analyze_loops's and the stick windows: where
    # does the slip start?
    start = np.where(np.isinf(stiffness), 0.0, 1.0 / stiffness)
    xi = x - start[:, None] * q
    _, slips, _ = _stick_and_slip(xi, branches, windows, floor, slip_threshold)
    # The stick sets: from the window's lower share up to a margin before the slip.
    sticks = []
    for share, branch, slip, window in zip(moved, branches, slips, windows, strict=True):
        onset = np.where(slip.any(axis=1)[:, None], _at_first(share, slip), high + _STICK_MARGIN)
        stick = _before(slip, branch) & (share >= low) & (share <= onset - _STICK_MARGIN)
        sticks.append(np.where(_enough(stick)[:, None], stick, window))
    if given:
        compliance, compliance_se = start, np.zeros(cycles)
    else:
        fitted, fitted_se = _compliance(x, q, sticks)
        measured = np.all([_enough(stick) for stick in sticks], axis=0) & np.isfinite(fitted)
        compliance = np.where(measured, fitted, start)
        compliance_se = np.where(measured, fitted_se, 0.0)
    mismatch = compliance < -3.0 * compliance_se  # the stick sides slope down
    compliance = np.maximum(compliance, 0.0)
    # Second pass, with the stiffness used and the stick sets.
    xi = x - compliance[:, None] * q
    sigma, slips, levels = _stick_and_slip(xi, branches, sticks, floor, slip_threshold)
    if given:  # a stiffness that does not fit the stick sides tilts both alike in ξ
        mismatch = mismatch | _tilted_alike(xi, q, sticks, _TILT_SPREAD * sigma + floor, floor)
    shift = _branch_shift(xi, slips, levels)
    forward, backward = (_sorted_branch(xi, q, slip) for slip in slips)
    ends = []
    for xs, _, count in (forward, backward):
        last = np.take_along_axis(xs, np.maximum(count - 1, 0)[:, None], axis=1)[:, 0]
        ends.append((np.where(count > 0, xs[:, 0], np.nan), np.where(count > 0, last, np.nan)))
    return {
        "compliance": compliance,
        "compliance_se": compliance_se,
        "mismatch": mismatch,
        "shift": shift,
        "forward": forward,
        "backward": backward,
        "lowest": np.maximum(ends[0][0], ends[1][0]),
        "highest": np.minimum(ends[0][1], ends[1][1]),
    }


def _resample(xs, qs, count, grid, scale, inside):
    r"""``qs(xs)`` at the positions ``scale * grid`` (one row per cycle), by 3-point fractions."""
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
    index = [base + np.minimum(middle + k, last) for k in (-1, 0, 1)]
    xa, xb, xc = (xs.ravel()[i] for i in index)
    qa, qb, qc = (qs.ravel()[i] for i in index)
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
    q_forward, *line_forward = _resample(*forward, grid, scale, inside)
    q_backward, *line_backward = _resample(*backward, grid, scale, inside)
    up, down = np.arctan(q_forward / load), np.arctan(q_backward / load)
    mu, slope = np.tan(0.5 * (up - down)), np.tan(0.5 * (up + down))
    return q_forward, q_backward, mu, slope, (line_forward, line_backward)


def branch_noise(xs, qs, count, central):
    """Standard deviation of a branch's samples about the branch, in its central part."""
    x0, x1, x2 = xs[:, :-2], xs[:, 1:-1], xs[:, 2:]
    q0, q1, q2 = qs[:, :-2], qs[:, 1:-1], qs[:, 2:]
    u = np.divide(x1 - x0, x2 - x0, out=np.full_like(x0, 0.5), where=x2 > x0)
    residual = q1 - q0 - u * (q2 - q0)
    use = (np.arange(1, xs.shape[1] - 1)[None, :] < (count - 1)[:, None]) & (
        np.abs(x1) <= central[:, None]
    )
    return np.sqrt(masked_sum(residual**2, use) / masked_sum(1.0 + u**2 + (1.0 - u) ** 2, use))


def sample_weights(left, share, gain, width):
    """Weight of each sample of a branch in a sum over grid points of ``gain`` times its value."""
    cycles = left.shape[0]
    base = (width * np.arange(cycles))[:, None]
    gain = np.where(np.isfinite(gain), gain, 0.0)
    index = np.concatenate([(base + left).ravel(), (base + left + 1).ravel()])
    weight = np.concatenate([(gain * (1.0 - share)).ravel(), (gain * share).ravel()])
    return np.bincount(index, weight, minlength=cycles * width + 1)[: cycles * width].reshape(
        cycles, width
    )
