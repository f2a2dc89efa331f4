r"""The steps of :func:`ecofmaps.analyze_loops` that run along each branch of each loop.

A branch runs from one reversal to the next: the rising branch from a loop's lowest
displacement to its highest, the falling branch back. Each is laid out as a row (branch,
point) starting at its reversal and padded by repeating its last point: the rising
branches of a block's cycles, then their falling branches. The steps along the rows run in
the compiled kernels of :mod:`ecofmaps.measured.kernels`, a row at a time, so that a row's
numbers do not depend on the block it was laid out in. The methods are described in
:mod:`ecofmaps.measured.analysis`.
"""

from __future__ import annotations

import numpy as np

from ecofmaps.measured import kernels

__all__ = ["both", "branch_rows", "line_crossings", "stick_lines", "zero_force_crossings"]

#: Samples with :math:`|Q|` below this share of :math:`Q^*` locate a zero-force crossing
#: that is not on a stick segment.
_ZERO_FORCE_BAND = 0.25


def both(values):
    """A per-cycle array for the rising then the falling branch rows."""
    return np.concatenate([values, values])


def branch_rows(block, top):
    """The rising branches (start to top) and falling ones (top to the end) as rows.

    Returns the displacement and force rows and the number of each row's own points
    (the rest of a row repeats its last point).
    """
    cycles = top.size
    first = np.concatenate([np.zeros_like(top), top])
    last = np.concatenate([top, block.count])
    length = last - first + 1
    width = int(length.max())
    if not block.continuous:  # a loop may begin inside its stretch and wrap round it
        point = np.minimum(first[:, None] + np.arange(width), last[:, None])
        index = block.samples(point, np.tile(np.arange(cycles), 2))
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


def stick_lines(x, y, length, span, window):
    r"""Lines :math:`\Delta = c + Q/S` through the stick segments after the two reversals.

    A segment starts as the branch's samples whose force has moved away from the
    reversal's by a share of the branch's force swing within ``window``, up to the first
    sample beyond it (with fewer than two, the chord from the reversal to the first sample
    past the lower share). A first line is fitted, with one compliance :math:`1/S` for both
    branches of a cycle and an intercept for each; each segment then grows along its
    branch until two samples in a row lie more than three standard deviations (of the
    first line's residuals, at least :math:`10^{-9}` of the displacement's ``span``) off its
    line (the slip that follows bends away from it; a single noisy sample does not stop
    it), and the lines are fitted again to the grown segments.

    A segment is curved where a term :math:`bQ^2` added to its line is significant (more
    than 8 standard errors) and changes its slope :math:`d\Delta/dQ` from one end of the
    segment to the other by more than 5 % of the compliance.

    Parameters
    ----------
    x, y : numpy.ndarray, shape (rows, width)
        Displacement and force of the branch rows (:func:`branch_rows`). [m], [N]
    length : numpy.ndarray of int64, shape (rows,)
        Points of each row.
    span : numpy.ndarray, shape (cycles,)
        Peak-to-peak displacement of each cycle. [m]
    window : tuple of float
        Shares of the branch's force swing between which a segment starts. [-]

    Returns
    -------
    compliance : numpy.ndarray, shape (cycles,)
        The common compliance :math:`1/S` of each cycle. [m/N]
    intercept : numpy.ndarray, shape (rows,)
        The intercept :math:`c` of each branch row. [m]
    across : numpy.ndarray of bool, shape (rows,)
        The grown segment holds forces of both signs (it reaches across zero force).
    fit : dict of str to numpy.ndarray
        Per cycle: ``residual``, the root mean square displacement off the lines [m];
        ``unexplained``, the share of the displacement's variance along the segments that
        they leave [-]; ``curved``, True where a segment bends.
    """
    low, high = (float(share) for share in window)
    compliance, intercept, across, residual, unexplained, curved = kernels.stick_lines(
        x, y, length, span, low, high
    )
    fit = {"residual": residual, "unexplained": unexplained, "curved": curved}
    return compliance, intercept, across, fit


