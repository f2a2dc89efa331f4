"""Steps 3 and 4 of the loop pipeline: each loop centred (offsets and drift removed) and measured
(amplitude, slip amplitude, energy, ECoF, stiffness, GICoF ...), with the flags of the checks
each cycle failed; ``docs/method-loops.md`` ("Centring the loops", "Measuring each loop")."""

import dataclasses
import itertools
from collections.abc import Iterator

import numpy as np

from ecofmaps._interrupts import check_interrupted
from ecofmaps.measured import kernels, quality
from ecofmaps.measured.cycles import MIN_SAMPLES, Cycles, loop_points

#: Samples of the cycles laid out at once by :func:`loop_blocks`.
_BLOCK = 1 << 17
#: Whole cycles on either side of a cycle whose force centres give their noise.
_NOISE_REACH = 4
#: Whole cycles on either side of a cycle whose samples its centring reads: the force
#: centres of :data:`_NOISE_REACH` cycles, each centred by its neighbours' displacement.
NEIGHBOURS = _NOISE_REACH + 1
#: The median of the absolute second difference of white noise over its standard deviation.
SECOND_DIFFERENCE = 0.6744897501960817 * np.sqrt(6.0)
#: The same of its lower quartile.
_QUARTILE_SECOND_DIFFERENCE = 0.3186393639643752 * np.sqrt(6.0)
#: Fewest samples of a cycle whose noise is read from its second differences (not its corners).
_NOISE_SAMPLES = 4 * MIN_SAMPLES
#: Fewest samples of a cycle whose extremes are read through its noise: in fewer, the
#: parabola round a peak follows its few samples' shape more than it averages the noise.
_EXTREME_SAMPLES = 8 * MIN_SAMPLES
#: Energy ratio :math:`A = E_d/(4\Delta^* Q^*)` above which a loop is gross slip (Fouvry et al.).
GROSS_SLIP_THRESHOLD = 0.2
#: The ratios of :func:`loop_ratios` reported when the rig's stiffness is given.
_RIG_RATIOS = (
    "opening_ratio",
    "contact_amplitude",
    "contact_energy_ratio",
    "contact_opening_ratio",
)
#: The per-cycle quantities, in the Dataset's order.
_PER_CYCLE = (
    "amplitude",
    "slip_amplitude",
    "max_force",
    "dissipated_energy",
    "ecof",
    "cof_max",
    "energy_ratio",
    "stiffness",
    *quality.GICOF,
    "displacement_offset",
    "force_offset",
    "force_drift_se",
    "stick_residual",
)
#: The reasons this step flags: not those of the scale or of the reading along the stroke.
_UNMEASURED = ("implausible-amplitude", "implausible-cof", *quality.READING_REASONS)
_MEASURED = tuple(r for r in quality.REASONS if r not in _UNMEASURED)
#: A gross-slip loop whose GICoF lies within this share of Q*/P is crossed by its stick line
#: where it slides at a constant force: its GICoF is read even if its stick sides are curved.
_PLATEAU = 0.02
#: Mindlin's law (docs/method-loops.md) is fitted to the stick where the force has risen by less
#: than this share of the way to its sliding value (the law is steep beyond); it is followed when
#: its curved part is this share of the stick's extent and this many standard errors, the fit
#: leaves no more than this many times the displacement's noise or this share of the stroke, and
#: each branch slides over this many samples. The first of three passes reads about this many
#: samples a branch.
_MINDLIN_STICK, _MINDLIN_SHARE, _MINDLIN_T = 0.9, 0.05, 5.0
_MINDLIN_SPREAD, _MINDLIN_ROUNDING, _MINDLIN_SLIDING, _MINDLIN_SIFT = 3.0, 1e-3, 3, 32
#: Samples with :math:`|Q|` below this share of :math:`Q^*` locate a crossing off the stick.
_ZERO_FORCE_BAND = 0.25


