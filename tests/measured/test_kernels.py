"""The compiled kernels of ecofmaps.measured.kernels against plain computations, row by row.

Each kernel is checked against an independent computation in plain Python and NumPy
(``np.linalg.lstsq`` and ``np.polyfit`` for the fits, an explicit search for each crossing
and per-loop NumPy reductions) on branch rows of noisy model loops and on
random rows: short rows, rows padded with NaN past their points (a kernel reads no point
past a row's length, or NaN would show), rows with no crossing. Fits are compared to a
relative 1e-9 (sums in another order, and least squares by QR: well-conditioned rows agree
to about 1e-13); the extremes and tops are compared to the bit.
"""

import numpy as np
import pytest

from ecofmaps.measured import kernels
from ecofmaps.measured.cycles import find_cycles
from ecofmaps.measured.measure import branch_rows, loop_blocks
from ecofmaps.measured.synthetic import synthetic_recording

LOAD = 450.0
EXAMPLE_2 = dict(amplitude=50e-6, load=LOAD, stiffness=35e6, mu=0.8, aspect_ratio=0.2)
RTOL = 1e-9
WINDOW = (0.05, 0.45)


def model_rows(seed, cycles=6, noise=0.005):
    """Branch rows of noisy model loops: x, y, length, span and max_force per cycle."""
    displacement, force = synthetic_recording(
        **EXAMPLE_2,
        cycles=cycles,
        displacement_noise=noise * 50e-6,
        force_noise=2 * noise * 450.0,
        seed=seed,
    )
    block = next(iter(loop_blocks(find_cycles(displacement), displacement, force)))
    highest, lowest, strongest, weakest = (
        extreme
        for values in (block.displacement, block.force)
        for extreme in kernels.fitted_extremes(values, block.offset, block.count, np.inf)[:2]
    )
    _, top = kernels.loop_measures(
        block.displacement, block.force, block.offset, block.count, block.rotation, highest
    )
    max_force = 0.5 * (strongest - weakest)
    x, y, length = branch_rows(block, top)
    return x, y, length, highest - lowest, max_force


def nan_padded(x, y, length, extra=5):
    """The rows with NaN past each row's points (and a few more columns of them)."""
    width = x.shape[1] + extra
    outside = np.arange(width) >= length[:, None]
    padded = [np.pad(a, ((0, 0), (0, extra)), mode="edge") for a in (x, y)]
    for a in padded:
        a[outside] = np.nan
    return padded


# --------------------------------------------------------------------------- stick lines


def brute_stick_lines(x, y, length, span, low, high):
    """The stick lines by their definition, one cycle at a time, fitted by lstsq."""
    rows = length.size
    cycles = rows // 2
    out = {name: np.empty(cycles) for name in ("compliance", "residual", "unexplained")}
    out["intercept"], out["across"] = np.empty(rows), np.zeros(rows, bool)
    out["curved"] = np.zeros(cycles, bool)
    for c in range(cycles):
        pair = (c, c + cycles)
        rowsxy = [(x[r, : length[r]], y[r, : length[r]]) for r in pair]
        segments = [first_segment(q, low, high) for _, q in rowsxy]
        slope, cs = common_line(rowsxy, segments)
        residuals = [
            d[s] - a - slope * q[s] for (d, q), s, a in zip(rowsxy, segments, cs, strict=True)
        ]
        points = sum(s.size for s in segments)
        spread = np.sqrt(sum(np.sum(r**2) for r in residuals) / max(points - 3, 1))
        tolerance = max(3.0 * spread, 1e-9 * span[c])
        segments = [
            grown(d, q, s, a, slope, tolerance)
            for (d, q), s, a in zip(rowsxy, segments, cs, strict=True)
        ]
        slope, cs = common_line(rowsxy, segments)
        out["compliance"][c] = slope
        total, variance = 0.0, 0.0
        for r, (d, q), s, a in zip(pair, rowsxy, segments, cs, strict=True):
            out["intercept"][r] = a
            out["across"][r] = np.any(q[s] < 0) and np.any(q[s] > 0)
            residual = d[s] - a - slope * q[s]
            total += np.sum(residual**2)
            variance += np.sum((d[s] - d[s].mean()) ** 2)
            out["curved"][c] |= bends(residual, q[s], slope)
        out["residual"][c] = np.sqrt(total / points_of(segments))
        out["unexplained"][c] = total / variance
    return out


def points_of(segments):
    return sum(s.size for s in segments)


def first_segment(q, low, high):
    """Indices of the first stick segment of a row (see branches.stick_lines)."""
    moved = np.abs(q - q[0]) / (q.max() - q.min())
    beyond = np.flatnonzero(moved > high)
    stop = beyond[0] if beyond.size else q.size
    inside = np.flatnonzero(moved[:stop] >= low)
    if inside.size >= 2:
        return inside
    past = np.flatnonzero(moved >= low)
    return np.array([0]) if not past.size or past[0] == 0 else np.array([0, past[0]])


