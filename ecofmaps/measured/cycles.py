r"""Step 2 of the loop pipeline: the cycles of a recording (at the displacement reversals, or by
its cycle numbers), found by passes a block at a time, and the runs of missing samples.
The method is explained in ``docs/method-loops.md`` ("Finding the cycles")."""

import dataclasses

import numpy as np

from ecofmaps.measured import samples as passes

#: Fewest samples in one complete cycle: two branches, each with a stick and a slip part.
MIN_SAMPLES = 8

#: The least local half-band of the reversal detector, as a share of the whole recording's.
LEAST_LEVEL = 0.05
#: The least local half-band in standard deviations of the displacement's white noise.
NOISE_LEVEL = 5.0
#: The mean absolute second difference of white noise over its standard deviation.
_MEAN_SECOND_DIFFERENCE = np.sqrt(6.0 * 2.0 / np.pi)
#: A stretch between bottom runs within this share of the period is one regular cycle.
_REGULAR = 0.1
#: Strokes in a row differing by more than this share of the larger: the amplitude steps.
_STEP = 0.05
#: A recording longer than this with fewer than two bottom reversals is not read as one loop.
_ONE_LOOP = 1 << 24
#: Share of the stroke within which two displacements are one (a loop's ends, beside a gap).
_TOLERANCE = 0.01


@dataclasses.dataclass(frozen=True, eq=False)
class Cycles:
    """Complete cycles of a recording: the stretch of samples of each, and its loop's start.
    ``missing`` (the cycle holds a missing sample) and ``hidden`` (a drive's period in which
    no reversal was found) are one flag per cycle, all False unless given."""

    start: np.ndarray
    count: np.ndarray
    rotation: np.ndarray
    label: np.ndarray
    continuous: bool
    incomplete_cycles: int
    dropped_samples: int
    missing: np.ndarray | None = None
    missing_samples: int = 0
    first_missing: int = -1
    hidden: np.ndarray | None = None

    def __post_init__(self):
        for name in ("missing", "hidden"):
            if getattr(self, name) is None:
                object.__setattr__(self, name, np.zeros(self.start.size, dtype=bool))

    @property
    def whole(self) -> np.ndarray:
        """True for the cycles without a missing sample, found at their reversals."""
        return ~(self.missing | self.hidden)

    def rows(self, rows: slice) -> "Cycles":
        """The cycles ``rows`` (a slice of consecutive rows) as a table of their own."""
        per_cycle = ("start", "count", "rotation", "label", "missing", "hidden")
        return dataclasses.replace(self, **{name: getattr(self, name)[rows] for name in per_cycle})

    def indices(self, rows=slice(None)):
        """Sample indices round the loops ``rows`` (a row each, padded), and their points."""
        count = self.count[rows][:, None]
        point = np.minimum(np.arange(int(count.max()) + 1), count)
        first, rotation = self.start[rows][:, None], self.rotation[rows][:, None]
        return loop_points(first, count, rotation, self.continuous, point), count[:, 0] + 1


def loop_points(first, count, rotation, continuous: bool, point):
    """Index of the points ``point`` (0 to ``count``) round loops of ``count`` samples from
    ``first``, begun ``rotation`` samples in (a continuous one at its first, which closes it)."""
    if continuous:
        return first + np.where(point < count, point, 0)
    position = rotation + point
    return first + position - count * (position >= count)


def _joined(samples: passes.Samples, function, arguments, channels=("displacement",), extra=0):
    """What ``function`` found in each block of ``samples``, joined in order."""
    return np.concatenate(samples.map(function, channels, arguments, extra), axis=-1)


