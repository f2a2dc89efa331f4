r"""The model on a groove of any shape: the dimensionless core on a scar profile.

The pad at contact position :math:`x` feels the profile's slope :math:`g(X)` at
:math:`X = xW/x_o` (eq. 11; :math:`x_o = \Delta^*` by default, or :math:`X = x`), and eq. 9
holds pointwise: :math:`Q_\pm = P(\pm\mu + g)/(1 \mp \mu g)`.

Units
-----
Lengths along the profile are measured in units of :math:`A = \Delta^* W/x_o`, the stroke
in profile coordinates, so the contact position is :math:`\xi = X/A = x/\Delta^*`, and
the rig enters through :math:`\lambda = P/(S\Delta^*)`. The slip branches are
:math:`F_\pm(\xi) = \xi + \lambda q_\pm(\xi)`, :math:`q = Q/P`: the pad slips forward
where the actuator :math:`D = \Delta/\Delta^*` exceeds :math:`F_+`, backward where it falls
below :math:`F_-`, and sticks in between (eq. 10). With :math:`x_o = \Delta^*`,
:math:`A = W` for every amplitude: the steady loop depends on :math:`\Delta^*`, :math:`P`
and :math:`S` through :math:`\lambda` only.

The steady loop by first passage
--------------------------------
On a stroke from :math:`\xi_s` to :math:`D = 1` the pad stops at the first
:math:`\xi \ge \xi_s` with :math:`F_+(\xi) \ge 1` (the quasi-static return map; where
:math:`F_+` falls, the pad jumps ahead at constant :math:`D`). Starting at rest at the scar
centre, three first passages (forward, backward, forward) reach the steady loop
:math:`[\xi_-, \xi_+]`: after them the return map is at a fixed point (the forward map is
monotone, and :math:`F_+ < 1` on :math:`[\xi_-, \xi_+)`, :math:`F_- > -1` on
:math:`(\xi_-, \xi_+]`). :math:`\delta^* = \Delta^*(\xi_+ - \xi_-)/2`.

The energy is the loop's area, :math:`E_d = \oint Q\,d\Delta = \oint Q\,dx`, with
:math:`Q = S(\Delta - x)` during a jump; in the units above
:math:`E_d/(S\Delta^{*2}) = \int_{\xi_-}^{\xi_+} (M_+ - M_-)\,d\xi`, where :math:`M_+` is
the running maximum of :math:`F_+` from :math:`\xi_-` and :math:`M_-` the running minimum
of :math:`F_-` from :math:`\xi_+`. Without jumps :math:`M_\pm = F_\pm` and

.. math:: \frac{\mu_E}{\mu} = 1 + \frac{1}{\xi_+ - \xi_-}\int_{\xi_-}^{\xi_+}
          e\,d\xi, \qquad e = \frac{q_+ - q_-}{2\mu} - 1
          = \frac{(1 + \mu^2)g^2}{1 - \mu^2 g^2} \ge 0,

so :math:`\mu_E \ge \mu` on every profile; jumps add :math:`\int (M_+ - F_+) -
\int (M_- - F_-) \ge 0` over :math:`4\lambda d`.

Exactness
---------
The slope is piecewise linear between samples. On each segment :math:`q_+` is then convex
and :math:`q_-` concave in :math:`\xi`, so :math:`F_+` cannot exceed a level inside a
segment unless it does at an end: first passages are found exactly at the samples and the
crossing inside the segment solves a quadratic (:func:`_crossing`); the integrals of
:math:`e` and :math:`q_+` over a segment have closed forms (:func:`_mean_excess`,
:func:`_mean_traction`). Everything is exact up to rounding for the piecewise linear slope.

Tables
------
What depends on the profile, :math:`\mu` and :math:`A` only is computed once
(:func:`profile_tables`): :math:`q_+` at the samples, the cumulative integral of :math:`e`,
and for each sample the interval of :math:`\lambda` over which :math:`F_+ < 1` there, kept
in a sparse table of block intersections, so that a first passage is a descent of
:math:`\log_2 N` gathers; range tables give the peak force and whether :math:`F_\pm` are
monotone over the slip (no jumps). A point then costs :math:`O(\log N)`; where the pad
jumps, :func:`jump_area` adds the jumps' areas in :math:`O(N)`.

The functions here are pure ``jax.numpy`` and check nothing.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ecofmaps.model.regimes import BEYOND_PROFILE, GROSS_SLIP, NO_GROSS_SLIP, SELF_LOCKING

__all__ = [
    "Side",
    "SteadyLoop",
    "Tables",
    "draw_loop",
    "jump_area",
    "mean_excess",
    "mean_traction",
    "profile_tables",
    "simulation_step",
    "simulation_tables",
    "steady_loop",
    "traction_forward",
]

_TINY = float(np.nextafter(0.0, 1.0))  # the interval [0, _TINY) holds only lambda = 0

# log1p(r)/r - 1 + r/2 = sum_{m>=0} (-1)^m r^(m+2)/(m+3) for |r| < 1/8, where the first
# omitted term is below 1e-17 of the sum; above, the direct formula loses at most a factor
# 3/r^2 < 200 of eps relative to log1p(r)/r.
_SERIES_LIMIT = 0.125
_E2_SERIES = tuple((-1.0) ** m / (m + 3) for m in range(17, -1, -1))


class Side(NamedTuple):
    """One orientation of a profile: the forward stroke's view, or the mirrored one.

    Every leaf has a leading group axis (one entry per friction coefficient and length).
    """

    position: jax.Array  # (U, N) sample positions in units of the stroke, increasing
    slope: jax.Array  # (U, N)
    force: jax.Array  # (U, N) q_+ at the samples, +inf where mu g >= 1
    bounds: jax.Array  # (U, K, N + 1, 2) sparse table of the intervals' ends (K = 1: dense);
    # column N is a sentinel


class Tables(NamedTuple):
    """Everything the steady loop needs that does not depend on the rig (see module)."""

    forward: Side
    backward: Side  # the mirrored profile: position -p[::-1], slope -g[::-1]
    excess: jax.Array  # (U, N) integral of e from sample 0 to each sample
    critical: jax.Array  # (U, K, N - 1) range-min table: largest lambda without jumps, per segment
    peak: jax.Array  # (U, K, N) range-max table of q_+ at the samples
    trough: jax.Array  # (U, K, N) range-max table of -q_- at the samples
    mu: jax.Array  # (U,)
    start_segment: jax.Array  # (U,) segment holding the scar centre
    start_fraction: jax.Array  # (U,)


class SteadyLoop(NamedTuple):
    """The steady loop of one point, in the units of the module docstring."""

    minus: jax.Array  # xi_-
    plus: jax.Array  # xi_+
    ecof_ratio: jax.Array  # 1 + mean excess (without the jumps' share)
    monotone: jax.Array  # no jumps: F_+ and F_- monotone over [xi_-, xi_+]
    peak_force: jax.Array  # largest Q/P over the loop
    regime: jax.Array  # Regime code (GROSS_SLIP, NO_GROSS_SLIP, SELF_LOCKING, BEYOND_PROFILE)
    ends: tuple  # ((k_-, t_-), (k_+, t_+)) segments and fractions of the ends


# ---------------------------------------------------------------------------------------
# Pointwise formulae
# ---------------------------------------------------------------------------------------


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
    linearly from ``slope_a`` to ``slope_b`` (exact; needs :math:`\mu|g| < 1` on it).

    With :math:`w_\pm = 1 \mp \mu g_a`, :math:`r_\pm = \mp\mu\Delta g/w_\pm` and
    :math:`E_2(r) = \ln(1+r)/r - 1 + r/2`:
    :math:`\bar e = \frac{1+\mu^2}{2}\left[\frac{2g_a^2}{w_+w_-} + \frac{2g_a\Delta g}
    {(w_+w_-)^2} + \frac{E_2(r_+)/w_+ + E_2(r_-)/w_-}{\mu^2}\right]`, the mean of
    :math:`(q_+ - q_-)/(2\mu) - 1` written so that nothing cancels as :math:`\mu g \to 0`.
    """
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
    linearly from ``slope_a`` to ``slope_b`` (exact; needs :math:`\mu g < 1` on it).

    :math:`\bar q_+ = \mu + (1 + \mu^2)\left[\Delta g/(2w) + E_2(r)/\mu + g_a\right]/w`,
    :math:`w = 1 - \mu g_a`, :math:`r = -\mu\Delta g/w`: the mean of :math:`1/w` over the
    segment is :math:`\ln(1 + r)/(rw)`.
    """
    margin = 1.0 - mu * slope_a
    change = slope_b - slope_a
    inner = 0.5 * change / margin + _log_ratio_excess(-mu * change / margin) / mu + slope_a
    return mu + (1.0 + mu * mu) * inner / margin


def _crossing(start, length, slope_a, change, mu, lam, level):
    r"""Fraction :math:`t \in [0, 1]` of a segment where :math:`F_+ = \xi + \lambda q_+`
    first reaches ``level`` from below.

    The segment runs from ``start`` over ``length`` with the slope going linearly from
    ``slope_a`` by ``change``. Multiplied by :math:`w = 1 - \mu g > 0`,
    :math:`F_+ = L` is the quadratic :math:`\varphi(t) = (\xi - L)w + \lambda(\mu + g) = 0`
    with :math:`\varphi(0) < 0`; its smallest positive root, in the form without
    cancellation. For a rigid rig (:math:`\lambda = 0`) it is :math:`\xi = L`.
    """
    w0 = 1.0 - mu * slope_a
    w1 = -mu * change
    offset = start - level
    a = length * w1
    b = offset * w1 + length * w0 + lam * change
    c = offset * w0 + lam * (mu + slope_a)
    root = jnp.sqrt(jnp.maximum(b * b - 4.0 * a * c, 0.0))
    b_positive = b > 0.0
    linear = a == 0.0
    t = jnp.where(
        b_positive,
        -2.0 * c / jnp.where(b_positive, b + root, 1.0),
        (root - b) / (2.0 * jnp.where(linear, 1.0, a)),
    )
    t = jnp.where(~b_positive & linear, 1.0, t)
    t = jnp.where(lam == 0.0, (level - start) / length, t)
    return jnp.clip(t, 0.0, 1.0)


# ---------------------------------------------------------------------------------------
# Tables
# ---------------------------------------------------------------------------------------


def _levels(count: int) -> int:
    """Levels of a first-passage table over ``count`` samples: sum of 2**l >= count."""
    return max(1, int(np.ceil(np.log2(count + 1))))


def _shift(values, step: int, fill):
    return jnp.concatenate([values[step:], jnp.full((step,), fill, values.dtype)])


def _sparse(values, levels: int, combine, identity):
    """Table ``T[l, i] = combine(values[i : i + 2**l])`` with ``identity`` past the end."""
    table = [values]
    for level in range(1, levels):
        previous = table[-1]
        table.append(combine(previous, _shift(previous, 2 ** (level - 1), identity)))
    return jnp.stack(table)


def _intervals(position, force, levels: int):
    """Where ``position + lam * force < 1`` over ``lam >= 0``: the open interval
    (lower, upper) of each sample, sparse in ``levels`` levels, with a sentinel sample that
    never holds it."""
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
    lower = jnp.where(finite & (force < 0.0), ratio, -jnp.inf)
    lower = jnp.concatenate([lower, jnp.array([jnp.inf])])
    upper = jnp.concatenate([upper, jnp.array([-jnp.inf])])
    return jnp.stack(
        [
            _sparse(lower, levels, jnp.maximum, jnp.inf),
            _sparse(upper, levels, jnp.minimum, -jnp.inf),
        ],
        axis=-1,
    )


def _side(position, slope, mu, sparse: bool) -> Side:
    force = traction_forward(slope, mu)
    levels = _levels(position.size) if sparse else 1
    return Side(position, slope, force, _intervals(position, force, levels))


def _range_levels(count: int) -> int:
    return int(np.floor(np.log2(max(count, 1)))) + 1


def profile_tables(position, slope, mu, length, sparse: bool = True) -> Tables:
    r"""The tables of one profile for one :math:`\mu` and one stroke length :math:`A`.

    Parameters
    ----------
    position : jax.Array, shape (N,)
        Sample positions :math:`X`, increasing, relative to the scar centre. [m]
    slope : jax.Array, shape (N,)
        Slopes :math:`g` at the samples. [1]
    mu : jax.Array, shape ()
        Friction coefficient. [1]
    length : jax.Array, shape ()
        Stroke length :math:`A = \Delta^* W/x_o` in profile coordinates. [m]
    sparse : bool
        Build the :math:`O(N\log N)` tables for :math:`O(\log N)` queries (for many points
        sharing :math:`\mu` and :math:`A`), or only the :math:`O(N)` ones (one point).

    Returns
    -------
    tables : Tables
        With a leading group axis of length 1.
    """
    p = position / length
    g = slope
    n = p.size
    forward = _side(p, g, mu, sparse)
    backward = _side(-p[::-1], -g[::-1], mu, sparse)
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
    levels = _range_levels(n) if sparse else 1
    start = jnp.clip(jnp.searchsorted(p, 0.0, side="right") - 1, 0, n - 2)
    tables = Tables(
        forward=forward,
        backward=backward,
        excess=excess,
        critical=_sparse(critical, _range_levels(n - 1) if sparse else 1, jnp.minimum, jnp.inf),
        peak=_sparse(forward.force, levels, jnp.maximum, -jnp.inf),
        trough=_sparse(trough, levels, jnp.maximum, -jnp.inf),
        mu=mu,
        start_segment=start,
        start_fraction=(0.0 - p[start]) / (p[start + 1] - p[start]),
    )
    return jax.tree.map(lambda leaf: leaf[None], tables)


# ---------------------------------------------------------------------------------------
# Queries
# ---------------------------------------------------------------------------------------


def _at(table, group, *index):
    """``table[group, *index]`` as one gather from the flattened table (XLA's gathers with
    several index dimensions are several times slower on CPU)."""
    flat = group
    for size, i in zip(table.shape[1:], index, strict=True):
        flat = flat * size + i
    return table.reshape(-1)[flat]


def _first_holding(side: Side, group, value, begin, sparse: bool):
    """First sample index >= ``begin`` whose interval does not hold ``value``, or N."""
    n = side.position.shape[-1]
    if sparse:
        index = begin
        rows = side.bounds.reshape(-1, 2)
        levels, columns = side.bounds.shape[1:3]
        for level in reversed(range(levels)):
            bounds = rows[(group * levels + level) * columns + jnp.minimum(index, n)]
            below = (bounds[..., 0] < value) & (value < bounds[..., 1])
            index = jnp.where(below, index + 2**level, index)
        return jnp.minimum(index, n)
    lower, upper = side.bounds[group, 0, :n, 0], side.bounds[group, 0, :n, 1]
    holds = ~((lower < value) & (value < upper)) & (jnp.arange(n) >= begin)
    return jnp.where(jnp.any(holds), jnp.argmax(holds), n)


def _range(table, group, first, last, combine, identity, sparse: bool):
    """``combine`` over ``table[group]`` at indices ``first..last`` (identity if empty)."""
    if sparse:
        count = jnp.maximum(last - first + 1, 1).astype(jnp.int32)
        level = 31 - jax.lax.clz(count)
        a = _at(table, group, level, first)
        b = _at(table, group, level, jnp.maximum(last - jnp.left_shift(1, level) + 1, 0))
        return jnp.where(last >= first, combine(a, b), identity)
    row = table[group, 0]
    index = jnp.arange(row.size)
    inside = (index >= first) & (index <= last)
    values = jnp.where(inside, row, identity)
    return values.max() if identity == -jnp.inf else values.min()


def _normal(segment, fraction, n: int):
    """``(k, t)`` with ``t < 1`` unless at the last sample."""
    roll = (fraction >= 1.0) & (segment < n - 2)
    return segment + roll, jnp.where(roll, 0.0, jnp.minimum(fraction, 1.0))


def _mirror(segment, fraction, n: int):
    """The same position on the mirrored profile."""
    return _normal(n - 2 - segment, 1.0 - fraction, n)


def _point(side: Side, group, segment, fraction):
    """Position and slope at ``(segment, fraction)``."""
    p0, p1 = _at(side.position, group, segment), _at(side.position, group, segment + 1)
    g0, g1 = _at(side.slope, group, segment), _at(side.slope, group, segment + 1)
    return p0 + fraction * (p1 - p0), g0 + fraction * (g1 - g0)


def _passage(side: Side, group, mu, lam, value, level, segment, fraction, sparse: bool):
    """First passage of ``F_+ >= level`` from ``(segment, fraction)``: new position, ran off."""
    n = side.position.shape[-1]
    start, start_slope = _point(side, group, segment, fraction)
    force = jnp.where(lam > 0.0, lam * traction_forward(start_slope, mu), 0.0)
    stick = start + force >= level
    j = _first_holding(side, group, value, segment + 1, sparse)
    off = (j >= n) & ~stick
    j = jnp.clip(j, 1, n - 1)
    same = j - 1 == segment
    left = _at(side.position, group, j - 1)
    a = jnp.where(same, start, left)
    slope_a = jnp.where(same, start_slope, _at(side.slope, group, j - 1))
    b, slope_b = _at(side.position, group, j), _at(side.slope, group, j)
    t = _crossing(a, b - a, slope_a, slope_b - slope_a, mu, lam, level)
    reached = a + t * (b - a)
    new = _normal(j - 1, (reached - left) / (b - left), n)
    return jnp.where(stick, segment, new[0]), jnp.where(stick, fraction, new[1]), off


def steady_loop(tables: Tables, group, lam, sparse: bool = True) -> SteadyLoop:
    r"""The steady loop of one point (see module): ends, :math:`\mu_E/\mu`, peak, regime.

    Parameters
    ----------
    tables : Tables
        From :func:`profile_tables` (stacked over groups).
    group : jax.Array of int, shape ()
        The point's group (its :math:`\mu` and :math:`A`).
    lam : jax.Array, shape ()
        :math:`\lambda = P/(S\Delta^*)` >= 0.
    sparse : bool
        Whether ``tables`` were built sparse.

    Returns
    -------
    loop : SteadyLoop
        ``ecof_ratio`` lacks the jumps' share where ``monotone`` is False (:func:`jump_area`).
    """
    forward, backward = tables.forward, tables.backward
    n = forward.position.shape[-1]
    mu = _at(tables.mu, group)
    k, t = _at(tables.start_segment, group), _at(tables.start_fraction, group)
    k, t, off_1 = _passage(forward, group, mu, lam, lam, 1.0, k, t, sparse)
    k, t, off_2 = _passage(backward, group, mu, lam, lam, 1.0, *_mirror(k, t, n), sparse)
    k_minus, t_minus = _mirror(k, t, n)
    k_plus, t_plus, off_3 = _passage(forward, group, mu, lam, lam, 1.0, k_minus, t_minus, sparse)
    minus, slope_minus = _point(forward, group, k_minus, t_minus)
    plus, slope_plus = _point(forward, group, k_plus, t_plus)
    width = plus - minus

    # The integral of e over [xi_-, xi_+]: the table between the samples inside and the end
    # pieces, each taken from the sample on the loop's side (a locking point, where e is
    # singular, can lie just beyond either end).
    def piece(a, slope_a, b, slope_b):
        return (b - a) * mean_excess(slope_a, slope_b, mu)

    after, slope_after = _point(forward, group, k_minus + 1, 0.0)
    before, slope_before = _point(forward, group, k_plus, 0.0)
    table = _at(tables.excess, group, k_plus) - _at(tables.excess, group, k_minus + 1)
    split = piece(minus, slope_minus, after, slope_after) + table
    split = split + piece(before, slope_before, plus, slope_plus)
    integral = jnp.where(k_minus == k_plus, piece(minus, slope_minus, plus, slope_plus), split)
    stuck = width == 0.0
    ratio = 1.0 + integral / jnp.where(stuck, 1.0, width)
    critical = _range(tables.critical, group, k_minus, k_plus, jnp.minimum, jnp.inf, sparse)
    peak = _range(tables.peak, group, k_minus + 1, k_plus, jnp.maximum, -jnp.inf, sparse)
    peak = jnp.maximum(
        peak, jnp.maximum(traction_forward(slope_minus, mu), traction_forward(slope_plus, mu))
    )
    trough = _range(tables.trough, group, k_minus + 1, k_plus, jnp.maximum, -jnp.inf, sparse)
    trough = jnp.maximum(
        trough, jnp.maximum(traction_forward(-slope_minus, mu), traction_forward(-slope_plus, mu))
    )
    # A rigid rig passes a locking point; a rig stiff enough to stop the pad within rounding
    # of one (lambda ~ 1e-17 of the stroke) gives an infinite force there too.
    locked = ~(jnp.isfinite(peak) & jnp.isfinite(trough) & jnp.isfinite(integral))
    stick_force = (1.0 - plus) / jnp.where(lam > 0.0, lam, 1.0)  # the stick line at D = 1
    off = off_1 | off_2 | off_3
    regime = jnp.where(
        off,
        int(BEYOND_PROFILE),
        jnp.where(locked, int(SELF_LOCKING), jnp.where(stuck, int(NO_GROSS_SLIP), int(GROSS_SLIP))),
    ).astype(jnp.int32)
    return SteadyLoop(
        minus=minus,
        plus=plus,
        ecof_ratio=jnp.where(stuck, jnp.nan, ratio),
        monotone=stuck | (lam <= critical),
        peak_force=jnp.where(stuck, stick_force, peak),
        regime=regime,
        ends=((k_minus, t_minus), (k_plus, t_plus)),
    )


def _running_levels(side: Side, group, mu, lam, start, end):
    """Per segment of a forward stroke from ``start`` to ``end`` (``(k, t)`` pairs): the
    piece ``[a, b]`` it covers, its slopes, and the running maximum ``L`` of :math:`F_+`
    at ``a`` (from the stroke's start)."""
    n = side.position.shape[-1]
    p, g, q = side.position[group], side.slope[group], side.force[group]
    (k_a, t_a), (k_b, t_b) = start, end
    xa, ga = _point(side, group, k_a, t_a)
    xb, gb = _point(side, group, k_b, t_b)
    values = p + jnp.where(lam > 0.0, lam * q, 0.0)
    index = jnp.arange(n)
    inside = (index > k_a) & (index <= k_b)
    fa = xa + jnp.where(lam > 0.0, lam * traction_forward(ga, mu), 0.0)
    running = jnp.maximum(fa, jax.lax.cummax(jnp.where(inside, values, -jnp.inf)))
    segment = jnp.arange(n - 1)
    first, last = segment == k_a, segment == k_b
    a = jnp.where(first, xa, p[:-1])
    slope_a = jnp.where(first, ga, g[:-1])
    b = jnp.where(last, xb, p[1:])
    slope_b = jnp.where(last, gb, g[1:])
    level = jnp.where(first, fa, running[:-1])
    value_b = jnp.where(
        last, xb + jnp.where(lam > 0.0, lam * traction_forward(gb, mu), 0.0), values[1:]
    )
    active = (segment >= k_a) & (segment <= k_b) & (b > a)
    return a, b, slope_a, slope_b, level, value_b, active


def jump_area(side: Side, group, mu, lam, start, end):
    r""":math:`\int (M_+ - F_+)\,d\xi` over a forward stroke from ``start`` to ``end``.

    :math:`M_+` is the running maximum of :math:`F_+` from the stroke's start: the actuator
    position while the pad slips or jumps. On each segment piece :math:`[a, b]`,
    :math:`F_+` (convex) lies below the level :math:`L = M_+(a)` on :math:`[a, c)`, where
    :math:`c` is where it climbs back to :math:`L` (:func:`_crossing`), or :math:`b`. The
    area there is :math:`(c - a)(L - (a + c)/2 - \lambda\bar q_+)`. :math:`O(N)`.

    Parameters
    ----------
    side : Tables.forward or Tables.backward
    group : jax.Array of int
    mu, lam : jax.Array
    start, end : tuple of (segment, fraction)
        The stroke's ends on ``side``.

    Returns
    -------
    area : jax.Array
        >= 0, in units of :math:`A^2` (0 where :math:`F_+` rises all along).
    """
    a, b, slope_a, slope_b, level, value_b, active = _running_levels(
        side, group, mu, lam, start, end
    )
    change = slope_b - slope_a
    t = _crossing(a, b - a, slope_a, change, mu, lam, level)
    t = jnp.where(value_b >= level, t, 1.0)
    c = a + t * (b - a)
    slope_c = slope_a + t * change
    area = (c - a) * (level - 0.5 * (a + c) - lam * mean_traction(slope_a, slope_c, mu))
    return jnp.sum(jnp.where(active & (c > a), area, 0.0))


def _branch(side: Side, group, mu, lam, start, end, num: int):
    """``num`` points of a forward stroke from ``start`` to ``end``: actuator D and Q/P."""
    a, b, slope_a, slope_b, level, _, _ = _running_levels(side, group, mu, lam, start, end)
    xa, _ = _point(side, group, *start)
    xb, _ = _point(side, group, *end)
    xi = xa + (xb - xa) * jnp.linspace(0.0, 1.0, num)
    xi = xi.at[-1].set(xb)
    segment = jnp.arange(b.size)
    ends = jnp.where(segment < start[0], -jnp.inf, jnp.where(segment > end[0], jnp.inf, b))
    k = jnp.clip(jnp.searchsorted(ends, xi, side="left"), start[0], end[0])
    fraction = jnp.where(b[k] > a[k], (xi - a[k]) / jnp.where(b[k] > a[k], b[k] - a[k], 1.0), 0.0)
    slope = slope_a[k] + fraction * (slope_b[k] - slope_a[k])
    q = traction_forward(slope, mu)
    value = xi + jnp.where(lam > 0.0, lam * q, 0.0)
    actuator = jnp.maximum(level[k], value)
    slipping = value >= level[k]
    q = jnp.where(slipping, q, (actuator - xi) / jnp.where(lam > 0.0, lam, 1.0))
    return actuator, q


def draw_loop(tables: Tables, group, lam, loop: SteadyLoop, num: int):
    """The steady loop's actuator positions D and forces Q/P, ``2 num + 1`` points.

    Starts at the reversal (D = -1), slips forward (jumping where :math:`F_+` falls) to
    D = 1, then back; the stick segments are the straight lines between the branches.
    With no gross slip the points lie on the stick line through the stuck position.
    """
    n = tables.forward.position.shape[-1]
    mu = tables.mu[group]
    lower, upper = loop.ends
    d_forward, q_forward = _branch(tables.forward, group, mu, lam, lower, upper, num)
    d_back, q_back = _branch(
        tables.backward, group, mu, lam, _mirror(*upper, n), _mirror(*lower, n), num
    )
    actuator = jnp.concatenate([-d_back[-1:], d_forward, -d_back])
    force = jnp.concatenate([-q_back[-1:], q_forward, -q_back])
    stuck = loop.regime == int(NO_GROSS_SLIP)
    line = jnp.linspace(-1.0, 1.0, 2 * num + 1)
    stick_force = (line - loop.plus) / jnp.where(lam > 0.0, lam, 1.0)
    return jnp.where(stuck, line, actuator), jnp.where(stuck, stick_force, force)


# ---------------------------------------------------------------------------------------
# Time-domain return map
# ---------------------------------------------------------------------------------------


def simulation_tables(position, slope, mu, lam) -> Tables:
    r"""Tables for a time history at one :math:`(\mu, \lambda)`: per sample, the actuator
    positions :math:`D` at which :math:`F_+ \ge D` fails, :math:`(F_+, \infty)`, sparse.

    ``position`` is in the units of the history (the scar's half-width for
    :func:`ecofmaps.simulate`), ``lam`` the compliance ratio in the same units.
    """

    def side(p, g):
        force = traction_forward(g, mu)
        values = p + jnp.where(lam > 0.0, lam * force, 0.0)
        levels = _levels(p.size)
        lower = jnp.concatenate([values, jnp.array([jnp.inf])])
        upper = jnp.concatenate([jnp.full(p.size, jnp.inf), jnp.array([-jnp.inf])])
        bounds = jnp.stack(
            [
                _sparse(lower, levels, jnp.maximum, jnp.inf),
                _sparse(upper, levels, jnp.minimum, -jnp.inf),
            ],
            axis=-1,
        )
        return Side(p, g, force, bounds)

    n = position.size
    start = jnp.clip(jnp.searchsorted(position, 0.0, side="right") - 1, 0, n - 2)
    empty = jnp.zeros((1, 1))
    tables = Tables(
        forward=side(position, slope),
        backward=side(-position[::-1], -slope[::-1]),
        excess=jnp.zeros(1),
        critical=empty,
        peak=empty,
        trough=empty,
        mu=mu,
        start_segment=start,
        start_fraction=(0.0 - position[start]) / (position[start + 1] - position[start]),
    )
    return jax.tree.map(lambda leaf: leaf[None], tables)


def simulation_step(tables: Tables, lam, state, actuator):
    """One step of the return map: the pad sticks or slips to the exact equilibrium.

    ``state`` is ``(segment, fraction, q, off)``; returns the new state and Q/P (NaN once
    the pad has run off the profile or locked on a rigid rig).
    """
    forward, backward = tables.forward, tables.backward
    n = forward.position.shape[-1]
    mu = tables.mu[0]
    k, t, q, off = state
    x, g = _point(forward, 0, k, t)
    has_lam = lam > 0.0
    ahead = x + jnp.where(has_lam, lam * traction_forward(g, mu), 0.0)
    behind = x - jnp.where(has_lam, lam * traction_forward(-g, mu), 0.0)
    go_forward = actuator > ahead
    go_back = actuator < behind
    kf, tf, off_f = _passage(forward, 0, mu, lam, actuator, actuator, k, t, True)
    kb, tb, off_b = _passage(backward, 0, mu, lam, -actuator, -actuator, *_mirror(k, t, n), True)
    kb, tb = _mirror(kb, tb, n)
    k_new = jnp.where(go_forward, kf, jnp.where(go_back, kb, k))
    t_new = jnp.where(go_forward, tf, jnp.where(go_back, tb, t))
    _, g_new = _point(forward, 0, k_new, t_new)
    q_slip = jnp.where(go_forward, traction_forward(g_new, mu), -traction_forward(-g_new, mu))
    q_stick = jnp.where(has_lam, (actuator - x) / jnp.where(has_lam, lam, 1.0), q)
    q_new = jnp.where(go_forward | go_back, q_slip, q_stick)
    off = off | (go_forward & off_f) | (go_back & off_b) | ~jnp.isfinite(q_new)
    return (k_new, t_new, q_new, off), jnp.where(off, jnp.nan, q_new)