def common_line(rowsxy, segments):
    """One slope, an intercept per row: lstsq of Δ on [Q, 1 (rising), 1 (falling)]."""
    q = np.concatenate([q[s] for (_, q), s in zip(rowsxy, segments, strict=True)])
    d = np.concatenate([d[s] for (d, _), s in zip(rowsxy, segments, strict=True)])
    first = np.concatenate([np.full(s.size, k == 0) for k, s in enumerate(segments)])
    design = np.stack([q, first.astype(float), (~first).astype(float)], axis=1)
    (slope, a0, a1), *_ = np.linalg.lstsq(design, d, rcond=None)
    return slope, (a0, a1)


def grown(d, q, segment, intercept, slope, tolerance):
    """The segment grown until two samples in a row lie off its line by the tolerance."""
    off = np.abs(d - intercept - slope * q) > tolerance
    stop = d.size
    for j in range(segment[0], d.size - 1):
        if off[j] and off[j + 1]:
            stop = j
            break
    return np.union1d(segment, np.arange(segment[0], stop))


def bends(residual, q, slope):
    """A term b(Q - mean)² fitted to the residual: significant by 8 standard errors and
    changing the slope by 5 % from one end of the segment to the other."""
    if residual.size <= 3:
        return False
    square = (q - q.mean()) ** 2
    (b, _), (sse,) = np.polyfit(square, residual, 1, full=True)[:2]
    error = np.sqrt(sse / (residual.size - 3)) / np.sqrt(np.sum((square - square.mean()) ** 2))
    change = 4.0 * abs(b) * np.sqrt(square.max()) / abs(slope)
    return abs(b) / error > 8.0 and change > 0.05


def assert_stick_lines(x, y, length, span):
    compliance, intercept, across, residual, unexplained, curved = kernels.stick_lines(
        x, y, length, span, *WINDOW
    )
    expected = brute_stick_lines(x, y, length, span, *WINDOW)
    np.testing.assert_allclose(compliance, expected["compliance"], rtol=RTOL)
    np.testing.assert_allclose(intercept, expected["intercept"], rtol=0, atol=RTOL * 50e-6)
    np.testing.assert_allclose(residual, expected["residual"], rtol=1e-7)
    np.testing.assert_allclose(unexplained, expected["unexplained"], rtol=1e-7)
    np.testing.assert_array_equal(across, expected["across"])
    np.testing.assert_array_equal(curved, expected["curved"])


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_stick_lines_of_model_loops(seed):
    x, y, length, span, _ = model_rows(seed)
    assert_stick_lines(x, y, length, span)


def test_stick_lines_ignore_what_lies_past_a_row():
    x, y, length, span, _ = model_rows(4)
    plain = kernels.stick_lines(x, y, length, span, *WINDOW)
    padded = kernels.stick_lines(*nan_padded(x, y, length), length, span, *WINDOW)
    for a, b in zip(plain, padded, strict=True):
        np.testing.assert_array_equal(a, b)


def test_stick_lines_of_random_short_rows():
    """Random rows of 3 to 12 points (sparse windows take the chord from the reversal)."""
    rng = np.random.default_rng(5)
    cycles = 40
    length = rng.integers(3, 13, 2 * cycles)
    y = np.cumsum(rng.uniform(0.5, 1.5, (2 * cycles, 12)), axis=1) - 6.0
    y[cycles:] *= -1.0
    x = 1e-6 * y + rng.normal(scale=1e-8, size=y.shape)
    x, y = nan_padded(x, y, length, extra=0)
    span = np.full(cycles, 2e-5)
    assert_stick_lines(x, y, length, span)


def test_a_row_is_measured_alike_in_any_block():
    """A cycle's numbers do not depend on the other cycles laid out with it."""
    x, y, length, span, _ = model_rows(6, cycles=8)
    cycles = span.size
    whole = kernels.stick_lines(x, y, length, span, *WINDOW)
    pick = np.array([2, 5])
    rows = np.concatenate([pick, pick + cycles])
    part = kernels.stick_lines(
        np.ascontiguousarray(x[rows]), np.ascontiguousarray(y[rows]), length[rows],
        span[pick], *WINDOW,
    )  # fmt: skip
    for a, b in zip(whole, part, strict=True):
        chosen = rows if a.size == 2 * cycles else pick
        np.testing.assert_array_equal(a[chosen], b)


# --------------------------------------------------------------------- zero-force crossings


