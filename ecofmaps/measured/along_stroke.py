r"""The per-cycle kernels of the loop read along the stroke (:mod:`ecofmaps.measured.resolved`).

On both slip branches at the same contact position :math:`\xi = \Delta - Q/S`,
:math:`\mu(\xi) = \tan((\arctan q_+ - \arctan q_-)/2)` and
:math:`g(\xi) = \tan((\arctan q_+ + \arctan q_-)/2)` with :math:`q_\pm = Q_\pm/P` (eq. 9 at
the local slope). :func:`along_stroke_values` reads them for a block of cycles at a time, vectorised
over the cycles: the per-cycle values over each cycle's central part
(:func:`_central_values`), the values along the stroke on a common grid
(:func:`_along_stroke`), and the checks of :data:`QUALITY_FLAGS`. The method and its checks
are described in :mod:`ecofmaps.measured.resolved`.
"""

from __future__ import annotations

import numpy as np

from ecofmaps._interrupts import check_interrupted
from ecofmaps.measured.quality import (
    ALL,
    REASONS,
    RESOLVED,
    add_reason,
    has_reason,
)
from ecofmaps.measured.resampling import branch_noise, read_branches, sample_weights
from ecofmaps.measured.stick_slip import masked_median, masked_sum, slip_branches

__all__ = ["QUALITY_FLAGS", "along_stroke_values"]

#: Quality flags, in the order they are tested.
#: The reasons this reading adds to a cycle's ``quality`` (ecofmaps.measured.quality) that
#: leave its values NaN, the first that applies; ``'gicof-varies'``, which reaches the
#: GICoF only, is added besides.
QUALITY_FLAGS = ("stiffness-mismatch", "no-overlap", "few-slip-samples", "mu-varies")

#: μ(ξ) varies along the stroke when the means over the inner and the outer half of the
#: central part differ by this share of μ and by this many standard errors.
_VARIATION = 0.03
_VARIATION_SIGNIFICANCE = 4.0

#: Values of μ(ξ) beyond this many robust standard deviations of the median are clipped.
_WINSOR = 3.0

#: Blocks of the central part whose means give the scatter of μ(ξ) (batch means).
_SCATTER_BLOCKS = 8

#: The GICoF is flagged where the block means of μ(ξ) scatter about a straight line by
#: this share of μ (standard deviation) beyond the noise.
_GICOF_WIGGLE = 0.015

#: The largest lag-one autocorrelation of the block means that is believed.
_R1 = 0.8

#: Cycles analysed together: a block's arrays stay in the processor's cache.
_BLOCK = 512

#: Points of each cycle's own grid over its central part, for the per-cycle values.
_CENTRAL_POINTS = 201

#: Fewest slip samples of each branch in the central part.
_SLIP_SAMPLES = 8

#: The median absolute deviation of a normal distribution over its standard deviation.
_MAD = 1.482602218505602


# Arrays of shape (cycles, width), rows running once round a loop from its lowest
# displacement; ``valid`` marks the loop's points, NaN padding elsewhere.


