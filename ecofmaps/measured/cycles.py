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
Schmitt trigger, the extremes of each run) go a chunk of ``_CHUNK`` samples at a time.

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
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ecofmaps._inputs import check

__all__ = ["MIN_SAMPLES", "Cycles", "find_cycles", "labelled_cycles", "split_cycles"]

#: Fewest samples in one complete cycle: two branches, each with a stick and a slip part.
#: The one definition for the analysis, the fit and the synthetic recordings.
MIN_SAMPLES = 8

#: Samples read at once by the passes over the whole recording.
_CHUNK = 1 << 18


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
    """

    start: np.ndarray
    count: np.ndarray
    rotation: np.ndarray
    label: np.ndarray
    continuous: bool
    incomplete_cycles: int
    dropped_samples: int

    @property
    def width(self) -> int:
        """Points round the longest loop, the closing point included. [1]"""
        return int(self.count.max()) + 1 if self.count.size else 1

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


def _chunks(size: int):
    """``(a, b)`` bounds of the chunks of a recording of ``size`` samples."""
    return ((a, min(a + _CHUNK, size)) for a in range(0, size, _CHUNK))


def _first_at(x: np.ndarray, starts: np.ndarray, value: np.ndarray) -> np.ndarray:
    """Index of the first sample equal to ``value[k]`` in each run ``k`` beginning at ``starts``.

    Every run holds its value (its extreme, say).
    """
    ends = np.append(starts[1:], x.size)
    first = np.full(starts.size, -1, dtype=np.int64)
    for a, b in _chunks(x.size):
        r0, r1 = np.searchsorted(ends, a, side="right"), np.searchsorted(starts, b)
        lengths = np.minimum(ends[r0:r1], b) - np.maximum(starts[r0:r1], a)
        hits = np.flatnonzero(x[a:b] == np.repeat(value[r0:r1], lengths)) + a
        run = np.searchsorted(starts, hits, side="right") - 1
        leading = np.flatnonzero(np.diff(run, prepend=-1))  # the first hit of each run
        run, hits = run[leading], hits[leading]
        fresh = first[run] < 0
        first[run[fresh]] = hits[fresh]
    return first


def _largest_steps(x: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Largest step between consecutive samples within each run beginning at ``starts``."""
    cuts = np.union1d(starts, np.arange(0, x.size, _CHUNK))
    ends = np.append(starts[1:], x.size) - 1  # no step from a run's last sample
    largest = np.empty(cuts.size)
    for a, b in _chunks(x.size):
        p, q = np.searchsorted(cuts, [a, b])
        step = np.abs(np.diff(x[a : b + 1], append=x[-1]))[: b - a]
        inside = ends[(ends >= a) & (ends < b)]
        step[inside - a] = 0.0
        largest[p:q] = np.maximum.reduceat(step, cuts[p:q] - a)
    return np.maximum.reduceat(largest, np.searchsorted(cuts, starts))


#: Quantiles of the reversal detector's range (the 1st and 99th percentiles).
_QUANTILES = np.array([1.0, 99.0]) / 100.0

#: Size of the random sample that brackets the percentiles of a long recording.
_SAMPLE = 1 << 16


