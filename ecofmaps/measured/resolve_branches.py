"""The numerics of the reading along the stroke: the stiffness and the slip of each branch, the
branches resampled at contact positions, the values along the stroke and per cycle, their noise
and the weights of their samples in the standard errors (``docs/method-loops.md``)."""

from __future__ import annotations

import numpy as np

from ecofmaps._interrupts import check_interrupted
from ecofmaps.measured import quality
from ecofmaps.measured.measure import SECOND_DIFFERENCE

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


def _masked_sum(values, mask):
    """Sum of each row over ``mask`` (NaN elsewhere is ignored)."""
    return np.sum(np.where(mask, values, 0.0), axis=-1)


def _masked_median(values, mask):
    """Median of each row over ``mask`` (NaN for an empty row)."""
    ordered = np.sort(np.where(mask, values, np.inf), axis=-1)
    count = np.count_nonzero(mask, axis=-1)
    low = np.take_along_axis(ordered, np.maximum(count - 1, 0)[:, None] // 2, axis=-1)[:, 0]
    high = np.take_along_axis(ordered, count[:, None] // 2, axis=-1)[:, 0]
    return np.where(count > 0, 0.5 * (low + high), np.nan)


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
        dq = q - _masked_sum(q, mask)[:, None] / count
        dx = x - _masked_sum(x, mask)[:, None] / count
        covariance += _masked_sum(dq * dx, mask)
        variance += _masked_sum(dq * dq, mask)
        centred.append((dq, dx))
    compliance = covariance / variance
    squares = sum(
        _masked_sum((dx - compliance[:, None] * dq) ** 2, mask)
        for (dq, dx), mask in zip(centred, sticks, strict=True)
    )
    points = sum(np.count_nonzero(mask, axis=1) for mask in sticks)
    return compliance, np.sqrt(squares / np.maximum(points - 3, 1) / variance)


def _stick_and_slip(xi, branches, sticks, floor, slip_threshold):
    """Noise and the slip of each branch."""
    # σ from the second differences in the stick sets (a smooth trend of ξ hardly enters them).
    second = np.abs(xi[:, :-2] - 2.0 * xi[:, 1:-1] + xi[:, 2:])
    triples = np.zeros_like(second, dtype=bool)
    for stick in sticks:
        triples |= stick[:, :-2] & stick[:, 1:-1] & stick[:, 2:]
    sigma = _masked_median(second, triples) / SECOND_DIFFERENCE
    sigma = np.where(np.isfinite(sigma), sigma, 0.0)
    threshold = slip_threshold * sigma + floor
    slips, levels = [], []
    for branch, stick, sign in zip(branches, sticks, (1.0, -1.0), strict=True):
        # The stick level: the set's median, or the reversal's ξ where the set is too small.
        level = np.where(_enough(stick), _masked_median(xi, stick), _at_first(xi, branch)[:, 0])
        # Slip: beyond the threshold, and every later sample of the branch too.
        beyond = np.where(branch, sign * xi, np.inf)
        least = np.minimum.accumulate(beyond[:, ::-1], axis=1)[:, ::-1]
        slips.append(branch & (least > (sign * level + threshold)[:, None]))
        levels.append(level)
    return sigma, slips, levels


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
    qs = np.take_along_axis(np.where(slip, q, np.nan), order, axis=1)
    return np.take_along_axis(key, order, axis=1), qs, np.count_nonzero(slip, axis=1)


def _slip_branches(x, q, valid, stiffness, amplitude, options):
    """The stiffness (given, else fitted), the checks of the stick sets and the slip branches."""
    cycles, given = x.shape[0], options.stiffness is not None
    floor = _ROUNDING * amplitude
    top = np.argmax(np.where(valid, x, -np.inf), axis=1)[:, None]
    j = np.arange(x.shape[1])[None, :]
    branches = valid & (j <= top), valid & (j >= top)  # rising to the top, falling from it
    # The share of its branch's force swing by which each sample has moved from the reversal.
    moved = [np.abs(q - _at_first(q, branch)) / _span(q, branch)[:, None] for branch in branches]
    (low, high), slip_threshold = options.stick_window, options.slip_threshold
    windows = [
        _before(share > high, branch) & (share >= low)
        for share, branch in zip(moved, branches, strict=True)
    ]
    # First pass, with the given or analyze_loops's stiffness and the windows: where is slip?
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
    gaps = []  # how far the rising branch's slip lies beyond the falling one's, in ξ
    for slip, level in zip(slips, levels[::-1], strict=True):
        # The last slip samples of the branch in time: its slip runs to the reversal.
        last = slip & (np.cumsum(slip[:, ::-1], axis=1)[:, ::-1] <= _END_SAMPLES)
        gaps.append(_masked_median(xi, last) - level)
    shift = 0.5 * (gaps[0] - gaps[1])
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
    (cycles, width), points = xs.shape, grid.size
    at = scale[:, None] * grid[None, :]
    # How many samples lie at or below each position: a histogram over the grid, summed.
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


def _read_branches(forward, backward, grid, scale, inside, load):
    """Q+, Q-, μ and g at the positions ``scale * grid``, and the line weights of each branch."""
    q_forward, *line_forward = _resample(*forward, grid, scale, inside)
    q_backward, *line_backward = _resample(*backward, grid, scale, inside)
    up, down = np.arctan(q_forward / load), np.arctan(q_backward / load)
    mu, slope = np.tan(0.5 * (up - down)), np.tan(0.5 * (up + down))
    return q_forward, q_backward, mu, slope, (line_forward, line_backward)


def _branch_noise(xs, qs, count, central):
    """Standard deviation of a branch's samples about the branch, in its central part."""
    x0, x1, x2 = xs[:, :-2], xs[:, 1:-1], xs[:, 2:]
    q0, q1, q2 = qs[:, :-2], qs[:, 1:-1], qs[:, 2:]
    u = np.divide(x1 - x0, x2 - x0, out=np.full_like(x0, 0.5), where=x2 > x0)
    residual = q1 - q0 - u * (q2 - q0)
    use = (np.arange(1, xs.shape[1] - 1)[None, :] < (count - 1)[:, None]) & (
        np.abs(x1) <= central[:, None]
    )
    return np.sqrt(_masked_sum(residual**2, use) / _masked_sum(1.0 + u**2 + (1.0 - u) ** 2, use))


def _sample_weights(left, share, gain, width):
    """Weight of each sample of a branch in a sum over grid points of ``gain`` times its value."""
    cycles = left.shape[0]
    size, base = cycles * width, (width * np.arange(cycles))[:, None]
    gain = np.where(np.isfinite(gain), gain, 0.0)
    index = np.concatenate([(base + left).ravel(), (base + left + 1).ravel()])
    weight = np.concatenate([(gain * (1.0 - share)).ravel(), (gain * share).ravel()])
    return np.bincount(index, weight, minlength=size + 1)[:size].reshape(cycles, width)


#: The reasons that leave a cycle's values NaN, by code (``'gicof-varies'`` comes besides).
_QUALITY_FLAGS = quality.READING_REASONS[:4]
#: Values of μ(ξ) beyond this many robust standard deviations of the median are clipped.
_WINSOR = 3.0
#: The largest lag-one autocorrelation of the block means that is believed.
_R1 = 0.8
#: Cycles analysed together: a block's arrays stay in the processor's cache.
_BLOCK = 512
#: Points of each cycle's own grid over its central part, for the per-cycle values.
_CENTRAL_POINTS = 201
#: The median absolute deviation of a normal distribution over its standard deviation.
_MAD = 1.482602218505602


def _central_values(forward, backward, central, load):
    """mu_resolved, its variance, k and g0 of g ≈ g0 + kξ, the sensitivity to 1/S."""
    width = forward[0].shape[1]
    unit = np.linspace(-1.0, 1.0, _CENTRAL_POINTS)
    at = central[:, None] * unit[None, :]
    inside = np.broadcast_to(np.isfinite(central)[:, None], at.shape)
    q_forward, q_backward, mu, slope, lines = _read_branches(
        forward, backward, unit, central, inside, load
    )
    finite = np.isfinite(mu)
    points = np.count_nonzero(finite, axis=1)
    middle = _masked_median(mu, finite)
    bound = (_WINSOR * _MAD * _masked_median(np.abs(mu - middle[:, None]), finite))[:, None]
    clipped = np.clip(mu, middle[:, None] - bound, middle[:, None] + bound)
    mu_resolved = _masked_sum(clipped, finite) / points
    # The noise variance through each branch's sample weights, of the mean and of the contrast.
    kept = finite & (np.abs(mu - middle[:, None]) <= bound)
    inner = kept & (np.abs(unit) <= 0.5)
    outer = kept & ~inner
    inner_points, outer_points = (np.count_nonzero(m, axis=1)[:, None] for m in (inner, outer))
    contrast = np.where(inner, 1.0 / inner_points, np.where(outer, -1.0 / outer_points, 0.0))
    variation = _masked_sum(mu * contrast, kept)
    factor = 0.5 * (1.0 + mu**2) / load
    variance, variation_variance = np.zeros((2, central.size))
    for branch, force, (left, share), sign in zip(
        (forward, backward), (q_forward, q_backward), lines, (1.0, -1.0), strict=True
    ):
        gain = np.where(kept, sign * factor / (1.0 + (force / load) ** 2), 0.0)
        noise = _branch_noise(*branch, central) ** 2
        weight = _sample_weights(left, share, gain / points[:, None], width)
        variance += noise * np.sum(weight**2, axis=1)
        weight = _sample_weights(left, share, gain * contrast, width)
        variation_variance += noise * np.sum(weight**2, axis=1)
    varies = (np.abs(variation) > quality.VARIATION * np.abs(mu_resolved)) & (
        np.abs(variation) > quality.VARIATION_SIGNIFICANCE * np.sqrt(variation_variance)
    )
    mean_xi, mean_g = _masked_sum(at, finite) / points, _masked_sum(slope, finite) / points
    dxi = at - mean_xi[:, None]
    k = _masked_sum(dxi * (slope - mean_g[:, None]), finite) / _masked_sum(dxi**2, finite)
    # The sensitivities of mu_resolved to the compliance 1/S and to a shift of a branch along ξ.
    turning = k[:, None] / (1.0 + slope**2)
    factor = 0.5 * (1.0 + mu_resolved**2) / points
    sensitivity = factor * _masked_sum(turning * (q_forward - q_backward), finite)
    shifting = -factor * _masked_sum(turning, finite)
    # An offset ε of the falling branch's force against the rising one's moves Q± by ∓ε/2.
    lifts = 1.0 / (1.0 + (q_forward / load) ** 2) + 1.0 / (1.0 + (q_backward / load) ** 2)
    offsetting = 0.5 * factor * _masked_sum(lifts, finite) / load
    # The scatter of μ(ξ) beyond the noise: correlated residuals, the model's misfit.
    scatter, wiggle = _scatter_variance(mu, finite, unit)
    # μ(ξ) wiggles beyond the noise: the GICoF, read at one position, is not the mean friction.
    excess = np.sqrt(np.maximum(wiggle - variance * quality.SCATTER_BLOCKS, 0.0))
    wavers = excess > quality.GICOF_WIGGLE * np.abs(mu_resolved)
    variance = np.fmax(variance, scatter)  # the noise alone where too few blocks
    tilt = mean_g - k * mean_xi
    return mu_resolved, variance, k, tilt, sensitivity, varies, shifting, wavers, offsetting


def _scatter_variance(mu, kept, unit):
    r"""Variance of the mean of ``mu`` over ``kept`` from the scatter of its block means."""
    n_blocks = quality.SCATTER_BLOCKS
    member = np.minimum((0.5 * (unit + 1.0) * n_blocks).astype(int), n_blocks - 1)
    blocks = member[:, None] == np.arange(n_blocks)[None, :]
    counts = kept.astype(np.float64) @ blocks
    means = (np.where(kept, mu, 0.0) @ blocks) / np.maximum(counts, 1.0)
    used = counts > 0
    number = np.count_nonzero(used, axis=1)
    centre = _masked_sum(means, used) / number
    residual = np.where(used, means - centre[:, None], 0.0)
    squares = np.sum(residual**2, axis=1)
    lagged = np.sum(residual[:, 1:] * residual[:, :-1], axis=1)
    r1 = np.clip(np.divide(lagged, squares, out=np.zeros_like(squares), where=squares > 0), 0, _R1)
    spread = squares / np.maximum(number - 1, 1) / np.maximum(number, 1)
    place = np.where(used, np.arange(n_blocks)[None, :], 0.0)
    place = np.where(used, place - (_masked_sum(place, used) / number)[:, None], 0.0)
    trend = np.sum(residual * place, axis=1) / np.sum(place**2, axis=1)
    wiggle = np.sum((residual - trend[:, None] * place) ** 2, axis=1) / (number - 2)
    few = number < 3
    return np.where(few, np.nan, spread * (1.0 + r1) / (1.0 - r1)), np.where(few, np.nan, wiggle)


def _along_stroke(part, grid, tilt, load, level):
    """Q±, μ, g (levelled by ``tilt`` if ``level``) and h of a block over the common ``grid``."""
    lowest, highest = part["lowest"][:, None], part["highest"][:, None]
    cycles = tilt.size
    inside = np.isfinite(tilt)[:, None] & (grid >= lowest) & (grid <= highest)
    q_forward, q_backward, mu, slope, _ = _read_branches(
        part["forward"], part["backward"], grid, np.ones(cycles), inside, load
    )
    if level:
        slope = slope - tilt[:, None]
    # The felt profile: trapezoidal integral of g, zero at ξ = 0.
    pieces = np.nan_to_num(0.5 * (slope[:, 1:] + slope[:, :-1]) * np.diff(grid))
    profile = np.concatenate([np.zeros((cycles, 1)), np.cumsum(pieces, axis=1)], axis=1)
    profile -= profile[:, np.searchsorted(grid, 0.0)][:, None]
    return mu, slope, np.where(inside, profile, np.nan), q_forward, q_backward


#: The values along the stroke, over (cycle, position), as :func:`_along_stroke` returns them.
_ALONG = ("mu", "slope", "felt_profile", "force_forward", "force_backward")


def along_stroke_values(x, q, load, stiffness, amplitude, inherited, options, drift_se):
    """Every resolved quantity of the centred loops ``x``, ``q``."""
    cycles, valid = x.shape[0], np.isfinite(x) & np.isfinite(q)
    blocks = [slice(start, start + _BLOCK) for start in range(0, max(cycles, 1), _BLOCK)]
    parts = []
    for block in blocks:
        check_interrupted()
        part = _slip_branches(*(a[block] for a in (x, q, valid, stiffness, amplitude)), options)
        lowest, highest = part["lowest"], part["highest"]
        overlap = (lowest < 0.0) & (highest > 0.0)
        usable = ~inherited[block] & ~part["mismatch"] & overlap
        central = np.where(usable, options.central * np.minimum(highest, -lowest), np.nan)
        values = _central_values(part["forward"], part["backward"], central, load)
        samples = [
            np.count_nonzero(np.abs(np.where(np.isfinite(xs), xs, np.inf)) <= central[:, None], 1)
            for xs, _, _ in (part["forward"], part["backward"])
        ]
        few = (np.minimum(*samples) < quality.SLIP_SAMPLES) | ~np.isfinite(values[0])
        flags = (part["mismatch"], ~overlap, few, values[5])
        part["flags"] = np.where(inherited[block], 0, np.select(flags, range(1, 5), 0))
        part["values"] = values
        if options.positions is None:  # the branches are not read again: not held
            del part["forward"], part["backward"]
        parts.append(part)

    def joined(name):
        return np.concatenate([part[name] for part in parts])

    flag = joined("flags")
    flags = {reason: flag == code for code, reason in enumerate(_QUALITY_FLAGS, start=1)}
    ok = ~inherited & (flag == 0)
    mu_resolved, variance, k, tilt, sensitivity, _, shifting, wavers, offsetting = (
        np.concatenate(values) for values in zip(*(part["values"] for part in parts), strict=True)
    )
    flags["gicof-varies"] = wavers & ((flag == 0) | (flag == 4)) & ~inherited
    lowest, highest = joined("lowest"), joined("highest")
    nan = np.where(ok, 1.0, np.nan)
    se_squared = variance + (sensitivity * joined("compliance_se")) ** 2
    se_squared = se_squared + (shifting * joined("shift")) ** 2 + (offsetting * drift_se) ** 2
    per_cycle = {
        "mu_resolved": mu_resolved * nan,
        "mu_resolved_se": np.sqrt(se_squared) * nan,
        "aspect_ratio": 0.5 * k * amplitude * nan,
        "tilt": tilt * nan,
        "stiffness": 1.0 / joined("compliance"),
        "position_min": lowest * nan,
        "position_max": highest * nan,
    }
    grid = options.positions
    if grid is None:
        return {}, per_cycle, flags, None
    if np.ndim(grid) == 0:  # over the widest resolved range, or the stroke if none is
        reach = np.maximum(highest, -lowest)[ok]
        half = reach.max() if reach.size else np.max(amplitude, initial=0.0, where=amplitude > 0)
        grid = np.linspace(-1.0, 1.0, grid) * (half if half > 0.0 else 1.0)
    level = options.force_offset is None
    along = [
        _along_stroke(part, grid, per_cycle["tilt"][block], load, level)
        for part, block in zip(parts, blocks, strict=True)
    ]
    per_position = {name: np.concatenate([a[i] for a in along]) for i, name in enumerate(_ALONG)}
    return per_position, per_cycle, flags, grid
