"""Compiled (numba) kernels of the measuring steps (:mod:`ecofmaps.measured.measure`, ``samples``),
a loop or a branch row at a time, cached on disk; every array float64 and C-contiguous
(``docs/method-loops.md``)."""

import math

import numba
import numpy as np

#: How numba compiles the kernels: cached on disk, NumPy's division by zero, no GIL held.
_COMPILE = {"cache": True, "error_model": "numpy", "nogil": True}
#: The lower quartile of the absolute sixth difference of white noise over its standard
#: deviation: a smooth loop's, sampled a few dozen times a cycle or more, is far below it.
_QUARTILE_SIXTH_DIFFERENCE = 0.3186393639643752 * np.sqrt(924.0)
_SIXTH = np.array([1.0, -6.0, 15.0, -20.0, 15.0, -6.0, 1.0])
#: A loop's extreme is read from the parabola fitted over the samples within this many noise
#: standard deviations of it, where the noise exceeds this share of the loop's range (below,
#: it is rounding); a step where the loop closes counts beyond this many standard errors.
_EXTREME_DEPTH, _NOISE_FREE, _STEP_T = 3.0, 1e-6, 3.0
#: A stick segment grows until two samples in a row are this many standard deviations off.
_STICK_SPREAD = 3.0
#: A stick segment is curved when a term in the squared force, added to its line, is
#: significant by more than this many standard errors and changes its slope from one end to
#: the other by more than this share.
_CURVATURE_T, _CURVATURE_CHANGE = 8.0, 0.05
#: Fewest samples in the window of the curve fitted at a GICoF crossing.
_FIT_SAMPLES = 5
#: In a GICoF window where the part of :math:`\xi Q` that :math:`\xi` does not explain has
#: below this share of its variance (a constant sliding force), :math:`Q = a + b\xi` is fitted.
_COLLINEAR = 1e-24


@numba.njit(**_COMPILE)
def _first_segment(y, n, low, high, segment):
    """Mark a row's first stick segment in ``segment``; return the column it ends before."""
    highest, lowest = y[0], y[0]
    for j in range(1, n):
        highest, lowest = max(highest, y[j]), min(lowest, y[j])
    swing = highest - lowest
    segment[:] = False
    count, end = 0, n
    for j in range(n):
        moved = abs(y[j] - y[0]) / swing
        if moved > high:
            end = j
            break
        if moved >= low:
            segment[j] = True
            count += 1
    if count >= 2:
        return end
    segment[:end] = False
    segment[0] = True
    for j in range(n):
        if abs(y[j] - y[0]) / swing >= low:
            segment[j] = True
            return j + 1
    return 1


@numba.njit(**_COMPILE)
def _line_sums(u, v, end, segment, sums):
    """Into ``sums``: count, means of ``u``, ``v``, sums of du dv, du du, dv dv (marked points)."""
    count, sum_u, sum_v = 0.0, 0.0, 0.0
    for j in range(end):
        if segment[j]:
            count, sum_u, sum_v = count + 1.0, sum_u + u[j], sum_v + v[j]
    mean_u, mean_v = sum_u / count, sum_v / count
    uv, uu, vv = 0.0, 0.0, 0.0
    for j in range(end):
        if segment[j]:
            du, dv = u[j] - mean_u, v[j] - mean_v
            uv, uu, vv = uv + du * dv, uu + du * du, vv + dv * dv
    sums[0], sums[1], sums[2], sums[3], sums[4], sums[5] = count, mean_u, mean_v, uv, uu, vv


@numba.njit(**_COMPILE)
def _grow(x, y, n, segment, end, intercept, slope, tolerance):
    """Grow a segment until two samples in a row lie off its line; return its end column."""
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
    return max(stop, end)