def brute_zero_force(x, y, length, band, intercept, across, rounding):
    """Crossings with Q = 0 by an explicit search and np.polyfit, one row at a time."""
    rows = length.size
    crossing, on_loop = np.empty(rows), np.zeros(rows, bool)
    for r in range(rows):
        n = length[r]
        d, q = x[r, :n], y[r, :n]
        before = q < 0 if r < rows // 2 else q > 0
        count = int(np.sum(before))
        after = min(max(count, 1), n - 1)
        near = np.abs(q) <= band[r]
        near[after] = True
        near[after - 1] = True
        # Δ = a + bQ through the samples near zero force: a at Q = 0.
        local = np.polyfit(q[near], d[near], 1)[1]
        at = intercept[r] if across[r] else local
        inside = d[near].min() - rounding[r] <= at <= d[near].max() + rounding[r]
        (x0, x1), (y0, y1) = d[after - 1 : after + 1], q[after - 1 : after + 1]
        if not inside:
            between = min(x0, x1) - rounding[r] <= intercept[r] <= max(x0, x1) + rounding[r]
            share = y0 / (y0 - y1) if y0 != y1 else 0.5
            at = intercept[r] if between else x0 + share * (x1 - x0)
        crossing[r] = at
        on_loop[r] = 1 <= count <= n - 1 and (inside or (y0 * y1 <= 0 and y0 != y1))
    return crossing, on_loop


@pytest.mark.parametrize("seed", [1, 7])
def test_zero_force_crossings(seed):
    x, y, length, span, max_force = model_rows(seed)
    _, intercept, across, *_ = kernels.stick_lines(x, y, length, span, *WINDOW)
    rng = np.random.default_rng(seed)
    across = across & (rng.random(across.size) < 0.5)  # half of them by the local line
    arguments = (
        length, np.tile(0.25 * max_force, 2), intercept, across, np.tile(1e-9 * span, 2)
    )  # fmt: skip
    crossing, on_loop = kernels.zero_force_crossings(*nan_padded(x, y, length), *arguments)
    expected, expected_on = brute_zero_force(x, y, *arguments)
    np.testing.assert_allclose(crossing, expected, rtol=0, atol=RTOL * 50e-6)
    np.testing.assert_array_equal(on_loop, expected_on)
    assert on_loop.all()


def test_rows_with_no_zero_force_crossing():
    """Rows whose force keeps one sign: the crossing is found on the chord, off the loop."""
    rng = np.random.default_rng(3)
    cycles = 10
    length = rng.integers(2, 30, 2 * cycles)
    y = 1.0 + rng.random((2 * cycles, 30))
    y[:cycles] *= -1.0  # every sample before the crossing on the rising rows ...
    x = rng.normal(size=y.shape)
    arguments = (length, np.full(2 * cycles, 0.2), rng.normal(size=2 * cycles),
                 np.zeros(2 * cycles, bool), np.full(2 * cycles, 1e-9))  # fmt: skip
    crossing, on_loop = kernels.zero_force_crossings(*nan_padded(x, y, length), *arguments)
    expected, expected_on = brute_zero_force(x, y, *arguments)
    np.testing.assert_allclose(crossing, expected, rtol=RTOL, atol=1e-12)
    np.testing.assert_array_equal(on_loop, expected_on)
    assert not on_loop.any()


# ----------------------------------------------------------------------- GICoF crossings


def brute_line_crossings(x, y, length, compliance, half_width, load, rounding):
    """Crossings with Q = SΔ: lstsq of Q on [1, ξ, ξQ] in the window, or interpolation."""
    rows = length.size
    force, on_loop = np.empty(rows), np.zeros(rows, bool)
    for r in range(rows):
        n = length[r]
        q = y[r, :n]
        xi = x[r, :n] - q * compliance[r]
        before = xi < 0 if r < rows // 2 else xi > 0
        after = min(max(int(np.sum(before)), 1), n - 1)
        window = np.abs(xi) <= half_width[r]
        change = xi[after - 1] - xi[after]
        share = xi[after - 1] / change if change != 0 else 0.5
        if np.sum(window) >= 5:
            w = window
            design = np.stack([np.ones(w.sum()), xi[w], xi[w] * q[w] / load], axis=1)
            force[r] = np.linalg.lstsq(design, q[w], rcond=None)[0][0]
            fitted = True
        else:
            force[r] = q[after - 1] + share * (q[after] - q[after - 1])
            window[after - 1 : after + 1] = True
            fitted = False
        sides = np.any(window & before) and np.any(window & ~before)
        within = q[window].min() - rounding[r] <= force[r] <= q[window].max() + rounding[r]
        on_loop[r] = sides and within and (fitted or 0.0 <= share <= 1.0)
    return force, on_loop