def _parts_after_gaps(samples, gaps, line, band, runs):
    """The trigger's runs cut where samples resume after a long gap inside them."""
    starts, kind, extreme, value = runs
    gaps, long = gaps
    long = long[long[:, 1] < samples.size]
    inside = np.searchsorted(starts, long[:, 1], side="right") - 1
    cut = long[starts[inside] < long[:, 0], 1]
    if not cut.size:
        return np.arange(starts.size), starts, extreme, value
    part_start = np.union1d(starts, cut)
    part_run = np.searchsorted(starts, part_start, side="right") - 1
    affected = np.isin(part_run, part_run[np.isin(part_start, cut)])
    begin, run_of = part_start[affected], part_run[affected]
    end = np.append(part_start, samples.size)[1:][affected]
    found = _joined(samples, passes.part_extremes, (passes._CHUNK, gaps, line, begin, end))
    part, highest, top, lowest, bottom, most, least = found
    part = part.astype(np.int64)
    first_piece = np.searchsorted(part, np.arange(begin.size))
    centre, level = (passes.level_at(v, begin) for v in band)  # where each part begins
    own = kind[run_of]
    decided = np.where(
        own > 0,
        np.fmax.reduceat(most, first_piece) > centre + level,
        np.fmin.reduceat(least, first_piece) < centre - level,
    )
    # A part inside the band joins the one before it in its run (after it, if it comes first).
    first = np.concatenate([[True], run_of[1:] != run_of[:-1]])
    count = np.cumsum(decided) - decided  # the parts before that decided their run's kind
    at_first = count[np.maximum.accumulate(np.where(first, np.arange(first.size), 0))]
    new_group = first | (decided & (count > at_first))
    first_part = np.flatnonzero(new_group)
    piece_group = (np.cumsum(new_group) - 1)[part]
    group_extreme, group_value = _run_extremes(
        piece_group, first_piece[first_part], own[first_part] > 0, (highest, top, lowest, bottom)
    )
    kept = ~affected
    kept[np.flatnonzero(affected)[first_part]] = True
    run, extremes, values = part_run[kept], extreme[part_run[kept]], value[part_run[kept]]
    where = np.isin(np.flatnonzero(kept), np.flatnonzero(affected))
    extremes[where], values[where] = group_extreme, group_value
    return run, part_start[kept], extremes.astype(np.int64), values


def _run_extremes(run, first, rising, pieces):
    """Each run's extreme (its pieces' highest if ``rising``, else lowest): sample and value."""
    highest, top, lowest, bottom = pieces
    high, high_at = passes.extremes_of_runs(np.fmax, highest, top, run, first)
    low, low_at = passes.extremes_of_runs(np.fmin, lowest, bottom, run, first)
    return np.where(rising, high_at, low_at), np.where(rising, high, low)


def _period(starts, kind) -> float:
    """The median distance between the starts of the bottom runs (NaN with fewer than two)."""
    low = starts[kind < 0]
    return float(np.median(np.diff(low))) if low.size > 1 else np.nan


def _hidden_by_gaps(parts, samples, gaps, margin):
    """Which extremes of the runs' parts lie within ``margin`` of a sample beside a long gap."""
    begin, extreme, value = parts
    gaps, long = gaps
    if not long.size:
        return np.zeros(extreme.size, dtype=bool)
    end = np.append(begin[1:], samples.size)
    edges = np.stack([long[:, 0] - 1, long[:, 1]], axis=1).ravel()  # the samples beside
    inside = (edges >= 0) & (edges < samples.size)
    at_edges = np.full(edges.size, np.nan)
    at_edges[inside] = _joined(samples, passes.values_at, (gaps, edges[inside]))
    before_gap, after_gap = at_edges[0::2], at_edges[1::2]
    after = np.searchsorted(long[:, 0], extreme, side="right")
    before = np.searchsorted(long[:, 1], extreme, side="right") - 1
    following, preceding = np.minimum(after, long.shape[0] - 1), np.maximum(before, 0)
    hidden = (after < long.shape[0]) & (long[following, 0] < end)
    hidden &= np.abs(before_gap[following] - value) < margin
    beside = (before >= 0) & (long[preceding, 1] >= begin)
    return hidden | (beside & (np.abs(after_gap[preceding] - value) < margin))