class Stretch:
    """A stretch of a recording (samples ``low`` on) indexed like the whole recording."""

    def __init__(self, values, low: int):
        self.values, self.low = values, low

    def __getitem__(self, key):
        if isinstance(key, slice):
            return self.values[key.start - self.low : key.stop - self.low]
        return self.values[np.asarray(key) - self.low]


@dataclasses.dataclass(frozen=True, eq=False)
class LoopBlock:
    """The centred loops of a block of consecutive cycles, from :func:`loop_blocks`."""

    rows: slice
    displacement: np.ndarray
    force: np.ndarray
    offset: np.ndarray
    count: np.ndarray
    rotation: np.ndarray
    continuous: bool
    displacement_centre: np.ndarray
    force_centre: np.ndarray
    force_swing: np.ndarray
    force_drift_se: np.ndarray

    def samples(self, point, rows=slice(None)):
        """Index into ``displacement`` and ``force`` of points round the loops ``rows``."""
        first, count, turn = (a[rows][:, None] for a in (self.offset, self.count, self.rotation))
        return loop_points(first, count, turn, self.continuous, point)

    def loops(self, width: int):
        """The loops as padded rows (cycle, point) of ``width`` points, NaN past each end."""
        index = self.samples(np.minimum(np.arange(width), self.count[:, None]))
        inside = np.arange(width) <= self.count[:, None]
        return tuple(np.where(inside, v[index], np.nan) for v in (self.displacement, self.force))


def loop_blocks(
    cycles: Cycles, displacement, force, rows=None, force_sign=1.0
) -> Iterator[LoopBlock]:
    """The loops of ``cycles``, each moved to its centre, block by block."""
    first, stop, _ = (rows or slice(None)).indices(cycles.label.size)
    # The whole cycles, by position among them: a block is consecutive whole cycles.
    kept = np.flatnonzero(cycles.whole)
    begin, end = (int(p) for p in np.searchsorted(kept, [first, stop]))
    if not cycles.continuous:
        for block in _whole_blocks(cycles, kept, begin, end):
            yield _labelled_block(cycles, displacement, force, kept[block], force_sign)
        return
    if begin == end:  # no whole cycle among the rows
        return
    start, count = cycles.start[kept], cycles.count[kept]
    middle, centre_x = _displacement_centres(start, count, displacement, begin, end)
    centre_q = np.empty(kept.size)
    ready = max(begin - _NOISE_REACH, 0)  # the force's centres are known below this cycle
    for block in _whole_blocks(cycles, kept, begin, end):
        # The centred values depend on the sample index alone. The force's drift within the
        # block needs the centres of the cycles either side, their noise _NOISE_REACH more.
        needed = min(block.stop + _NOISE_REACH, kept.size)
        lower, upper = min(ready, block.start), max(needed, block.stop)
        low, high = int(start[lower]), int(start[upper - 1] + count[upper - 1])
        around = slice(max(lower - 1, 0), upper + 1)
        x = displacement[low:high] - _drift(low, high, middle, centre_x, around)
        if ready < needed:
            cut, q = slice(ready, needed), _signed(force[low:high], force_sign)
            centre_q[cut] = _path_means(x, q, start[cut] - low, count[cut], closed=False)
            ready = needed
        a, b = int(start[block.start]), int(start[block.stop - 1] + count[block.stop - 1])
        near = slice(max(block.start - 1, 0), block.stop + 1)
        offset = start[block] - a
        swing = kernels.stretch_ranges(np.ascontiguousarray(force[a:b]), offset, count[block])
        yield LoopBlock(
            rows=slice(int(kept[block.start]), int(kept[block.stop - 1]) + 1),
            displacement=x[a - low : b - low],
            force=_signed(force[a:b], force_sign) - _drift(a, b, middle, centre_q, near),
            offset=offset,
            count=count[block],
            rotation=cycles.rotation[kept[block]],
            continuous=True,
            displacement_centre=centre_x[block],
            force_centre=centre_q[block],
            force_swing=swing,
            force_drift_se=_drift_se(middle, count, centre_q, block),
        )


