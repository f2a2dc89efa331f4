r"""The dimensionless core on a scar profile: slip branches (eq. 9 pointwise) and the tables
of what depends on the profile, :math:`\mu` and the stroke only, which
:mod:`ecofmaps.model.first_passage` reads the steady loop off. Pure ``jax.numpy``, no checks;
the method is explained in ``docs/model.md`` (the model on a scar profile).
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

_TINY = float(np.nextafter(0.0, 1.0))  # the interval [0, _TINY) holds only lambda = 0

# log1p(r)/r - 1 + r/2 = sum_{m>=0} (-1)^m r^(m+2)/(m+3) for |r| < 1/8, where the first
# omitted term is below 1e-17 of the sum; above, the direct formula loses at most a factor
# 3/r^2 < 200 of eps relative to log1p(r)/r.
_SERIES_LIMIT = 0.125
_E2_SERIES = tuple((-1.0) ** m / (m + 3) for m in range(17, -1, -1))


class Side(NamedTuple):
    """One orientation of a profile: the forward stroke's view, or the mirrored one."""

    position: jax.Array  # (U, N) sample positions in units of the stroke, increasing
    slope: jax.Array  # (U, N)
    force: jax.Array  # (U, N) q_+ at the samples, +inf where mu g >= 1
    bounds: jax.Array  # (U, K, N + 1, 2) sparse table of the intervals' ends (K = 1: dense);
    # column N is a sentinel


class Tables(NamedTuple):
    """Everything the steady loop needs that does not depend on the rig (``docs/model.md``)."""

    forward: Side
    backward: Side  # the mirrored profile: position -p[::-1], slope -g[::-1]
    excess: jax.Array  # (U, N) integral of e from sample 0 to each sample
    critical: jax.Array  # (U, K, N - 1) range-min table: largest lambda without jumps, per segment
    peak: jax.Array  # (U, K, N) range-max table of q_+ at the samples
    trough: jax.Array  # (U, K, N) range-max table of -q_- at the samples
    mu: jax.Array  # (U,)
    start_segment: jax.Array  # (U,) segment holding the scar centre
    start_fraction: jax.Array  # (U,)


def traction_forward(slope, mu):
    """:math:`q_+ = (\\mu + g)/(1 - \\mu g)` (eq. 9), +inf at and beyond locking."""
    margin = 1.0 - mu * slope
    positive = margin > 0.0
    return jnp.where(positive, (mu + slope) / jnp.where(positive, margin, 1.0), jnp.inf)


def _log_ratio_excess(r):
    """:math:`\\ln(1 + r)/r - 1 + r/2` for :math:`r > -1`, without cancellation."""
    small = jnp.abs(r) < _SERIES_LIMIT
    rs = jnp.where(small, r, 0.0)
    series = jnp.zeros_like(rs)
    for coefficient in _E2_SERIES:  # Horner's rule, unrolled at trace time
        series = series * rs + coefficient
    rl = jnp.where(small, 1.0, r)
    direct = jnp.log1p(rl) / rl - 1.0 + 0.5 * rl
    return jnp.where(small, series * rs * rs, direct)


def mean_excess(slope_a, slope_b, mu):
    r"""Mean of :math:`e = (1 + \mu^2)g^2/(1 - \mu^2g^2)` over a segment where :math:`g` runs
    linearly from ``slope_a`` to ``slope_b`` (exact; needs :math:`\mu|g| < 1` on it)."""
    w_plus = 1.0 - mu * slope_a
    w_minus = 1.0 + mu * slope_a
    change = slope_b - slope_a
    product = w_plus * w_minus
    tails = (
        _log_ratio_excess(-mu * change / w_plus) / w_plus
        + _log_ratio_excess(mu * change / w_minus) / w_minus
    )
    total = (
        2.0 * slope_a * slope_a / product
        + 2.0 * slope_a * change / (product * product)
        + tails / (mu * mu)
    )
    return 0.5 * (1.0 + mu * mu) * total


def mean_traction(slope_a, slope_b, mu):
    r"""Mean of :math:`q_+ = (\mu + g)/(1 - \mu g)` over a segment where :math:`g` runs
    linearly from ``slope_a`` to ``slope_b`` (exact; needs :math:`\mu g < 1` on it)."""
    margin = 1.0 - mu * slope_a
    change = slope_b - slope_a
    inner = 0.5 * change / margin + _log_ratio_excess(-mu * change / margin) / mu + slope_a
    return mu + (1.0 + mu * mu) * inner / margin


