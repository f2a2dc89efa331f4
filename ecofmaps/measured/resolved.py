r"""Friction and groove slope read along the whole stroke of every measured loop.

At the contact position :math:`\xi = \Delta - Q/S` (eq. 10) the model's two slip branches
are :math:`Q_+/P = \tan(\alpha + \varphi)` and :math:`Q_-/P = \tan(\alpha - \varphi)`
(eq. 9), with :math:`\varphi = \arctan\mu` and :math:`\alpha = \arctan g(\xi)` the local
slope of whatever groove the pad sits in. Where both branches slip over the same
:math:`\xi`, they give both, exactly:

.. math::

    \mu(\xi) = \tan\frac{\arctan(Q_+/P) - \arctan(Q_-/P)}{2}, \qquad
    g(\xi) = \tan\frac{\arctan(Q_+/P) + \arctan(Q_-/P)}{2},

and :math:`h(\xi) = \int_0^\xi g\,d\xi` is the scar's profile as the pad feels it. The
GICoF (eq. 17-18) is the special case :math:`\xi = 0`. :func:`resolve_loops` reads them
off every cycle of a recording; :func:`resolve_analyzed_loops` does the same from the loops
that :func:`ecofmaps.analyze_loops` kept (``keep_loops=True``), so cycles, centring and the
stiffness come from there. The work is on padded arrays, one row per cycle: no Python loop
over cycles or samples.

The method, per cycle
---------------------
Each centred loop runs from its lowest displacement up the *rising* branch to its highest
and back down the *falling* one.

* **Stick windows.** On each branch, the samples whose force has moved away from the
  reversal's by a share between ``stick_window[0]`` and ``stick_window[1]`` (default 5 %
  and 45 %) of the branch's force swing, up to the first sample beyond the upper share. In
  the model the contact sticks there (up to zero force at least, when the groove slope at
  the reversal is below :math:`\mu`): the contact position :math:`\xi` stands still, and
  the samples lie on a vertical line of the :math:`(\xi, Q)` plane.
* **Stiffness.** Given, or measured: the compliance :math:`1/S` common to the two windows,
  each with its own intercept, fitted by least squares of :math:`\Delta` on :math:`Q`
  (:math:`\Delta = \xi_s + Q/S`). This is the start of :func:`ecofmaps.analyze_loops`'s
  stiffness, without the growth of the segments towards the slip, whose first samples
  lean the line. Where a window has fewer than three samples (sparse loops), the
  stiffness of :func:`ecofmaps.analyze_loops` is used.
* **Noise and stick level.** The stick level :math:`\xi_s` of each branch is the median
  of :math:`\xi` over its window. The noise :math:`\sigma` of :math:`\xi` is read from the
  differences of successive samples in the two windows,
  :math:`\operatorname{median}|\xi_{i+1} - \xi_i| / (0.6745\sqrt2)`, which a slow
  curvature of the window does not inflate.
* **Slip.** A sample of the rising branch slips if it and every later sample of the
  branch lie more than ``slip_threshold`` (default 4) times :math:`\sigma` above the stick
  level (below it on the falling branch). Only the run of slip up to the next reversal
  counts, so a noisy stick sample cannot pass for slip; the first samples of slip, within
  the threshold of the stick level, are left out. Noise-free, :math:`\sigma = 0` and
  every sample that has moved (by more than :math:`10^{-9}\Delta^*`) slips.
* **Resampling.** The slip samples of each branch, sorted by :math:`\xi`, are
  interpolated onto a grid of positions common to all cycles, symmetric about
  :math:`\xi = 0`, over the range where both branches slip (interpolation only: nothing
  is read beyond a branch's outermost slip samples). Through the three samples nearest
  each grid point the interpolant is the linear fraction :math:`Q = (a + b\xi)/(1 + c\xi)`,
  which is eq. 9 for a parabolic groove, so the model's branches are resampled exactly;
  where it would have a pole near the three samples (noisy samples that do not rise
  monotonically, or a branch that is flat to rounding), the straight line between the two
  samples around the grid point.
* **Averages.** ``mu_resolved`` is the mean of :math:`\mu(\xi)` over the central part of
  the stroke, :math:`|\xi| \le` ``central`` times the shorter half of the resolved range,
  after values beyond three robust standard deviations of the median are clipped to
  that bound (winsorised). Its standard error comes from batch means: the central part is
  cut into ``blocks`` (default 8) equal lengths of :math:`\xi`, each several samples
  long, so that their means are nearly independent although neighbouring grid points share
  samples; the standard error is the standard deviation of the block means over
  :math:`\sqrt{\text{blocks}}`. When the stiffness is measured, its own uncertainty (from
  the scatter about the stick lines) is added in quadrature through the sensitivity
  :math:`\partial\bar\mu/\partial(1/S) = \tfrac12(1 + \bar\mu^2)\,
  \overline{\alpha'(\xi)(Q_+ - Q_-)}`: an error of :math:`S` moves the two branches in
  opposite directions along :math:`\xi`, and with a sloping groove that shifts every
  :math:`\mu(\xi)` the same way.
* **Equivalent parabolic groove.** A least-squares line :math:`g \approx g_0 + k\xi`
  over the central part; ``aspect_ratio`` is :math:`z_o/x_o = k\Delta^*/2` (eq. 7 with the
  paper's :math:`x_o = \Delta^*`). The intercept :math:`g_0` absorbs a tilt of the groove
  and the small shift of :math:`\xi` that an error of the loop's centre makes.
* **Felt profile.** :math:`h(\xi)`, the trapezoidal integral of :math:`g` over the grid,
  zero at :math:`\xi = 0`.

Quality
-------
A cycle whose numbers cannot be stood behind has NaN for every resolved value and its
``quality`` says why (the first reason, in this order):

* ``'not-gross-slip'``: :func:`ecofmaps.analyze_loops` labels it partial slip.
* ``'curved-stick'``: a stick window is not a vertical line in :math:`\xi`: the spread of
  :math:`\xi` about its stick level exceeds three times the noise :math:`\sigma` (a rounded
  loop, as polymers and micro-slip draw, or a given stiffness that is wrong), or the
  measured compliance is negative beyond three standard errors.
* ``'no-overlap'``: no range of :math:`\xi` around the loop's centre where both branches
  slip.
* ``'few-slip-samples'``: a block of the central part holds fewer than two slip samples of
  either branch (a sparsely sampled or digitised loop): the average would be read off
  straight lines between samples far apart, and its scatter would not show its error.

Otherwise ``'ok'``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ecofmaps._inputs import check
from ecofmaps.measured.analysis import GROSS_SLIP_THRESHOLD, analyze_loops

__all__ = ["resolve_analyzed_loops", "resolve_loops"]

#: Quality flags, in the order they are tested.
QUALITY_FLAGS = (
    "not-gross-slip",
    "stiffness-mismatch",
    "curved-stick",
    "no-overlap",
    "few-slip-samples",
    "mu-varies",
)

#: A given stiffness does not fit when it tilts the stick sets by this many σ.
_TILT_SPREAD = 3.0

#: A stick set is curved when its quadratic term exceeds this many standard errors.
_CURVATURE_SIGNIFICANCE = 5.0

#: μ(ξ) varies along the stroke when the means over the inner and the outer half of the
#: central part differ by this share of μ and by this many standard errors.
_VARIATION = 0.03
_VARIATION_SIGNIFICANCE = 4.0

#: Values of μ(ξ) beyond this many robust standard deviations of the median are clipped.
_WINSOR = 3.0

#: Cycles analysed together: a block's arrays stay in the processor's cache.
_BLOCK = 512

#: Points of each cycle's own grid over its central part, for the per-cycle values.
_CENTRAL_POINTS = 201

#: Fewest slip samples of each branch in the central part.
_SLIP_SAMPLES = 8

#: Fewest samples in a stick set to measure the stiffness, the stick level and the noise.
_STICK_SAMPLES = 3

#: The stick set ends this share of the force swing before the first slip sample.
_STICK_MARGIN = 0.05

#: A sample has moved off the stick level, noise-free, beyond this share of Δ*.
_ROUNDING = 1e-9

#: Normal-distribution constants: MAD -> σ, and the median of |N(0, 6)| (second differences).
_MAD = 1.482602218505602
_SECOND_DIFFERENCE = 0.6744897501960817 * np.sqrt(6.0)

# -> _nomenclature
_ATTRS = {
    "cycle": ("cycle number", "1"),
    "position": ("contact position ξ = Δ - Q/S (eq. 10), centred", "m"),
    "load": ("normal load P", "N"),
    "mu": ("coefficient of friction μ(ξ) read along the stroke", "1"),
    "slope": ("groove slope g(ξ) felt along the stroke", "1"),
    "profile": ("felt groove profile h(ξ) = ∫g dξ, zero at the centre", "m"),
    "force_forward": ("tangential force on the forward slip branch Q+(ξ), centred", "N"),
    "force_backward": ("tangential force on the backward slip branch Q-(ξ), centred", "N"),
    "mu_resolved": ("coefficient of friction averaged over the central stroke", "1"),
    "mu_resolved_se": ("standard error of mu_resolved", "1"),
    "aspect_ratio": ("equivalent parabolic groove z_o/x_o (x_o = Δ*) from g ≈ g0 + kξ", "1"),
    "tilt": ("mean groove slope g0 from g ≈ g0 + kξ (levelled off the slope if centred)", "1"),
    "stiffness": ("rig stiffness S used for the contact position", "N/m"),
    "position_offset": ("contact position of the loop centre, ξ = 0, in the recording", "m"),
    "position_min": ("lower end of the range where both branches slip", "m"),
    "position_max": ("upper end of the range where both branches slip", "m"),
    "quality": ("'ok', or why the resolved values are NaN", ""),
}


def _attrs(name: str) -> dict:
    long_name, units = _ATTRS[name]
    return {"long_name": long_name, "units": units}


def _masked_sum(values, mask):
    return np.sum(np.where(mask, values, 0.0), axis=-1)


def _masked_median(values, mask):
    """Median of each row over ``mask`` (NaN for an empty row)."""
    ordered = np.sort(np.where(mask, values, np.inf), axis=-1)
    count = np.count_nonzero(mask, axis=-1)
    low = np.take_along_axis(ordered, np.maximum(count - 1, 0)[:, None] // 2, axis=-1)[:, 0]
    high = np.take_along_axis(ordered, count[:, None] // 2, axis=-1)[:, 0]
    return np.where(count > 0, 0.5 * (low + high), np.nan)


# --- per-cycle kernels ---------------------------------------------------------------------
# Arrays of shape (cycles, width), rows running once round a loop from its lowest
# displacement; ``valid`` marks the loop's points, NaN padding elsewhere.


def _branches(x, valid):
    """Masks of the rising branch (start to top) and of the falling one (top to the end)."""
    top = np.argmax(np.where(valid, x, -np.inf), axis=1)
    j = np.arange(x.shape[1])[None, :]
    return valid & (j <= top[:, None]), valid & (j >= top[:, None])


def _moved(q, branch):
    """Share of the branch's force swing by which each sample has moved from its reversal."""
    span = np.max(np.where(branch, q, -np.inf), axis=1) - np.min(
        np.where(branch, q, np.inf), axis=1
    )
    start = np.take_along_axis(q, np.argmax(branch, axis=1)[:, None], axis=1)
    return np.abs(q - start) / span[:, None]


