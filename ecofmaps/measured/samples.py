r"""Step 1 of the loop pipeline: a recording's channels (:class:`Samples`, NumPy or dask) read a
block at a time, and the passes that find the cycles (the straight line, the percentiles, the
trigger's runs, the runs of cycle numbers); ``docs/method-loops.md`` ("Finding the cycles")."""

import sys

import numpy as np

from ecofmaps._parallel import stretch
from ecofmaps.measured import kernels

#: Samples read at once by the passes over the whole recording.
_CHUNK = 1 << 18
#: Samples per block of a lazy recording when its own chunks do not say.
_BLOCK = 1 << 22
#: Quantiles of the reversal detector's range (the 1st and 99th percentiles).
_QUANTILES = np.array([1.0, 99.0]) / 100.0
#: Size of the random sample that brackets the percentiles of a long recording.
_SAMPLE = 1 << 16
#: The channels of a recording, in the order a block function receives them.
_CHANNELS = ("displacement", "force", "cycle", "missing")


def _chunks(start: int, stop: int, chunk: int):
    """``(a, b)`` bounds of the chunks of samples ``start`` to ``stop - 1``."""
    return ((a, min(a + chunk, stop)) for a in range(start, stop, chunk))


def _blanked(x, a: int, b: int, gaps) -> np.ndarray:
    """``x`` (samples ``a`` to ``b - 1``) with NaN at the missing ones (a copy if any)."""
    first, last = np.searchsorted(gaps[:, 1], a, side="right"), np.searchsorted(gaps[:, 0], b)
    if first >= last:
        return x
    x = np.array(x, dtype=np.float64)
    for begin, end in gaps[first:last]:
        x[max(begin, a) - a : min(end, b) - a] = np.nan
    return x


def _piece_extremes(x, cuts, a: int):
    """Largest and smallest finite value of each piece of ``x`` and its first sample (or -1),
    found among the samples equal to it (not by a run index over every sample)."""
    lengths = np.diff(cuts, append=x.size)
    found = []
    for reduce in (np.fmax, np.fmin):
        value = reduce.reduceat(x, cuts)
        hits = np.flatnonzero(x == np.repeat(value, lengths))
        after = np.searchsorted(hits, cuts)
        index = hits[np.minimum(after, max(hits.size - 1, 0))] if hits.size else cuts
        inside = (after < hits.size) & (index < cuts + lengths)
        found += [value, np.where(inside, index + a, -1)]
    return found


def _finite_ends(x, cuts):
    """The first and last finite value of each piece ``x[cuts[k]:cuts[k + 1]]``, or NaN."""
    finite = np.flatnonzero(np.isfinite(x))
    ends = np.append(cuts[1:], x.size)
    if not finite.size:
        return np.full(cuts.size, np.nan), np.full(cuts.size, np.nan)
    first = np.minimum(np.searchsorted(finite, cuts), finite.size - 1)
    last = np.maximum(np.searchsorted(finite, ends) - 1, 0)
    has = (finite[first] >= cuts) & (finite[first] < ends)
    return np.where(has, x[finite[first]], np.nan), np.where(has, x[finite[last]], np.nan)


def extremes_of_runs(reduce, values, index, run, first):
    """Each run's ``reduce`` (``np.fmax`` or ``np.fmin``) of ``values`` from its ``first``, and
    the first ``index`` where a value is it (-1 if none)."""
    extreme = reduce.reduceat(values, first)
    found = ends_of_runs(run, values == extreme[run], index, first.size, first=True)
    return extreme, np.where(np.isnan(found), -1, found).astype(np.int64)


