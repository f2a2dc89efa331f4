r"""A recording of fretting loops cut into cycles, each laid out as one row of a padded array.

A recording is a long series of samples :math:`(\Delta_i, Q_i)`. :func:`split_cycles` cuts
it at the displacement reversals; :func:`labelled_cycles` uses a cycle number recorded with
each sample instead. Both return :class:`Cycles`: for every complete cycle, the indices of
its samples as one row of a padded 2-D array, running once round the loop from its lowest
displacement back to it (the last point closes the loop). Everything is vectorised: no
Python loop over samples or over cycles.

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

Offsets and drift
-----------------
:meth:`Cycles.centred_loops` moves every loop to its centre: the mean of :math:`\Delta`
and of :math:`Q` along the loop weighted by the displacement travelled,
:math:`\oint \Delta\,|d\Delta| / \oint |d\Delta|` (trapezoids). For a loop symmetric
about a point (the model's steady loop, with or without ploughing peaks at both ends of
the stroke) that point is the centre, and the mean averages the noise of every sample.
For cycles cut from one continuous recording, the centres are interpolated linearly along
the sample index from the middle of one cycle to the next and subtracted sample by
sample, which also removes a slow drift of :math:`\Delta` (or of :math:`Q`) within each
cycle; labelled cycles (possibly recorded far apart) are each moved by their own centre.
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["MIN_SAMPLES", "Cycles", "labelled_cycles", "masked_sum", "split_cycles"]

#: Fewest samples in one complete cycle: two branches, each with a stick and a slip part.
MIN_SAMPLES = 8


@dataclasses.dataclass(frozen=True, eq=False)
class Cycles:
    """Complete cycles of a recording as rows of a padded index array.

    Attributes
    ----------
    samples : numpy.ndarray of int, shape (cycles, width)
        Row ``k`` lists the sample indices of cycle ``k`` in order round the loop, starting
        at its lowest displacement and ending with the point that closes the loop; padded
        by repeating the closing index.
    valid : numpy.ndarray of bool, shape (cycles, width)
        True on the points of each loop, False on the padding.
    label : numpy.ndarray of int64, shape (cycles,)
        The cycle number: the recorded one, or 1, 2, ... in order of the complete cycles.
    continuous : bool
        True when the cycles follow each other without a gap (cut at reversals), so a slow
        drift can be interpolated from one cycle to the next.
    incomplete_cycles : int
        Incomplete cycles dropped (at the ends of the recording, or labelled cycles that do
        not close).
    dropped_samples : int
        Samples that belong to no complete cycle.
    """

    samples: np.ndarray
    valid: np.ndarray
    label: np.ndarray
    continuous: bool
    incomplete_cycles: int
    dropped_samples: int

    def centred_loops(self, displacement, force):
        """The loops as padded rows, each moved to its centre (module notes).

        Parameters
        ----------
        displacement, force : numpy.ndarray
            The recording the cycles were found in. [m], [N]

        Returns
        -------
        x, q : numpy.ndarray, shape (cycles, width)
            Centred displacement and force round each loop, NaN on the padding. [m], [N]
        centre_x, centre_q : numpy.ndarray, shape (cycles,)
            The centres removed. [m], [N]
        """
        x = np.where(self.valid, displacement[self.samples], np.nan)
        q = np.where(self.valid, force[self.samples], np.nan)
        points = np.count_nonzero(self.valid, axis=1)
        middle = masked_sum(self.samples.astype(np.float64), self.valid) / points
        at = self.samples.astype(np.float64)
        segments = self.valid[:, 1:].copy()
        if self.continuous:  # the segment closing the loop is no part of the path
            segments[np.arange(points.size), points - 2] = False

        def centred(values, path):
            """``values`` less their mean weighted by the displacement travelled on ``path``."""
            weight = np.where(segments, np.abs(np.diff(path, axis=1)), 0.0)
            middles = 0.5 * (values[:, 1:] + values[:, :-1])
            centre = masked_sum(weight * middles, segments) / weight.sum(axis=1)
            if self.continuous:
                return values - _interpolate(at, middle, centre), centre
            return values - centre[:, None], centre

        x, centre_x = centred(x, x)
        # The force's weights come from the displacement without its drift, so that a drift
        # does not weigh one branch more than the other.
        q, centre_q = centred(q, x)
        return x, q, centre_x, centre_q


def _interpolate(at, points, values):
    """Piecewise-linear interpolation, extended linearly beyond the first and last points."""
    inside = np.interp(at, points, values)
    if points.size < 2:
        return inside
    first = values[0] + (at - points[0]) * (values[1] - values[0]) / (points[1] - points[0])
    last = values[-1] + (at - points[-1]) * (values[-1] - values[-2]) / (points[-1] - points[-2])
    return np.where(at < points[0], first, np.where(at > points[-1], last, inside))


def masked_sum(values, mask):
    """Sum of ``values`` over each row where ``mask`` is True (NaN elsewhere is ignored)."""
    return np.sum(np.where(mask, values, 0.0), axis=1)


def _run_index(starts: np.ndarray, size: int) -> np.ndarray:
    """For each of ``size`` samples, the number of the run (beginning at ``starts``) it is in."""
    first = np.zeros(size, dtype=np.int64)
    first[starts] = 1
    return np.cumsum(first) - 1


def _first_of_runs(values: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Index of the first maximum of ``values`` within each run beginning at ``starts``."""
    run = _run_index(starts, values.size)
    best = np.maximum.reduceat(values, starts)
    hits = np.flatnonzero(values == best[run])
    _, first = np.unique(run[hits], return_index=True)
    return hits[first]


