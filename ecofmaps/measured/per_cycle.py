r"""The per-cycle measurements of fretting loops, vectorised over blocks of cycles.

:func:`measure_cycles` measures every quantity of
:func:`~ecofmaps.measured.analysis.analyze_loops` (amplitude, slip amplitude, dissipated
energy, ECoF, energy ratio, rig stiffness, GICoF, ...) on cycles already found, a block of
centred loops at a time (:mod:`ecofmaps.measured.centring`, :mod:`ecofmaps.measured.branches`),
with no Python loop over samples or cycles, and says which checks of
:data:`ecofmaps.measured.quality.REASONS` each cycle failed. The methods are described in
:mod:`ecofmaps.measured.analysis`.
"""

from __future__ import annotations

import numpy as np

from ecofmaps._interrupts import check_interrupted
from ecofmaps.measured import kernels
from ecofmaps.measured.branches import (
    both,
    branch_rows,
    line_crossings,
    stick_lines,
    zero_force_crossings,
)
from ecofmaps.measured.centring import loop_blocks
from ecofmaps.measured.cycles import MIN_SAMPLES, Cycles
from ecofmaps.measured.quality import (
    ANTICLOCKWISE_SHARE,
    REASONS,
)

__all__ = ["GROSS_SLIP_THRESHOLD", "measure_cycles"]


#: Energy ratio :math:`A = E_d/(4\Delta^* Q^*)` above which a loop is gross slip (the
#: sliding transition of Fouvry, Kapsa and Vincent).
GROSS_SLIP_THRESHOLD = 0.2


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
    "gicof",
    "gicof_forward",
    "gicof_backward",
    "crossing_displacement_forward",
    "crossing_displacement_backward",
    "displacement_offset",
    "force_offset",
    "force_drift_se",
    "stick_residual",
)


#: A stick segment must explain all but this share of the displacement's variance along it.
_UNEXPLAINED = 0.2


def _loop_values(block, load, options):
    """Every per-cycle quantity of a block of centred loops, and the checks it failed.

    Returns the quantities (module notes; not yet NaN where a check fails) and the flags
    of :data:`ecofmaps.measured.quality.REASONS` (reason -> per cycle).
    """
    # The extremes, the loop's area by trapezoids (the segment that closes it included)
    # and its top, where the rising branch ends.
    highest, lowest, max_force, energy, top = kernels.loop_measures(
        block.displacement, block.force, block.offset, block.count, block.rotation
    )
    span = highest - lowest
    amplitude = 0.5 * span
    bx, by, length = branch_rows(block, top)
    compliance, intercept, across, fit = stick_lines(bx, by, length, span, options["stick_window"])
    crossing, zero_on_loop = zero_force_crossings(
        bx, by, length, max_force, across, intercept, span
    )
    cycles = block.count.size
    slip = 0.5 * (crossing[cycles:] - crossing[:cycles])
    half_width = options["crossing_window"] * np.abs(slip)
    at, force, on_loop = line_crossings(
        bx, by, length, both(compliance), both(half_width), load, both(max_force)
    )
    energy_ratio = energy / (4.0 * amplitude * max_force)
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
        "stick_residual": fit["residual"],
    }
    rounding = 1e-9
    anticlockwise = energy_ratio < -ANTICLOCKWISE_SHARE
    flags = {
        "few-samples": block.count < MIN_SAMPLES,
        "constant-force": ~(block.force_swing > 0.0),
        # A cycle cut at the reversals cannot turn back by more than the band: that
        # would have been a reversal.
        "several-loops": np.zeros(cycles, dtype=bool)
        if block.continuous
        else _turns_back(bx, options["hysteresis"] * span),
        "anticlockwise": anticlockwise,
        "energy-ratio-above-1": energy_ratio > 1.0 + rounding,
        "negative-stiffness": compliance < 0.0,
        "no-stick": (~(fit["unexplained"] <= _UNEXPLAINED) & ~np.isinf(values["stiffness"]))
        | np.isnan(compliance),  # a rigid rig's vertical stick sides explain all but 0/0
        "negative-area": (energy_ratio < 0.0) & ~anticlockwise,
        "negative-slip": ~(slip > 0.0),
        "no-zero-crossing": ~(zero_on_loop[:cycles] & zero_on_loop[cycles:]),
        "curved-stick": fit["curved"],
        "no-crossing": ~(on_loop[:cycles] & on_loop[cycles:]),
        "not-gross-slip": ~(energy_ratio > options["gross_slip_threshold"]),
    }
    return values, flags