def _drift_se(middle, count, centre, rows: slice):
    """``force_drift_se`` of the loops ``rows``: the branch offset the drift correction leaves."""
    first, stop, size = rows.start, rows.stop, centre.size
    noise = kernels.second_difference_medians(centre, first, stop, _NOISE_REACH) / SECOND_DIFFERENCE
    if size == 2:  # no second difference: the one first difference, noise and drift
        noise = np.full(stop - first, abs(centre[1] - centre[0]) / np.sqrt(2.0))
    # The weights a_j of the centres in the offset, in the cycle's own period: a quarter
    # of the slope to each neighbour, or half the one line over the whole cycle at an end.
    i = np.arange(first, stop)
    has_left, has_right = i > 0, i < size - 1
    left = (middle[i] - middle[np.maximum(i - 1, 0)]) / count[i]
    right = (middle[np.minimum(i + 1, size - 1)] - middle[i]) / count[i]
    share = np.where(has_left & has_right, 0.25, 0.5)
    a_left = np.where(has_left, -share / np.where(has_left, left, 1.0), 0.0)
    a_right = np.where(has_right, share / np.where(has_right, right, 1.0), 0.0)
    squares = a_left**2 + a_right**2 + (a_left + a_right) ** 2
    return np.where(squares > 0.0, noise * np.sqrt(squares), 0.0)


def _whole_blocks(cycles: Cycles, kept, begin: int, end: int) -> Iterator[slice]:
    """Blocks of consecutive whole cycles ``kept[begin:end]``, as slices of ``kept``."""
    breaks = np.flatnonzero(np.diff(kept[begin:end]) != 1) + begin + 1
    for a, b in itertools.pairwise([begin, *breaks.tolist(), end]):
        yield from _blocks(cycles.count[kept[a:b]] + 1, a)


def _labelled_block(cycles: Cycles, displacement, force, block, sign) -> LoopBlock:
    """The loops of consecutive labelled cycles (rows ``block``), each by its own centre."""
    start, count = cycles.start[block], cycles.count[block]
    offset = np.concatenate([[0], np.cumsum(count[:-1])])
    index = np.repeat(start - offset, count) + np.arange(int(count.sum()))
    x, q = displacement[index], sign * force[index]
    swing = kernels.stretch_ranges(q, offset, count)
    centre_x = _path_means(x, x, offset, count, closed=True)
    x -= np.repeat(centre_x, count)
    # The force's weights come from the centred displacement, as for drifting loops.
    centre_q = _path_means(x, q, offset, count, closed=True)
    q -= np.repeat(centre_q, count)
    return LoopBlock(
        rows=slice(int(block[0]), int(block[-1]) + 1),
        displacement=x,
        force=q,
        offset=offset,
        count=count,
        rotation=cycles.rotation[block],
        continuous=False,
        displacement_centre=centre_x,
        force_centre=centre_q,
        force_swing=swing,
        force_drift_se=np.zeros(count.size),
    )