def _central_values(forward, backward, central, load):
    """mu_resolved, its variance, k and g0 of g ≈ g0 + kξ, the sensitivity to 1/S.

    Read on each cycle's own grid over its central part, ``|ξ| <= central``: nothing here
    depends on the other cycles. The variance is the noise's, or the scatter's of μ(ξ)
    along the part where that is larger (:func:`_scatter_variance`). Also whether μ(ξ)
    varies between the inner and the outer half of the part beyond ``_VARIATION`` of μ and
    beyond its noise, the sensitivity to a shift of the rising branch against the falling
    one along ξ, whether μ(ξ) wiggles about a straight line beyond ``_GICOF_WIGGLE``, and
    the sensitivity to an offset of the falling branch's force against the rising one's.
    """
    width = forward[0].shape[1]
    usable = np.isfinite(central)
    unit = np.linspace(-1.0, 1.0, _CENTRAL_POINTS)
    at = central[:, None] * unit[None, :]
    inside = np.broadcast_to(usable[:, None], at.shape)
    q_forward, q_backward, mu, slope, lines = read_branches(
        forward, backward, unit, central, inside, load
    )
    finite = np.isfinite(mu)
    points = np.count_nonzero(finite, axis=1)
    middle = masked_median(mu, finite)
    bound = (_WINSOR * _MAD * masked_median(np.abs(mu - middle[:, None]), finite))[:, None]
    clipped = np.clip(mu, middle[:, None] - bound, middle[:, None] + bound)
    mu_resolved = masked_sum(clipped, finite) / points
    # The noise variance: each branch's noise through the weights of its samples. The same
    # for the difference between the means over the inner and the outer half of the part.
    kept = finite & (np.abs(mu - middle[:, None]) <= bound)
    inner = kept & (np.abs(unit) <= 0.5)
    outer = kept & ~inner
    inner_points = np.count_nonzero(inner, axis=1)[:, None]
    outer_points = np.count_nonzero(outer, axis=1)[:, None]
    contrast = np.where(inner, 1.0 / inner_points, np.where(outer, -1.0 / outer_points, 0.0))
    variation = masked_sum(mu * contrast, kept)
    factor = 0.5 * (1.0 + mu**2) / load
    variance = np.zeros(central.size)
    variation_variance = np.zeros(central.size)
    for branch, force, (left, share), sign in (
        (forward, q_forward, lines[0], 1.0),
        (backward, q_backward, lines[1], -1.0),
    ):
        gain = np.where(kept, sign * factor / (1.0 + (force / load) ** 2), 0.0)
        noise = branch_noise(*branch, central) ** 2
        weight = sample_weights(left, share, gain / points[:, None], width)
        variance += noise * np.sum(weight**2, axis=1)
        weight = sample_weights(left, share, gain * contrast, width)
        variation_variance += noise * np.sum(weight**2, axis=1)
    varies = (np.abs(variation) > _VARIATION * np.abs(mu_resolved)) & (
        np.abs(variation) > _VARIATION_SIGNIFICANCE * np.sqrt(variation_variance)
    )
    mean_xi = masked_sum(at, finite) / points
    mean_g = masked_sum(slope, finite) / points
    dxi = at - mean_xi[:, None]
    k = masked_sum(dxi * (slope - mean_g[:, None]), finite) / masked_sum(dxi**2, finite)
    # The sensitivities of mu_resolved to the compliance 1/S and to a shift of the rising
    # branch against the falling one along ξ (module notes).
    turning = k[:, None] / (1.0 + slope**2)
    factor = 0.5 * (1.0 + mu_resolved**2) / points
    sensitivity = factor * masked_sum(turning * (q_forward - q_backward), finite)
    shifting = -factor * masked_sum(turning, finite)
    # An offset ε of the falling branch's force against the rising one's moves Q± by ∓ε/2.
    lifts = 1.0 / (1.0 + (q_forward / load) ** 2) + 1.0 / (1.0 + (q_backward / load) ** 2)
    offsetting = 0.5 * factor * masked_sum(lifts, finite) / load
    # The scatter of μ(ξ) beyond the noise: correlated residuals, the model's misfit.
    scatter, wiggle = _scatter_variance(mu, finite, unit)
    # μ(ξ) wiggles along the stroke beyond the noise: the GICoF, read at one position,
    # is not the mean friction (a straight trend is the same at the centre).
    excess = np.sqrt(np.maximum(wiggle - variance * _SCATTER_BLOCKS, 0.0))
    wavers = excess > _GICOF_WIGGLE * np.abs(mu_resolved)
    variance = np.fmax(variance, scatter)  # the noise alone where too few blocks
    tilt = mean_g - k * mean_xi
    return mu_resolved, variance, k, tilt, sensitivity, varies, shifting, wavers, offsetting


def _scatter_variance(mu, kept, unit):
    r"""Variance of the mean of ``mu`` over ``kept`` from the scatter of its block means.

    The central part is cut into ``_SCATTER_BLOCKS`` blocks of equal length; the block
    means' variance about their mean, over their number less one, and times
    :math:`(1 + r_1)/(1 - r_1)` for the lag-one autocorrelation :math:`r_1 \ge 0` of the
    block means (friction that varies slowly along the stroke), is the variance of the
    mean of independent blocks (batch means). NaN for fewer than three blocks.

    Also returns the variance of the block means about a straight line through them.
    """
    member = np.minimum((0.5 * (unit + 1.0) * _SCATTER_BLOCKS).astype(int), _SCATTER_BLOCKS - 1)
    blocks = member[:, None] == np.arange(_SCATTER_BLOCKS)[None, :]
    counts = kept.astype(np.float64) @ blocks
    means = (np.where(kept, mu, 0.0) @ blocks) / np.maximum(counts, 1.0)
    used = counts > 0
    number = np.count_nonzero(used, axis=1)
    centre = masked_sum(means, used) / number
    residual = np.where(used, means - centre[:, None], 0.0)
    squares = np.sum(residual**2, axis=1)
    lagged = np.sum(residual[:, 1:] * residual[:, :-1], axis=1)
    r1 = np.clip(np.divide(lagged, squares, out=np.zeros_like(squares), where=squares > 0), 0, _R1)
    spread = squares / np.maximum(number - 1, 1) / np.maximum(number, 1)
    place = np.where(used, np.arange(_SCATTER_BLOCKS)[None, :], 0.0)
    place = np.where(used, place - (masked_sum(place, used) / number)[:, None], 0.0)
    trend = np.sum(residual * place, axis=1) / np.sum(place**2, axis=1)
    wiggle = np.sum((residual - trend[:, None] * place) ** 2, axis=1) / (number - 2)
    few = number < 3
    return np.where(few, np.nan, spread * (1.0 + r1) / (1.0 - r1)), np.where(few, np.nan, wiggle)