def zero_force_crossings(x, y, length, max_force, across, intercept, span):
    r"""Displacement where each branch row crosses :math:`Q = 0`, and whether on the loop.

    Where the stick segment reaches across zero force (``across``), it is the intercept of
    the line fitted to it, :math:`\Delta = c + Q/S`. Elsewhere a straight line
    :math:`\Delta = a + bQ` is fitted to the two samples around the crossing and the
    branch's samples with :math:`|Q|` below ``_ZERO_FORCE_BAND`` times the loop's
    ``max_force`` :math:`Q^*`, and gives :math:`a`. The crossing is on the loop if the
    branch has samples of both signs of force and it lies within the displacements of
    those samples (to rounding of the displacement ``span``). Else it is taken between
    the two samples around the crossing, if they have forces of both signs: where the
    stick line crosses zero force between them, or on the chord joining them.

    Parameters
    ----------
    x, y : numpy.ndarray, shape (rows, width)
        Displacement and force of the branch rows (:func:`branch_rows`). [m], [N]
    length : numpy.ndarray of int64, shape (rows,)
        Points of each row.
    max_force, span : numpy.ndarray, shape (cycles,)
        Half the peak-to-peak force, and the peak-to-peak displacement, of each
        cycle. [N], [m]
    across, intercept : numpy.ndarray, shape (rows,)
        From :func:`stick_lines`. [-], [m]

    Returns
    -------
    crossing : numpy.ndarray, shape (rows,)
        Displacement at :math:`Q = 0`. [m]
    on_loop : numpy.ndarray of bool, shape (rows,)
        The crossing lies on the loop.
    """
    band = both(_ZERO_FORCE_BAND * max_force)
    return kernels.zero_force_crossings(x, y, length, band, intercept, across, both(1e-9 * span))


def line_crossings(x, y, length, compliance, half_width, load, scale):
    r"""Where each branch row crosses :math:`Q = S\Delta`: displacement, force, on the loop.

    On the line the contact position :math:`\xi = \Delta - Q/S` (eq. 10) is zero. The
    branch's samples with :math:`|\xi|` up to ``half_width`` are fitted by least squares
    with :math:`Q = a + b\xi + c\xi Q`, which is eq. 9 for any groove slope
    (:math:`a = \mu P`, :math:`b = kP`, :math:`c = \mu k`) and a smooth three-parameter
    curve otherwise; the crossing is :math:`Q = a`. The regressors are centred and
    :math:`\xi Q` is orthogonalised against :math:`\xi` (Gram-Schmidt), so that :math:`a`
    stays exact when the two are nearly collinear; where :math:`\xi Q` adds only rounding
    to :math:`\xi` (a flat groove), :math:`Q = a + b\xi` is fitted. With fewer than five
    samples in the window, :math:`Q` is interpolated linearly at :math:`\xi = 0` between
    the two samples around the crossing.

    The crossing is on the loop if measured samples of the branch lie on both sides of
    :math:`\xi = 0` (in the window, or the two interpolated between), and its force lies
    within theirs (to rounding of ``scale``, the loop's :math:`Q^*`).

    Parameters
    ----------
    x, y : numpy.ndarray, shape (rows, width)
        Displacement and force of the branch rows (:func:`branch_rows`). [m], [N]
    length : numpy.ndarray of int64, shape (rows,)
        Points of each row.
    compliance, half_width, scale : numpy.ndarray, shape (rows,)
        :math:`1/S` of each row's cycle, the window's half-width and :math:`Q^*`.
        [m/N], [m], [N]
    load : float
        Normal load :math:`P`. [N]

    Returns
    -------
    displacement, force : numpy.ndarray, shape (rows,)
        Where each row crosses the line. [m], [N]
    on_loop : numpy.ndarray of bool, shape (rows,)
        The crossing lies on the loop.
    """
    force, on_loop = kernels.line_crossings(
        x, y, length, compliance, half_width, float(load), 1e-9 * scale
    )
    return force * compliance, force, on_loop