def _before(mask, branch):
    """The samples of ``branch`` before the first sample of ``mask``."""
    return branch & ~np.maximum.accumulate(branch & mask, axis=1)


def _compliance(x, q, sticks):
    """Least-squares compliance common to lines Δ = ξ_s + cQ through each stick set.

    Returns the compliance and its standard error (from the residuals about the lines).
    """
    covariance = np.zeros(x.shape[0])
    variance = np.zeros(x.shape[0])
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


def _curvature(xi, q, stick):
    """Quadratic term of ξ = a + bu + cu² over a stick set, and its standard error per σ.

    ``u`` is the force standardised over the set; the quadratic is fitted with the
    polynomial w = u² - 1 - m₃u orthogonal to 1 and u over the set (m₃ the mean of u³).
    """
    count = np.count_nonzero(stick, axis=1)
    u = np.where(stick, q, 0.0)
    u -= (np.sum(u, axis=1) / count)[:, None]
    u *= stick
    square = u * u
    u /= np.sqrt(np.sum(square, axis=1) / count)[:, None]
    np.multiply(u, u, out=square)
    skew = np.sum(square * u, axis=1) / count
    w = square - 1.0 - skew[:, None] * u
    w *= stick
    norm = np.sum(w * w, axis=1)
    solvable = (count > _STICK_SAMPLES) & (norm > 0.0)
    curvature = np.where(solvable, np.sum(w * np.where(stick, xi, 0.0), axis=1) / norm, 0.0)
    return curvature, 1.0 / np.sqrt(np.where(solvable, norm, 1.0))