def crossing_fraction(start, length, slope_a, change, mu, lam, level):
    r"""Fraction :math:`t \in [0, 1]` of a segment where :math:`F_+ = \xi + \lambda q_+`
    first reaches ``level`` from below."""
    w0 = 1.0 - mu * slope_a
    w1 = -mu * change
    offset = start - level
    a = length * w1
    b = offset * w1 + length * w0 + lam * change
    c = offset * w0 + lam * (mu + slope_a)
    # Each branch sees safe inputs where it is not taken, so that its derivative is finite
    # there too (a NaN times the zero weight of the branch not taken is still NaN).
    discriminant = b * b - 4.0 * a * c
    real = discriminant > 0.0
    root = jnp.where(real, jnp.sqrt(jnp.where(real, discriminant, 1.0)), 0.0)
    b_positive = b > 0.0
    linear = a == 0.0
    t = jnp.where(
        b_positive,
        -2.0 * c / jnp.where(b_positive, b + root, 1.0),
        (root - b) / (2.0 * jnp.where(linear, 1.0, a)),
    )
    t = jnp.where(~b_positive & linear, 1.0, t)
    rigid = (lam == 0.0) & (length != 0.0)
    t = jnp.where(rigid, (level - start) / jnp.where(rigid, length, 1.0), t)
    return jnp.clip(t, 0.0, 1.0)


def centre_segment(position) -> dict:
    """The segment holding the scar centre, and the centre's fraction along it."""
    start = jnp.clip(jnp.searchsorted(position, 0.0, side="right") - 1, 0, position.size - 2)
    fraction = (0.0 - position[start]) / (position[start + 1] - position[start])
    return {"start_segment": start, "start_fraction": fraction}


def table_levels(count: int) -> int:
    """Levels of a sparse table over ``count`` samples: the fewest whose 2**l sum to >= count."""
    return max(1, int(np.ceil(np.log2(count + 1))))


def sparse_table(values, levels: int, combine, identity):
    """Table ``T[l, i] = combine(values[i : i + 2**l])`` with ``identity`` past the end."""
    table = [values]
    for level in range(1, levels):
        previous, step = table[-1], 2 ** (level - 1)
        shifted = jnp.concatenate([previous[step:], jnp.full((step,), identity, previous.dtype)])
        table.append(combine(previous, shifted))
    return jnp.stack(table)


def _intervals(position, force, levels: int):
    """Where ``position + lam * force < 1`` over ``lam >= 0``."""
    finite = jnp.isfinite(force)
    below = position < 1.0
    nonzero = finite & (force != 0.0)
    ratio = (1.0 - position) / jnp.where(nonzero, force, 1.0)
    upper = jnp.where(
        ~finite,
        jnp.where(below, _TINY, -jnp.inf),  # locked: only a rigid rig passes (and locks)
        jnp.where(
            force > 0.0,
            ratio,
            jnp.where(force == 0.0, jnp.where(below, jnp.inf, -jnp.inf), jnp.inf),
        ),
    )
    return interval_table(jnp.where(finite & (force < 0.0), ratio, -jnp.inf), upper, levels)


def interval_table(lower, upper, levels: int):
    """The sparse tables of the intervals ``(lower, upper)`` per sample, and a sentinel."""
    lower = jnp.concatenate([lower, jnp.array([jnp.inf])])
    upper = jnp.concatenate([upper, jnp.array([-jnp.inf])])
    return jnp.stack(
        [
            sparse_table(lower, levels, jnp.maximum, jnp.inf),
            sparse_table(upper, levels, jnp.minimum, -jnp.inf),
        ],
        axis=-1,
    )


def _side(position, slope, mu, levels: int) -> Side:
    force = traction_forward(slope, mu)
    return Side(position, slope, force, _intervals(position, force, levels))


def profile_tables(position, slope, mu, length, sparse: bool = True) -> Tables:
    r"""The tables of one profile for one :math:`\mu` and one stroke length :math:`A`."""
    p = position / length
    g = slope
    n = p.size
    levels = table_levels(n) if sparse else 1
    forward = _side(p, g, mu, levels)
    backward = _side(-p[::-1], -g[::-1], mu, levels)
    step = jnp.diff(p)
    segment = step * mean_excess(g[:-1], g[1:], mu)
    segment = jnp.where(jnp.isfinite(segment), segment, 0.0)  # locked segments: never in a loop
    excess = jnp.concatenate([jnp.zeros(1), jnp.cumsum(segment)])
    # F_+ is convex on a segment, so it rises over it iff it rises at its left end; F_- is
    # concave, so iff it rises at its right end (lambda q' = lambda (1 + mu^2) g' / w^2).
    rate = jnp.diff(g) / step
    margin = jnp.minimum(
        jnp.maximum(1.0 - mu * g[:-1], 0.0) ** 2, jnp.maximum(1.0 + mu * g[1:], 0.0) ** 2
    )
    falling = rate < 0.0
    critical = jnp.where(
        falling, margin / ((1.0 + mu * mu) * jnp.where(falling, -rate, 1.0)), jnp.inf
    )
    trough = backward.force[::-1]  # -q_- at the samples, in the original order
    tables = Tables(
        forward=forward,
        backward=backward,
        excess=excess,
        critical=sparse_table(critical, table_levels(n - 1) if sparse else 1, jnp.minimum, jnp.inf),
        peak=sparse_table(forward.force, levels, jnp.maximum, -jnp.inf),
        trough=sparse_table(trough, levels, jnp.maximum, -jnp.inf),
        mu=mu,
        **centre_segment(p),
    )
    return jax.tree.map(lambda leaf: leaf[None], tables)