def _along_stroke(forward, backward, grid, lowest, highest, tilt, load, level):
    """Q±, μ, g (levelled by ``tilt`` if ``level``) and h over the common ``grid``."""
    cycles = lowest.size
    inside = np.isfinite(tilt)[:, None] & (grid >= lowest[:, None]) & (grid <= highest[:, None])
    q_forward, q_backward, mu, slope, _ = read_branches(
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
        "felt_profile": np.where(inside, profile, np.nan),
        "force_forward": q_forward,
        "force_backward": q_backward,
    }


#: The values along the stroke, over (cycle, position).
_ALONG = ("mu", "slope", "felt_profile", "force_forward", "force_backward")


def _reaches_resolved(quality) -> np.ndarray:
    """True for the cycles whose ``quality`` lists a reason that leaves the resolved values NaN."""
    reaching = [
        r for r, (_, scope) in REASONS.items() if scope == ALL or set(RESOLVED) & set(scope)
    ]
    return np.logical_or.reduce([has_reason(quality, reason) for reason in reaching])


def joined_values(parts, index):
    """The per-cycle values number ``index`` of :func:`_central_values`, over all blocks."""
    return np.concatenate([part["values"][index] for part in parts])


def _blocks(cycles):
    """Slices of at most ``_BLOCK`` cycles: the arrays of a block stay in the cache."""
    return [slice(start, start + _BLOCK) for start in range(0, max(cycles, 1), _BLOCK)]


def along_stroke_values(x, q, valid, load, stiffness, amplitude, quality, given, options, drift_se):
    """Every resolved quantity of the centred loops ``x``, ``q`` (module notes).

    ``stiffness`` is the given S (``given`` True) or analyze_loops's, per cycle, and
    ``quality`` analyze_loops's: a cycle it flags for a reason that reaches the resolved
    values is not read. ``drift_se`` is the standard error of the offset between each
    loop's branches that its centring left (analyze_loops's ``force_drift_se``) [N].
    Returns the per-position and per-cycle arrays, the quality (with this reading's reasons
    added) and the grid. The work is done on blocks of cycles, each block vectorised.
    """
    inherited = _reaches_resolved(quality)
    cycles = x.shape[0]
    parts = []
    for block in _blocks(cycles):
        check_interrupted()
        part = slip_branches(
            x[block],
            q[block],
            valid[block],
            stiffness[block],
            amplitude[block],
            given,
            options["stick_window"],
            options["slip_threshold"],
        )
        lowest, highest = part["lowest"], part["highest"]
        overlap = (lowest < 0.0) & (highest > 0.0)
        usable = ~inherited[block] & ~part["mismatch"] & overlap
        central = np.where(usable, options["central"] * np.minimum(highest, -lowest), np.nan)
        values = _central_values(part["forward"], part["backward"], central, load)
        samples = [
            np.count_nonzero(np.abs(np.where(np.isfinite(xs), xs, np.inf)) <= central[:, None], 1)
            for xs, _, _ in (part["forward"], part["backward"])
        ]
        few = (np.minimum(*samples) < _SLIP_SAMPLES) | ~np.isfinite(values[0])
        flags = (part["mismatch"], ~overlap, few, values[5])
        part["flags"] = np.where(inherited[block], 0, np.select(flags, range(1, 5), 0))
        part["values"] = values
        if options["positions"] is None:  # the branches are not read again: not held
            del part["forward"], part["backward"]
        parts.append(part)

    def joined(name):
        return np.concatenate([part[name] for part in parts])

    flag = joined("flags")
    for code, reason in enumerate(QUALITY_FLAGS, start=1):
        quality = add_reason(quality, flag == code, reason)
    ok = ~inherited & (flag == 0)
    wavers = joined_values(parts, 7) & ((flag == 0) | (flag == 4))
    quality = add_reason(quality, wavers & ~inherited, "gicof-varies")
    lowest, highest = joined("lowest"), joined("highest")
    mu_resolved, variance, k, tilt, sensitivity, _, shifting, _, offsetting = (
        joined_values(parts, i) for i in range(9)
    )
    nan = np.where(ok, 1.0, np.nan)
    compliance = joined("compliance")
    per_cycle = {
        "mu_resolved": mu_resolved * nan,
        "mu_resolved_se": np.sqrt(
            variance
            + (sensitivity * joined("compliance_se")) ** 2
            + (shifting * joined("shift")) ** 2
            + (offsetting * drift_se) ** 2
        )
        * nan,
        "aspect_ratio": 0.5 * k * amplitude * nan,
        "tilt": tilt * nan,
        "stiffness": 1.0 / compliance,
        "position_min": lowest * nan,
        "position_max": highest * nan,
    }
    # Over the grid of positions common to all cycles: the values along the stroke.
    grid = options["positions"]
    if grid is None:
        return {}, per_cycle, quality, None
    if np.ndim(grid) == 0:  # over the widest resolved range, or the stroke if none is
        reach = np.maximum(highest, -lowest)[ok]
        half = reach.max() if reach.size else np.max(amplitude, initial=0.0, where=amplitude > 0)
        grid = np.linspace(-1.0, 1.0, grid) * (half if half > 0.0 else 1.0)
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
