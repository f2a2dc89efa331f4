r"""The steps of :func:`ecofmaps.analyze_loops` that run along each branch of each loop.

A branch runs from one reversal to the next: the rising branch from a loop's lowest
displacement to its highest, the falling branch back. Each is laid out as a row (branch,
point) starting at its reversal and padded by repeating its last point: the rising
branches of a block's cycles, then their falling branches, so that every step runs once
over both branches of every cycle, vectorised. The methods are described in
:mod:`ecofmaps.measured.analysis`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["both", "branch_rows", "line_crossings", "stick_lines", "zero_force_crossings"]

#: Samples with :math:`|Q|` below this share of :math:`Q^*` locate a zero-force crossing
#: that is not on a stick segment.
_ZERO_FORCE_BAND = 0.25

#: A stick segment grows until two samples in a row are this many standard deviations off.
_STICK_SPREAD = 3.0

#: Fewest samples in the window of the curve fitted at a GICoF crossing.
_FIT_SAMPLES = 5

#: A stick segment is curved when a term in the squared force, added to its line, is
#: significant by more than this many standard errors ...
_CURVATURE_T = 8.0

#: ... and changes its slope from one end to the other by more than this share.
_CURVATURE_CHANGE = 0.05

#: In a GICoF window where the variance of :math:`\xi Q` not explained by :math:`\xi` is
#: below this share of its own (rounding: the force is constant along the slip), the line
#: :math:`Q = a + b\xi` is fitted.
_COLLINEAR = 1e-24


def _dot(a, b):
    """Sum of ``a * b`` along each row."""
    return np.einsum("ij,ij->i", a, b)


def _counts(flags):
    """The number of True along each row of a 2-D boolean array (as np.count_nonzero, faster)."""
    return np.einsum("ij->i", flags.view(np.uint8), dtype=np.int64)


def both(values):
    """A per-cycle array for the rising then the falling branch rows."""
    return np.concatenate([values, values])


def _from_first(flags):
    """True from the first True of each row on (a cumulative OR along the rows)."""
    first = np.argmax(flags, axis=1)
    found = flags[np.arange(flags.shape[0]), first]
    return np.arange(flags.shape[1]) >= np.where(found, first, flags.shape[1])[:, None]


def _columns(mask) -> slice:
    """The columns that hold every True of ``mask`` (sums over it need no others)."""
    (used,) = np.nonzero(np.any(mask, axis=0))
    return slice(used[0], used[-1] + 1) if used.size else slice(0, 0)


def _bracket(before, length):
    """Index of the sample just past a sign change on each branch row.

    ``before`` marks the branch's samples on the starting side. The change is placed after
    as many samples as the branch has on that side, so a few noisy samples on the wrong
    side do not move it far.
    """
    return np.clip(_counts(before), 1, length - 1)


def branch_rows(block, top):
    """The rising branches (start to top) and falling ones (top to the end) as rows.

    Returns the displacement and force rows, the mask of each row's own points and the
    number of them.
    """
    cycles = top.size
    first = np.concatenate([np.zeros_like(top), top])
    last = np.concatenate([top, block.count])
    length = last - first + 1
    j = np.arange(int(length.max()))
    valid = j < length[:, None]
    if not block.continuous:  # a loop may begin inside its stretch and wrap round it
        point = np.minimum(first[:, None] + j, last[:, None])
        index = block.samples(point, np.tile(np.arange(cycles), 2))
        return block.displacement[index], block.force[index], valid, length
    # Each row is a stretch of the samples from its reversal on, up to its last point:
    # the top of a rising branch; the loop's first sample, which closes a falling one.
    start = np.tile(block.offset, 2) + first
    end = np.concatenate([block.offset + top, block.offset])
    tail = ~(j < (length - 1)[:, None])  # the last point and the padding
    x, y = (_stretch_rows(values, start, end, tail) for values in (block.displacement, block.force))
    return x, y, valid, length


def _stretch_rows(values, start, end, tail):
    """Rows of ``values`` from each ``start`` on, with ``values[end]`` where ``tail``."""
    width = tail.shape[1]
    over = start + width > values.size  # rows that would run past the samples
    if values.size >= width:  # a view of every stretch of ``width`` samples, rows copied
        out = np.lib.stride_tricks.sliding_window_view(values, width)[np.where(over, 0, start)]
    else:
        out = np.empty(tail.shape)
    if over.any():
        index = np.minimum(start[over, None] + np.arange(width), values.size - 1)
        out[over] = values[index]
    np.copyto(out, values[end][:, None], where=tail)
    return out


def _line(mask, u, v, spread=False):
    """Sums of the least-squares line of ``v`` on ``u`` through each row's masked points.

    Returns the count, the means of ``u`` and ``v``, and the sums of du dv and du du
    (deviations from the means); if ``spread``, also the sum of dv dv, the mask as
    weights and du (zero off the mask), for :func:`_stick_fit`.
    """
    weight = mask.astype(np.float64)
    count = weight.sum(axis=1)
    mean_u = _dot(weight, u) / count
    mean_v = _dot(weight, v) / count
    du = (u - mean_u[:, None]) * weight
    dv = v - mean_v[:, None]
    sums = (count, mean_u, mean_v, _dot(du, dv), _dot(du, du))
    if spread:
        dv *= weight
        sums += (_dot(dv, dv), weight, du)
    return sums


def _common_line(mask, y, x, spread=False):
    r"""Lines :math:`\Delta = c + Q/S` through both branches' masked points, one slope.

    Returns the compliance :math:`1/S` of each cycle, the intercept :math:`c` of each
    branch row, and each row's sums from :func:`_line`.
    """
    sums = _line(mask, y, x, spread)
    count, mean_y, mean_x, covariance, variance = sums[:5]
    cycles = count.size // 2
    compliance = (covariance[:cycles] + covariance[cycles:]) / (
        variance[:cycles] + variance[cycles:]
    )
    return compliance, mean_x - both(compliance) * mean_y, sums


def stick_lines(x, y, valid, span, window):
    r"""Lines :math:`\Delta = c + Q/S` through the stick segments after the two reversals.

    A segment starts as the branch's samples whose force has moved away from the
    reversal's by a share of the branch's force swing within ``window``, up to the first
    sample beyond it (with fewer than two, the chord from the reversal to the first sample
    past the lower share). A first line is fitted; each segment then grows along its
    branch until two samples in a row lie more than ``_STICK_SPREAD`` standard deviations
    off its line (the slip that follows bends away from it; a single noisy sample does
    not stop it), and the lines are fitted again to the grown segments.

    Returns the common compliance :math:`1/S` of each cycle, the intercept :math:`c` of
    each branch row, the mask of each segment (over the first columns: no segment reaches
    further) and, per cycle, how well the lines fit (:func:`_stick_fit`).
    """
    low, high = window
    rows, width = x.shape
    swing = np.max(y, axis=1) - np.min(y, axis=1)
    # The segments begin before the force has moved past the upper share: look at the
    # first columns, and at all of them if a branch has not moved that far there.
    limit = min(width, max(16, width // 3))
    while True:
        moved = np.abs(y[:, :limit] - y[:, :1]) / swing[:, None]
        beyond = moved > high
        if limit == width or np.all(np.any(beyond | ~valid[:, :limit], axis=1)):
            break
        limit = width
    mask = np.zeros((rows, width), dtype=bool)
    mask[:, :limit] = valid[:, :limit] & (moved >= low) & ~_from_first(beyond)
    sparse = np.flatnonzero(_counts(mask[:, :limit]) < 2)
    if sparse.size:
        reach = np.argmax(valid[sparse, :limit] & (moved[sparse] >= low), axis=1)
        j = np.arange(width)
        mask[sparse] = (j == 0) | (j == reach[:, None])
    reach = _columns(mask[:, :limit]).stop  # the segments end before this column
    compliance, intercept, sums = _common_line(mask[:, :reach], y[:, :reach], x[:, :reach])
    slope = both(compliance)[:, None]
    # The growth is followed over the first columns, and over all if it reaches their end.
    end = min(x.shape[1], 2 * reach + 8)
    residual = x[:, :end] - intercept[:, None] - slope * y[:, :end]
    segment = residual[:, :reach]
    squares = _dot(segment * mask[:, :reach], segment)
    cycles = compliance.size
    points = sums[0][:cycles] + sums[0][cycles:]
    spread = np.sqrt((squares[:cycles] + squares[cycles:]) / np.maximum(points - 3, 1))
    tolerance = both(np.maximum(_STICK_SPREAD * spread, 1e-9 * span))[:, None]
    while True:
        after = _from_first(mask[:, :end]) & valid[:, :end]
        outside = after & (np.abs(residual) > tolerance)
        outside[:, :-1] &= outside[:, 1:]  # two in a row; a branch's last sample alone is not
        outside[:, -1] = False
        grown = mask[:, :end] | (after & ~_from_first(outside))
        if end == x.shape[1] or not grown[:, -1].any():
            break
        end = x.shape[1]
        residual = x - intercept[:, None] - slope * y
    end = _columns(grown).stop
    grown = grown[:, :end]
    compliance, intercept, sums = _common_line(grown, y[:, :end], x[:, :end], spread=True)
    fit = _stick_fit(x[:, :end], y[:, :end], compliance, intercept, sums)
    return compliance, intercept, grown, fit


def _stick_fit(x, y, compliance, intercept, sums):
    r"""How well the lines through the stick segments fit, per cycle.

    ``sums`` are those of :func:`_common_line` with ``spread``, which hold the segments as
    weights.

    ``residual`` is the root mean square displacement off the lines; ``unexplained`` the
    share of the displacement's variance along the segments that they leave; ``curved``
    is True where a segment bends: a term :math:`bQ^2` added to its line is significant
    (more than ``_CURVATURE_T`` standard errors) and changes its slope
    :math:`d\Delta/dQ` from one end of the segment to the other by more than
    ``_CURVATURE_CHANGE`` of the compliance.
    """
    count, _, _, _, force_variance, variance, weight, deviation = sums
    cycles = compliance.size
    residual = (x - intercept[:, None] - both(compliance)[:, None] * y) * weight
    squares = _dot(residual, residual)
    # The residual against the squared force from its mean, sq: each branch's residual
    # sums to zero (its own intercept), so it needs no centring; sq's spread is
    # sum(sq^2) - n mean(sq)^2, with sum(sq) the force's variance.
    square = np.square(deviation, out=deviation)  # the force from its mean, squared
    spread = _dot(square, square) - force_variance**2 / count
    bend = _dot(residual, square) / spread
    error = np.sqrt(np.maximum(squares - bend * bend * spread, 0.0) / np.maximum(count - 3, 1))
    significance = np.abs(bend) * np.sqrt(spread) / error
    reach = np.sqrt(np.max(square, axis=1))  # the largest force from the segment's mean
    change = 4.0 * np.abs(bend) * reach / np.abs(both(compliance))
    curved = (count > 3) & (significance > _CURVATURE_T) & (change > _CURVATURE_CHANGE)
    total = squares[:cycles] + squares[cycles:]
    points = count[:cycles] + count[cycles:]
    return {
        "residual": np.sqrt(total / points),
        "unexplained": total / (variance[:cycles] + variance[cycles:]),
        "curved": curved[:cycles] | curved[cycles:],
    }


def zero_force_crossings(x, y, valid, length, max_force, stick, intercept, span):
    r"""Displacement where each branch row crosses :math:`Q = 0`, and whether on the loop.

    Where the stick segment ``stick`` reaches across zero force, it is the intercept of
    the line fitted to it, :math:`\Delta = c + Q/S`. Elsewhere a straight line
    :math:`\Delta = a + bQ` is fitted to the two samples around the crossing and the
    branch's samples with :math:`|Q|` below ``_ZERO_FORCE_BAND`` times the loop's
    ``max_force`` :math:`Q^*`, and gives :math:`a`. The crossing is on the loop if the
    branch has samples of both signs of force and it lies within the displacements of
    those samples (to rounding of the displacement ``span``). Else it is taken between
    the two samples around the crossing, if they have forces of both signs: where the
    stick line crosses zero force between them, or on the chord joining them.
    """
    cycles = length.size // 2
    negative, positive = y < 0.0, y > 0.0
    # Samples before the crossing: negative force on the rising branch, positive on the other.
    before = np.empty_like(valid)
    np.logical_and(negative[:cycles], valid[:cycles], out=before[:cycles])
    np.logical_and(positive[cycles:], valid[cycles:], out=before[cycles:])
    count = _counts(before)
    after = np.clip(count, 1, length - 1)
    near = valid & (np.abs(y) <= both(_ZERO_FORCE_BAND * max_force)[:, None])
    rows = np.arange(length.size)
    near[rows, after] = True  # the two samples around the crossing (after >= 1 if valid)
    near[rows[after >= 1], after[after >= 1] - 1] = True
    columns = _columns(near)
    near, x_near = near[:, columns], x[:, columns]
    _, mean_y, mean_x, covariance, variance = _line(near, y[:, columns], x_near)
    local = mean_x - covariance / variance * mean_y
    reach = stick.shape[1]  # no stick segment reaches further
    across = np.any(stick & negative[:, :reach], axis=1) & np.any(
        stick & positive[:, :reach], axis=1
    )
    crossing = np.where(across, intercept, local)
    rounding = 1e-9 * both(span)
    inside = (crossing >= np.min(np.where(near, x_near, np.inf), axis=1) - rounding) & (
        crossing <= np.max(np.where(near, x_near, -np.inf), axis=1) + rounding
    )
    # Else, between the two samples around the crossing: the stick line if it crosses zero
    # force there (the stick goes on past zero force between two samples), or the chord.
    x0, x1, y0, y1 = x[rows, after - 1], x[rows, after], y[rows, after - 1], y[rows, after]
    low, high = np.minimum(x0, x1) - rounding, np.maximum(x0, x1) + rounding
    chord = x0 + np.divide(y0, y0 - y1, out=np.full_like(y0, 0.5), where=y0 != y1) * (x1 - x0)
    stick_between = (intercept >= low) & (intercept <= high)
    crossing = np.where(inside, crossing, np.where(stick_between, intercept, chord))
    straddle = (y0 * y1 <= 0.0) & (y0 != y1)
    on_loop = (count >= 1) & (count <= length - 1) & (inside | straddle)
    return crossing, on_loop


def _curve_intercept(window, scaled, y, load):
    r"""Intercept :math:`a` of the least-squares :math:`Q = a + b\xi + c\xi Q` in each window.

    ``window`` marks the samples of each row to fit, ``scaled`` their contact position
    :math:`\xi` over the window's half-width, ``y`` their force (columns that hold no window
    may be left out).

    The regressors are centred on their means and :math:`\xi Q` is orthogonalised against
    :math:`\xi` sample by sample (Gram-Schmidt), so that :math:`a` stays exact when the two
    are nearly collinear (a force nearly constant along the slip). Where :math:`\xi Q`
    adds only rounding to :math:`\xi` (a flat groove), :math:`Q = a + b\xi` is fitted.
    """
    weight = window.astype(np.float64)
    count = weight.sum(axis=1)
    s = np.where(window, scaled, 0.0)
    z = s * y / load
    mean_s, mean_z = s.sum(axis=1) / count, z.sum(axis=1) / count
    mean_q = _dot(weight, y) / count
    ds, dz, dq = (
        (values - mean[:, None]) * weight
        for values, mean in ((s, mean_s), (z, mean_z), (y, mean_q))
    )
    ss = _dot(ds, ds)
    ratio = _dot(ds, dz) / ss
    rest = dz - ratio[:, None] * ds  # the part of ξQ that ξ does not explain
    squares = _dot(rest, rest)
    c = np.where(squares > _COLLINEAR * _dot(dz, dz), _dot(rest, dq) / squares, 0.0)
    return mean_q - _dot(ds, dq) / ss * mean_s - c * (mean_z - ratio * mean_s)


def line_crossings(x, y, valid, length, compliance, half_width, load, scale):
    r"""Where each branch row crosses :math:`Q = S\Delta`: displacement, force, on the loop.

    On the line the contact position :math:`\xi = \Delta - Q/S` (eq. 10) is zero. The
    branch's samples with :math:`|\xi|` below ``half_width`` are fitted by least squares
    with :math:`Q = a + b\xi + c\xi Q`, which is eq. 9 for any groove slope
    (:math:`a = \mu P`, :math:`b = kP`, :math:`c = \mu k`) and a smooth three-parameter
    curve otherwise; the crossing is :math:`Q = a`. With fewer than ``_FIT_SAMPLES``
    samples in the window, :math:`Q` is interpolated linearly at :math:`\xi = 0` between
    the two samples around the crossing.

    The crossing is on the loop if measured samples of the branch lie on both sides of
    :math:`\xi = 0` (in the window, or the two interpolated between), and its force lies
    within theirs (to rounding of ``scale``, the loop's :math:`Q^*`).
    """
    cycles = length.size // 2
    position = x - y * compliance[:, None]  # the contact position (eq. 10)
    # Samples before the crossing: ξ < 0 on the rising branch (from -δ*), ξ > 0 on the other.
    before = np.empty_like(valid)
    np.less(position[:cycles], 0.0, out=before[:cycles])
    np.greater(position[cycles:], 0.0, out=before[cycles:])
    before &= valid
    after = _bracket(before, length)
    rows = np.arange(length.size)
    q0, q1 = y[rows, after - 1], y[rows, after]
    v0, v1 = position[rows, after - 1], position[rows, after]
    change = v0 - v1
    share = np.divide(v0, change, out=np.full_like(v0, 0.5), where=change != 0.0)
    guess = q0 + share * (q1 - q0)
    window = valid & (np.abs(position) <= half_width[:, None])
    enough = _counts(window) >= _FIT_SAMPLES
    columns = _columns(window)
    scaled = position[:, columns] / half_width[:, None]
    intercept = _curve_intercept(window[:, columns], scaled, y[:, columns], load)
    force = np.where(enough, intercept, guess)
    displacement = force * compliance
    # On the loop: the fitted window, or the interpolated pair, holds samples on both
    # sides of ξ = 0, and the crossing's force lies within theirs.
    window[rows, after] |= ~enough
    window[rows, after - 1] |= ~enough
    columns = _columns(window)  # now with the pairs interpolated between
    window, before, y = window[:, columns], before[:, columns], y[:, columns]
    sides = np.any(window & before, axis=1) & np.any(window & ~before, axis=1)
    rounding = 1e-9 * scale
    on_loop = (
        sides
        & np.where(enough, True, (share >= 0.0) & (share <= 1.0))
        & (force >= np.min(np.where(window, y, np.inf), axis=1) - rounding)
        & (force <= np.max(np.where(window, y, -np.inf), axis=1) + rounding)
    )
    return displacement, force, on_loop
