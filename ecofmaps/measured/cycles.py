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
what it found per chunk (sums, the ends and extremes of runs; :mod:`ecofmaps.measured.passes`),
which are joined here in order: the cycles are the same, sample for sample, however the
recording is held.

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

from ecofmaps.measured import passes
from ecofmaps.measured.passes import (
    displacement_line,
    displacement_percentiles,
    ends_of_runs,
    first_of_runs,
    labelled_runs,
    missing_in,
    survey,
    trigger_runs,
)
from ecofmaps.measured.samples import Samples

__all__ = ["MIN_SAMPLES", "Cycles", "find_cycles", "labelled_cycles", "split_cycles"]

#: Fewest samples in one complete cycle: two branches, each with a stick and a slip part.
#: The one definition for the analysis, the fit and the synthetic recordings.
MIN_SAMPLES = 8


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
        The cycle number: the recorded one, or the drive's, 1, 2, ... from the first
        complete cycle, where a stretch with missing samples counts the drive's periods it
        spans (a gap leaves a hole in the numbering).
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


# --- the passes over the samples, a block at a time ----------------------------------------


# --- joining the passes ----------------------------------------------------------------------


def _with_missing(cycles: Cycles, gaps) -> Cycles:
    """``cycles`` with the cycles that hold a sample of ``gaps`` marked."""
    if not gaps.size:
        return cycles
    return dataclasses.replace(
        cycles,
        missing=missing_in(gaps, cycles.start, cycles.count),
        missing_samples=int((gaps[:, 1] - gaps[:, 0]).sum()),
        first_missing=int(gaps[0, 0]),
    )


def _drive_numbers(cycles: Cycles) -> Cycles:
    """``cycles`` (cut at the reversals) numbered as the drive made them: a stretch that
    holds missing samples over more than one period (a gap that swallowed reversals) counts
    the periods it spans, the median stretch of the cycles without missing samples, so the
    cycles after a gap keep their numbers and the gap leaves a hole in the numbering."""
    if cycles.missing is None or cycles.missing.all():
        return cycles
    period = float(np.median(cycles.count[~cycles.missing] - 1))
    spans = np.ones(cycles.count.size, dtype=np.int64)
    gapped = cycles.missing
    spans[gapped] = np.maximum(np.rint((cycles.count[gapped] - 1) / period), 1).astype(np.int64)
    label = 1 + np.concatenate([[0], np.cumsum(spans[:-1])]).astype(np.int64)
    return dataclasses.replace(cycles, label=label)


def _split(samples: Samples, hysteresis: float, tolerance: float) -> Cycles:
    """:func:`split_cycles` of any :class:`Samples`."""
    n = samples.size
    if n < 2:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    sums, gaps, sample_at, sampled, finite, _ = survey(samples)
    count = int(sums[:, 0].sum())
    line = displacement_line(sums, n)
    low, high = displacement_percentiles(samples, gaps, line, sample_at, sampled, count)
    half_range = 0.5 * (high - low)
    if not half_range > 0.0:
        raise ValueError("the displacement does not oscillate: no reversal can be found")
    centre = 0.5 * (high + low)
    stroke = 2.0 * half_range
    found = samples.map(
        trigger_runs,
        ("displacement",),
        (passes._CHUNK, gaps, line, (centre, hysteresis * half_range)),
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
        first_of_runs(run, highest, top, highest_of_run),
        first_of_runs(run, lowest, bottom, lowest_of_run),
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


def _labelled(samples: Samples, tolerance: float) -> Cycles:
    """:func:`labelled_cycles` of any :class:`Samples` with cycle numbers."""
    n = samples.size
    _, gaps, _, _, _, labels = survey(samples)
    known = [pair for pair in labels if pair is not None]
    if not known:
        raise ValueError("no cycle number is given: the cycle column is empty")
    carries, carry = {}, known[0][0]
    for (a, _), pair in zip(samples.blocks() if samples.lazy else [(0, n)], labels, strict=True):
        carries[a] = carry
        if pair is not None:
            carry = pair[1]
    pieces = np.concatenate(
        samples.map(
            labelled_runs, ("displacement", "cycle"), (passes._CHUNK, gaps, carries), extra=1
        ),
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
    lowest_at = first_of_runs(run, lowest, bottom, floor)
    valued = np.isfinite(x_first)
    begin = ends_of_runs(run, valued, x_first, starts.size, first=True)
    end = ends_of_runs(run, valued, x_last, starts.size, first=False)
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
    return _split(Samples(x, None, chunk=passes._CHUNK), hysteresis, tolerance)


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
    return _labelled(Samples(x, None, np.asarray(cycle), chunk=passes._CHUNK), tolerance)


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
    samples = Samples(displacement, force, cycle, missing, runner=runner, chunk=passes._CHUNK)
    if cycle is None:
        return _split(samples, hysteresis, 0.01)
    return _labelled(samples, 0.01)