def _turns_back(x, band):
    """True for the cycles whose displacement turns back within a branch by more than
    ``band``: the rising branches (the first half of the rows) fall below their running
    maximum, or the falling ones rise above their running minimum (the rows' padding
    repeats their last point, which changes neither)."""
    cycles = band.size
    rising, falling = x[:cycles], x[cycles:]
    drop = np.max(np.maximum.accumulate(rising, axis=1) - rising, axis=1)
    rise = np.max(falling - np.minimum.accumulate(falling, axis=1), axis=1)
    return np.maximum(drop, rise) > band


def measure_cycles(
    cycles: Cycles,
    displacement,
    force,
    load,
    *,
    hysteresis=0.5,
    stick_window=(0.05, 0.45),
    crossing_window=0.7,
    gross_slip_threshold=GROSS_SLIP_THRESHOLD,
    flip_force=False,
    rows=None,
    keep_loops=False,
    recorded_load=None,
):
    """The per-cycle quantities of :func:`analyze_loops` for cycles already found.

    Parameters
    ----------
    cycles : Cycles
        Cycles of the recording (:func:`ecofmaps.measured.cycles.find_cycles`).
    displacement, force : numpy.ndarray
        The recording, float64; NaN only in the cycles marked missing. Any object that
        gives stretches of it by sample index (``displacement[a:b]``) will do. [m], [N]
    load : float
        Normal load :math:`P`. [N]
    hysteresis, stick_window, crossing_window, gross_slip_threshold, flip_force
        As for :func:`analyze_loops` (not checked here).
    rows : slice, optional
        Consecutive cycles to measure; default all.
    keep_loops : bool
        Also return the centred loops as NaN-padded (cycle, point) arrays.
    recorded_load : numpy.ndarray, optional
        The normal load at each sample, when it was recorded (indexed as ``force``): its
        mean over each cycle is ``normal_load``. [N]

    Returns
    -------
    values : dict of str to numpy.ndarray
        Each quantity of :func:`analyze_loops` over the cycles, offsets and stick residual
        included, as measured: not yet NaN where a check fails; and ``normal_load`` with a
        ``recorded_load``.
    flags : dict of str to numpy.ndarray of bool
        The checks of :data:`ecofmaps.measured.quality.REASONS` each cycle failed.
    loops : tuple of numpy.ndarray or None
        Centred displacement and force round each loop, if ``keep_loops``. [m], [N]
    """
    first, stop, _ = (rows or slice(None)).indices(cycles.label.size)
    options = {
        "hysteresis": hysteresis,
        "stick_window": stick_window,
        "crossing_window": crossing_window,
        "gross_slip_threshold": gross_slip_threshold,
    }
    values = {name: np.full(stop - first, np.nan) for name in _PER_CYCLE}
    flags = {reason: np.zeros(stop - first, dtype=bool) for reason in REASONS}
    if cycles.missing is not None:  # not measured: their values stay NaN
        flags["missing-samples"] = cycles.missing[first:stop].copy()
    loops = None
    if keep_loops:
        width = int(cycles.count[first:stop].max()) + 1
        loops = tuple(np.full((stop - first, width), np.nan) for _ in range(2))
    sign = -1.0 if flip_force else 1.0
    blocks = loop_blocks(cycles, displacement, force, slice(first, stop), sign)
    with np.errstate(divide="ignore", invalid="ignore"):  # degenerate cycles give NaN
        for block in blocks:
            check_interrupted()
            out = slice(block.rows.start - first, block.rows.stop - first)
            computed, failed = _loop_values(block, load, options)
            for name, value in computed.items():
                values[name][out] = value
            for reason, flag in failed.items():
                flags[reason][out] = flag
            if keep_loops:
                for loop, centred in zip(loops, block.loops(loops[0].shape[1]), strict=True):
                    loop[out] = centred
    if recorded_load is not None:
        values["normal_load"] = _cycle_means(recorded_load, cycles, first, stop)
    return values, flags, loops


def _cycle_means(series, cycles: Cycles, first: int, stop: int) -> np.ndarray:
    """The mean of the finite values of ``series`` over the samples of each of the cycles
    ``first`` to ``stop - 1`` (each a stretch of consecutive samples; NaN if none)."""
    start, count = cycles.start[first:stop], cycles.count[first:stop]
    if start.size == 0:
        return np.empty(0)
    low = int(start.min())
    values = np.asarray(series[low : int((start + count).max())], dtype=np.float64)
    finite = np.isfinite(values)
    sums, counts = (
        np.concatenate([[0.0], np.cumsum(a)]) for a in (np.where(finite, values, 0.0), finite)
    )
    ends, begins = start + count - low, start - low
    with np.errstate(invalid="ignore"):  # a cycle without a finite value: NaN
        return (sums[ends] - sums[begins]) / (counts[ends] - counts[begins])