def _stick_and_slip(xi, q, branches, sticks, floor, slip_threshold, judge=True):
    """Noise, straightness of the stick sets and the slip of each branch (module notes).

    Returns the noise σ of ξ, whether both stick sets are straight (when ``judge``), and
    the two slip masks.
    """
    # σ from the second differences within the stick sets: a smooth trend of ξ (a rounded
    # loop, a wrong stiffness) hardly enters them, white noise does with variance 6σ².
    second = np.abs(xi[:, :-2] - 2.0 * xi[:, 1:-1] + xi[:, 2:])
    triples = np.zeros_like(second, dtype=bool)
    for stick in sticks:
        triples |= stick[:, :-2] & stick[:, 1:-1] & stick[:, 2:]
    sigma = _masked_median(second, triples) / _SECOND_DIFFERENCE
    sigma = np.where(np.isfinite(sigma), sigma, 0.0)
    threshold = slip_threshold * sigma + floor
    straight = np.ones(xi.shape[0], dtype=bool)
    slips = []
    for branch, stick, sign in zip(branches, sticks, (1.0, -1.0), strict=True):
        # The stick level: the set's median, or the reversal's ξ where the set has too few
        # samples to judge (a sparse loop, or the model's loop drawn with straight sides).
        judged = np.count_nonzero(stick, axis=1) >= _STICK_SAMPLES
        reversal = np.take_along_axis(xi, np.argmax(branch, axis=1)[:, None], axis=1)[:, 0]
        level = np.where(judged, _masked_median(xi, stick), reversal)
        if judge:
            curvature, unit_error = _curvature(xi, q, stick)
            straight &= np.abs(curvature) <= _CURVATURE_SIGNIFICANCE * unit_error * sigma + floor
        # Slip: beyond the threshold, and every later sample of the branch too.
        beyond = np.where(branch, sign * xi, np.inf)
        least = np.minimum.accumulate(beyond[:, ::-1], axis=1)[:, ::-1]
        slips.append(branch & (least > (sign * level + threshold)[:, None]))
    return sigma, straight, slips


