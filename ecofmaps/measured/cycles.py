r"""A recording of fretting loops cut into cycles.

A recording is a long series of samples :math:`(\Delta_i, Q_i)`. :func:`split_cycles` cuts
it at the displacement reversals; :func:`labelled_cycles` uses a cycle number recorded with
each sample instead; :func:`find_cycles` chooses between the two, for
:func:`ecofmaps.analyze_loops` and :func:`ecofmaps.fit_loop` alike. They return
:class:`Cycles`: for every complete cycle, the stretch of samples it covers (first sample
and count) and where in the stretch its loop begins, at its lowest displacement. A loop
runs once round from there and back to it (the last point closes the loop).
:mod:`ecofmaps.measured.centring` moves the loops to their centres.

No Python loop runs over samples or over cycles, and nothing the size of the recording is
held beyond the recording itself: the passes over it (the detrending, its percentiles, the
Schmitt trigger, the extremes of each run) go a chunk of ``_CHUNK`` samples at a time. A
long recording held as dask arrays (:mod:`ecofmaps.measured.samples`) goes through the same
passes a block of chunks at a time, each block where its task runs, and each pass returns
what it found per chunk (sums, the ends and extremes of runs), which are joined here in
order: the cycles are the same, sample for sample, however the recording is held.

Finding the reversals
---------------------
The displacement is detrended by a straight line fitted over the whole recording (so a
steady drift does not move it across the thresholds) and passed through a Schmitt trigger:
it is *high* once it has risen above ``+hysteresis`` times the half-range and stays so
until it falls below ``-hysteresis`` times the half-range (the half-range is half the
distance between the 1st and 99th percentiles). Noise smaller than the hysteresis band
cannot make a false reversal. The top reversal of a cycle is the highest sample of a high
run, the bottom reversal the lowest sample of a low run. A cycle runs from one bottom
reversal to the next.

The first and last runs may be cut short by the ends of the recording. Their extreme is a
reversal if it lies inside the run, or, when it is the recording's first or last sample,
if it comes within ``tolerance`` of the stroke :math:`2\Delta^*` of the nearest extreme of
the same kind (a recording that starts or ends exactly at a reversal). The samples before
the first and after the last bottom reversal are incomplete cycles: they are dropped and
counted. A recording with fewer than two bottom reversals is read as a single loop if it
closes (see :func:`labelled_cycles`).

Missing samples
---------------
A sample is missing when its displacement, force or cycle number is not finite (an empty
cell, NaN), or a ``missing`` mask says so. The line, the percentiles and the trigger use the
other samples only (a missing sample neither starts nor ends a run, nor is an extreme), and
a missing cycle number takes the one before it. A cycle whose stretch holds a missing
sample is kept in the table, marked in :attr:`Cycles.missing`: the analysis reports it as
skipped, with no values, and centres its neighbours without it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ecofmaps.measured.samples import Samples

__all__ = ["MIN_SAMPLES", "Cycles", "find_cycles", "labelled_cycles", "split_cycles"]

#: Fewest samples in one complete cycle: two branches, each with a stick and a slip part.
#: The one definition for the analysis, the fit and the synthetic recordings.
MIN_SAMPLES = 8

#: Samples read at once by the passes over the whole recording.
_CHUNK = 1 << 18

#: A recording longer than this with fewer than two bottom reversals is not read as one loop.
_ONE_LOOP = 1 << 24


@dataclasses.dataclass(frozen=True, eq=False)
class Cycles:
    """Complete cycles of a recording: the stretch of samples of each, and its loop's start.

    Attributes
    ----------
    start : numpy.ndarray of int64, shape (cycles,)
        First sample of each cycle's stretch of the recording.
    count : numpy.ndarray of int64, shape (cycles,)
        Samples in the stretch. A cycle cut at the reversals runs from its bottom
        reversal to the next one, both included.
    rotation : numpy.ndarray of int64, shape (cycles,)
        Where the loop begins, counted from ``start``: its lowest displacement (0 for
        cycles cut at the reversals). The loop runs through the stretch from there,
        wraps round to its beginning and ends by repeating its first sample.
    label : numpy.ndarray of int64, shape (cycles,)
        The cycle number: the recorded one, or 1, 2, ... in order of the complete cycles.
    continuous : bool
        True when the cycles follow each other without a gap (cut at the reversals: each
        stretch ends on the sample that begins the next), so a slow drift can be
        interpolated from one cycle to the next.
    incomplete_cycles : int
        Incomplete cycles dropped (at the ends of the recording, or labelled cycles that do
        not close).
    dropped_samples : int
        Samples that belong to no complete cycle.
    missing : numpy.ndarray of bool, shape (cycles,), or None
        True for the cycles whose stretch holds a missing sample; None if no sample of the
        recording is missing.
    missing_samples : int
        Missing samples in the whole recording.
    first_missing : int
        Index of the first missing sample, or -1.
    """

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

    @property
    def width(self) -> int:
        """Points round the longest loop, the closing point included. [1]"""
        return int(self.count.max()) + 1 if self.count.size else 1

    @property
    def whole(self) -> np.ndarray:
        """True for the cycles without a missing sample."""
        if self.missing is None:
            return np.ones(self.start.size, dtype=bool)
        return ~self.missing

    def rows(self, rows: slice) -> Cycles:
        """The cycles ``rows`` (a slice of consecutive rows) as a table of their own."""
        return dataclasses.replace(
            self,
            start=self.start[rows],
            count=self.count[rows],
            rotation=self.rotation[rows],
            label=self.label[rows],
            missing=None if self.missing is None else self.missing[rows],
        )

    def indices(self, rows=slice(None), width=None):
        """Sample indices round the loops ``rows``, one padded row per loop.

        Parameters
        ----------
        rows : slice or array_like of int
            The cycles (rows of this table).
        width : int, optional
            Points per row; default the longest of these loops, closing point included.

        Returns
        -------
        samples : numpy.ndarray of int64, shape (rows, width)
            Row ``k`` lists the samples of loop ``k`` in order round it, from its lowest
            displacement to the point that closes it, then repeats that closing sample.
        points : numpy.ndarray of int64, shape (rows,)
            Points round each loop, the closing one included.
        """
        start, count, rotation = self.start[rows], self.count[rows], self.rotation[rows]
        if width is None:
            width = int(count.max()) + 1
        j = np.arange(width)[None, :]
        if self.continuous:  # no rotation: the stretch, then its first sample again
            return start[:, None] + np.where(j < count[:, None], j, 0), count + 1
        count, rotation = count[:, None], rotation[:, None]
        position = rotation + j
        position = np.where(position >= count, position - count, position)
        position = np.where(j < count, position, rotation)
        return start[:, None] + position, self.count[rows] + 1


def _chunks(start: int, stop: int, chunk: int):
    """``(a, b)`` bounds of the chunks of samples ``start`` to ``stop - 1``."""
    return ((a, min(a + chunk, stop)) for a in range(start, stop, chunk))


def _blanked(x, a: int, b: int, gaps) -> np.ndarray:
    """``x`` (samples ``a`` to ``b - 1``) with NaN at the missing ones (a copy if any).

    ``gaps`` is an (m, 2) array of the ``[start, stop)`` of each run of missing samples.
    """
    first = np.searchsorted(gaps[:, 1], a, side="right")
    last = np.searchsorted(gaps[:, 0], b)
    if first >= last:
        return x
    x = np.array(x, dtype=np.float64)
    for begin, end in gaps[first:last]:
        x[max(begin, a) - a : min(end, b) - a] = np.nan
    return x


def _piece_extremes(x, cuts):
    """Largest and smallest finite value of each piece ``x[cuts[k]:cuts[k + 1]]`` and the
    first index (in ``x``) of each, -1 where a piece has no finite value."""
    lengths = np.diff(cuts, append=x.size)
    found = []
    for reduce in (np.fmax, np.fmin):
        value = reduce.reduceat(x, cuts)
        hits = np.flatnonzero(x == np.repeat(value, lengths))
        after = np.searchsorted(hits, cuts)
        index = hits[np.minimum(after, max(hits.size - 1, 0))] if hits.size else cuts
        inside = (after < hits.size) & (index < cuts + lengths)
        found += [value, np.where(inside, index, -1)]
    return found


def _first_of_runs(run, value, index, target):
    """The first ``index`` of each run whose piece ``value`` equals the run's ``target``
    (-1 for a run with none).

    ``run`` numbers the pieces' runs (0, 1, ... in order).
    """
    hits = np.flatnonzero(value == target[run])
    runs = np.arange(target.size)
    if not hits.size:
        return np.full(target.size, -1, dtype=np.int64)
    at = np.minimum(np.searchsorted(run[hits], runs), hits.size - 1)
    return np.where(run[hits[at]] == runs, index[hits[at]], -1).astype(np.int64)


def _finite_ends(x, cuts):
    """The first and last finite value of each piece ``x[cuts[k]:cuts[k + 1]]`` (NaN for a
    piece without one)."""
    finite = np.flatnonzero(np.isfinite(x))
    ends = np.append(cuts[1:], x.size)
    if not finite.size:
        return np.full(cuts.size, np.nan), np.full(cuts.size, np.nan)
    first = np.minimum(np.searchsorted(finite, cuts), finite.size - 1)
    last = np.maximum(np.searchsorted(finite, ends) - 1, 0)
    has = (finite[first] >= cuts) & (finite[first] < ends)
    return np.where(has, x[finite[first]], np.nan), np.where(has, x[finite[last]], np.nan)


# --- the passes over the samples, a block at a time ----------------------------------------


def _survey(start, stop, arguments, x, q, cycle, mask):
    """Sums for the straight line through the finite displacements, runs of missing
    samples, the displacement at the percentile sample's indices, and the first and last
    finite index and cycle number of the block (see :func:`_line`)."""
    size, chunk, sample_at = arguments
    middle = 0.5 * (size - 1)
    sums, gaps, finite, labels = [], [], [], []
    for a, b in _chunks(start, stop, chunk):
        i, j = a - start, b - start
        xa = x[i:j]
        bad = ~np.isfinite(xa)
        if q is not None:
            bad |= ~np.isfinite(q[i:j])
        if cycle is not None and cycle.dtype.kind not in "iub":
            bad |= ~np.isfinite(cycle[i:j])
        if mask is not None:
            bad |= np.asarray(mask[i:j], dtype=bool)
        t = np.arange(a - middle, b - middle)
        if not bad.any():
            k, u = b - a, a - middle  # sums of t and t² in closed form
            sums.append(
                (k, np.add.reduce(xa), np.einsum("i,i->", t, xa), k * u + k * (k - 1) / 2,
                 k * u * u + u * k * (k - 1) + (k - 1) * k * (2 * k - 1) / 6)
            )  # fmt: skip
            finite += [a, b - 1]
        else:
            good = ~bad
            xg, tg = xa[good], t[good]
            sums.append((xg.size, np.add.reduce(xg), np.einsum("i,i->", tg, xg), tg.sum(),
                         np.einsum("i,i->", tg, tg)))  # fmt: skip
            edges = np.flatnonzero(np.diff(bad.view(np.int8), prepend=0, append=0))
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
        d = _detrended(_blanked(x[a - start : b - start], a, b, gaps), a, b, line)
        kept.append(d[(d <= upper) | (d >= lower)])
    return np.concatenate(kept)


def _trigger(start, stop, arguments, x):
    """The Schmitt trigger's runs begun in the block, and the extremes of its pieces.

    Returns the runs' first samples and kinds (+1 high, -1 low; a run that continues the
    block's previous one in kind is left out, but not across blocks), and for each piece
    (cut at the block's chunks and at those first samples): its first sample, largest and
    smallest finite displacement and the first sample of each.
    """
    chunk, gaps, line, (centre, level) = arguments
    entries, kinds, pieces = [], [], []
    previous = 0
    for a, b in _chunks(start, stop, chunk):
        xa = _blanked(x[a - start : b - start], a, b, gaps)
        d = _detrended(xa, a, b, line)
        state = (d > centre + level).view(np.int8) - (d < centre - level).view(np.int8)
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
        highest, top, lowest, bottom = _piece_extremes(xa, cuts)
        pieces.append(
            np.stack([cuts + a, highest, np.where(top >= 0, top + a, -1), lowest,
                      np.where(bottom >= 0, bottom + a, -1)])
        )  # fmt: skip
    return np.concatenate(entries), np.concatenate(kinds), np.concatenate(pieces, axis=1)


def _labelled_runs(start, stop, arguments, x, cycle):
    """Pieces of runs of equal cycle numbers in the block, cut at its chunks: first
    sample, cycle number, samples, largest and smallest finite displacement, the first
    sample of the smallest, the first and last finite displacement, and the largest step
    between consecutive samples of the run (to the sample after the block too).

    ``x`` and ``cycle`` hold one sample past the block when there is one.
    """
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
        highest, _, lowest, bottom = _piece_extremes(xa, cuts)
        x_first, x_last = _finite_ends(xa, cuts)
        pieces.append(
            np.stack([cuts + a, label[cuts].astype(np.float64), np.diff(np.append(cuts, b - a)),
                      highest, lowest, np.where(bottom >= 0, bottom + a, -1), x_first, x_last,
                      np.fmax.reduceat(step, cuts)])
        )  # fmt: skip
    return np.concatenate(pieces, axis=1)


# --- joining the passes ----------------------------------------------------------------------

#: Quantiles of the reversal detector's range (the 1st and 99th percentiles).
_QUANTILES = np.array([1.0, 99.0]) / 100.0

#: Size of the random sample that brackets the percentiles of a long recording.
_SAMPLE = 1 << 16


def _detrended(x, a: int, b: int, line):
    """The displacements ``x`` of samples ``a`` to ``b - 1`` less the straight ``line``."""
    mean, mean_t, slope, middle = line
    # Exact: the sample indices less the middle are integers or halves below 2**52.
    return (x - mean) - (np.arange(a - middle, b - middle) - mean_t) * slope


def _survey_all(samples: Samples):
    """Pass one: the straight line, the runs of missing samples, the percentile sample."""
    size = samples.size
    # The sample's order does not matter: its values are sorted.
    sample_at = np.sort(np.random.default_rng(0).integers(0, size, _SAMPLE))
    found = samples.map(
        _survey, ("displacement", "force", "cycle", "missing"), (size, _CHUNK, sample_at)
    )
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


def _line(sums, size: int):
    """``(mean, mean_t, slope, middle)`` of the least-squares line through the finite
    displacements over t = i - (size - 1)/2 (see :func:`_detrended`)."""
    count = sums[:, 0].sum()
    middle = 0.5 * (size - 1)
    if count == size:  # every sample: the t sum to 0 and their squares to n(n² - 1)/12
        return (
            sum(sums[:, 1].tolist()) / size,
            0.0,
            sum(sums[:, 2].tolist()) / ((size * (size * size - 1)) / 12),
            middle,
        )
    if count < 2:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    sx, stx, st, stt = (sum(sums[:, k].tolist()) for k in (1, 2, 3, 4))
    mean, mean_t = sx / count, st / count
    spread = stt - st * mean_t
    return mean, mean_t, (stx - st * mean) / spread if spread > 0 else 0.0, middle


def _percentiles(samples: Samples, gaps, line, sample_at, sampled, count: int):
    """``np.percentile`` of the finite detrended displacements at the 1st and 99th
    percentile, exactly.

    A long recording is not held at once: a random sample of it brackets each order
    statistic needed (by eight standard errors of the sample's quantile), one pass a chunk
    at a time keeps the values inside the brackets and counts those below, and the order
    statistics are selected among these. NumPy's linear interpolation between them is
    repeated operation by operation, so the result is the same to the last bit.
    """
    mean, mean_t, slope, middle = line
    if count <= _CHUNK:
        tails = np.concatenate(
            samples.map(_tails, ("displacement",), (_CHUNK, gaps, line, (np.inf, -np.inf)))
        )
        return np.percentile(tails, _QUANTILES * 100.0, overwrite_input=True)
    virtual = (count - 1) * _QUANTILES  # NumPy's virtual index, method "linear"
    rank = np.floor(virtual).astype(np.int64)
    missing = np.zeros(sample_at.size, dtype=bool)
    if gaps.size:
        run = np.searchsorted(gaps[:, 0], sample_at, side="right") - 1
        missing = (run >= 0) & (sample_at < gaps[np.maximum(run, 0), 1])
    sample = (sampled - mean) - ((sample_at - middle) - mean_t) * slope
    sample = np.sort(sample[~missing & np.isfinite(sample)])
    drawn = sample.size
    quantile = _QUANTILES * drawn
    spread = 8.0 * np.sqrt(_QUANTILES * (1.0 - _QUANTILES) * drawn) + 8.0
    low = np.floor(quantile - spread).astype(np.int64)
    high = np.ceil(quantile + spread).astype(np.int64)
    low = np.where(low > 0, sample[np.clip(low, 0, drawn - 1)], -np.inf)
    high = np.where(high < drawn - 1, sample[np.clip(high, 0, drawn - 1)], np.inf)
    tails = np.concatenate(
        samples.map(_tails, ("displacement",), (_CHUNK, gaps, line, (high[0], low[1])))
    )
    result = np.empty(2)
    for k in range(2):
        kept = tails[(tails >= low[k]) & (tails <= high[k])]
        below = (
            np.count_nonzero(tails < low[k])
            if k == 0
            else count - np.count_nonzero(tails >= low[k])
        )
        j = rank[k] - below
        if not 0 <= j < kept.size - 1:  # the sample missed: hold every value once
            whole = np.concatenate(
                samples.map(_tails, ("displacement",), (_CHUNK, gaps, line, (np.inf, -np.inf)))
            )
            return np.percentile(whole, _QUANTILES * 100.0, overwrite_input=True)
        previous, following = np.partition(kept, [j, j + 1])[[j, j + 1]]
        gamma = virtual[k] - rank[k]
        difference = following - previous
        result[k] = (
            following - difference * (1.0 - gamma)
            if gamma >= 0.5
            else previous + difference * gamma
        )
    return result


def _missing_in(gaps, start, count):
    """True for each stretch ``start``, ``count`` that holds a sample of ``gaps``."""
    if not gaps.size:
        return None
    after = np.searchsorted(gaps[:, 1], start, side="right")  # first gap ending after start
    return (after < gaps.shape[0]) & (gaps[np.minimum(after, gaps.shape[0] - 1), 0] < start + count)


def _with_missing(cycles: Cycles, gaps) -> Cycles:
    """``cycles`` with the cycles that hold a sample of ``gaps`` marked."""
    if not gaps.size:
        return cycles
    return dataclasses.replace(
        cycles,
        missing=_missing_in(gaps, cycles.start, cycles.count),
        missing_samples=int((gaps[:, 1] - gaps[:, 0]).sum()),
        first_missing=int(gaps[0, 0]),
    )


def _split(samples: Samples, hysteresis: float, tolerance: float) -> Cycles:
    """:func:`split_cycles` of any :class:`Samples`."""
    n = samples.size
    if n < 2:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    sums, gaps, sample_at, sampled, finite, _ = _survey_all(samples)
    count = int(sums[:, 0].sum())
    line = _line(sums, n)
    low, high = _percentiles(samples, gaps, line, sample_at, sampled, count)
    half_range = 0.5 * (high - low)
    if not half_range > 0.0:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    centre = 0.5 * (high + low)
    stroke = 2.0 * half_range
    found = samples.map(
        _trigger, ("displacement",), (_CHUNK, gaps, line, (centre, hysteresis * half_range))
    )
    # A run begins where the state (+1 above the band, -1 below it, 0 inside) differs from
    # the last one decided; samples before the first decision take that first one. The 99th
    # percentile lies above the band, so some state is decided.
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
    highest_of_run = np.fmax.reduceat(highest, first_piece)
    lowest_of_run = np.fmin.reduceat(lowest, first_piece)
    extreme = np.where(
        kind > 0,
        _first_of_runs(run, highest, top, highest_of_run),
        _first_of_runs(run, lowest, bottom, lowest_of_run),
    ).astype(np.int64)
    value = np.where(kind > 0, highest_of_run, lowest_of_run)
    accepted = np.ones(starts.size, dtype=bool)
    runs = starts.size
    first_finite, last_finite = finite[0][0], finite[-1][1]
    for edge, boundary, neighbour in ((0, first_finite, 2), (runs - 1, last_finite, runs - 3)):
        # The runs alternate in kind, so the nearest run of the same kind is two away.
        if extreme[edge] != boundary:
            continue
        if 0 <= neighbour < runs:
            accepted[edge] = abs(value[edge] - value[neighbour]) <= tolerance * stroke
        else:
            accepted[edge] = False
    bottoms = extreme[(kind < 0) & accepted]
    if bottoms.size < 2:
        # Not two bottom reversals: the recording may still be one closed loop that starts
        # and ends elsewhere on the loop.
        if n > _ONE_LOOP:
            raise ValueError(
                f"no complete cycle in {n} samples: fewer than two displacement reversals"
            )
        return _labelled(samples.constant_cycle(), tolerance)
    # Each loop runs from its bottom reversal to the next and back to its first sample, so
    # it is closed even if the displacement drifted in between.
    start = bottoms[:-1]
    leading, trailing = int(bottoms[0]), int(n - 1 - bottoms[-1])
    return _with_missing(
        Cycles(
            start=start,
            count=bottoms[1:] - start + 1,
            rotation=np.zeros_like(start),
            label=np.arange(1, start.size + 1, dtype=np.int64),
            continuous=True,
            incomplete_cycles=int(leading > 0) + int(trailing > 0),
            dropped_samples=leading + trailing,
        ),
        gaps,
    )


def _labelled(samples: Samples, tolerance: float) -> Cycles:
    """:func:`labelled_cycles` of any :class:`Samples` with cycle numbers."""
    n = samples.size
    _, gaps, _, _, _, labels = _survey_all(samples)
    known = [pair for pair in labels if pair is not None]
    if not known:
        raise ValueError("no cycle number is given: the cycle column is empty")
    carries, carry = {}, known[0][0]
    for (a, _), pair in zip(samples.blocks() if samples.lazy else [(0, n)], labels, strict=True):
        carries[a] = carry
        if pair is not None:
            carry = pair[1]
    pieces = np.concatenate(
        samples.map(_labelled_runs, ("displacement", "cycle"), (_CHUNK, gaps, carries), extra=1),
        axis=1,
    )
    piece_start, label, size, highest, lowest, bottom, x_first, x_last, step = pieces
    new = np.concatenate([[True], label[1:] != label[:-1]])
    first_piece = np.flatnonzero(new)
    run = np.cumsum(new) - 1
    starts = piece_start[first_piece].astype(np.int64)
    count = np.add.reduceat(size, first_piece).astype(np.int64)
    top = np.fmax.reduceat(highest, first_piece)
    floor = np.fmin.reduceat(lowest, first_piece)
    has = np.isfinite(floor)
    lowest_at = _first_of_runs(run, lowest, bottom, floor)
    valued = np.isfinite(x_first)
    begin = _ends_of_runs(run, valued, x_first, starts.size, first=True)
    end = _ends_of_runs(run, valued, x_last, starts.size, first=False)
    largest = np.fmax.reduceat(step, first_piece)
    stroke = top - floor
    gap = np.abs(end - begin)
    typical = np.nanmedian(stroke) if has.any() else np.nan
    complete = (
        (count >= MIN_SAMPLES)
        & (stroke >= 0.5 * typical)
        & (stroke > 0.0)
        & (gap <= 1.5 * np.where(np.isnan(largest), 0.0, largest) + tolerance * stroke)
    )
    start, count = starts[complete], count[complete]
    return _with_missing(
        Cycles(
            start=start,
            count=count,
            rotation=lowest_at[complete] - start,
            label=np.rint(label[first_piece][complete]).astype(np.int64),
            continuous=False,
            incomplete_cycles=int(np.count_nonzero(~complete)),
            dropped_samples=int(n - count.sum()),
        ),
        gaps,
    )


def _ends_of_runs(run, valued, values, runs: int, first: bool):
    """The first (or last) of ``values`` over the pieces of each run where ``valued``."""
    result = np.full(runs, np.nan)
    pieces = np.flatnonzero(valued)
    if not pieces.size:
        return result
    owner = run[pieces]
    pick = np.searchsorted(owner, np.arange(runs), side="left" if first else "right")
    if not first:
        pick -= 1
    inside = (pick >= 0) & (pick < pieces.size)
    pick = np.clip(pick, 0, pieces.size - 1)
    ok = inside & (owner[pick] == np.arange(runs))
    result[ok] = values[pieces[pick[ok]]]
    return result


def split_cycles(displacement, hysteresis: float = 0.5, tolerance: float = 0.01) -> Cycles:
    """Cut a continuous recording into complete cycles at its displacement reversals.

    Parameters
    ----------
    displacement : numpy.ndarray
        Displacement at each sample, in time order (NaN where missing). [m]
    hysteresis : float
        Half-width of the Schmitt trigger's band, as a fraction of the displacement's
        half-range (0 < hysteresis < 1). Noise below it makes no false reversal. [1]
    tolerance : float
        How close to the neighbouring reversal (as a fraction of the stroke) an extreme
        at the very start or end of the recording must come to count as a reversal. [1]

    Returns
    -------
    cycles : Cycles
        Complete cycles from each bottom reversal to the next (both included).

    Raises
    ------
    ValueError
        If the displacement does not oscillate.

    Notes
    -----
    See the module's documentation for the method.
    """
    x = np.asarray(displacement, dtype=np.float64)
    return _split(Samples(x, None, chunk=_CHUNK), hysteresis, tolerance)


def labelled_cycles(displacement, cycle, tolerance: float = 0.01) -> Cycles:
    r"""Complete cycles of a recording whose samples carry their cycle number.

    Parameters
    ----------
    displacement : numpy.ndarray
        Displacement at each sample, in time order (NaN where missing). [m]
    cycle : numpy.ndarray
        Cycle number of each sample; each run of equal numbers is one cycle (the cycles
        may be loops recorded now and then during a long test). A missing (NaN) number
        takes the one before it. [1]
    tolerance : float
        Allowed gap, as a fraction of the cycle's stroke, between its last and first
        samples on top of 1.5 times its largest step. [1]

    Returns
    -------
    cycles : Cycles
        Each labelled cycle that closes, turned round to start at its lowest displacement
        and closed by repeating that sample.

    Notes
    -----
    A labelled cycle is complete if it has at least :data:`MIN_SAMPLES` samples, its
    stroke is at least half the median stroke of the recording, and it closes: the gap
    between its last and first displacements is at most 1.5 times its largest step
    between samples plus ``tolerance`` times its stroke. A loop cut short by the start or
    the end of the recording fails the last test.
    """
    x = np.asarray(displacement, dtype=np.float64)
    return _labelled(Samples(x, None, np.asarray(cycle), chunk=_CHUNK), tolerance)


def find_cycles(
    displacement, cycle=None, hysteresis: float = 0.5, *, force=None, missing=None, runner=None
) -> Cycles:
    """The complete cycles of a recording: numbered ones, or cut at the reversals.

    Parameters
    ----------
    displacement : numpy.ndarray or dask.array.Array
        Displacement at each sample, in time order, float64 (NaN where missing). [m]
    cycle : array_like, optional
        Cycle number of each sample (see :func:`labelled_cycles`); without it the
        recording is cut at its reversals (:func:`split_cycles`). [1]
    hysteresis : float
        Band of the reversal detector (see :func:`split_cycles`). [1]
    force : numpy.ndarray or dask.array.Array, optional
        The force, whose missing samples are missing samples too. [N]
    missing : array_like of bool, optional
        Samples to treat as missing besides the non-finite ones.
    runner : ecofmaps._parallel.Runner, optional
        Where the passes over dask arrays run.

    Returns
    -------
    cycles : Cycles
        With :attr:`Cycles.missing` marking the cycles that hold a missing sample.

    Raises
    ------
    ValueError
        If ``cycle`` does not hold one number per sample, or the displacement does not
        oscillate.
    """
    if cycle is not None:
        if getattr(cycle, "ndim", np.ndim(cycle)) != 1:
            raise ValueError("cycle must be one-dimensional (one value per sample)")
        if cycle.shape[0] != displacement.shape[0]:
            raise ValueError(
                f"cycle must have one value per sample: {cycle.shape[0]} values for "
                f"{displacement.shape[0]} samples"
            )
    samples = Samples(displacement, force, cycle, missing, runner=runner, chunk=_CHUNK)
    if cycle is None:
        return _split(samples, hysteresis, 0.01)
    return _labelled(samples, 0.01)