@numba.njit(**_COMPILE)
def _curved(x, y, end, segment, intercept, compliance, line):
    """Squared residual of a segment off its line, whether it bends, whether Q changes sign."""
    count, mean_y, force_variance = line[0], line[1], line[4]
    squares, fourth, product, largest = 0.0, 0.0, 0.0, 0.0
    negative, positive = False, False
    for j in range(end):
        if segment[j]:
            residual = x[j] - intercept - compliance * y[j]
            deviation = y[j] - mean_y
            square = deviation * deviation
            squares += residual * residual
            fourth += square * square
            product += residual * square
            largest = max(largest, square)
            negative, positive = negative or y[j] < 0.0, positive or y[j] > 0.0
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
    r"""Lines :math:`\Delta = c + Q/S` through the stick segments of each cycle's rows."""
    rows, width = x.shape
    cycles = rows // 2
    compliance, intercept = np.empty(cycles), np.empty(rows)
    residual, unexplained = np.empty(cycles), np.empty(cycles)
    across, curved = np.zeros(rows, np.bool_), np.zeros(cycles, np.bool_)
    segments, ends, lines = np.zeros((2, width), np.bool_), np.empty(2, np.int64), np.empty((2, 6))
    for c in range(cycles):
        for k in range(2):
            r = c + k * cycles
            ends[k] = _first_segment(y[r], length[r], low, high, segments[k])
            _line_sums(y[r], x[r], ends[k], segments[k], lines[k])
        slope = (lines[0, 3] + lines[1, 3]) / (lines[0, 4] + lines[1, 4])
        squares = 0.0
        for k in range(2):
            r, first = c + k * cycles, lines[k, 2] - slope * lines[k, 1]
            squares += _curved(x[r], y[r], ends[k], segments[k], first, slope, lines[k])[0]
        spread = math.sqrt(squares / max(lines[0, 0] + lines[1, 0] - 3.0, 1.0))
        tolerance = _STICK_SPREAD * spread  # the larger, NaN if either is (as np.maximum)
        if not (tolerance >= 1e-9 * span[c] or math.isnan(tolerance)):
            tolerance = 1e-9 * span[c]
        for k in range(2):
            r, first = c + k * cycles, lines[k, 2] - slope * lines[k, 1]
            ends[k] = _grow(x[r], y[r], length[r], segments[k], ends[k], first, slope, tolerance)
            _line_sums(y[r], x[r], ends[k], segments[k], lines[k])
        compliance[c] = (lines[0, 3] + lines[1, 3]) / (lines[0, 4] + lines[1, 4])
        total = 0.0
        for k in range(2):
            r = c + k * cycles
            intercept[r] = lines[k, 2] - compliance[c] * lines[k, 1]
            squares, bends, across[r] = _curved(
                x[r], y[r], ends[k], segments[k], intercept[r], compliance[c], lines[k]
            )
            total += squares
            curved[c] |= bends
        residual[c] = math.sqrt(total / (lines[0, 0] + lines[1, 0]))
        unexplained[c] = total / (lines[0, 5] + lines[1, 5])
    return compliance, intercept, across, residual, unexplained, curved


@numba.njit(**_COMPILE)
def _sample_pair(length, count, width):
    """The columns of the two samples around a row's crossing (-1 read as NumPy does)."""
    after = min(max(count, 1), length - 1)
    return (after - 1) % width, after


@numba.njit(**_COMPILE)
def zero_force_crossings(x, y, length, band, intercept, across, rounding):
    r"""Displacement where each branch row crosses :math:`Q = 0`, and whether on the loop."""
    rows, width = x.shape
    crossing, on_loop = np.empty(rows), np.zeros(rows, np.bool_)
    near, line = np.zeros(width, np.bool_), np.empty(6)
    for r in range(rows):
        n, rising = length[r], r < rows // 2
        count = 0  # samples before the crossing: below zero rising, above falling
        for j in range(n):
            count += y[r, j] < 0.0 if rising else y[r, j] > 0.0
            near[j] = abs(y[r, j]) <= band[r]
        previous, after = _sample_pair(n, count, width)
        near[after] = True
        near[previous] |= after >= 1  # not column -1, the padding
        _line_sums(y[r], x[r], n, near, line)
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
            share = y0 / (y0 - y1) if y0 != y1 else 0.5
            between = min(x0, x1) - rounding[r] <= intercept[r] <= max(x0, x1) + rounding[r]
            at = intercept[r] if between else x0 + share * (x1 - x0)
        crossing[r] = at
        straddle = y0 * y1 <= 0.0 and y0 != y1
        on_loop[r] = count >= 1 and count <= n - 1 and (inside or straddle)
    return crossing, on_loop