def _sorted_branch(xi, q, slip):
    """The slip samples of a branch sorted by ξ (padded with +inf / NaN), and their count."""
    key = np.where(slip, xi, np.inf)
    order = np.argsort(key, axis=1, kind="stable")
    return (
        np.take_along_axis(key, order, axis=1),
        np.take_along_axis(np.where(slip, q, np.nan), order, axis=1),
        np.count_nonzero(slip, axis=1),
    )


def _resample(xs, qs, count, grid, scale, inside):
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


def _read(forward, backward, grid, scale, inside, load):
    """Q+, Q-, μ and g at the positions ``scale * grid``, and the line weights of each branch."""
    q_forward, *line_forward = _resample(*forward, grid, scale, inside)
    q_backward, *line_backward = _resample(*backward, grid, scale, inside)
    up = np.arctan(q_forward / load)
    down = np.arctan(q_backward / load)
    mu = np.tan(0.5 * (up - down))
    slope = np.tan(0.5 * (up + down))
    return q_forward, q_backward, mu, slope, (line_forward, line_backward)


def _noise(xs, qs, count, central):
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
    return np.sqrt(_masked_sum(residual**2, use) / _masked_sum(1.0 + u**2 + (1.0 - u) ** 2, use))


def _weights(left, share, gain, width):
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


def _slip_branches(x, q, valid, stiffness, amplitude, given, options):
    """The stiffness, the checks of the stick sets, and the two slip branches (module notes).

    Returns a dict with the compliance and its standard error, ``mismatch`` and
    ``curved`` (per cycle), the sorted slip branches ``forward`` and ``backward`` and the
    range ``lowest`` .. ``highest`` where both slip.
    """
    cycles = x.shape[0]
    floor = _ROUNDING * amplitude
    branches = _branches(x, valid)
    moved = [_moved(q, branch) for branch in branches]
    low, high = options["stick_window"]
    windows = [
        _before(share > high, branch) & (share >= low)
        for share, branch in zip(moved, branches, strict=True)
    ]
    # First pass, with the given stiffness or analyze_loops's and the stick windows: where
    # does the slip start?
    start = np.where(np.isinf(stiffness), 0.0, 1.0 / stiffness)
    xi = x - start[:, None] * q
    *_, slips = _stick_and_slip(
        xi, q, branches, windows, floor, options["slip_threshold"], judge=False
    )
    # The stick sets: from the window's lower share up to a margin before the slip.
    sticks = []
    for share, branch, slip, window in zip(moved, branches, slips, windows, strict=True):
        onset = np.take_along_axis(share, np.argmax(slip, axis=1)[:, None], axis=1)
        onset = np.where(slip.any(axis=1)[:, None], onset, high + _STICK_MARGIN)
        stick = _before(slip, branch) & (share >= low) & (share <= onset - _STICK_MARGIN)
        enough = np.count_nonzero(stick, axis=1) >= _STICK_SAMPLES
        sticks.append(np.where(enough[:, None], stick, window))
    if given:
        compliance, compliance_se = start, np.zeros(cycles)
    else:
        fitted, fitted_se = _compliance(x, q, sticks)
        enough = np.all([np.count_nonzero(s, axis=1) >= _STICK_SAMPLES for s in sticks], axis=0)
        measured = enough & np.isfinite(fitted)
        compliance = np.where(measured, fitted, start)
        compliance_se = np.where(measured, fitted_se, 0.0)
    negative = compliance < -3.0 * compliance_se
    compliance = np.maximum(compliance, 0.0)
    # Second pass, with the stiffness used and the stick sets.
    xi = x - compliance[:, None] * q
    sigma, straight, slips = _stick_and_slip(
        xi, q, branches, sticks, floor, options["slip_threshold"]
    )
    mismatch = np.zeros(cycles, dtype=bool)
    if given:  # a stiffness that does not fit the stick sides tilts them in ξ
        tilt, _ = _compliance(xi, q, sticks)
        span = np.max(
            [
                np.max(np.where(s, q, -np.inf), axis=1) - np.min(np.where(s, q, np.inf), axis=1)
                for s in sticks
            ],
            axis=0,
        )
        judged = np.all([np.count_nonzero(s, axis=1) >= _STICK_SAMPLES for s in sticks], axis=0)
        mismatch = judged & ~(np.abs(tilt) * span <= _TILT_SPREAD * sigma + floor)
    forward = _sorted_branch(xi, q, slips[0])
    backward = _sorted_branch(xi, q, slips[1])
    ends = []
    for xs, _, count in (forward, backward):
        last = np.take_along_axis(xs, np.maximum(count - 1, 0)[:, None], axis=1)[:, 0]
        ends.append((np.where(count > 0, xs[:, 0], np.nan), np.where(count > 0, last, np.nan)))
    return {
        "compliance": compliance,
        "compliance_se": compliance_se,
        "mismatch": mismatch,
        "curved": negative | ~straight,
        "forward": forward,
        "backward": backward,
        "lowest": np.maximum(ends[0][0], ends[1][0]),
        "highest": np.minimum(ends[0][1], ends[1][1]),
    }