@pytest.mark.parametrize(("seed", "share"), [(1, 0.7), (2, 0.7), (3, 0.02), (1, 0.1)])
def test_line_crossings(seed, share):
    """Fitted windows (0.7 δ*), windows of fewer than five samples (interpolated) and of
    four or five (0.1 of 30 µm)."""
    x, y, length, span, max_force = model_rows(seed)
    compliance = np.tile(kernels.stick_lines(x, y, length, span, *WINDOW)[0], 2)
    half_width = np.full(length.size, share * 30e-6)
    arguments = (length, compliance, half_width, LOAD, np.tile(1e-9 * max_force, 2))
    force, on_loop = kernels.line_crossings(*nan_padded(x, y, length), *arguments)
    expected, expected_on = brute_line_crossings(x, y, *arguments)
    np.testing.assert_allclose(force, expected, rtol=0, atol=RTOL * LOAD)
    np.testing.assert_array_equal(on_loop, expected_on)
    assert on_loop.all()


# ----------------------------------------------------------------------- centring sums


def random_stretches(rng, loops=30):
    count = rng.integers(2, 60, loops)
    offset = np.concatenate([[0], np.cumsum(count[:-1])])
    size = int(count.sum())
    return rng.normal(size=size), rng.normal(size=size), offset, count


@pytest.mark.parametrize("closed", [False, True])
def test_path_means(closed):
    rng = np.random.default_rng(8)
    path, values, offset, count = random_stretches(rng)
    expected = []
    for a, n in zip(offset, count, strict=True):
        p, v = path[a : a + n], values[a : a + n]
        if closed:
            p, v = np.append(p, p[0]), np.append(v, v[0])
        weight = np.abs(np.diff(p))
        expected.append(np.sum(weight * (v[1:] + v[:-1]) / 2) / np.sum(weight))
    np.testing.assert_allclose(kernels.path_means(path, values, offset, count, closed),
                               expected, rtol=1e-12)  # fmt: skip


def test_ranges_and_loop_measures():
    rng = np.random.default_rng(9)
    x, y, offset, count = random_stretches(rng)
    rotation = rng.integers(0, count)
    x[offset + count // 2] = x[offset + count - 1] = 10.0  # two tops: the first one counts
    highest, lowest, _, _ = kernels.fitted_extremes(x, offset, count, np.inf)
    area, top = kernels.loop_measures(x, y, offset, count, rotation, highest)
    max_force = np.subtract(*kernels.fitted_extremes(y, offset, count, np.inf)[:2]) / 2
    np.testing.assert_array_equal(kernels.stretch_ranges(y, offset, count), 2 * max_force)
    for k, (a, n) in enumerate(zip(offset, count, strict=True)):
        d, q = x[a : a + n], y[a : a + n]
        assert (highest[k], lowest[k], max_force[k]) == (d.max(), d.min(), np.ptp(q) / 2)
        shoelace = np.sum((q + np.roll(q, -1)) * (np.roll(d, -1) - d)) / 2
        assert area[k] == pytest.approx(shoelace, rel=1e-12, abs=1e-12 * np.ptp(d) * np.ptp(q))
        assert top[k] == np.argmax(np.roll(d, -rotation[k]))


@pytest.mark.parametrize("mean_t", [0.0, 0.37])
def test_detrended_is_numpy_to_the_bit(mean_t):
    """The line's numbers as np.arange and NumPy's operations make them (NaN stays NaN)."""
    rng = np.random.default_rng(10)
    x = rng.normal(size=1000) * 1e-5
    x[[3, 500]] = np.nan
    first, middle, mean, slope = 123457, 0.5 * (2_000_001 - 1), 2e-6, 3e-12
    trend = (np.arange(first - middle, first + x.size - middle) - mean_t) * slope
    expected = (x - mean) - trend
    result = kernels.detrended(x, first, mean, mean_t, slope, middle)
    np.testing.assert_array_equal(result, expected)


def test_second_difference_medians_are_numpy_medians():
    """Each cycle's median of the absolute second differences within ``reach`` of it, NaN
    ones left out (and NaN where none is left), against np.nanmedian over explicit windows."""
    rng = np.random.default_rng(4)
    values = rng.normal(size=40)
    values[[7, 8, 30]] = np.nan
    second = np.full(values.size, np.nan)
    second[1:-1] = np.abs(values[:-2] - 2 * values[1:-1] + values[2:])
    for reach in (1, 2, 4):
        expected = []
        for i in range(3, 37):
            window = second[max(i - reach + 1, 1) : min(i + reach, values.size - 1)]
            finite = window[np.isfinite(window)]
            expected.append(np.median(finite) if finite.size else np.nan)
        got = kernels.second_difference_medians(values, 3, 37, reach)
        np.testing.assert_array_equal(got, expected)