def _survey(start, stop, arguments, x, q, cycle, mask):
    """The block's part of :func:`survey`: line sums, gaps, sample, finite ends, labels."""
    size, chunk, sample_at = arguments
    middle = 0.5 * (size - 1)
    sums, gaps, finite, labels = [], [], [], []
    for a, b in _chunks(start, stop, chunk):
        i, j = a - start, b - start
        xa = x[i:j]
        good = np.isfinite(xa)
        if q is not None:
            good &= np.isfinite(q[i:j])
        if cycle is not None and cycle.dtype.kind not in "iub":
            good &= np.isfinite(cycle[i:j])
        if mask is not None:
            good &= ~np.asarray(mask[i:j], dtype=bool)
        t = np.arange(a - middle, b - middle)
        if good.all():
            k, u = b - a, a - middle  # sums of t and t² in closed form
            st = k * u + k * (k - 1) / 2
            stt = k * u * u + u * k * (k - 1) + (k - 1) * k * (2 * k - 1) / 6
            sums.append((k, np.add.reduce(xa), np.einsum("i,i->", t, xa), st, stt))
            finite += [a, b - 1]
        else:
            xg, tg = xa[good], t[good]
            stt = np.einsum("i,i->", tg, tg)
            sums.append((xg.size, np.add.reduce(xg), np.einsum("i,i->", tg, xg), tg.sum(), stt))
            edges = np.flatnonzero(np.diff((~good).view(np.int8), prepend=0, append=0))
            gaps.append(edges.reshape(-1, 2) + a)
            if xg.size:
                where = np.flatnonzero(good)
                finite += [a + where[0], a + where[-1]]
        if cycle is not None:
            ca = cycle[i:j]
            ca = ca[np.isfinite(ca)] if ca.dtype.kind not in "iub" else ca
            if ca.size:
                labels.append((ca[0], ca[-1]))
    picked = sample_at[(sample_at >= start) & (sample_at < stop)]
    return {
        "sums": np.array(sums, dtype=np.float64).reshape(-1, 5),
        "gaps": np.concatenate(gaps) if gaps else np.zeros((0, 2), np.int64),
        "finite": (finite[0], finite[-1]) if finite else None,
        "labels": (labels[0][0], labels[-1][1]) if labels else None,
        "sampled": x[picked - start],
    }


def _tails(start, stop, arguments, x):
    """The detrended displacements of the block within the percentiles' brackets."""
    chunk, gaps, line, (upper, lower) = arguments
    kept = []
    for a, b in _chunks(start, stop, chunk):
        d = detrended(_blanked(x[a - start : b - start], a, b, gaps), a, line)
        kept.append(d[(d <= upper) | (d >= lower)])
    return np.concatenate(kept)