def _central_values(forward, backward, central, load):
    """mu_resolved, its noise variance, k and g0 of g ≈ g0 + kξ, the sensitivity to 1/S.

    Read on each cycle's own grid over its central part, ``|ξ| <= central``: nothing here
    depends on the other cycles. Also whether μ(ξ) varies between the inner and the outer
    half of the part beyond ``_VARIATION`` of μ and beyond its noise.
    """
    width = forward[0].shape[1]
    usable = np.isfinite(central)
    unit = np.linspace(-1.0, 1.0, _CENTRAL_POINTS)
    at = central[:, None] * unit[None, :]
    inside = np.broadcast_to(usable[:, None], at.shape)
    q_forward, q_backward, mu, slope, lines = _read(forward, backward, unit, central, inside, load)
    finite = np.isfinite(mu)
    points = np.count_nonzero(finite, axis=1)
    middle = _masked_median(mu, finite)
    bound = (_WINSOR * _MAD * _masked_median(np.abs(mu - middle[:, None]), finite))[:, None]
    clipped = np.clip(mu, middle[:, None] - bound, middle[:, None] + bound)
    mu_resolved = _masked_sum(clipped, finite) / points
    # The noise variance: each branch's noise through the weights of its samples. The same
    # for the difference between the means over the inner and the outer half of the part.
    kept = finite & (np.abs(mu - middle[:, None]) <= bound)
    inner = kept & (np.abs(unit) <= 0.5)
    outer = kept & ~inner
    share_inner = np.count_nonzero(inner, axis=1)[:, None]
    share_outer = np.count_nonzero(outer, axis=1)[:, None]
    contrast = np.where(inner, 1.0 / share_inner, np.where(outer, -1.0 / share_outer, 0.0))
    variation = _masked_sum(mu * contrast, kept)
    factor = 0.5 * (1.0 + mu**2) / load
    variance = np.zeros(central.size)
    variation_variance = np.zeros(central.size)
    for branch, force, (left, share), sign in (
        (forward, q_forward, lines[0], 1.0),
        (backward, q_backward, lines[1], -1.0),
    ):
        gain = np.where(kept, sign * factor / (1.0 + (force / load) ** 2), 0.0)
        noise = _noise(*branch, central) ** 2
        weight = _weights(left, share, gain / points[:, None], width)
        variance += noise * np.sum(weight**2, axis=1)
        weight = _weights(left, share, gain * contrast, width)
        variation_variance += noise * np.sum(weight**2, axis=1)
    varies = (np.abs(variation) > _VARIATION * mu_resolved) & (
        np.abs(variation) > _VARIATION_SIGNIFICANCE * np.sqrt(variation_variance)
    )
    mean_xi = _masked_sum(at, finite) / points
    mean_g = _masked_sum(slope, finite) / points
    dxi = at - mean_xi[:, None]
    k = _masked_sum(dxi * (slope - mean_g[:, None]), finite) / _masked_sum(dxi**2, finite)
    # The sensitivity of mu_resolved to the compliance 1/S (module notes).
    turning = k[:, None] / (1.0 + slope**2) * (q_forward - q_backward)
    sensitivity = 0.5 * (1.0 + mu_resolved**2) * _masked_sum(turning, finite) / points
    return mu_resolved, variance, k, mean_g - k * mean_xi, sensitivity, varies


