r"""The steady loop on a scar profile, read off the tables of :mod:`ecofmaps.model.profile_core`
by first passage, its jumps' areas, its drawing, and the return map in time. Pure ``jax.numpy``,
no checks; the method is explained in ``docs/model.md`` (the model on a scar profile).
"""

from __future__ import annotations

import sys
from typing import NamedTuple

import jax
import jax.numpy as jnp

from ecofmaps.model import profile_core as core
from ecofmaps.model.regimes import BEYOND_PROFILE, GROSS_SLIP, NO_GROSS_SLIP, SELF_LOCKING

#: Peak traction ratio |Q|/P beyond which a steady loop is reported self-locking, 1/sqrt(eps)
#: (about 6.7e7): the loop's area, a difference of forces of that size, is left to rounding.
JAMMED_TRACTION = sys.float_info.epsilon**-0.5


class SteadyLoop(NamedTuple):
    """The steady loop of one point, in the units of ``docs/model.md``."""

    minus: jax.Array  # xi_-
    plus: jax.Array  # xi_+
    ecof_ratio: jax.Array  # 1 + mean excess (without the jumps' share)
    monotone: jax.Array  # no jumps: F_+ and F_- monotone over [xi_-, xi_+]
    peak_force: jax.Array  # largest Q/P over the loop
    regime: jax.Array  # Regime code (GROSS_SLIP, NO_GROSS_SLIP, SELF_LOCKING, BEYOND_PROFILE)
    ends: tuple  # ((k_-, t_-), (k_+, t_+)) segments and fractions of the ends


def _at(table, group, *index):
    """``table[group, *index]`` as one gather from the flattened table (faster on CPU)."""
    flat = group
    for size, i in zip(table.shape[1:], index, strict=True):
        flat = flat * size + i
    return table.reshape(-1)[flat]


def _first_holding(side: core.Side, group, value, begin, sparse: bool):
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
    return _normal(n - 2 - segment, 1.0 - fraction, n)


def _point(side: core.Side, group, segment, fraction):
    """Position and slope at ``(segment, fraction)``."""
    p0, p1 = _at(side.position, group, segment), _at(side.position, group, segment + 1)
    g0, g1 = _at(side.slope, group, segment), _at(side.slope, group, segment + 1)
    return p0 + fraction * (p1 - p0), g0 + fraction * (g1 - g0)


def _actuator(position, force, lam):
    """Actuator position :math:`\\xi + \\lambda q` at which the pad slips with ``force`` q."""
    return position + jnp.where(lam > 0.0, lam * force, 0.0)


def _passage(side: core.Side, group, mu, lam, value, level, segment, fraction, sparse: bool):
    """First passage of ``F_+ >= level`` from ``(segment, fraction)``: new position, ran off."""
    n = side.position.shape[-1]
    start, start_slope = _point(side, group, segment, fraction)
    stick = _actuator(start, core.traction_forward(start_slope, mu), lam) >= level
    j = _first_holding(side, group, value, segment + 1, sparse)
    off = (j >= n) & ~stick
    j = jnp.clip(j, 1, n - 1)
    same = j - 1 == segment
    left = _at(side.position, group, j - 1)
    a = jnp.where(same, start, left)
    slope_a = jnp.where(same, start_slope, _at(side.slope, group, j - 1))
    b, slope_b = _at(side.position, group, j), _at(side.slope, group, j)
    t = core.crossing_fraction(a, b - a, slope_a, slope_b - slope_a, mu, lam, level)
    reached = a + t * (b - a)
    new = _normal(j - 1, (reached - left) / (b - left), n)
    return jnp.where(stick, segment, new[0]), jnp.where(stick, fraction, new[1]), off