@numba.njit(**_COMPILE)
def _curve_intercept(scaled, product, window, y, n):
    r"""Intercept :math:`a` of :math:`Q = a + b\xi + c\xi Q` through the window, and its count."""
    count, sum_s, sum_z, sum_q = 0.0, 0.0, 0.0, 0.0
    for j in range(n):
        if window[j]:
            count += 1.0
            sum_s += scaled[j]
            sum_z += product[j]
            sum_q += y[j]
    mean_s, mean_z, mean_q = sum_s / count, sum_z / count, sum_q / count
    ss, sz, zz, sq = 0.0, 0.0, 0.0, 0.0
    for j in range(n):
        if window[j]:
            ds, dz, dq = scaled[j] - mean_s, product[j] - mean_z, y[j] - mean_q
            ss, sz, zz, sq = ss + ds * ds, sz + ds * dz, zz + dz * dz, sq + ds * dq
    ratio = sz / ss
    rr, rq = 0.0, 0.0
    for j in range(n):
        if window[j]:
            ds, dz, dq = scaled[j] - mean_s, product[j] - mean_z, y[j] - mean_q
            rest = dz - ratio * ds  # the part of ξQ that ξ does not explain
            rr, rq = rr + rest * rest, rq + rest * dq
    c = rq / rr if rr > _COLLINEAR * zz else 0.0
    return mean_q - sq / ss * mean_s - c * (mean_z - ratio * mean_s), count


@numba.njit(**_COMPILE)
def line_crossings(x, y, length, compliance, half_width, load, rounding):
    r"""Force where each branch row crosses :math:`Q = S\Delta`, and whether on the loop."""
    rows, width = x.shape
    force, on_loop = np.empty(rows), np.zeros(rows, np.bool_)
    scaled, product = np.empty(width), np.empty(width)
    window, before = np.zeros(width, np.bool_), np.zeros(width, np.bool_)
    for r in range(rows):
        n, rising, h = length[r], r < rows // 2, half_width[r]
        count = 0
        for j in range(n):
            position = x[r, j] - y[r, j] * compliance[r]  # the contact position (eq. 10)
            before[j] = position < 0.0 if rising else position > 0.0
            count += before[j]
            window[j] = abs(position) <= h
            if window[j]:
                scaled[j] = position / h
                product[j] = scaled[j] * y[r, j] / load
        previous, after = _sample_pair(n, count, width)
        before[previous] &= previous < n  # column -1: padding, never before the crossing
        v0 = x[r, previous] - y[r, previous] * compliance[r]
        v1 = x[r, after] - y[r, after] * compliance[r]
        q0, q1 = y[r, previous], y[r, after]
        share = v0 / (v0 - v1) if v0 - v1 != 0.0 else 0.5
        intercept, fitted = _curve_intercept(scaled, product, window, y[r], n)
        # On the loop: the fitted window, or the pair interpolated between, holds samples
        # on both sides of ξ = 0, and the crossing's force lies within theirs.
        fits = fitted >= _FIT_SAMPLES
        force[r] = intercept if fits else q0 + share * (q1 - q0)
        sides, lowest, highest = 0, np.inf, -np.inf
        for j in range(n):
            if window[j]:
                sides |= 1 if before[j] else 2
                lowest, highest = min(lowest, y[r, j]), max(highest, y[r, j])
        if not fits:
            for j in (previous, after):
                sides |= 1 if before[j] else 2
                lowest, highest = min(lowest, y[r, j]), max(highest, y[r, j])
        within = lowest - rounding[r] <= force[r] <= highest + rounding[r]
        on_loop[r] = sides == 3 and within and (fits or (share >= 0.0 and share <= 1.0))
    return force, on_loop


@numba.njit(**_COMPILE)
def _trapezoid(path, values, i):
    """The length of segment ``i`` to ``i + 1`` of ``path`` and its weighted mean value."""
    weight = abs(path[i + 1] - path[i])
    return weight, weight * (0.5 * (values[i + 1] + values[i]))