def _along_stroke(forward, backward, grid, lowest, highest, tilt, load, level):
    """Q±, μ, g (levelled by ``tilt`` if ``level``) and h over the common ``grid``."""
    cycles = lowest.size
    inside = np.isfinite(tilt)[:, None] & (grid >= lowest[:, None]) & (grid <= highest[:, None])
    q_forward, q_backward, mu, slope, _ = _read(
        forward, backward, grid, np.ones(cycles), inside, load
    )
    if level:
        slope = slope - tilt[:, None]
    # The felt profile: trapezoidal integral of g, zero at ξ = 0.
    pieces = np.nan_to_num(0.5 * (slope[:, 1:] + slope[:, :-1]) * np.diff(grid))
    profile = np.concatenate([np.zeros((cycles, 1)), np.cumsum(pieces, axis=1)], axis=1)
    profile -= profile[:, np.searchsorted(grid, 0.0)][:, None]
    return {
        "mu": mu,
        "slope": slope,
        "profile": np.where(inside, profile, np.nan),
        "force_forward": q_forward,
        "force_backward": q_backward,
    }


#: The values along the stroke, over (cycle, position).
_ALONG = ("mu", "slope", "profile", "force_forward", "force_backward")


def _blocks(cycles):
    """Slices of at most ``_BLOCK`` cycles: the arrays of a block stay in the cache."""
    return [slice(start, start + _BLOCK) for start in range(0, max(cycles, 1), _BLOCK)]


def _resolve(x, q, valid, load, stiffness, amplitude, gross, given, options):
    """Every resolved quantity of the centred loops ``x``, ``q`` (module notes).

    ``stiffness`` is the given S (``given`` True) or analyze_loops's, per cycle. Returns
    the per-position and per-cycle arrays, the quality and the grid. The work is done
    on blocks of cycles, each block vectorised.
    """
    cycles = x.shape[0]
    parts = []
    for block in _blocks(cycles):
        part = _slip_branches(
            x[block], q[block], valid[block], stiffness[block], amplitude[block], given, options
        )
        lowest, highest = part["lowest"], part["highest"]
        overlap = (lowest < 0.0) & (highest > 0.0)
        usable = gross[block] & ~part["mismatch"] & ~part["curved"] & overlap
        central = np.where(usable, options["central"] * np.minimum(highest, -lowest), np.nan)
        values = _central_values(part["forward"], part["backward"], central, load)
        samples = [
            np.count_nonzero(np.abs(np.where(np.isfinite(xs), xs, np.inf)) <= central[:, None], 1)
            for xs, _, _ in (part["forward"], part["backward"])
        ]
        few = (np.minimum(*samples) < _SLIP_SAMPLES) | ~np.isfinite(values[0])
        reasons = (~gross[block], part["mismatch"], part["curved"], ~overlap, few, values[5])
        part["quality"] = np.select(reasons, QUALITY_FLAGS, "ok")
        part["values"] = values
        parts.append(part)

    def joined(name):
        return np.concatenate([part[name] for part in parts])

    quality = joined("quality")
    ok = quality == "ok"
    lowest, highest = joined("lowest"), joined("highest")
    mu_resolved, variance, k, tilt, sensitivity = (
        np.concatenate([part["values"][i] for part in parts]) for i in range(5)
    )
    nan = np.where(ok, 1.0, np.nan)
    compliance = joined("compliance")
    per_cycle = {
        "mu_resolved": mu_resolved * nan,
        "mu_resolved_se": np.sqrt(variance + (sensitivity * joined("compliance_se")) ** 2) * nan,
        "aspect_ratio": 0.5 * k * amplitude * nan,
        "tilt": tilt * nan,
        "stiffness": 1.0 / compliance,
        "position_min": lowest * nan,
        "position_max": highest * nan,
    }
    # Over the grid of positions common to all cycles: the values along the stroke.
    grid = options["positions"]
    if np.ndim(grid) == 0:
        reach = np.maximum(highest, -lowest)[ok]
        grid = np.linspace(-1.0, 1.0, grid) * (reach.max() if reach.size else 0.0)
    per_position = {name: np.empty((cycles, grid.size)) for name in _ALONG}
    for part, block in zip(parts, _blocks(cycles), strict=True):
        along = _along_stroke(
            part["forward"],
            part["backward"],
            grid,
            lowest[block],
            highest[block],
            per_cycle["tilt"][block],
            load,
            options["force_offset"] is None,
        )
        for name in _ALONG:
            per_position[name][block] = along[name]
    return per_position, per_cycle, quality, grid


# --- the public functions -------------------------------------------------------------------