def steady_loop(tables: core.Tables, group, lam, sparse: bool = True) -> SteadyLoop:
    r"""The steady loop of one point (``docs/model.md``): ends, :math:`\mu_E/\mu`, peak, regime."""
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
        return (b - a) * core.mean_excess(slope_a, slope_b, mu)

    after, slope_after = _point(forward, group, k_minus + 1, 0.0)
    before, slope_before = _point(forward, group, k_plus, 0.0)
    table = _at(tables.excess, group, k_plus) - _at(tables.excess, group, k_minus + 1)
    split = piece(minus, slope_minus, after, slope_after) + table
    split = split + piece(before, slope_before, plus, slope_plus)
    integral = jnp.where(k_minus == k_plus, piece(minus, slope_minus, plus, slope_plus), split)
    stuck = width == 0.0
    ratio = 1.0 + integral / jnp.where(stuck, 1.0, width)
    critical = _range(tables.critical, group, k_minus, k_plus, jnp.minimum, jnp.inf, sparse)

    def largest(table, slope_a, slope_b):
        inside = _range(table, group, k_minus + 1, k_plus, jnp.maximum, -jnp.inf, sparse)
        ends = jnp.maximum(core.traction_forward(slope_a, mu), core.traction_forward(slope_b, mu))
        return jnp.maximum(inside, ends)

    peak = largest(tables.peak, slope_minus, slope_plus)
    trough = largest(tables.trough, -slope_minus, -slope_plus)
    # Infinite at a locking point (a rigid rig, or one stiff to within rounding); jammed above
    # JAMMED_TRACTION (docs/model.md).
    locked = ~(jnp.isfinite(peak) & jnp.isfinite(trough) & jnp.isfinite(integral))
    locked = locked | (jnp.maximum(peak, trough) > JAMMED_TRACTION)
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


def _running_levels(side: core.Side, group, mu, lam, start, end):
    """Per segment of a forward stroke from ``start`` to ``end`` (``(k, t)`` pairs)."""
    n = side.position.shape[-1]
    p, g, q = side.position[group], side.slope[group], side.force[group]
    (k_a, t_a), (k_b, t_b) = start, end
    xa, ga = _point(side, group, k_a, t_a)
    xb, gb = _point(side, group, k_b, t_b)
    values = _actuator(p, q, lam)
    index = jnp.arange(n)
    inside = (index > k_a) & (index <= k_b)
    fa = _actuator(xa, core.traction_forward(ga, mu), lam)
    running = jnp.maximum(fa, jax.lax.cummax(jnp.where(inside, values, -jnp.inf)))
    segment = jnp.arange(n - 1)
    first, last = segment == k_a, segment == k_b
    a = jnp.where(first, xa, p[:-1])
    slope_a = jnp.where(first, ga, g[:-1])
    b = jnp.where(last, xb, p[1:])
    slope_b = jnp.where(last, gb, g[1:])
    level = jnp.where(first, fa, running[:-1])
    value_b = jnp.where(last, _actuator(xb, core.traction_forward(gb, mu), lam), values[1:])
    active = (segment >= k_a) & (segment <= k_b) & (b > a)
    return a, b, slope_a, slope_b, level, value_b, active


def _jump_area(side: core.Side, group, mu, lam, start, end):
    r""":math:`\int (M_+ - F_+)\,d\xi` over a forward stroke from ``start`` to ``end``."""
    a, b, slope_a, slope_b, level, value_b, active = _running_levels(
        side, group, mu, lam, start, end
    )
    change = slope_b - slope_a
    t = core.crossing_fraction(a, b - a, slope_a, change, mu, lam, level)
    t = jnp.where(value_b >= level, t, 1.0)
    c = a + t * (b - a)
    slope_c = slope_a + t * change
    area = (c - a) * (level - 0.5 * (a + c) - lam * core.mean_traction(slope_a, slope_c, mu))
    return jnp.sum(jnp.where(active & (c > a), area, 0.0))


def _branch(side: core.Side, group, mu, lam, start, end, num: int):
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
    q = core.traction_forward(slope, mu)
    value = _actuator(xi, q, lam)
    actuator = jnp.maximum(level[k], value)
    slipping = value >= level[k]
    q = jnp.where(slipping, q, (actuator - xi) / jnp.where(lam > 0.0, lam, 1.0))
    return actuator, q