def level_at(level, samples):
    """The trigger's half-band (or centre) at ``samples`` [m]: ``level``, or if it is local,
    ``(width, levels)``, one level per stretch of ``width`` samples counted from sample 0."""
    return level[1][samples // level[0]] if isinstance(level, tuple) else level


def local_extremes(start, stop, arguments, x):
    """Per stretch of ``width`` samples that a chunk cuts: its number, largest and smallest
    detrended displacement, finite samples, and sum and number of the finite absolute second
    differences less a sine's own (``-curvature`` × the displacement about ``centre``)."""
    chunk, gaps, line, width, (centre, curvature) = arguments
    found = [np.empty((6, 0))]
    for a, b in _chunks(start, stop, chunk):
        d = detrended(_blanked(x[a - start : b - start], a, b, gaps), a, line)
        first = np.arange(a // width, (b - 1) // width + 1)
        cuts = np.maximum(first * width, a) - a
        highest, lowest = np.fmax.reduceat(d, cuts), np.fmin.reduceat(d, cuts)
        finite = np.add.reduceat(np.isfinite(d), cuts)
        second = np.abs(np.diff(d, 2, prepend=np.nan, append=np.nan) + curvature * (d - centre))
        rough = np.add.reduceat(np.nan_to_num(second), cuts)
        counted = np.add.reduceat(np.isfinite(second), cuts)
        found.append(np.stack([first.astype(np.float64), highest, lowest, finite, rough, counted]))
    return np.concatenate(found, axis=1)


def trigger_runs(start, stop, arguments, x):
    """The Schmitt trigger's runs begun in the block, and the extremes of its pieces."""
    chunk, gaps, line, (centre, band) = arguments
    entries, kinds, pieces, previous = [], [], [], 0
    for a, b in _chunks(start, stop, chunk):
        xa = _blanked(x[a - start : b - start], a, b, gaps)
        d = detrended(xa, a, line)
        level, middle = (level_at(v, np.arange(a, b)) for v in (band, centre))
        state = (d > middle + level).view(np.int8) - (d < middle - level).view(np.int8)
        entry = np.concatenate([[0], np.flatnonzero(state[1:] != state[:-1]) + 1])
        kind = state[entry]
        entry, kind = entry[kind != 0], kind[kind != 0]  # into a decided state
        change = kind != np.concatenate([[previous], kind[:-1]])
        entry, kind = entry[change], kind[change]
        if kind.size:
            previous = kind[-1]
        entries.append(entry + a)
        kinds.append(kind)
        cuts = entry if entry.size and entry[0] == 0 else np.concatenate([[0], entry])
        pieces.append(np.stack([cuts + a, *_piece_extremes(xa, cuts, a)]))
    return np.concatenate(entries), np.concatenate(kinds), np.concatenate(pieces, axis=1)


def labelled_runs(start, stop, arguments, x, cycle):
    """Pieces of runs of equal cycle numbers cut at the chunks: first sample, number, samples,
    largest and smallest displacement, the smallest's sample, the first and last finite one,
    and the largest step between samples of the run (to the one after the block too)."""
    chunk, gaps, carries = arguments
    carry = carries[start]
    pieces = []
    for a, b in _chunks(start, stop, chunk):
        ahead = min(b + 1, start + cycle.size)  # one sample past the chunk, if any
        label = np.asarray(cycle[a - start : ahead - start])
        if label.dtype.kind not in "iub":
            known = np.isfinite(label)
            if not known.all():  # a missing cycle number takes the one before it
                last = np.maximum.accumulate(np.where(known, np.arange(label.size), -1))
                label = np.where(last >= 0, label[np.maximum(last, 0)], carry)
            carry = label[b - 1 - a]
        xa = _blanked(x[a - start : ahead - start], a, ahead, gaps)
        step = np.abs(np.diff(xa))  # step[i]: from sample a + i to the next
        step[label[1:] != label[:-1]] = np.nan  # no step from a run's last sample
        label, xa, step = label[: b - a], xa[: b - a], step[: b - a]
        if step.size < label.size:
            step = np.append(step, np.nan)
        cuts = np.concatenate([[0], np.flatnonzero(label[1:] != label[:-1]) + 1])
        highest, _, lowest, bottom = _piece_extremes(xa, cuts, a)
        runs = [cuts + a, label[cuts].astype(np.float64), np.diff(np.append(cuts, b - a))]
        ends = _finite_ends(xa, cuts)
        largest = np.fmax.reduceat(step, cuts)
        pieces.append(np.stack([*runs, highest, lowest, bottom, *ends, largest]))
    return np.concatenate(pieces, axis=1)


def detrended(x, a: int, line):
    """The displacements ``x`` of samples ``a`` on less the :func:`displacement_line`."""
    return kernels.detrended(np.ascontiguousarray(x, dtype=np.float64), a, *map(float, line))


def survey(samples: "Samples"):
    """Pass one: the straight line, the runs of missing samples, the percentile sample."""
    size = samples.size
    # The sample's order does not matter: its values are sorted.
    sample_at = np.sort(np.random.default_rng(0).integers(0, size, _SAMPLE))
    found = samples.map(_survey, _CHANNELS, (size, _CHUNK, sample_at))
    sums = np.concatenate([part["sums"] for part in found])
    gaps = np.concatenate([part["gaps"] for part in found])
    if gaps.size:  # runs of missing samples that meet at a chunk's edge are one run
        joined = np.flatnonzero(gaps[1:, 0] != gaps[:-1, 1]) + 1
        gaps = np.stack(
            [gaps[np.concatenate([[0], joined]), 0], gaps[np.append(joined - 1, -1), 1]], axis=1
        )
    sampled = np.concatenate([part["sampled"] for part in found])
    finite = [part["finite"] for part in found if part["finite"] is not None]
    labels = [part["labels"] for part in found]
    return sums, gaps.astype(np.int64), sample_at, sampled, finite, labels


def displacement_line(sums, size: int):
    """``(mean, mean_t, slope, middle)`` of the least-squares line through the finite
    displacements over t = i - (size - 1)/2 (see :func:`detrended`)."""
    count = sums[:, 0].sum()
    middle = 0.5 * (size - 1)
    if count == size:  # every sample: the t sum to 0 and their squares to n(n² - 1)/12
        sx, stx = sum(sums[:, 1].tolist()), sum(sums[:, 2].tolist())
        return sx / size, 0.0, stx / ((size * (size * size - 1)) / 12), middle
    if count < 2:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    sx, stx, st, stt = (sum(sums[:, k].tolist()) for k in (1, 2, 3, 4))
    mean, mean_t = sx / count, st / count
    spread = stt - st * mean_t
    return mean, mean_t, (stx - st * mean) / spread if spread > 0 else 0.0, middle


def _percentiles(samples: "Samples", gaps, line):
    """The percentiles of every finite detrended displacement, held at once."""
    every = samples.map(_tails, ("displacement",), (_CHUNK, gaps, line, (np.inf, -np.inf)))
    return np.percentile(np.concatenate(every), _QUANTILES * 100.0, overwrite_input=True)


def displacement_percentiles(samples: "Samples", gaps, line, sample_at, sampled, count: int):
    """The 1st and 99th percentile of the finite detrended displacements, exactly."""
    mean, mean_t, slope, middle = line
    if count <= _CHUNK:
        return _percentiles(samples, gaps, line)
    virtual = (count - 1) * _QUANTILES  # NumPy's virtual index, method "linear"
    rank = np.floor(virtual).astype(np.int64)
    missing = missing_in(gaps, sample_at, 1) if gaps.size else np.zeros(sample_at.size, bool)
    sample = (sampled - mean) - ((sample_at - middle) - mean_t) * slope
    sample = np.sort(sample[~missing & np.isfinite(sample)])
    drawn = sample.size
    quantile = _QUANTILES * drawn
    spread = 8.0 * np.sqrt(_QUANTILES * (1.0 - _QUANTILES) * drawn) + 8.0
    low = np.floor(quantile - spread).astype(np.int64)
    high = np.ceil(quantile + spread).astype(np.int64)
    low = np.where(low > 0, sample[np.clip(low, 0, drawn - 1)], -np.inf)
    high = np.where(high < drawn - 1, sample[np.clip(high, 0, drawn - 1)], np.inf)
    brackets = (_CHUNK, gaps, line, (high[0], low[1]))
    tails = np.concatenate(samples.map(_tails, ("displacement",), brackets))
    result = np.empty(2)
    for k in range(2):
        kept = tails[(tails >= low[k]) & (tails <= high[k])]
        if k == 0:
            below = np.count_nonzero(tails < low[k])
        else:
            below = count - np.count_nonzero(tails >= low[k])
        j = rank[k] - below
        if not 0 <= j < kept.size - 1:  # the sample missed: hold every value once
            return _percentiles(samples, gaps, line)
        previous, following = np.partition(kept, [j, j + 1])[[j, j + 1]]
        gamma, step = virtual[k] - rank[k], following - previous
        result[k] = following - step * (1.0 - gamma) if gamma >= 0.5 else previous + step * gamma
    return result


def missing_in(gaps, start, count):
    """True for each stretch ``start``, ``count`` that holds a sample of ``gaps`` (some)."""
    after = np.searchsorted(gaps[:, 1], start, side="right")  # first gap ending after start
    return (after < gaps.shape[0]) & (gaps[np.minimum(after, gaps.shape[0] - 1), 0] < start + count)


def ends_of_runs(run, valued, values, runs: int, first: bool):
    """The first (or last) of ``values`` over the pieces of each run where ``valued``."""
    result = np.full(runs, np.nan)
    pieces = np.flatnonzero(valued)
    if not pieces.size:
        return result
    owner = run[pieces]
    pick = np.searchsorted(owner, np.arange(runs), side="left" if first else "right") - (not first)
    inside = (pick >= 0) & (pick < pieces.size)
    pick = np.clip(pick, 0, pieces.size - 1)
    ok = inside & (owner[pick] == np.arange(runs))
    result[ok] = values[pieces[pick[ok]]]
    return result


def part_extremes(start, stop, arguments, x):
    """Per piece of a part ``[begin, end)`` in a chunk: the part, its highest and lowest
    displacement with their first samples, and its highest and lowest detrended one."""
    chunk, gaps, line, begin, end = arguments
    found = [np.empty((7, 0))]
    for a, b in _chunks(start, stop, chunk):
        first, last = np.searchsorted(end, a, side="right"), np.searchsorted(begin, b)
        if first >= last:
            continue
        part = np.arange(first, last)
        lower, upper = np.maximum(begin[part], a) - a, np.minimum(end[part], b) - a
        cuts = np.unique(np.concatenate([[0], lower, upper]))
        cuts = cuts[cuts < b - a]
        at = np.searchsorted(cuts, lower)  # the piece of each part
        xa = _blanked(np.asarray(x[a - start : b - start], dtype=np.float64), a, b, gaps)
        d = detrended(xa, a, line)
        extremes = [e[at] for e in _piece_extremes(xa, cuts, a)]
        ranges = [np.fmax.reduceat(d, cuts)[at], np.fmin.reduceat(d, cuts)[at]]
        found.append(np.stack([part.astype(np.float64), *extremes, *ranges]))
    return np.concatenate(found, axis=1)


def values_at(start, stop, arguments, x):
    """The displacements at the samples ``at`` (sorted) in the block (NaN where missing)."""
    gaps, at = arguments
    at = at[(at >= start) & (at < stop)]
    if not at.size:
        return np.empty(0)
    stretch = np.asarray(x[at[0] - start : at[-1] + 1 - start], dtype=np.float64)
    return _blanked(stretch, at[0], at[-1] + 1, gaps)[at - at[0]]


def is_lazy(value) -> bool:
    """Whether ``value`` is a dask collection, or an xarray object backed by one."""
    if "dask" not in sys.modules:  # nothing can be lazy before dask is imported
        return False
    data = getattr(value, "data", None) if hasattr(value, "dims") else value
    return sys.modules["dask"].is_dask_collection(data)


class Samples:
    """The channels of one recording."""

    def __init__(self, displacement, force, cycle=None, missing=None, *, runner=None):
        self.arrays = (displacement, force, cycle, missing)
        self.size = int(displacement.shape[0])
        self.lazy = any(is_lazy(a) for a in self.arrays)
        self.runner = runner
        if self.lazy and runner is None:
            raise ValueError("a lazy recording needs a runner")
        chunks = getattr(displacement, "chunks", None)
        block = int(chunks[0][0]) if chunks and chunks[0] else _BLOCK
        self.block = max(1, round(block / _CHUNK)) * _CHUNK  # whole chunks of the passes

    def blocks(self):
        """``(start, stop)`` of each block of a lazy recording (the grid)."""
        return [(a, min(a + self.block, self.size)) for a in range(0, self.size, self.block)]

    def map(self, function, channels, arguments=(), extra: int = 0) -> list:
        """``function(start, stop, arguments, *arrays)`` over the recording's blocks."""
        selected = [self.arrays[_CHANNELS.index(name)] for name in channels]
        if not self.lazy:
            return [function(0, self.size, arguments, *selected)]

        def tasks():
            for a, b in self.blocks():
                end = min(b + extra, self.size)
                arrays = (None if s is None else stretch(s, a, end) for s in selected)
                yield (a, b, arguments, *arrays)

        return list(self.runner.map(function, tasks()))


class MissingSampleError(ValueError):
    """A missing sample (0-based index ``sample``) where ``nan_policy='raise'``: ``what`` is
    wrong (None: NaN or empty), ``skips`` what ``nan_policy='skip'`` does instead."""

    def __init__(self, sample: int, what=None, skips=None):
        self.sample, self.what = int(sample), what
        self.skips = skips or (
            "analyses the cycles without missing samples and reports the others as skipped"
        )
        what = what or f"sample {self.sample} is missing (NaN or empty)"
        super().__init__(f"{what}; nan_policy='skip' {self.skips}")