def _accepted_reversals(parts, hidden, edges, scale):
    """Which extremes of the runs' parts are reversals."""
    run, kind, extreme, value = parts
    tolerance, least = scale
    at_edge = np.isin(extreme, edges)
    near = np.zeros(run.size, dtype=bool)
    for sign in (-1, 1):
        sure = np.flatnonzero(~at_edge & ~hidden & (kind == sign))
        mine = np.flatnonzero(at_edge & (kind == sign))
        if not sure.size or not mine.size:
            continue
        after = np.searchsorted(sure, mine)
        for other, exists in ((after - 1, after > 0), (after, after < sure.size)):
            other = sure[np.clip(other, 0, sure.size - 1)]
            near[mine] |= exists & (np.abs(value[mine] - value[other]) <= tolerance)
    accepted = np.where(at_edge, near, ~hidden)
    # Twins: the parts of one run either side of a gap, both taken for reversals.
    close = (run[1:] == run[:-1]) & (np.abs(extreme[1:] - extreme[:-1]) < least)
    twins = np.flatnonzero(close & accepted[1:] & accepted[:-1])
    outer = kind[twins] * (value[twins + 1] - value[twins]) > 0
    accepted[np.where(outer, twins, twins + 1)] = False
    return accepted


def _deep_ends(value, accepted):
    """False for a sweep's end run nearer the next reversal than ¾ of the stroke after it."""
    deep = np.ones(value.size, dtype=bool)
    reversals = np.flatnonzero(accepted)
    for first, next_, after in ((0, 1, 2), (-1, -2, -3)):
        if reversals.size < 3 or reversals[first] != (0 if first == 0 else value.size - 1):
            continue
        end, near, far = value[reversals[[first, next_, after]]]
        deep[reversals[first]] = abs(end - near) >= 0.75 * abs(far - near)
    return deep


def _steps(kind, extreme, value) -> bool:
    """Whether the drive's amplitude steps: periodic reversals, a stroke changing, then held."""
    bottoms = extreme[kind < 0]
    if bottoms.size < 3:
        return False
    regular = np.abs(np.diff(bottoms) / np.median(np.diff(bottoms)) - 1.0) <= _REGULAR
    stroke = np.abs(np.diff(value))
    turns = kind[1:] != kind[:-1]
    alternate = turns[4:] & turns[3:-1] & turns[2:-2] & turns[1:-3] & turns[:-4]
    differ = np.abs(stroke[2:] - stroke[:-2]) > _STEP * np.fmax(stroke[2:], stroke[:-2])
    step = differ[:-2] & ~differ[2:]  # stroke k+2 differs from k, k+4 agrees with k+2
    return bool(regular.mean() >= 0.5 and (alternate & step).any())


def _with_missing(cycles: Cycles, gaps) -> Cycles:
    """``cycles`` with the cycles that hold a sample of ``gaps`` marked."""
    if not gaps.size:
        return cycles
    return dataclasses.replace(
        cycles,
        missing=passes.missing_in(gaps, cycles.start, cycles.count),
        missing_samples=int((gaps[:, 1] - gaps[:, 0]).sum()),
        first_missing=int(gaps[0, 0]),
    )


def _drive_numbers(cycles: Cycles, merged: bool = False) -> Cycles:
    """``cycles`` numbered as the drive made them: a gapped (or ``merged``) stretch's periods."""
    whole = cycles.whole
    if not whole.any() or (whole.all() and not merged):
        return cycles
    period = float(np.median(cycles.count[whole] - 1))
    if merged:
        stretch = np.diff(cycles.start + cycles.rotation)  # from each to the next
    else:
        stretch = np.where(whole, period, cycles.count - 1)[:-1]
    spans = np.maximum(np.rint(stretch / period), 1).astype(np.int64)
    label = 1 + np.concatenate([[0], np.cumsum(spans)]).astype(np.int64)
    return dataclasses.replace(cycles, label=label)