@numba.njit(**_COMPILE)
def path_means(path, values, offset, count, closed):
    """Mean of ``values`` round each loop weighted by the distance travelled along ``path``."""
    mean = np.empty(offset.size)
    for k in range(offset.size):
        first, last = offset[k], offset[k] + count[k] - 1
        length, total, length_odd, total_odd = 0.0, 0.0, 0.0, 0.0
        for i in range(first, last - 1, 2):
            weight, weighted = _trapezoid(path, values, i)
            weight_odd, weighted_odd = _trapezoid(path, values, i + 1)
            length, total = length + weight, total + weighted
            length_odd, total_odd = length_odd + weight_odd, total_odd + weighted_odd
        if (last - first) % 2:
            weight, weighted = _trapezoid(path, values, last - 1)
            length, total = length + weight, total + weighted
        length, total = length + length_odd, total + total_odd
        if closed:
            gap = abs(path[first] - path[last])
            total += gap * (0.5 * (values[first] + values[last]))
            length += gap
        mean[k] = total / length
    return mean


@numba.njit(**_COMPILE)
def second_difference_medians(values, first, stop, reach):
    """Per ``i`` from ``first`` to ``stop - 1``, the median of the finite :math:`|v_{j-1} - 2v_j
    + v_{j+1}|` over :math:`|j - i| <` ``reach`` within the values, or NaN."""
    result = np.empty(stop - first)
    window = np.empty(2 * reach - 1)
    for i in range(first, stop):
        n = 0
        for j in range(max(i - reach + 1, 1), min(i + reach, values.size - 1)):
            value = abs(values[j - 1] - 2.0 * values[j] + values[j + 1])
            if math.isfinite(value):  # sorted in as it comes (a handful of values)
                k = n
                while k > 0 and window[k - 1] > value:
                    window[k] = window[k - 1]
                    k -= 1
                window[k] = value
                n += 1
        if n == 0:
            result[i - first] = np.nan
        elif n % 2:
            result[i - first] = window[n // 2]
        else:
            result[i - first] = 0.5 * (window[n // 2 - 1] + window[n // 2])
    return result


@numba.njit(**_COMPILE)
def stretch_ranges(values, offset, count):
    """Largest less smallest of ``values`` over each stretch ``offset``, ``count`` (their unit)."""
    ranges = np.empty(offset.size)
    for k in range(offset.size):
        highest = lowest = values[offset[k]]
        for i in range(offset[k] + 1, offset[k] + count[k]):
            highest, lowest = max(highest, values[i]), min(lowest, values[i])
        ranges[k] = highest - lowest
    return ranges


@numba.njit(**_COMPILE)
def loop_measures(x, y, offset, count, rotation, highest):
    """Area of each centred loop, and its top: its first point from its start at ``highest``."""
    area, top = np.empty(offset.size), np.empty(offset.size, np.int64)
    for k in range(offset.size):
        first, last = offset[k], offset[k] + count[k] - 1
        total, total_odd = 0.0, 0.0  # two interleaved chains of segments, as in path_means
        for i in range(first, last - 1, 2):
            total += (y[i + 1] + y[i]) * (x[i + 1] - x[i])
            total_odd += (y[i + 2] + y[i + 1]) * (x[i + 2] - x[i + 1])
        if (last - first) % 2:  # the last segment
            total += (y[last] + y[last - 1]) * (x[last] - x[last - 1])
        area[k] = 0.5 * (total + total_odd + (y[first] + y[last]) * (x[first] - x[last]))
        for point in range(count[k]):
            position = rotation[k] + point
            if x[first + position - (count[k] if position >= count[k] else 0)] == highest[k]:
                top[k] = point
                break
    return area, top


@numba.njit(**_COMPILE)
def _fitted_peak(values, first, n, at, span, sign):
    """How far below ``sign`` times the loop's sample ``at`` the parabola fitted round it lies."""
    reach, eighth = n // 4, n // 8
    half = max(reach, eighth + 3)
    near = np.empty(2 * half + 1)  # sign times the samples at + j, the loop taken as closed
    for j in range(-half, half + 1):
        near[half + j] = sign * values[first + (at + j) % n]
    sixth = np.zeros(2 * eighth + 1)  # the sixth differences centred within an eighth cycle
    for j in range(sixth.size):
        for k in range(7):
            sixth[j] += _SIXTH[k] * near[half - eighth + j + k - 3]
        sixth[j] = abs(sixth[j])
    sd = np.partition(sixth, eighth // 2)[eighth // 2] / _QUARTILE_SIXTH_DIFFERENCE
    if not sd > _NOISE_FREE * span:
        return 0.0
    ends = np.ones(2, np.int64)  # the last sample within the depth each side, before 3 are not
    for side in range(2):
        for j in range(1, reach + 1):
            if near[half + (1 - 2 * side) * j] >= near[half] - _EXTREME_DEPTH * sd:
                ends[side] = j
            elif j > ends[side] + 2:
                break
    if near[half - ends[1]] < near[half] - _EXTREME_DEPTH * sd > near[half + ends[0]]:
        return 0.0  # no other sample near it: the noise hardly lifts it
    # The normal equations of 1, j/half, (j/half)² and a step where the loop closes
    normal, sums, row, steps = np.zeros((4, 4)), np.zeros(4), np.ones(4), 0
    for j in range(-ends[1], ends[0] + 1):
        row[1] = j / half
        row[2] = row[1] * row[1]
        row[3] = 1.0 if at + j < 0 or at + j >= n else 0.0
        steps += row[3] > 0.0
        for r in range(4):
            sums[r] += row[r] * (near[half + j] - near[half])
            for c in range(4):
                normal[r, c] += row[r] * row[c]
    for col in range(3):  # Gaussian elimination (positive definite: no pivoting)
        for r in range(col + 1, 4):
            factor = normal[r, col] / normal[col, col]
            for c in range(col, 4):
                normal[r, c] -= factor * normal[col, c]
            sums[r] -= factor * sums[col]
    step = abs(sums[3]) > _STEP_T * sd * np.sqrt(normal[3, 3])  # its t over its standard error
    m = 4 if 0 < steps < ends[0] + ends[1] - 2 and step else 3  # the unknowns: with the step?
    for r in range(m - 1, -1, -1):  # back substitution, for the first unknown
        for k in range(r + 1, m):
            sums[r] -= normal[r, k] * sums[k]
        sums[r] /= normal[r, r]
    return sums[0]


@numba.njit(**_COMPILE)
def fitted_extremes(values, offset, count, least):
    """Highest and lowest sample of each loop, and the same or, from ``least`` samples on, the
    fitted parabolas' values there (through the noise; docs/method-loops.md). [m] or [N]"""
    highest, lowest = np.empty(offset.size), np.empty(offset.size)
    fitted_high, fitted_low = np.empty(offset.size), np.empty(offset.size)
    for k in range(offset.size):
        first, n = offset[k], count[k]
        top = bottom = 0
        for i in range(1, n):
            top = i if values[first + i] > values[first + top] else top
            bottom = i if values[first + i] < values[first + bottom] else bottom
        highest[k], lowest[k] = values[first + top], values[first + bottom]
        fitted_high[k], fitted_low[k] = highest[k], lowest[k]
        if n >= least:
            span = highest[k] - lowest[k]
            fitted_high[k] += _fitted_peak(values, first, n, top, span, 1.0)
            fitted_low[k] -= _fitted_peak(values, first, n, bottom, span, -1.0)
    return highest, lowest, fitted_high, fitted_low


@numba.njit(**_COMPILE)
def detrended(x, first, mean, mean_t, slope, middle):
    """Displacements less a straight line over the sample index, in one pass."""
    result = np.empty(x.size)
    start = first - middle  # an integer or a half, exact
    for i in range(x.size):
        result[i] = (x[i] - mean) - ((start + i) - mean_t) * slope
    return result


@numba.njit(**_COMPILE)
def branch_stretches(values, start, end, length, width):
    """Rows of ``width``: ``length - 1`` samples from ``start`` on, then ``values[end]``."""
    rows = np.empty((start.size, width))
    for r in range(start.size):
        for j in range(length[r] - 1):
            rows[r, j] = values[start[r] + j]
        rows[r, length[r] - 1 :] = values[end[r]]
    return rows