def _percentiles(values, size: int):
    """``np.percentile`` of ``values(0, size)`` at the 1st and 99th percentile, exactly.

    A long recording is not held at once: a random sample of it brackets each order
    statistic needed (by eight standard errors of the sample's quantile), one pass a chunk
    at a time counts the values below each bracket and keeps those inside, and the order
    statistics are selected among these. NumPy's linear interpolation between them is
    repeated operation by operation, so the result is the same to the last bit.
    """
    if size <= _CHUNK:
        return np.percentile(values(0, size), _QUANTILES * 100.0, overwrite_input=True)
    virtual = (size - 1) * _QUANTILES  # NumPy's virtual index, method "linear"
    rank = np.floor(virtual).astype(np.int64)
    sample = np.sort(values(np.random.default_rng(0).integers(0, size, _SAMPLE)))
    spread = 8.0 * np.sqrt(_QUANTILES * (1.0 - _QUANTILES) * _SAMPLE) + 8.0
    low = np.floor(_QUANTILES * _SAMPLE - spread).astype(np.int64)
    high = np.ceil(_QUANTILES * _SAMPLE + spread).astype(np.int64)
    low = np.where(low > 0, sample[np.clip(low, 0, _SAMPLE - 1)], -np.inf)
    high = np.where(high < _SAMPLE - 1, sample[np.clip(high, 0, _SAMPLE - 1)], np.inf)
    tails = []  # the values up to the first bracket's top or from the second's bottom
    for a, b in _chunks(size):
        chunk = values(a, b)
        tails.append(chunk[(chunk <= high[0]) | (chunk >= low[1])])
    tails = np.concatenate(tails)
    result = np.empty(2)
    for k in range(2):
        kept = tails[(tails >= low[k]) & (tails <= high[k])]
        below = (
            np.count_nonzero(tails < low[k]) if k == 0 else size - np.count_nonzero(tails >= low[k])
        )
        j = rank[k] - below
        if not 0 <= j < kept.size - 1:  # the sample missed: hold the whole recording once
            whole = np.concatenate([values(a, b) for a, b in _chunks(size)])
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


def _runs(x: np.ndarray, hysteresis: float):
    """Schmitt-trigger runs of the detrended displacement: starts, kind (+1/-1), stroke."""
    n = x.size
    if n < 2:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    middle = 0.5 * (n - 1)
    mean = x.mean()
    # The least-squares slope over t = i - (n - 1)/2, whose squares sum to n(n² - 1)/12.
    slope = sum(
        np.einsum("i,i->", np.arange(a - middle, b - middle), x[a:b]) for a, b in _chunks(n)
    ) / ((n * (n * n - 1)) / 12)

    def detrended(a, b=None):
        """The detrended displacement at samples a to b - 1, or at the indices ``a``."""
        if b is None:
            return (x[a] - mean) - (a - middle) * slope
        # Exact: the sample indices less the middle are integers or halves below 2**52.
        return (x[a:b] - mean) - np.arange(a - middle, b - middle) * slope

    low, high = _percentiles(detrended, n)
    half_range = 0.5 * (high - low)
    if not half_range > 0.0:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    centre = 0.5 * (high + low)
    level = hysteresis * half_range
    # A run begins where the state (+1 above the band, -1 below it, 0 inside) differs from
    # the last one decided; samples before the first decision take that first one. The 99th
    # percentile lies above the band, so some state is decided.
    starts, kinds, previous = [], [], 0
    for a, b in _chunks(n):
        d = detrended(a, b)
        state = (d > centre + level).view(np.int8) - (d < centre - level).view(np.int8)
        entries = np.concatenate([[0], np.flatnonzero(state[1:] != state[:-1]) + 1])
        kind = state[entries]
        entries, kind = entries[kind != 0], kind[kind != 0]  # into a decided state
        change = kind != np.concatenate([[previous], kind[:-1]])
        starts.append(entries[change] + a)
        kinds.append(kind[change])
        if kind.size:
            previous = kind[-1]
    starts, kind = np.concatenate(starts), np.concatenate(kinds).astype(np.float64)
    starts[0] = 0
    return starts, kind, 2.0 * half_range