def _trigger(samples: passes.Samples, gaps, line, band):
    """The trigger's runs: first sample, kind (+1 high, -1 low), extreme and its value."""
    found = samples.map(passes.trigger_runs, ("displacement",), (passes._CHUNK, gaps, line, band))
    # A run begins where the state (+1 above the band, -1 below, 0 inside) differs from the last
    # decided; samples before the first decision (the 99th percentile is above the band) take it.
    starts, kinds, previous = [], [], 0
    for entry, kind, _ in found:
        if kind.size and kind[0] == previous:
            entry, kind = entry[1:], kind[1:]
        starts.append(entry)
        kinds.append(kind)
        if kind.size:
            previous = kind[-1]
    starts, kind = np.concatenate(starts), np.concatenate(kinds).astype(np.float64)
    starts[0] = 0
    piece_start, highest, top, lowest, bottom = np.concatenate([f[2] for f in found], axis=1)
    run = np.searchsorted(starts, piece_start.astype(np.int64), side="right") - 1
    first_piece = np.searchsorted(run, np.arange(starts.size))
    return starts, kind, *_run_extremes(run, first_piece, kind > 0, (highest, top, lowest, bottom))


def _local_level(samples: passes.Samples, gaps, line, runs, hysteresis: float, band):
    """The trigger's local ``((width, centres), (width, half-bands))``, or None if not needed."""
    starts, kind, period, step = runs
    centre, level = band
    bottoms = starts[kind < 0]
    regular = np.abs(np.diff(bottoms) / (step * period) - 1.0) <= _REGULAR
    longest = np.diff(bottoms, prepend=0, append=samples.size).max()
    if np.count_nonzero(regular) < 2 or regular.mean() < 0.5 or longest <= 1.5 * period:
        return None
    width = max(int(period) // 2, MIN_SAMPLES)
    sine = (centre, 4.0 * np.sin(np.pi / period) ** 2)  # Δ²x = -4 sin²(π/T) x
    found = _joined(samples, passes.local_extremes, (passes._CHUNK, gaps, line, width, sine))
    stretch, highest, lowest, finite, rough, counted = found
    first = np.flatnonzero(np.diff(stretch, prepend=-1.0))
    # the noise: the median stretch's mean absolute second difference less a sine's own
    rough, counted = np.add.reduceat(rough, first), np.add.reduceat(counted, first)
    noise = np.nanmedian(np.where(counted > 0, rough / np.maximum(counted, 1), np.nan))
    least = max(LEAST_LEVEL * level, NOISE_LEVEL * noise / _MEAN_SECOND_DIFFERENCE)
    highest, lowest = np.fmax.reduceat(highest, first), np.fmin.reduceat(lowest, first)
    # a stretch cut short (by a gap or the end) may miss its peak: its neighbours' instead
    short = np.add.reduceat(finite, first) < width
    highest[short], lowest[short] = np.nan, np.nan
    # the middle of the narrower period holding each stretch if the amplitude is held
    high, low = np.pad(highest, 1, mode="edge"), np.pad(lowest, 1, mode="edge")
    top, bottom = np.maximum(high[:-1], high[1:]), np.minimum(low[:-1], low[1:])  # NaN if short
    span, own = top - bottom, high - low
    held = np.fmin(span[:-1], span[1:]) <= 2.5 * np.fmin(np.fmin(own[:-2], own[1:-1]), own[2:])
    before = np.fmin(span[:-1], span[1:]) == span[:-1]
    middle = 0.5 * np.where(before, top[:-1] + bottom[:-1], top[1:] + bottom[1:])
    middle = np.where(held & ~np.isnan(middle), middle, centre)
    amplitude = np.pad(np.fmax(highest - middle, middle - lowest), 1, mode="edge")
    local = hysteresis * np.fmin(np.fmin(amplitude[:-2], amplitude[1:-1]), amplitude[2:])
    local = np.clip(np.where(np.isnan(local), level, local), min(least, level), level)
    return None if (local >= level).all() else ((width, middle), (width, local))


def _drive_cycles(bottoms, tops, n: int, period: float) -> Cycles:
    """Cycles cut between bottom and top reversals, and hidden rows for periods without one."""
    none = np.zeros(0, dtype=np.int64)
    if not tops.size:
        return Cycles(none, none, none, none, False, 1, n)
    after = np.searchsorted(tops, bottoms)
    has_top = after < tops.size
    has_top[:-1] &= tops[np.minimum(after[:-1], tops.size - 1)] < bottoms[1:]
    top = tops[np.minimum(after, tops.size - 1)]
    quarter = int(period) // 4
    wide = has_top & (top - bottoms > 3 * quarter)  # hidden cycles between
    # a last bottom without a top after it, or a first without a bottom before its top,
    # is a cycle if a hidden drive period lies beyond it
    last = np.zeros(bottoms.size, dtype=bool)
    last[-1] = not has_top[-1] and n - 1 - bottoms[-1] - quarter >= 1.5 * period
    end = np.where(has_top, np.where(wide, bottoms + quarter, (bottoms + top) // 2), -1)
    end = np.where(last, bottoms + quarter, end)
    begin = np.where(wide, top - quarter, end)  # of the next cycle
    lead = tops[0] - quarter if tops[0] < bottoms[0] and tops[0] - quarter >= 1.5 * period else -1
    begin = np.concatenate([[lead], begin[:-1]])  # of each bottom's cycle
    # or three quarters before its bottom if the top before lies beyond hidden cycles
    begin = np.where((begin >= 0) & (bottoms - begin > 5 * quarter), bottoms - 3 * quarter, begin)
    pair = (begin >= 0) & (end >= 0)  # two cuts, one bottom reversal between
    start, stop, bottom = begin[pair], end[pair], bottoms[pair]
    if not start.size:
        return Cycles(none, none, none, none, False, 1, n)
    # the drive's periods in each hole, and before and after (less a lead-in or lead-out);
    # a hidden row's bottom three quarters in, as a cycle's, for its number
    head, inner, tail = start[0], start[1:] - stop[:-1], n - 1 - stop[-1]
    ends = np.rint(np.array([head, tail]) / period) - 1
    hidden = np.concatenate([ends[:1], np.rint(inner / period), ends[1:]]).clip(0).astype(int)
    length = np.concatenate([[period], inner / np.maximum(hidden[1:-1], 1), [period]])
    hole = np.repeat(np.arange(hidden.size), hidden)
    j = np.arange(hole.size) - np.repeat(np.cumsum(hidden) - hidden, hidden)
    j -= np.where(hole == 0, hidden[0], 0)  # the head's run back from the first cycle
    at = np.concatenate([[start[0]], stop])  # each hole's end next to a cycle
    size = np.rint(length[hole]).astype(np.int64)
    first = np.concatenate([start, np.rint(at[hole] + length[hole] * j).astype(np.int64)])
    rows = np.argsort(first, kind="stable")
    first, is_hidden = first[rows], rows >= start.size
    count = np.concatenate([stop - start, size])[rows] + 1
    rotation = np.concatenate([bottom - start, (3 * size) // 4])[rows]
    gap = first[1:] > first[:-1] + count[:-1] - 1
    leading, trailing = int(first[0]), int(n - first[-1] - count[-1])
    return Cycles(
        start=first,
        count=count,
        rotation=rotation,
        label=np.arange(1, first.size + 1, dtype=np.int64),
        continuous=False,
        incomplete_cycles=int(leading > 0) + int(trailing > 0) + int(np.count_nonzero(gap)),
        dropped_samples=leading + trailing + int((first[1:] - first[:-1] - count[:-1])[gap].sum()),
        hidden=is_hidden,
    )


def _split(samples: passes.Samples, hysteresis: float) -> Cycles:
    """The cycles of ``samples`` cut at the displacement reversals."""
    n = samples.size
    if n < 2:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    sums, gaps, sample_at, sampled, finite, _ = passes.survey(samples)
    count = int(sums[:, 0].sum())
    line = passes.displacement_line(sums, n)
    low, high = passes.displacement_percentiles(samples, gaps, line, sample_at, sampled, count)
    half_range = 0.5 * (high - low)
    if not half_range > 0.0:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    band = (0.5 * (high + low), hysteresis * half_range)
    starts, kind, extreme, value = _trigger(samples, gaps, line, band)
    period = _period(starts, kind)
    # every other cycle under the band: the bottom runs two periods apart, half a period
    # from a top to the next bottom (or back) still
    gone = np.diff(extreme)
    falling, rising = gone[kind[:-1] > 0], gone[kind[:-1] < 0]
    half = min(np.median(falling), np.median(rising)) if falling.size and rising.size else np.nan
    step = 2 if 2 * half < 0.75 * period else 1
    runs = (starts, kind, period / step, step)
    level = _local_level(samples, gaps, line, runs, hysteresis, band)
    if level is not None:  # kept if it finds smaller cycles (more bottom runs)
        local = _trigger(samples, gaps, line, level)
        if np.count_nonzero(local[1] < 0) > np.count_nonzero(kind < 0):
            band = level
            starts, kind, extreme, value = local
            period = _period(starts, kind)
        else:
            level = None
    # A gap shorter than half the samples beyond the band in a half period of a triangle
    # wave cannot have hidden a run of the other kind: the trigger goes on over it.
    long_gaps = gaps[gaps[:, 1] - gaps[:, 0] >= 0.25 * (1.0 - hysteresis) * period]
    gapped, margin = (gaps, long_gaps), _TOLERANCE * (high - low)
    parts = _parts_after_gaps(samples, gapped, line, band, (starts, kind, extreme, value))
    kind_of_part, extreme_of_part = kind[parts[0]], parts[2]
    # Beside a long gap, as at the ends of the recording: an extreme within the tolerance of
    # the sample next to the gap may lie where the samples stop.
    hidden = _hidden_by_gaps(parts[1:], samples, gapped, margin)
    edges, scale = (finite[0][0], finite[-1][1]), (margin, 0.5 * period)
    accepted = _accepted_reversals((parts[0], kind_of_part, *parts[2:]), hidden, edges, scale)
    if level is not None:
        accepted &= _deep_ends(parts[3], accepted)
    bottoms = extreme_of_part[(kind_of_part < 0) & accepted]
    if bottoms.size < 2:
        # Not two bottom reversals: the recording may still be one loop, begun anywhere on it.
        if n > _ONE_LOOP:
            raise ValueError(
                f"no complete cycle in {n} samples: fewer than two displacement reversals"
            )
        x, q, _, missing = samples.arrays  # as one cycle, numbered 0 (dask's if lazy)
        cycle = np.zeros_like(x, dtype=np.int64)
        return _labelled(passes.Samples(x, q, cycle, missing, runner=samples.runner))
    # the amplitude varies: cut where the drive's cycles meet
    if level is not None or _steps(kind_of_part[accepted], *(p[accepted] for p in parts[2:])):
        tops = extreme_of_part[(kind_of_part > 0) & accepted]
        found = _drive_cycles(bottoms, tops, n, float(np.median(np.diff(bottoms))))
        return _drive_numbers(_with_missing(found, gaps), merged=True)
    # Each loop runs from its bottom reversal to the next and back, closed despite a drift.
    start = bottoms[:-1]
    leading, trailing = int(bottoms[0]), int(n - 1 - bottoms[-1])
    cycles = Cycles(
        start=start,
        count=bottoms[1:] - start + 1,
        rotation=np.zeros_like(start),
        label=np.arange(1, start.size + 1, dtype=np.int64),
        continuous=True,
        incomplete_cycles=int(leading > 0) + int(trailing > 0),
        dropped_samples=leading + trailing,
    )
    return _drive_numbers(_with_missing(cycles, gaps))


def _labelled(samples: passes.Samples) -> Cycles:
    """The cycles of ``samples`` by their cycle numbers."""
    n = samples.size
    _, gaps, _, _, _, labels = passes.survey(samples)
    known = [pair for pair in labels if pair is not None]
    if not known:
        raise ValueError("no cycle number is given: the cycle column is empty")
    carries, carry = {}, known[0][0]
    for (a, _), pair in zip(samples.blocks() if samples.lazy else [(0, n)], labels, strict=True):
        carries[a] = carry
        if pair is not None:
            carry = pair[1]
    arguments, channels = (passes._CHUNK, gaps, carries), ("displacement", "cycle")
    pieces = _joined(samples, passes.labelled_runs, arguments, channels, extra=1)
    piece_start, label, size, highest, lowest, bottom, x_first, x_last, step = pieces
    new = np.concatenate([[True], label[1:] != label[:-1]])
    first_piece = np.flatnonzero(new)
    _check_labels(label[first_piece], piece_start[first_piece])
    run = np.cumsum(new) - 1
    starts = piece_start[first_piece].astype(np.int64)
    count = np.add.reduceat(size, first_piece).astype(np.int64)
    top = np.fmax.reduceat(highest, first_piece)
    floor, lowest_at = passes.extremes_of_runs(np.fmin, lowest, bottom, run, first_piece)
    valued = np.isfinite(x_first)
    begin = passes.ends_of_runs(run, valued, x_first, starts.size, first=True)
    end = passes.ends_of_runs(run, valued, x_last, starts.size, first=False)
    largest, stroke, gap = np.fmax.reduceat(step, first_piece), top - floor, np.abs(end - begin)
    typical = np.nanmedian(stroke) if np.isfinite(floor).any() else np.nan
    # A cycle with missing samples is kept whatever its shape: skipped as missing, not dropped.
    gapped = passes.missing_in(gaps, starts, count) if gaps.size else False
    complete = (count >= MIN_SAMPLES) & (
        gapped
        | (stroke >= 0.5 * typical)
        & (stroke > 0.0)
        & (gap <= 1.5 * np.where(np.isnan(largest), 0.0, largest) + _TOLERANCE * stroke)
    )
    start, count = starts[complete], count[complete]
    cycles = Cycles(
        start=start,
        count=count,
        rotation=lowest_at[complete] - start,
        label=np.rint(label[first_piece][complete]).astype(np.int64),
        continuous=False,
        incomplete_cycles=int(np.count_nonzero(~complete)),
        dropped_samples=int(n - count.sum()),
    )
    return _with_missing(cycles, gaps)


def _check_labels(number, start) -> None:
    """Raise for a cycle ``number`` (of a run from ``start``) not whole, or seen before."""
    instead = "--cycle-col none, or cycle=None, cuts the cycles at the reversals instead"
    if (split := np.flatnonzero(number != np.floor(number))).size:
        raise ValueError(
            f"the cycle number {number[split[0]]:g} of sample {start[split[0]]:.0f} is not a "
            f"whole number: is the cycle column a cycle counter? ({instead})"
        )
    _, first = np.unique(number, return_index=True)
    if first.size < number.size:
        again = np.setdiff1d(np.arange(number.size), first)[0]
        raise ValueError(
            f"the cycle number {number[again]:g} comes again at sample {start[again]:.0f}, after "
            f"other numbers: two cycles would share it (a counter that restarted?); number the "
            f"cycles anew ({instead})"
        )


def find_cycles(
    displacement, cycle=None, hysteresis: float = 0.5, *, force=None, missing=None, runner=None
) -> Cycles:
    """The complete cycles of a recording (arrays checked): numbered, or cut at the reversals."""
    samples = passes.Samples(displacement, force, cycle, missing, runner=runner)
    return _split(samples, hysteresis) if cycle is None else _labelled(samples)