def _blocks(points: np.ndarray, offset: int) -> Iterator[slice]:
    """Slices of consecutive rows of about ``_BLOCK`` points, padded to at most twice that."""
    rows = max(1, _BLOCK // max(int(np.median(points)), 1)) if points.size else 1
    pending = [(a, min(a + rows, points.size)) for a in range(0, points.size, rows)][::-1]
    while pending:
        a, b = pending.pop()
        if b - a > 1 and (b - a) * int(points[a:b].max()) > 2 * _BLOCK:
            # A long loop among short ones: split the block rather than pad it.
            middle = (a + b) // 2
            pending += [(middle, b), (a, middle)]
        else:
            yield slice(a + offset, b + offset)


def _path_means(path, values, offset, count, closed: bool):
    """Mean of ``values`` round each loop weighted by the distance along ``path``."""
    path, values = (np.ascontiguousarray(a, dtype=np.float64) for a in (path, values))
    return kernels.path_means(path, values, offset, count, closed)


def _displacement_centres(start, count, displacement, first: int, stop: int):
    """Middle sample of every cycle, and the displacement centres within reach of the rows."""
    # The mean sample index round the loop, its closing point included (exact integers).
    middle = ((count * (2 * start + count - 1)) // 2 + start) / (count + 1)
    centre = np.full(start.size, np.nan)
    first, stop = max(first - NEIGHBOURS, 0), min(stop + NEIGHBOURS, start.size)
    groups = np.flatnonzero(np.diff((start[first:stop] - start[first]) // _BLOCK)) + first + 1
    for a, b in itertools.pairwise([first, *groups.tolist(), stop]):
        low, high = int(start[a]), int(start[b - 1] + count[b - 1])
        x = displacement[low:high]
        centre[a:b] = _path_means(x, x, start[a:b] - low, count[a:b], closed=False)
    return middle, centre


def _signed(values, sign):
    """``values`` times ``sign`` (±1), without a copy when it is +1."""
    return values if sign > 0 else -values


def _drift(low: int, high: int, points, values, near: slice):
    """``values`` over ``points`` at samples ``low`` on, between those ``near``, or beyond all."""
    at = np.arange(low, high, dtype=np.float64)
    result = np.interp(at, points[near], values[near])
    if points.size < 2:
        return result
    for end, inner, beyond, extrapolated in (
        (0, 1, at < points[0], near.start == 0),
        (-1, -2, at > points[-1], near.stop >= points.size),
    ):
        if extrapolated:
            step = (at[beyond] - points[end]) * (values[inner] - values[end])
            result[beyond] = values[end] + step / (points[inner] - points[end])
    return result


def loop_ratios(amplitude, max_force, energy, slip, rig_stiffness=None) -> dict:
    r"""The energy ratio :math:`A = E_d/(4\Delta^*Q^*)` and opening ratio
    :math:`B = \delta^*/\Delta^*` of loops [1], and on the contact's displacement
    :math:`\Delta^* - Q^*/S` [m] the same (NaN without the rig's ``rig_stiffness`` [N/m])."""
    contact = amplitude - max_force / (np.nan if rig_stiffness is None else rig_stiffness)
    with np.errstate(divide="ignore", invalid="ignore"):
        return {
            "energy_ratio": energy / (4.0 * amplitude * max_force),
            "opening_ratio": slip / amplitude,
            "contact_amplitude": contact,
            "contact_energy_ratio": energy / (4.0 * contact * max_force),
            "contact_opening_ratio": slip / contact,
        }


def _loop_values(block, options):
    """Every per-cycle quantity of a block of centred loops, and the checks it failed."""
    load = options.load
    # The samples' extremes; Δ* and Q*, half the range between them read through the noise if any
    (highest, lowest, *x_fitted), (strongest, weakest, *q_fitted) = (
        kernels.fitted_extremes(v, block.offset, block.count, _EXTREME_SAMPLES)
        for v in (block.displacement, block.force)
    )
    span, peak_force = highest - lowest, 0.5 * (strongest - weakest)
    amplitude, max_force = 0.5 * np.subtract(*x_fitted), 0.5 * np.subtract(*q_fitted)
    # The loop's area and its top, where the rising branch ends.
    energy, top = kernels.loop_measures(
        block.displacement, block.force, block.offset, block.count, block.rotation, highest
    )
    rows = branch_rows(block, top)
    compliance, intercept, across, residual, unexplained, curved = kernels.stick_lines(
        *rows, span, *options.stick_window
    )
    # Per branch row, the rising ones then the falling ones:
    band, rounding = np.tile(_ZERO_FORCE_BAND * peak_force, 2), np.tile(1e-9 * span, 2)
    crossing, zero_on_loop = kernels.zero_force_crossings(*rows, band, intercept, across, rounding)
    cycles = block.count.size
    slip = 0.5 * (crossing[cycles:] - crossing[:cycles])
    slope, half_width = np.tile(compliance, 2), np.tile(options.crossing_window * np.abs(slip), 2)
    force, on_loop = kernels.line_crossings(
        *rows, slope, half_width, float(load), 1e-9 * np.tile(peak_force, 2)
    )
    at = force * slope
    ratios = loop_ratios(amplitude, max_force, energy, slip, options.rig_stiffness)
    energy_ratio = ratios["energy_ratio"]
    values = {
        "amplitude": amplitude,
        "slip_amplitude": slip,
        "max_force": max_force,
        "dissipated_energy": energy,
        "ecof": energy / (4.0 * load * slip),
        "cof_max": max_force / load,
        "energy_ratio": energy_ratio,
        "stiffness": 1.0 / (compliance + 0.0),  # + 0.0: a rigid rig is +inf, not -inf
        "gicof": (force[:cycles] - force[cycles:]) / (2.0 * load),
        "gicof_forward": force[:cycles] / load,
        "gicof_backward": -force[cycles:] / load,
        "crossing_displacement_forward": at[:cycles],
        "crossing_displacement_backward": at[cycles:],
        "displacement_offset": block.displacement_centre,
        "force_offset": block.force_centre,
        "force_drift_se": block.force_drift_se,
        "stick_residual": residual,
    }
    if options.rig_stiffness is not None:
        values |= {name: ratios[name] for name in _RIG_RATIOS}
    anticlockwise = energy_ratio < -quality.ANTICLOCKWISE_SHARE
    sliding = quality.gross_slip(values, options)
    forward, backward, spring = _mindlin_sliding(rows, peak_force, span, sliding)
    mindlin = np.isfinite(forward)
    read = {"gicof_forward": forward / load, "gicof_backward": backward / load}
    read |= {"gicof": (forward + backward) / (2.0 * load), "stiffness": spring}
    for name, value in read.items():
        values[name] = np.where(mindlin, value, values[name])
    on_plateau = sliding & (np.abs(values["gicof"] / values["cof_max"] - 1.0) <= _PLATEAU)
    flags = {
        "few-samples": block.count < MIN_SAMPLES,
        "constant-force": ~(block.force_swing > 0.0),
        # A cycle cut at the reversals cannot turn back by more than the band (a reversal).
        "several-loops": np.zeros(cycles, dtype=bool)
        if block.continuous
        else _turns_back(rows[0], options.hysteresis * span),
        "anticlockwise": anticlockwise,
        "energy-ratio-above-1": energy_ratio > 1.0 + 1e-9,  # beyond rounding
        "negative-stiffness": compliance < 0.0,
        "no-stick": (
            (~(unexplained <= quality.UNEXPLAINED_SHARE) & ~np.isinf(values["stiffness"]))
            | np.isnan(compliance)
        )  # a rigid rig's vertical stick sides explain all but 0/0
        & ~mindlin,
        "negative-area": (energy_ratio < 0.0) & ~anticlockwise,
        "negative-slip": ~(slip > 0.0),
        "slip-beyond-amplitude": slip > amplitude * (1.0 + 1e-9),  # beyond rounding
        "no-zero-crossing": ~(zero_on_loop[:cycles] & zero_on_loop[cycles:]),
        "curved-stick": curved & ~on_plateau & ~mindlin,
        "curved-stick-sliding": curved & on_plateau & ~mindlin,
        "mindlin-stick": mindlin,
        "no-crossing": ~(on_loop[:cycles] & on_loop[cycles:]) & ~mindlin,
        "partial-slip": ~sliding,
        "noise-amplitude": (_noise_lift(block, block.displacement) > 0.5 * span)
        | (_noise_lift(block, block.force) > peak_force),
    }
    return values, flags


def _mindlin_sliding(rows, max_force, span, candidates):
    """Sliding forces (rising, falling) [N] and spring stiffness [N/m] of Mindlin sticks, or NaN."""
    x, y, length = rows
    cycles = max_force.size
    found = np.full((3, cycles), np.nan)
    pick = np.flatnonzero(candidates & (max_force > 0.0))
    sliding_force = max_force[pick]
    for passes in range(3):  # the sliding force, the stick fitted below it, where it ends
        # the first pass, which only sifts out straight sticks, on every few samples
        every = max(x.shape[1] // _MINDLIN_SIFT, 1) if passes == 0 else 1
        row = np.concatenate([pick, pick + cycles])
        sign = np.repeat([1.0, -1.0], pick.size)[:, None]  # the falling branches turned round
        u, q = sign * x[row, ::every], sign * y[row, ::every]
        valid = np.arange(0, x.shape[1], every) < length[row][:, None]
        force = np.tile(sliding_force, 2)[:, None]
        rise = (q + force) / (2.0 * force)
        stick = valid & (rise < _MINDLIN_STICK)
        curve = 1.0 - np.cbrt(1.0 - np.minimum(rise, 1.0)) ** 2
        line, inverse = _stick_line_fit(u, (curve, q), stick)
        share = line[:, 1] / (line[:, 1] + 2.0 * line[:, 2] * force[:, 0])
        # curved by a share of the stick's extent, its spring's compliance not below zero by
        # more: else not a sphere's (a flat contact's straight stick), and not fitted further
        curved = (share > _MINDLIN_SHARE) & (share < 1.0 / (1.0 - _MINDLIN_SHARE))
        both = np.tile(curved[: pick.size] & curved[pick.size :], 2)
        pick, line, inverse, u, q, valid, stick, curve, force = (
            v[both] for v in (np.tile(pick, 2), line, inverse, u, q, valid, stick, curve, force)
        )
        pick = pick[: pick.size // 2]
        end = line[:, :1] + line[:, 1:2] + line[:, 2:] * force
        sliding = valid & (u > end)
        count = sliding.sum(axis=1)
        each = np.where(count > 0, (q * sliding).sum(axis=1) / count, force[:, 0])
        sliding_force = 0.5 * (each[: pick.size] + each[pick.size :])
    off = np.where(stick, u - line[:, :1] - line[:, 1:2] * curve - line[:, 2:] * q, 0.0)
    spread = np.sqrt((off**2).sum(axis=1) / np.maximum(stick.sum(axis=1) - 3, 1))
    second = np.sort(np.where(valid[:, 2:], np.abs(np.diff(u, 2)), np.inf), axis=1)
    middle = np.maximum(valid[:, 2:].sum(axis=1) - 1, 0) // 2  # NaN-free: inf if none
    noise = np.take_along_axis(second, middle[:, None], axis=1)[:, 0] / SECOND_DIFFERENCE
    tolerance = np.maximum(_MINDLIN_SPREAD * noise, _MINDLIN_ROUNDING * np.tile(span[pick], 2))
    significant = line[:, 1] > _MINDLIN_T * spread * np.sqrt(inverse[:, 1, 1])
    follows = (spread <= tolerance) & significant & (count >= _MINDLIN_SLIDING)
    follows = follows[: pick.size] & follows[pick.size :]
    found[:2, pick[follows]] = each.reshape(2, -1)[:, follows]
    compliance = 0.5 * (line[: pick.size, 2] + line[pick.size :, 2])
    found[2, pick[follows]] = 1.0 / np.maximum(compliance[follows], 0.0)  # + inf if rigid
    return found


def _stick_line_fit(u, regressors, stick):
    """Least squares of ``u`` on 1 and ``regressors`` over each row's ``stick``, and (JᵀJ)⁻¹."""
    columns = [stick.astype(np.float64), *(np.where(stick, r, 0.0) for r in regressors)]
    normal = np.stack([np.stack([(a * b).sum(axis=1) for b in columns], -1) for a in columns], -2)
    normal[stick.sum(axis=1) < 4] = np.eye(len(columns))
    try:
        inverse = np.linalg.inv(normal)
    except np.linalg.LinAlgError:  # a degenerate loop (a constant force): least norm
        inverse = np.linalg.pinv(normal)
    moments = np.stack([(a * u).sum(axis=1) for a in columns], -1)
    return np.einsum("rik,rk->ri", inverse, moments), inverse


def _noise_lift(block, values):
    """Per cycle, how high noise lifts an extreme of ``values`` over NOISE_SHARE, or NaN. [m|N]"""
    lift = np.full(block.count.size, np.nan)
    (rows,) = np.nonzero(block.count >= _NOISE_SAMPLES)
    if not rows.size:
        return lift
    offset, count = block.offset[rows], block.count[rows]
    j = np.arange(1, int(count.max()) - 1)
    inside = j < count[:, None] - 1
    at = offset[:, None] + np.where(inside, j, 1)
    middle = values[at]
    second = values[at + 1] - 2.0 * middle + values[at - 1]
    sine = 4.0 * np.sin(np.pi / (count - 1.0))[:, None] ** 2
    rank = (np.arange(rows.size), (count - 3) // 4)
    quartiles = [
        np.sort(np.where(inside, np.abs(d), np.nan), axis=1)[rank]
        for d in (second, second + sine * middle)
    ]
    sigma = np.fmin(*quartiles) / _QUARTILE_SECOND_DIFFERENCE
    lift[rows] = sigma * np.sqrt(2.0 * np.log(count)) / quality.NOISE_SHARE
    return lift


def _turns_back(x, band):
    """True for the cycles whose displacement turns back within a branch row by over ``band``."""
    rising, falling = x[: band.size], x[band.size :]
    drop = np.max(np.maximum.accumulate(rising, axis=1) - rising, axis=1)
    rise = np.max(falling - np.minimum.accumulate(falling, axis=1), axis=1)
    return np.maximum(drop, rise) > band


def measure_cycles(cycles: Cycles, displacement, force, options, *, rows=None, keep_loops=False):
    """The per-cycle values of :func:`ecofmaps.analyze_loops` before the checks' NaN, their flags,
    and the centred loops NaN-padded over (cycle, point) if ``keep_loops``."""
    first, stop, _ = (rows or slice(None)).indices(cycles.label.size)
    names = _PER_CYCLE if options.rig_stiffness is None else _PER_CYCLE + _RIG_RATIOS
    values = {name: np.full(stop - first, np.nan) for name in names}
    flags = {reason: np.zeros(stop - first, dtype=bool) for reason in _MEASURED}
    flags["missing-samples"] = cycles.missing[first:stop].copy()  # not measured: NaN
    flags["no-reversal"] = cycles.hidden[first:stop].copy()
    width = int(cycles.count[first:stop].max()) + 1 if keep_loops else 0
    loops = tuple(np.full((stop - first, width), np.nan) for _ in range(2)) if keep_loops else None
    sign = -1.0 if options.flip_force else 1.0
    with np.errstate(divide="ignore", invalid="ignore"):  # degenerate cycles give NaN
        for block in loop_blocks(cycles, displacement, force, slice(first, stop), sign):
            check_interrupted()
            out = slice(block.rows.start - first, block.rows.stop - first)
            for table, part in zip((values, flags), _loop_values(block, options), strict=True):
                for name, value in part.items():
                    table[name][out] = value
            if keep_loops:
                for loop, centred in zip(loops, block.loops(width), strict=True):
                    loop[out] = centred
    return values, flags, loops


def branch_rows(block, top):
    """The rising branches (start to top) and falling ones (top to the end) as rows."""
    first = np.concatenate([np.zeros_like(top), top])
    last = np.concatenate([top, block.count])
    length = last - first + 1
    width = int(length.max())
    if not block.continuous:  # a loop may begin inside its stretch and wrap round it
        point = np.minimum(first[:, None] + np.arange(width), last[:, None])
        index = block.samples(point, np.tile(np.arange(top.size), 2))
        return block.displacement[index], block.force[index], length
    # Each row is a stretch of the samples from its reversal on, up to its last point:
    # the top of a rising branch; the loop's first sample, which closes a falling one.
    start = np.tile(block.offset, 2) + first
    end = np.concatenate([block.offset + top, block.offset])
    x, y = (
        kernels.branch_stretches(values, start, end, length, width)
        for values in (block.displacement, block.force)
    )
    return x, y, length