def _padded(start: np.ndarray, count: np.ndarray, rotation: np.ndarray, closing: np.ndarray):
    """Index rows ``start + (rotation + j) mod count`` for ``j < count``, then ``closing``."""
    width = int(count.max()) + 1
    j = np.arange(width)[None, :]
    count = count[:, None]
    inside = (rotation[:, None] + j) % count + start[:, None]
    samples = np.where(j < count, inside, closing[:, None])
    return samples, j <= count


def _runs(detrended: np.ndarray, hysteresis: float):
    """Schmitt-trigger runs of ``detrended``: their starts, kind (+1/-1), and the stroke."""
    low, high = np.percentile(detrended, [1.0, 99.0])
    half_range = 0.5 * (high - low)
    if not half_range > 0.0:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    centre = 0.5 * (high + low)
    level = hysteresis * half_range
    state = np.where(detrended > centre + level, 1, np.where(detrended < centre - level, -1, 0))
    # The 99th percentile lies above the band, so some state is decided. Forward-fill the
    # last decided state; samples before the first decision take that first one.
    decided = np.flatnonzero(state)
    last = np.maximum.accumulate(np.where(state != 0, np.arange(state.size), decided[0]))
    state = state[last]
    starts = np.concatenate([[0], np.flatnonzero(np.diff(state)) + 1])
    kind = state[starts]
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
    t = np.arange(n, dtype=np.float64) - 0.5 * (n - 1)
    detrended = x - x.mean() - t * (np.dot(t, x) / np.dot(t, t))
    starts, kind, stroke = _runs(detrended, hysteresis)
    extreme = _first_of_runs(x * kind[_run_index(starts, n)], starts)
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
    start, stop = bottoms[:-1], bottoms[1:]
    # Each loop runs from its bottom reversal to the next and back to its first sample, so
    # it is closed even if the displacement drifted in between.
    count = stop - start + 1
    samples, valid = _padded(start, count, np.zeros_like(count), start)
    leading, trailing = int(bottoms[0]), int(n - 1 - bottoms[-1])
    return Cycles(
        samples=samples,
        valid=valid,
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
    starts = np.concatenate([[0], np.flatnonzero(np.diff(label)) + 1])
    count = np.diff(np.append(starts, n))
    top = np.maximum.reduceat(x, starts)
    bottom = np.minimum.reduceat(x, starts)
    stroke = top - bottom
    lowest = _first_of_runs(-x, starts)
    step = np.abs(np.diff(x, append=x[-1]))
    step[np.append(starts[1:], n) - 1] = 0.0  # no step across a cycle boundary
    largest_step = np.maximum.reduceat(step, starts)
    gap = np.abs(x[np.append(starts[1:], n) - 1] - x[starts])
    complete = (
        (count >= MIN_SAMPLES)
        & (stroke >= 0.5 * np.median(stroke))
        & (stroke > 0.0)
        & (gap <= 1.5 * largest_step + tolerance * stroke)
    )
    if not complete.any():
        return _no_cycles(n, incomplete=starts.size)
    start, count, lowest = starts[complete], count[complete], lowest[complete]
    samples, valid = _padded(start, count, lowest - start, lowest)
    return Cycles(
        samples=samples,
        valid=valid,
        label=np.rint(label[start].astype(np.float64)).astype(np.int64),
        continuous=False,
        incomplete_cycles=int(np.count_nonzero(~complete)),
        dropped_samples=int(n - count.sum()),
    )


def _no_cycles(samples: int, incomplete: int) -> Cycles:
    return Cycles(
        samples=np.zeros((0, 1), dtype=np.int64),
        valid=np.zeros((0, 1), dtype=bool),
        label=np.zeros(0, dtype=np.int64),
        continuous=True,
        incomplete_cycles=incomplete,
        dropped_samples=samples,
    )