def _check_options(stiffness, force_offset, positions, central, slip_threshold, stick_window):
    """The options as a dict, or a ValueError naming the one out of range."""
    if stiffness is not None:
        check("stiffness", stiffness, "positive_or_inf", "N/m")
        if np.ndim(stiffness) != 0:
            raise ValueError("stiffness must be a single value [N/m]")
    if force_offset is not None:
        check("force_offset", force_offset, "finite", "N")
        if np.ndim(force_offset) != 0:
            raise ValueError("force_offset must be a single value [N]")
    if np.ndim(positions) == 0:
        if (
            isinstance(positions, bool)
            or not isinstance(positions, int | np.integer)
            or positions < 5
            or positions % 2 == 0
        ):
            raise ValueError(
                f"positions must be an odd integer >= 5 or an array of positions; got {positions!r}"
            )
        positions = int(positions)
    else:
        check("positions", positions, "finite", "m")
        positions = np.asarray(positions, dtype=np.float64)
        if positions.ndim != 1 or positions.size < 3 or np.any(np.diff(positions) <= 0.0):
            raise ValueError("positions must be one-dimensional and increasing, >= 3 of them [m]")
        if not np.any(positions == 0.0):
            raise ValueError("positions must include 0 (the centre, where the profile is zero) [m]")
    if not 0.0 < central <= 1.0:
        raise ValueError(f"central must satisfy 0 < central <= 1; got {central!r}")
    if not slip_threshold > 0.0:
        raise ValueError(f"slip_threshold must satisfy slip_threshold > 0; got {slip_threshold!r}")
    low, high = (float(share) for share in stick_window)
    if not 0.0 <= low < high <= 1.0:
        raise ValueError(f"stick_window must satisfy 0 <= low < high <= 1; got {stick_window!r}")
    return {
        "stiffness": None if stiffness is None else float(stiffness),
        "force_offset": None if force_offset is None else float(force_offset),
        "positions": positions,
        "central": float(central),
        "slip_threshold": float(slip_threshold),
        "stick_window": (low, high),
    }


_NEEDED = (
    "loop_displacement",
    "loop_force",
    "stiffness",
    "amplitude",
    "regime",
    "displacement_offset",
    "force_offset",
)


