r"""Compiled kernels for the steps of :func:`ecofmaps.analyze_loops` along each branch row.

Each kernel loops over the branch rows of a block of loops (:func:`ecofmaps.measured.branches.
branch_rows`) and does in one or a few passes along a row what the methods of
:mod:`ecofmaps.measured.branches` describe: the sums of a least-squares line, the growth of a
stick segment, the curvature test, the search for a crossing. The rows of a block are the
rising branches of its cycles, then their falling branches (row ``c`` and row
``c + cycles`` belong to cycle ``c``); row ``r`` holds ``length[r]`` points, padded to the
block's width by repeating its last point.

A row's numbers depend on that row (and its cycle's other row) alone, not on the block it
was laid out in. Sums run in the order of the samples.

The kernels are compiled by numba on first call and cached on disk (``cache=True``); with
``error_model="numpy"`` a division by zero gives an infinity or NaN, as in NumPy. Every
array is float64 (int64 for ``length``, bool for flags), C-contiguous, so each kernel has a
single compiled signature.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["line_crossings", "stick_lines", "zero_force_crossings"]

#: How numba compiles the kernels: cached on disk, NumPy's division by zero, no GIL held.
_COMPILE = {"cache": True, "error_model": "numpy", "nogil": True}

#: A stick segment grows until two samples in a row are this many standard deviations off.
_STICK_SPREAD = 3.0

#: A stick segment is curved when a term in the squared force, added to its line, is
#: significant by more than this many standard errors ...
_CURVATURE_T = 8.0

#: ... and changes its slope from one end to the other by more than this share.
_CURVATURE_CHANGE = 0.05

#: Fewest samples in the window of the curve fitted at a GICoF crossing.
_FIT_SAMPLES = 5

#: In a GICoF window where the variance of :math:`\xi Q` not explained by :math:`\xi` is
#: below this share of its own (rounding: the force is constant along the slip), the line
#: :math:`Q = a + b\xi` is fitted.
_COLLINEAR = 1e-24


@numba.njit(**_COMPILE)
def _maximum(a, b):
    """The larger of ``a`` and ``b``, NaN if either is (as ``np.maximum``)."""
    return a if a >= b or math.isnan(a) else b


@numba.njit(**_COMPILE)
def _first_segment(y, n, low, high, segment):
    """Mark a row's first stick segment in ``segment`` (cleared first); return its count.

    The samples whose force has moved from the reversal's by ``low`` to ``high`` of the
    row's force swing, up to the first one beyond ``high``; with fewer than two, the
    reversal and the first sample past ``low`` (the reversal alone if there is none).
    """
    swing = np.max(y) - np.min(y)
    segment[:] = False
    count = 0
    for j in range(n):
        moved = abs(y[j] - y[0]) / swing
        if moved > high:
            break
        if moved >= low:
            segment[j] = True
            count += 1
    if count >= 2:
        return count
    segment[:] = False
    segment[0] = True
    for j in range(n):
        if abs(y[j] - y[0]) / swing >= low:
            segment[j] = True
            return 2 if j > 0 else 1
    return 1


@numba.njit(**_COMPILE)
def _line_sums(u, v, n, segment):
    """Sums of the least-squares line of ``v`` on ``u`` through the marked points.

    Returns the count, the means of ``u`` and ``v``, and the sums of du dv, du du and
    dv dv (deviations from the means).
    """
    count, sum_u, sum_v = 0.0, 0.0, 0.0
    for j in range(n):
        if segment[j]:
            count += 1.0
            sum_u += u[j]
            sum_v += v[j]
    mean_u, mean_v = sum_u / count, sum_v / count
    uv, uu, vv = 0.0, 0.0, 0.0
    for j in range(n):
        if segment[j]:
            du, dv = u[j] - mean_u, v[j] - mean_v
            uv += du * dv
            uu += du * du
            vv += dv * dv
    return count, mean_u, mean_v, uv, uu, vv


@numba.njit(**_COMPILE)
def _squares_off(x, y, n, segment, intercept, slope):
    """Sum of the squared displacements of the marked points off :math:`\\Delta = c + sQ`."""
    squares = 0.0
    for j in range(n):
        if segment[j]:
            residual = x[j] - intercept - slope * y[j]
            squares += residual * residual
    return squares


@numba.njit(**_COMPILE)
def _grow(x, y, n, segment, intercept, slope, tolerance):
    """Grow a segment along its row until two samples in a row lie off its line by more
    than ``tolerance`` (a row's last sample alone does not stop it), in place."""
    first = 0
    while not segment[first]:
        first += 1
    stop, outside = n, False
    for j in range(first, n):
        off = abs(x[j] - intercept - slope * y[j]) > tolerance
        if off and outside:
            stop = j - 1
            break
        outside = off
    segment[first:stop] = True


@numba.njit(**_COMPILE)
def _curved(x, y, n, segment, intercept, compliance, line):
    """Squared residual of a row's segment off its line, whether it bends (a term
    :math:`bQ^2` significant and changing the slope), and whether it holds forces of both
    signs. ``line`` holds the segment's sums from :func:`_line_sums`."""
    count, mean_y, force_variance = line[0], line[1], line[4]
    squares, fourth, product, largest = 0.0, 0.0, 0.0, 0.0
    negative, positive = False, False
    for j in range(n):
        if segment[j]:
            residual = x[j] - intercept - compliance * y[j]
            deviation = y[j] - mean_y
            square = deviation * deviation
            squares += residual * residual
            fourth += square * square
            product += residual * square
            largest = max(largest, square)
            negative |= y[j] < 0.0
            positive |= y[j] > 0.0
    # The residual sums to zero (its own intercept): the squared force needs no centring.
    spread = fourth - force_variance**2 / count
    bend = product / spread
    unexplained = squares - bend * bend * spread
    if unexplained < 0.0:
        unexplained = 0.0
    error = math.sqrt(unexplained / max(count - 3.0, 1.0))
    significance = abs(bend) * math.sqrt(spread) / error
    change = 4.0 * abs(bend) * math.sqrt(largest) / abs(compliance)
    curved = count > 3.0 and significance > _CURVATURE_T and change > _CURVATURE_CHANGE
    return squares, curved, negative and positive


@numba.njit(**_COMPILE)
def stick_lines(x, y, length, span, low, high):
    r"""Lines :math:`\Delta = c + Q/S` through the stick segments of each cycle's rows.

    The method of :func:`ecofmaps.measured.branches.stick_lines`: first segments, a first
    line of common slope, each segment grown until two samples in a row lie more than
    three standard deviations off it, the line fitted again, its fit and curvature.

    Parameters
    ----------
    x, y : numpy.ndarray, shape (rows, width)
        Displacement and force of the branch rows. [m], [N]
    length : numpy.ndarray of int64, shape (rows,)
        Points of each row.
    span : numpy.ndarray, shape (cycles,)
        Peak-to-peak displacement of each cycle (sets the rounding). [m]
    low, high : float
        Shares of the row's force swing between which a segment starts. [-]

    Returns
    -------
    compliance : numpy.ndarray, shape (cycles,)
        The slope :math:`1/S` common to a cycle's two lines. [m/N]
    intercept : numpy.ndarray, shape (rows,)
        Each row's :math:`c`. [m]
    across : numpy.ndarray of bool, shape (rows,)
        The grown segment holds forces of both signs.
    residual : numpy.ndarray, shape (cycles,)
        Root mean square displacement off the lines. [m]
    unexplained : numpy.ndarray, shape (cycles,)
        Share of the displacement's variance along the segments left by the lines. [-]
    curved : numpy.ndarray of bool, shape (cycles,)
        A segment bends (:func:`ecofmaps.measured.branches.stick_lines`).
    """
    rows, width = x.shape
    cycles = rows // 2
    compliance, intercept = np.empty(cycles), np.empty(rows)
    residual, unexplained = np.empty(cycles), np.empty(cycles)
    across, curved = np.zeros(rows, np.bool_), np.zeros(cycles, np.bool_)
    segments = np.zeros((2, width), np.bool_)
    lines = np.empty((2, 6))
    for c in range(cycles):
        for k in range(2):
            r = c + k * cycles
            _first_segment(y[r], length[r], low, high, segments[k])
            lines[k] = _line_sums(y[r], x[r], length[r], segments[k])
        slope = (lines[0, 3] + lines[1, 3]) / (lines[0, 4] + lines[1, 4])
        squares = 0.0
        for k in range(2):
            r, first = c + k * cycles, lines[k, 2] - slope * lines[k, 1]
            squares += _squares_off(x[r], y[r], length[r], segments[k], first, slope)
        spread = math.sqrt(squares / max(lines[0, 0] + lines[1, 0] - 3.0, 1.0))
        tolerance = _maximum(_STICK_SPREAD * spread, 1e-9 * span[c])
        for k in range(2):
            r, first = c + k * cycles, lines[k, 2] - slope * lines[k, 1]
            _grow(x[r], y[r], length[r], segments[k], first, slope, tolerance)
            lines[k] = _line_sums(y[r], x[r], length[r], segments[k])
        compliance[c] = (lines[0, 3] + lines[1, 3]) / (lines[0, 4] + lines[1, 4])
        total = 0.0
        for k in range(2):
            r = c + k * cycles
            intercept[r] = lines[k, 2] - compliance[c] * lines[k, 1]
            squares, bends, across[r] = _curved(
                x[r], y[r], length[r], segments[k], intercept[r], compliance[c], lines[k]
            )
            total += squares
            curved[c] |= bends
        residual[c] = math.sqrt(total / (lines[0, 0] + lines[1, 0]))
        unexplained[c] = total / (lines[0, 5] + lines[1, 5])
    return compliance, intercept, across, residual, unexplained, curved


@numba.njit(**_COMPILE)
def _before(value, rising):
    """A sample lies before the crossing: ``value`` below zero on a rising row, above on a
    falling one."""
    return value < 0.0 if rising else value > 0.0


@numba.njit(**_COMPILE)
def _sample_pair(length, count, width):
    """The columns of the two samples around a row's crossing: the one just past the
    ``count`` samples before it (clipped to 1 to ``length - 1``), and the one before that
    (the last column, the row's padding, if that is column -1, as NumPy indexes)."""
    after = min(max(count, 1), length - 1)
    previous = after - 1
    return (previous + width if previous < 0 else previous), after


@numba.njit(**_COMPILE)
def zero_force_crossings(x, y, length, band, intercept, across, rounding):
    r"""Displacement where each branch row crosses :math:`Q = 0`, and whether on the loop.

    The method of :func:`ecofmaps.measured.branches.zero_force_crossings`.

    Parameters
    ----------
    x, y : numpy.ndarray, shape (rows, width)
        Displacement and force of the branch rows. [m], [N]
    length : numpy.ndarray of int64, shape (rows,)
        Points of each row.
    band : numpy.ndarray, shape (rows,)
        Samples with :math:`|Q|` up to this are fitted. [N]
    intercept : numpy.ndarray, shape (rows,)
        Displacement at zero force on each row's stick line. [m]
    across : numpy.ndarray of bool, shape (rows,)
        The row's stick segment reaches across zero force.
    rounding : numpy.ndarray, shape (rows,)
        Rounding of the displacement. [m]

    Returns
    -------
    crossing : numpy.ndarray, shape (rows,)
        Displacement at :math:`Q = 0`. [m]
    on_loop : numpy.ndarray of bool, shape (rows,)
        The crossing lies on the loop.
    """
    rows, width = x.shape
    crossing, on_loop = np.empty(rows), np.zeros(rows, np.bool_)
    near = np.zeros(width, np.bool_)
    for r in range(rows):
        n, rising = length[r], r < rows // 2
        count = 0
        for j in range(n):
            count += _before(y[r, j], rising)
        previous, after = _sample_pair(n, count, width)
        for j in range(n):
            near[j] = abs(y[r, j]) <= band[r]
        near[after] = True
        if after >= 1:
            near[previous] = True
        line = _line_sums(y[r], x[r], n, near)
        local = line[2] - line[3] / line[4] * line[1]
        lowest, highest = np.inf, -np.inf
        for j in range(n):
            if near[j]:
                lowest, highest = min(lowest, x[r, j]), max(highest, x[r, j])
        at = intercept[r] if across[r] else local
        inside = at >= lowest - rounding[r] and at <= highest + rounding[r]
        # Else between the two samples around the crossing: the stick line if it crosses
        # zero force there, or the chord.
        x0, x1, y0, y1 = x[r, previous], x[r, after], y[r, previous], y[r, after]
        if not inside:
            low, high = min(x0, x1) - rounding[r], max(x0, x1) + rounding[r]
            share = y0 / (y0 - y1) if y0 != y1 else 0.5
            between = intercept[r] >= low and intercept[r] <= high
            at = intercept[r] if between else x0 + share * (x1 - x0)
        crossing[r] = at
        straddle = y0 * y1 <= 0.0 and y0 != y1
        on_loop[r] = count >= 1 and count <= n - 1 and (inside or straddle)
    return crossing, on_loop


@numba.njit(**_COMPILE)
def _curve_intercept(position, y, n, half_width, load):
    r"""Intercept :math:`a` of the least-squares :math:`Q = a + b\xi + c\xi Q` through a
    row's samples with :math:`|\xi|` up to ``half_width``, and their count.

    The regressors are centred on their means and :math:`\xi Q` is orthogonalised against
    :math:`\xi` (Gram-Schmidt), so that :math:`a` stays exact when the two are nearly
    collinear; where :math:`\xi Q` adds only rounding to :math:`\xi`, :math:`Q = a + b\xi`.
    """
    count, sum_s, sum_z, sum_q = 0.0, 0.0, 0.0, 0.0
    for j in range(n):
        if abs(position[j]) <= half_width:
            s = position[j] / half_width
            count += 1.0
            sum_s += s
            sum_z += s * y[j] / load
            sum_q += y[j]
    mean_s, mean_z, mean_q = sum_s / count, sum_z / count, sum_q / count
    ss, sz, zz, sq = 0.0, 0.0, 0.0, 0.0
    for j in range(n):
        if abs(position[j]) <= half_width:
            s = position[j] / half_width
            ds, dz, dq = s - mean_s, s * y[j] / load - mean_z, y[j] - mean_q
            ss, sz, zz, sq = ss + ds * ds, sz + ds * dz, zz + dz * dz, sq + ds * dq
    ratio = sz / ss
    rr, rq = 0.0, 0.0
    for j in range(n):
        if abs(position[j]) <= half_width:
            s = position[j] / half_width
            ds, dz, dq = s - mean_s, s * y[j] / load - mean_z, y[j] - mean_q
            rest = dz - ratio * ds  # the part of ξQ that ξ does not explain
            rr, rq = rr + rest * rest, rq + rest * dq
    c = rq / rr if rr > _COLLINEAR * zz else 0.0
    return mean_q - sq / ss * mean_s - c * (mean_z - ratio * mean_s), count


@numba.njit(**_COMPILE)
def line_crossings(x, y, length, compliance, half_width, load, rounding):
    r"""Force where each branch row crosses :math:`Q = S\Delta`, and whether on the loop.

    The method of :func:`ecofmaps.measured.branches.line_crossings`.

    Parameters
    ----------
    x, y : numpy.ndarray, shape (rows, width)
        Displacement and force of the branch rows. [m], [N]
    length : numpy.ndarray of int64, shape (rows,)
        Points of each row.
    compliance : numpy.ndarray, shape (rows,)
        :math:`1/S` of each row's cycle. [m/N]
    half_width : numpy.ndarray, shape (rows,)
        Samples with a contact position :math:`|\xi|` up to this are fitted. [m]
    load : float
        Normal load :math:`P`. [N]
    rounding : numpy.ndarray, shape (rows,)
        Rounding of the force. [N]

    Returns
    -------
    force : numpy.ndarray, shape (rows,)
        Force at the crossing. [N]
    on_loop : numpy.ndarray of bool, shape (rows,)
        The crossing lies on the loop.
    """
    rows, width = x.shape
    force, on_loop = np.empty(rows), np.zeros(rows, np.bool_)
    position = np.empty(width)
    for r in range(rows):
        n, rising, h = length[r], r < rows // 2, half_width[r]
        for j in range(width):
            position[j] = x[r, j] - y[r, j] * compliance[r]  # the contact position (eq. 10)
        count = 0
        for j in range(n):
            count += _before(position[j], rising)
        previous, after = _sample_pair(n, count, width)
        q0, q1, v0, v1 = y[r, previous], y[r, after], position[previous], position[after]
        share = v0 / (v0 - v1) if v0 - v1 != 0.0 else 0.5
        intercept, fitted = _curve_intercept(position, y[r], n, h, load)
        enough = fitted >= _FIT_SAMPLES
        force[r] = intercept if enough else q0 + share * (q1 - q0)
        # On the loop: the fitted window, or the pair interpolated between, holds samples
        # on both sides of ξ = 0, and the crossing's force lies within theirs.
        sides, lowest, highest = 0, np.inf, -np.inf
        for j in range(n):
            if abs(position[j]) <= h or (not enough and j in (previous, after)):
                sides |= 1 if _before(position[j], rising) else 2
                lowest, highest = min(lowest, y[r, j]), max(highest, y[r, j])
        if not enough and previous >= n:  # column -1: padding, never before the crossing
            sides |= 2
            lowest, highest = min(lowest, y[r, previous]), max(highest, y[r, previous])
        on_loop[r] = (
            sides == 3
            and (enough or (share >= 0.0 and share <= 1.0))
            and force[r] >= lowest - rounding[r]
            and force[r] <= highest + rounding[r]
        )
    return force, on_loop