def _both_strokes(stroke, tables: core.Tables, group, lam, ends, *args):
    """``stroke`` forward from the lower end to the upper one, and back on the mirrored profile."""
    n = tables.forward.position.shape[-1]
    mu = tables.mu[group]
    lower, upper = ends
    forward = stroke(tables.forward, group, mu, lam, lower, upper, *args)
    mirrored = (_mirror(*upper, n), _mirror(*lower, n))
    return forward, stroke(tables.backward, group, mu, lam, *mirrored, *args)


def jump_areas(tables: core.Tables, group, lam, ends):
    """The jumps' areas of both strokes of the steady loop with ``ends``."""
    forward, backward = _both_strokes(_jump_area, tables, group, lam, ends)
    return forward + backward


def draw_loop(tables: core.Tables, group, lam, loop: SteadyLoop, num: int):
    """The steady loop's actuator positions D and forces Q/P, ``2 num + 1`` points."""
    forward, backward = _both_strokes(_branch, tables, group, lam, loop.ends, num)
    (d_forward, q_forward), (d_back, q_back) = forward, backward
    actuator = jnp.concatenate([-d_back[-1:], d_forward, -d_back])
    force = jnp.concatenate([-q_back[-1:], q_forward, -q_back])
    stuck = loop.regime == int(NO_GROSS_SLIP)
    line = jnp.linspace(-1.0, 1.0, 2 * num + 1)
    stick_force = (line - loop.plus) / jnp.where(lam > 0.0, lam, 1.0)
    return jnp.where(stuck, line, actuator), jnp.where(stuck, stick_force, force)


def simulation_tables(position, slope, mu, lam) -> core.Tables:
    r"""core.Tables for a time history at one :math:`(\mu, \lambda)`: per sample, the actuator
    positions :math:`D` at which :math:`F_+ \ge D` fails, :math:`(F_+, \infty)`, sparse."""

    def side(p, g):
        force = core.traction_forward(g, mu)
        values = _actuator(p, force, lam)
        bounds = core.interval_table(values, jnp.full(p.size, jnp.inf), core.table_levels(p.size))
        return core.Side(p, g, force, bounds)

    empty = jnp.zeros((1, 1))
    tables = core.Tables(
        forward=side(position, slope),
        backward=side(-position[::-1], -slope[::-1]),
        excess=jnp.zeros(1),
        critical=empty,
        peak=empty,
        trough=empty,
        mu=mu,
        **core.centre_segment(position),
    )
    return jax.tree.map(lambda leaf: leaf[None], tables)


def simulation_step(tables: core.Tables, lam, state, actuator):
    """One step of the return map: the pad sticks or slips to the exact equilibrium."""
    forward, backward = tables.forward, tables.backward
    n = forward.position.shape[-1]
    mu = tables.mu[0]
    k, t, q, off = state
    x, g = _point(forward, 0, k, t)
    has_lam = lam > 0.0
    ahead = _actuator(x, core.traction_forward(g, mu), lam)
    behind = x - jnp.where(has_lam, lam * core.traction_forward(-g, mu), 0.0)
    go_forward = actuator > ahead
    go_back = actuator < behind
    kf, tf, off_f = _passage(forward, 0, mu, lam, actuator, actuator, k, t, True)
    kb, tb, off_b = _passage(backward, 0, mu, lam, -actuator, -actuator, *_mirror(k, t, n), True)
    kb, tb = _mirror(kb, tb, n)
    k_new = jnp.where(go_forward, kf, jnp.where(go_back, kb, k))
    t_new = jnp.where(go_forward, tf, jnp.where(go_back, tb, t))
    _, g_new = _point(forward, 0, k_new, t_new)
    q_slip = jnp.where(
        go_forward, core.traction_forward(g_new, mu), -core.traction_forward(-g_new, mu)
    )
    q_stick = jnp.where(has_lam, (actuator - x) / jnp.where(has_lam, lam, 1.0), q)
    q_new = jnp.where(go_forward | go_back, q_slip, q_stick)
    off = off | (go_forward & off_f) | (go_back & off_b) | ~jnp.isfinite(q_new)
    return (k_new, t_new, q_new, off), jnp.where(off, jnp.nan, q_new)