def split_cycles(displacement, hysteresis: float = 0.5, tolerance: float = 0.01) -> Cycles:
    """Cut a continuous recording into complete cycles at its displacement reversals.

    Parameters
    ----------
    displacement : numpy.ndarray
        Displacement at each sample, in time order. [m]
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
    n = x.size
    starts, kind, stroke = _runs(x, hysteresis)
    highest, lowest = np.maximum.reduceat(x, starts), np.minimum.reduceat(x, starts)
    extreme = _first_at(x, starts, np.where(kind > 0, highest, lowest))
    accepted = np.ones(starts.size, dtype=bool)
    runs = starts.size
    for edge, boundary, neighbour in ((0, 0, 2), (runs - 1, n - 1, runs - 3)):
        # The runs alternate in kind, so the nearest run of the same kind is two away.
        if extreme[edge] != boundary:
            continue
        if 0 <= neighbour < runs:
            gap = abs(x[extreme[edge]] - x[extreme[neighbour]])
            accepted[edge] = gap <= tolerance * stroke
        else:
            accepted[edge] = False
    bottoms = extreme[(kind < 0) & accepted]
    if bottoms.size < 2:
        # Not two bottom reversals: the recording may still be one closed loop that starts
        # and ends elsewhere on the loop.
        return labelled_cycles(x, np.zeros(n, dtype=np.int64), tolerance)
    # Each loop runs from its bottom reversal to the next and back to its first sample, so
    # it is closed even if the displacement drifted in between.
    start = bottoms[:-1]
    leading, trailing = int(bottoms[0]), int(n - 1 - bottoms[-1])
    return Cycles(
        start=start,
        count=bottoms[1:] - start + 1,
        rotation=np.zeros_like(start),
        label=np.arange(1, start.size + 1, dtype=np.int64),
        continuous=True,
        incomplete_cycles=int(leading > 0) + int(trailing > 0),
        dropped_samples=leading + trailing,
    )


def labelled_cycles(displacement, cycle, tolerance: float = 0.01) -> Cycles:
    r"""Complete cycles of a recording whose samples carry their cycle number.

    Parameters
    ----------
    displacement : numpy.ndarray
        Displacement at each sample, in time order. [m]
    cycle : numpy.ndarray
        Cycle number of each sample; each run of equal numbers is one cycle (the cycles
        may be loops recorded now and then during a long test). [1]
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
    label = np.asarray(cycle)
    n = x.size
    starts = np.concatenate([[0], np.flatnonzero(label[1:] != label[:-1]) + 1])
    ends = np.append(starts[1:], n)
    count = ends - starts
    bottom = np.minimum.reduceat(x, starts)
    stroke = np.maximum.reduceat(x, starts) - bottom
    lowest = _first_at(x, starts, bottom)
    gap = np.abs(x[ends - 1] - x[starts])
    complete = (
        (count >= MIN_SAMPLES)
        & (stroke >= 0.5 * np.median(stroke))
        & (stroke > 0.0)
        & (gap <= 1.5 * _largest_steps(x, starts) + tolerance * stroke)
    )
    start, count = starts[complete], count[complete]
    return Cycles(
        start=start,
        count=count,
        rotation=lowest[complete] - start,
        label=np.rint(label[start].astype(np.float64)).astype(np.int64),
        continuous=False,
        incomplete_cycles=int(np.count_nonzero(~complete)),
        dropped_samples=int(n - count.sum()),
    )


def find_cycles(displacement, cycle=None, hysteresis: float = 0.5) -> Cycles:
    """The complete cycles of a recording: numbered ones, or cut at the reversals.

    Parameters
    ----------
    displacement : numpy.ndarray
        Displacement at each sample, in time order, float64. [m]
    cycle : array_like, optional
        Cycle number of each sample (see :func:`labelled_cycles`); without it the
        recording is cut at its reversals (:func:`split_cycles`). [1]
    hysteresis : float
        Band of the reversal detector (see :func:`split_cycles`). [1]

    Returns
    -------
    cycles : Cycles

    Raises
    ------
    ValueError
        If ``cycle`` does not hold one finite number per sample, or the displacement does
        not oscillate.
    """
    if cycle is None:
        return split_cycles(displacement, hysteresis)
    label = np.asarray(cycle)
    if label.ndim != 1:
        raise ValueError("cycle must be one-dimensional (one value per sample)")
    if label.size != displacement.size:
        raise ValueError(
            f"cycle must have one value per sample: {label.size} values for "
            f"{displacement.size} samples"
        )
    if label.dtype.kind not in "iub":  # integers are finite; anything else is checked
        check("cycle", label, "finite")
    return labelled_cycles(displacement, label)