def resolve_analyzed_loops(
    loops,
    stiffness=None,
    *,
    force_offset=None,
    positions=201,
    central=0.8,
    slip_threshold=4.0,
    stick_window=(0.05, 0.45),
) -> xr.Dataset:
    r"""Friction and groove slope along the stroke of the loops :func:`analyze_loops` kept.

    The work of :func:`resolve_loops` after its call of :func:`ecofmaps.analyze_loops`:
    for a recording already analysed with ``keep_loops=True``.

    Parameters
    ----------
    loops : xarray.Dataset
        The result of :func:`ecofmaps.analyze_loops` with ``keep_loops=True``.
    stiffness, force_offset, positions, central, slip_threshold, stick_window
        As for :func:`resolve_loops`.

    Returns
    -------
    resolved : xarray.Dataset
        As for :func:`resolve_loops`.

    Raises
    ------
    ValueError
        If ``loops`` lacks the loops (``keep_loops=False``), or for options out of range.
    """
    if not isinstance(loops, xr.Dataset) or any(name not in loops for name in _NEEDED):
        raise ValueError(
            "loops must be the Dataset of analyze_loops(..., keep_loops=True), with "
            + ", ".join(_NEEDED)
        )
    options = _check_options(
        stiffness, force_offset, positions, central, slip_threshold, stick_window
    )
    load = float(loops["load"])
    x = np.asarray(loops["loop_displacement"].values, dtype=np.float64)
    q = np.asarray(loops["loop_force"].values, dtype=np.float64)
    removed = np.asarray(loops["force_offset"].values, dtype=np.float64)
    if options["force_offset"] is not None:  # the force as recorded, less the given offset
        q = q + (removed - options["force_offset"])[:, None]
        removed = np.full_like(removed, options["force_offset"])
    given = options["stiffness"] is not None
    rig = np.full(x.shape[0], options["stiffness"]) if given else loops["stiffness"].values
    with np.errstate(divide="ignore", invalid="ignore"):
        per_position, per_cycle, quality, grid = _resolve(
            x,
            q,
            np.isfinite(x) & np.isfinite(q),
            load,
            np.asarray(rig, dtype=np.float64),
            np.asarray(loops["amplitude"].values, dtype=np.float64),
            loops["regime"].values == "gross slip",
            given,
            options,
        )
        per_cycle["position_offset"] = (
            loops["displacement_offset"].values - removed / per_cycle["stiffness"]
        )
    dims = ("cycle", "position")
    data = {name: (dims, value, _attrs(name)) for name, value in per_position.items()}
    for name, value in per_cycle.items():
        data[name] = ("cycle", value, _attrs(name))
    data["quality"] = ("cycle", quality, _attrs("quality"))
    coords = {
        "cycle": ("cycle", loops["cycle"].values, _attrs("cycle")),
        "position": ("position", grid, _attrs("position")),
        "load": ((), load, _attrs("load")),
    }
    attrs = {
        "title": "Fretting loops read along the stroke (ecofmaps.resolve_loops)",
        "stiffness_from": "given" if given else "the stick sets of each loop",
        "force_from": (
            "loops centred" if options["force_offset"] is None else "given force offset"
        ),
        "central": options["central"],
        "slip_threshold": options["slip_threshold"],
        "stick_window": list(options["stick_window"]),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def resolve_loops(
    displacement,
    force,
    load,
    stiffness=None,
    cycle=None,
    *,
    force_offset=None,
    positions=201,
    central=0.8,
    slip_threshold=4.0,
    stick_window=(0.05, 0.45),
    hysteresis=0.5,
    gross_slip_threshold=GROSS_SLIP_THRESHOLD,
) -> xr.Dataset:
    r"""Friction and groove slope read along the whole stroke of every loop of a recording.

    Parameters
    ----------
    displacement : array_like
        Applied displacement :math:`\Delta` at each sample, in time order. Offsets and a
        slow drift are removed (:func:`ecofmaps.analyze_loops`). [m]
    force : array_like
        Tangential force :math:`Q` at each sample. [N]
    load : float
        Normal load :math:`P`. [N]
    stiffness : float, optional
        Rig stiffness :math:`S` (``numpy.inf`` for a rigid rig); by default measured on
        each loop. [N/m]
    cycle : array_like, optional
        Cycle number of each sample, as for :func:`ecofmaps.analyze_loops`. [1]
    force_offset : float, optional
        The force sensor's offset, subtracted from the recorded force. By default each
        loop is centred on its own force instead, which also takes away the force a
        tilted groove adds to both branches: give the offset (0 for a zeroed sensor) to
        read a groove's tilt. [N]
    positions : int
        Points of the grid of contact positions, odd (>= 5) so that :math:`\xi = 0` is one.
    central : float
        Share of the resolved half-range, about :math:`\xi = 0`, averaged for
        ``mu_resolved`` and fitted for ``aspect_ratio`` (0 < central <= 1). [1]
    slip_threshold : float
        How many noise standard deviations of :math:`\xi` a sample must lie beyond the
        stick level to count as slipping (> 0). [1]
    stick_window : tuple of float
        Shares of a branch's force swing, away from its reversal, that bound the first
        stick window (0 <= low < high <= 1); also passed to
        :func:`ecofmaps.analyze_loops`. [1]
    hysteresis, gross_slip_threshold : float
        Passed to :func:`ecofmaps.analyze_loops`: the reversal detector's band, and the
        energy ratio above which a loop is gross slip. [1]

    Returns
    -------
    resolved : xarray.Dataset
        Over ``(cycle, position)``: ``mu`` :math:`\mu(\xi)`, ``slope`` :math:`g(\xi)`,
        ``profile`` :math:`h(\xi)` [m], ``force_forward`` and ``force_backward``
        :math:`Q_\pm(\xi)` [N]; NaN outside the range where both branches slip. Over
        ``cycle``: ``mu_resolved``, ``mu_resolved_se``, ``aspect_ratio``, ``stiffness``
        (the one used) [N/m], ``position_offset`` (where :math:`\xi = 0` lies in the
        recording's contact position), ``position_min``, ``position_max`` [m] and
        ``quality`` (``'ok'`` or the reason the values are NaN). The ``position``
        coordinate is :math:`\xi` [m], common to all cycles; the load is a scalar
        coordinate. ``resolved.sel(cycle=...).mu.plot()`` labels itself.

    Raises
    ------
    ValueError
        For bad inputs or options (those of :func:`ecofmaps.analyze_loops` too).

    See Also
    --------
    resolve_analyzed_loops : the same from :func:`ecofmaps.analyze_loops`'s result.

    Notes
    -----
    The method and the quality flags are in the documentation of
    :mod:`ecofmaps.measured.resolved`. It rests on eq. 9 (the slip traction at any local
    groove slope) and eq. 10 (the contact position); the GICoF (eq. 17-18) is its value at
    :math:`\xi = 0`, and eq. 7 with :math:`x_o = \Delta^*` gives the equivalent
    parabolic groove.

    Examples
    --------
    >>> import numpy as np, ecofmaps
    >>> displacement, force = ecofmaps.fretting_loop(50e-6, 450.0, 35e6, 0.8, 0.2)
    >>> resolved = ecofmaps.resolve_loops(np.asarray(displacement), np.asarray(force), 450.0)
    >>> print(f"{float(resolved.mu_resolved[0]):.9f} {float(resolved.aspect_ratio[0]):.9f}")
    0.800000000 0.200000000
    """
    options = _check_options(
        stiffness, force_offset, positions, central, slip_threshold, stick_window
    )
    loops = analyze_loops(
        displacement,
        force,
        load,
        cycle,
        hysteresis=hysteresis,
        stick_window=stick_window,
        gross_slip_threshold=gross_slip_threshold,
        keep_loops=True,
    )
    return resolve_analyzed_loops(loops, **options)
