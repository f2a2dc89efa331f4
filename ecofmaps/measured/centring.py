r"""Measured loops moved to their centres and laid out a block of cycles at a time.

:func:`loop_blocks` hands :func:`ecofmaps.analyze_loops` the cycles of a recording
(:class:`ecofmaps.measured.cycles.Cycles`) a block at a time, about ``_BLOCK`` samples, so
that its memory does not grow with the recording: each block is the centred samples of its
cycles, once, in time order, with where each cycle lies among them (:class:`LoopBlock`).
Sums over each cycle's samples run in the compiled kernels of
:mod:`ecofmaps.measured.kernels`, in the order of the samples.

Offsets and drift
-----------------
Every loop is moved to its centre: the mean of :math:`\Delta` and of :math:`Q` along the
loop weighted by the displacement travelled, :math:`\oint \Delta\,|d\Delta| / \oint
|d\Delta|` (trapezoids). For a loop symmetric about a point (the model's steady loop, with
or without ploughing peaks at both ends of the stroke) that point is the centre, and the
mean averages the noise of every sample. For cycles cut from one continuous recording, the
centres are interpolated linearly along the sample index from the middle of one cycle to
the next and subtracted sample by sample, which also removes a slow drift of
:math:`\Delta` (or of :math:`Q`) within each cycle; the weights of the force's centre come
from the displacement so centred. Labelled cycles (possibly recorded far apart) are each
moved by their own centre.

The drift correction is only as good as the centres: noise on the displacement (through
the weights) and on the force moves each centre, and a centre's error tilts the drift
subtracted from its neighbours, which offsets a loop's falling branch against its rising
one by :math:`\varepsilon = \sum_j a_j c_j` for the centres :math:`c_j` around it. For
equally spaced cycles :math:`\varepsilon = (c_{i+1} - c_{i-1})/4` (the mean of the linear
drift over each half of the cycle), and :math:`(c_{i+1} - c_i)/2` at the ends of the
recording, where the drift is extrapolated. ``force_drift_se`` is the standard error of
that offset, :math:`\sigma_c (\sum_j a_j^2)^{1/2}`, with the noise :math:`\sigma_c` of the
centres from their second differences over :data:`_NOISE_REACH` cycles on either side,
:math:`\operatorname{median}|c_{j-1} - 2c_j + c_{j+1}| / (0.6745\sqrt6)`, which a slow
drift hardly enters (a real drift that bends from cycle to cycle counts as noise: the
correction cannot follow it either). On a Coulomb slider recorded with 0.1 µm of
displacement noise on a 50 µm amplitude the centres scatter by about 1.7 N, and the
offset is the largest error of :func:`ecofmaps.resolve_loops`'s ``mu_resolved``; its
standard error counts it (:mod:`ecofmaps.measured.resolved`). Labelled cycles, each moved
by its own centre, have no such offset (zero).

Cycles that hold a missing sample (:attr:`ecofmaps.measured.cycles.Cycles.missing`) are not
laid out, and the drift is interpolated between the centres of the whole cycles on either
side of them. A block's samples are read as ``displacement[a:b]`` (and, for labelled
cycles, ``displacement[indices]``) with indices into the whole recording, so the arrays may
be any object that gives a stretch of it by those indices.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Iterator

import numpy as np

from ecofmaps.measured import kernels
from ecofmaps.measured.cycles import Cycles

__all__ = ["NEIGHBOURS", "LoopBlock", "loop_blocks"]

#: Samples of the cycles laid out at once by :func:`loop_blocks`.
_BLOCK = 1 << 17

#: Whole cycles on either side of a cycle whose force centres give their noise (module
#: notes); its second differences reach one cycle less.
_NOISE_REACH = 4

#: Whole cycles on either side of a cycle whose samples its centring reads: the force
#: centres of :data:`_NOISE_REACH` cycles, each centred by the displacement centres of its
#: own neighbours.
NEIGHBOURS = _NOISE_REACH + 1

#: The median absolute deviation of a normal distribution over its standard deviation,
#: times the standard deviation of a second difference of white noise over its own.
_SECOND_DIFFERENCE = 0.6744897501960817 * np.sqrt(6.0)


@dataclasses.dataclass(frozen=True, eq=False)
class LoopBlock:
    """The centred loops of a block of consecutive cycles, from :func:`loop_blocks`.

    Attributes
    ----------
    rows : slice
        The cycles of the block (rows of the :class:`Cycles`).
    displacement, force : numpy.ndarray, shape (samples,)
        Centred displacement and force of every sample of the block's cycles, once, in
        time order: each cycle is a stretch of them (cycles cut at the reversals share the
        sample between them). [m], [N]
    offset, count, rotation : numpy.ndarray of int64, shape (cycles,)
        Where each cycle's stretch begins in ``displacement``, its samples, and where its
        loop begins in it (as for :class:`Cycles`).
    continuous : bool
        As for :class:`Cycles`: the segment that closes each loop is not travelled.
    displacement_centre, force_centre : numpy.ndarray, shape (cycles,)
        The centres removed. [m], [N]
    force_drift_se : numpy.ndarray, shape (cycles,)
        Standard error of the offset between each loop's two branches that the drift
        correction leaves (module notes); zero for labelled cycles. [N]
    force_swing : numpy.ndarray, shape (cycles,)
        Range of the force as recorded over each cycle, before centring (a dead channel
        holds still; centred, its drift correction would make it a ramp). [N]
    """

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
        """Index into ``displacement`` and ``force`` of points round the loops ``rows``.

        ``point`` (one row per loop) counts from the loop's lowest displacement, 0 to
        ``count``; ``count`` is the point that closes the loop.
        """
        offset, count = self.offset[rows][:, None], self.count[rows][:, None]
        if self.continuous:  # no rotation: the stretch, then its first sample again
            return offset + np.where(point < count, point, 0)
        position = self.rotation[rows][:, None] + point
        return offset + position - count * (position >= count)

    def loops(self, width: int):
        """The loops as padded rows (cycle, point) of ``width`` points, NaN past each end."""
        point = np.minimum(np.arange(width), self.count[:, None])
        index = self.samples(point)
        inside = np.arange(width) <= self.count[:, None]
        return tuple(
            np.where(inside, values[index], np.nan) for values in (self.displacement, self.force)
        )


def loop_blocks(
    cycles: Cycles, displacement, force, rows=None, force_sign=1.0
) -> Iterator[LoopBlock]:
    """The loops of ``cycles``, each moved to its centre (module notes), block by block.

    Parameters
    ----------
    cycles : Cycles
        The cycles of the recording.
    displacement, force : numpy.ndarray
        The recording the cycles were found in, float64. [m], [N]
    rows : slice, optional
        Consecutive cycles to lay out (default all). The centring of cycles cut at the
        reversals still uses their neighbours.
    force_sign : float
        +1, or -1 to read the force with the other sign (without copying the recording).

    Yields
    ------
    block : LoopBlock
        Consecutive cycles, about ``_BLOCK`` samples in all, in order.
    """
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
    size = kept.size
    middle, centre_x = _displacement_centres(start, count, displacement, begin, end)
    centre_q = np.empty(size)
    ready = max(begin - _NOISE_REACH, 0)  # the force's centres are known below this cycle
    for block in _whole_blocks(cycles, kept, begin, end):
        # The centred values depend on the sample index alone. The force's drift within
        # the block needs the centres of the cycles on both sides of it, their noise
        # those of _NOISE_REACH cycles.
        needed = min(block.stop + _NOISE_REACH, size)
        lower, upper = min(ready, block.start), max(needed, block.stop)
        low, high = int(start[lower]), int(start[upper - 1] + count[upper - 1])
        x = displacement[low:high] - _drift(
            low, high, middle, centre_x, slice(max(lower - 1, 0), upper + 1)
        )
        if ready < needed:
            cut = slice(ready, needed)
            centre_q[cut] = _path_means(
                x, _signed(force[low:high], force_sign), start[cut] - low, count[cut], closed=False
            )
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
    """Standard error of the offset between the branches of the loops ``rows`` that the
    force's drift correction leaves (module notes), from the ``centre`` of every whole
    cycle at its ``middle`` sample; the centres of :data:`_NOISE_REACH` cycles on either
    side of ``rows`` are needed. [N]"""
    size = centre.size
    first, stop = rows.start, rows.stop
    noise = kernels.second_difference_medians(centre, first, stop, _NOISE_REACH)
    noise /= _SECOND_DIFFERENCE
    if size == 2:  # no second difference: the one first difference, noise and drift
        noise = np.full(stop - first, abs(centre[1] - centre[0]) / np.sqrt(2.0))
    # The weights a_j of the centres in the offset, in the cycle's own period: a quarter
    # of the slope to each neighbour, or half the one line over the whole cycle at an end.
    i = np.arange(first, stop)
    period = count[i].astype(np.float64)
    has_left, has_right = i > 0, i < size - 1
    left = (middle[i] - middle[np.maximum(i - 1, 0)]) / period
    right = (middle[np.minimum(i + 1, size - 1)] - middle[i]) / period
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


def _signed(values, sign):
    """``values``, or ``-values`` if ``sign`` is negative."""
    return values if sign > 0 else -values


def _labelled_block(cycles: Cycles, displacement, force, block, sign) -> LoopBlock:
    """The loops of consecutive labelled cycles (rows ``block``), each moved by its own
    centre."""
    start, count = cycles.start[block], cycles.count[block]
    offset = np.concatenate([[0], np.cumsum(count[:-1])])
    index = np.repeat(start - offset, count) + np.arange(int(count.sum()))
    x, q = displacement[index], _signed(force[index], sign)
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
    """Slices of consecutive rows of about ``_BLOCK`` points in all, such that padding
    each row to the longest does not more than double that (a long loop among short ones
    gets a block of its own)."""
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
    """Mean of ``values`` round each loop weighted by the distance along ``path``.

    The loops are stretches (``offset``, ``count``) of the flat arrays; ``closed`` adds
    the segment from each stretch's last sample back to its first.
    """
    path, values = (np.ascontiguousarray(a, dtype=np.float64) for a in (path, values))
    return kernels.path_means(path, values, offset, count, closed)


def _displacement_centres(start, count, displacement, first: int, stop: int):
    """Middle sample of every cycle cut at the reversals (stretches ``start``, ``count``),
    and the displacement centres of the cycles from :data:`NEIGHBOURS` before ``first`` to
    :data:`_NOISE_REACH` after ``stop - 1`` (NaN for the others), a block at a time.

    A cycle's path runs over its stretch only: the segment that closes the loop, from the
    next reversal back to the first sample, is not travelled.
    """
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


def _drift(low: int, high: int, points, values, near: slice):
    """``values`` interpolated over ``points`` at the samples ``low`` to ``high - 1``.

    Piecewise linear, extended linearly beyond the first and last points;
    ``points[near]`` bracket every sample that lies between two points. Inside, it is
    ``np.interp`` on the segments between points, to the bit (one pass).
    """
    xp, fp = points[near], values[near]
    # Sample i lies on segment j when xp[j] <= i < xp[j + 1].
    edges = np.clip(np.ceil(xp).astype(np.int64), low, high) - low
    result = np.empty(high - low)
    result[: edges[0]] = fp[0]
    result[edges[-1] :] = fp[-1]
    if xp.size > 1:  # every sample here lies on a segment between points
        result[edges[0] : edges[-1]] = kernels.interpolated(
            low + int(edges[0]), int(edges[-1] - edges[0]), xp, fp
        )
    if points.size < 2:
        return result
    if near.start == 0 and edges[0] > 0:
        at = np.arange(low, low + edges[0], dtype=np.float64)
        result[: edges[0]] = values[0] + (at - points[0]) * (values[1] - values[0]) / (
            points[1] - points[0]
        )
    if near.stop >= points.size:
        at = np.arange(low + edges[-1], high, dtype=np.float64)
        beyond = at > points[-1]
        result[edges[-1] :][beyond] = values[-1] + (at[beyond] - points[-1]) * (
            values[-1] - values[-2]
        ) / (points[-1] - points[-2])
    return result
