r"""Measured fretting loops, cycle by cycle: ECoF, GICoF, rig stiffness and the rest.

:func:`analyze_loops` reads a recording of the actuator displacement :math:`\Delta` and the
tangential force :math:`Q` (many cycles, or a single loop), cuts it into cycles and
removes the offsets and a slow drift (:mod:`ecofmaps.measured.cycles`), and measures each loop.
The work is vectorised over a block of cycles at a time (:mod:`ecofmaps.measured.centring`),
with no Python loop over samples or cycles, and its memory does not grow with the recording
beyond the per-cycle results: each branch of each loop (from one reversal to the next) is a
padded row, so that every per-branch step runs once over both branches of every cycle
(:mod:`ecofmaps.measured.branches`).

The quantities, per cycle
-------------------------
Each loop runs from its lowest displacement up the *rising* branch to its highest and
back down the *falling* branch.

* amplitude :math:`\Delta^*` and max_force :math:`Q^*`: half the peak-to-peak ranges.
* stiffness :math:`S`: the slope of the stick segments that follow the two reversals. One
  compliance :math:`1/S` common to both segments, each with its own intercept, is fitted
  by least squares of :math:`\Delta` on :math:`Q`, :math:`\Delta = c + Q/S` (eq. 10 with
  the contact position :math:`c` fixed): the displacement's noise is larger, relative to
  the segment's span, than the force's, and a rigid rig gives :math:`S = \infty`. A segment
  starts as the branch's samples whose force has moved away from the reversal's by a share
  between ``stick_window[0]`` and ``stick_window[1]`` (default 5 % and 45 %) of the
  branch's force swing, up to the first sample beyond the upper share: in the model the
  contact sticks after a reversal at least until the force crosses zero whenever the
  groove slope at the reversal is below :math:`\mu`, and skipping the first 5 % skips the
  noisy turn of the reversal. Each segment then grows along its branch until two samples
  in a row lie more than three standard deviations (of the first fit's residuals) off its
  line, where the slip bends away, and the slope is fitted again to the grown segments.
  A sparsely sampled loop with fewer than two samples in a window (a model loop draws each
  stick segment as one straight line) uses the chord from the reversal instead.
* slip_amplitude :math:`\delta^*`: half the width of the loop at :math:`Q = 0` (Figure 1a).
  Where a grown stick segment reaches across zero force, the crossing is its fitted line's
  intercept :math:`c`; otherwise a straight line through the branch's samples with
  :math:`|Q| < Q^*/4` and the two samples around the crossing.
* dissipated_energy :math:`E_d = \oint Q\,d\Delta`: the loop's area by the trapezoidal
  (shoelace) rule; the noise of the samples averages out of it.
* ecof :math:`\mu_E = E_d/(4P\delta^*)` (eq. 1), cof_max :math:`Q^*/P`, energy_ratio
  :math:`A = E_d/(4\Delta^* Q^*)`.
* gicof: :math:`Q/P` where the loop crosses the line :math:`Q = S\Delta` (eq. 17-18, the
  paper's Figure 6): gicof_forward on the rising branch, gicof_backward (sign reversed) on
  the falling one, and gicof their mean. On the line the contact position
  :math:`x = \Delta - Q/S` (eq. 10) is zero. The branch's samples with :math:`|x| <`
  ``crossing_window`` :math:`\times\,\delta^*` (default 0.7) are fitted by least squares
  with :math:`Q = a + bx + cxQ`, which is eq. 9 exactly for any groove slope
  (:math:`a = \mu P`, :math:`b = kP`, :math:`c = \mu k`) and a smooth three-parameter
  curve for other loops; the crossing is :math:`Q = a`. In the model the window lies
  inside the slip, away from any ploughing peak at the ends of the stroke. With fewer than
  five samples in the window, the crossing is interpolated between two samples. A small
  error in :math:`S` or in the centring moves the two crossings in opposite directions,
  and most of it cancels from their mean.
* stick_residual: the root mean square displacement off the stick lines.
* regime: the :class:`ecofmaps.Regime` code, as in the model and the maps: ``GROSS_SLIP``
  when the energy ratio :math:`A` exceeds ``gross_slip_threshold`` (default 0.2, the
  sliding transition of Fouvry, Kapsa and Vincent), else ``NO_GROSS_SLIP`` (partial
  slip); ``INVALID`` for a refused cycle. ECoF and GICoF describe sliding: they are NaN in
  partial slip. Like
  Fouvry's criterion, this also calls partial slip a gross-slip loop that slips over less
  than about a fifth of the stroke (for the model, :math:`A \approx \delta^*/\Delta^*`
  times :math:`\mu_E P/Q^*`); lower the threshold to read such loops.

Every cycle is checked before its numbers are reported (:mod:`ecofmaps.measured.quality`):
a loop that runs anticlockwise, has no area, no straight stick sides, a constant force,
crossings that are not on the measured loop, ... has the values concerned NaN and the
reasons in its ``quality``; the stick sides are *curved* when a :math:`Q^2` term is
significant and changes their slope by more than 5 % from end to end. A crossing with
:math:`Q = S\Delta` is on the loop when the branch has measured samples on both sides of
:math:`\xi = 0` in the fitted window (or the two interpolated between) and the crossing's
force lies within theirs; a zero-force crossing when it lies within the displacements of
the branch's samples near zero force.

For the model's loop every quantity is exact up to the sampling: :math:`\Delta^*`,
:math:`Q^*`, :math:`S`, :math:`\delta^*` and the GICoF to rounding when the loop's
reversals are sampled, :math:`E_d` to the trapezoidal rule's error on the curved slip
branches. The half-width at :math:`Q = 0` is the model's slip amplitude as long as the
groove slope at the ends of the slip, :math:`2 z_o \delta^*/x_o^2`, is below :math:`\mu`
(the force crosses zero while the contact sticks); beyond that it is smaller.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps._codes import warn
from ecofmaps._inputs import check, si_units
from ecofmaps._interrupts import check_interrupted
from ecofmaps.measured.branches import (
    both,
    branch_rows,
    line_crossings,
    stick_lines,
    zero_force_crossings,
)
from ecofmaps.measured.centring import loop_blocks
from ecofmaps.measured.cycles import MIN_SAMPLES, Cycles, find_cycles
from ecofmaps.measured.quality import (
    ALL,
    ANTICLOCKWISE_SHARE,
    REASONS,
    LoopQualityWarning,
    apply_quality,
    quality_strings,
    summary_of_counts,
)
from ecofmaps.measured.samples import is_lazy
from ecofmaps.model.regimes import GROSS_SLIP, INVALID, NO_GROSS_SLIP, Regime

__all__ = [
    "GROSS_SLIP_THRESHOLD",
    "NAN_POLICIES",
    "MissingSampleError",
    "Tally",
    "analyze_loops",
    "cycle_results",
    "measure_cycles",
]

#: What :func:`analyze_loops` does with missing samples: skip their cycles, or raise.
NAN_POLICIES = ("skip", "raise")

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
    "stick_residual",
)

#: How the quantities are measured on a loop (the netCDF ``comment`` attribute).
_COMMENTS = {
    "slip_amplitude": "half the loop's width at Q = 0",
    "dissipated_energy": "the loop's area",
    "stiffness": "slope of the stick segments",
    "regime": "GROSS_SLIP when the energy ratio exceeds gross_slip_threshold, else NO_GROSS_SLIP "
    "(partial slip); INVALID where the cycle is refused",
    "quality": "'ok' or the reasons for NaN, joined by '+' (ecofmaps.measured.quality)",
}

#: A stick segment must explain all but this share of the displacement's variance along it.
_UNEXPLAINED = 0.2

#: Plausible displacement amplitudes: outside this range the unit is probably wrong. [m]
_AMPLITUDE_RANGE = (0.1e-6, 10e-3)


def _attrs(name: str) -> dict:
    attrs = nomenclature.attrs(name)
    if name in _COMMENTS:
        attrs["comment"] = _COMMENTS[name]
    return attrs


def _loop_values(block, load, options):
    """Every per-cycle quantity of a block of centred loops, and the checks it failed.

    Returns the quantities (module notes; not yet NaN where a check fails) and the flags
    of :data:`ecofmaps.measured.quality.REASONS` (reason -> per cycle).
    """
    x, y = block.displacement, block.force
    highest, lowest = block.extremes(x)
    span = highest - lowest
    amplitude = 0.5 * span
    max_force = 0.5 * np.subtract(*block.extremes(y))
    # The loop's area by trapezoids, the segment that closes it included.
    first, last = block.offset, block.offset + block.count - 1
    closing = (y[first] + y[last]) * (x[first] - x[last])
    energy = 0.5 * (block.sums((y[1:] + y[:-1]) * np.diff(x)) + closing)
    bx, by, valid, length = branch_rows(block, block.first_point(x, highest))
    compliance, intercept, stick, fit = stick_lines(bx, by, valid, span, options["stick_window"])
    crossing, zero_on_loop = zero_force_crossings(
        bx, by, valid, length, max_force, stick, intercept, span
    )
    cycles = block.count.size
    slip = 0.5 * (crossing[cycles:] - crossing[:cycles])
    half_width = options["crossing_window"] * np.abs(slip)
    at, force, on_loop = line_crossings(
        bx, by, valid, length, both(compliance), both(half_width), load, both(max_force)
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

    Returns
    -------
    values : dict of str to numpy.ndarray
        Each quantity of :func:`analyze_loops` over the cycles, offsets and stick residual
        included, as measured: not yet NaN where a check fails.
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
    return values, flags, loops


def _refusal_hint(flags: dict) -> str:
    """What the user may do about a recording whose every cycle is refused (``flags``:
    whether every cycle, or any for ``negative-stiffness``, carries the reason)."""
    if flags["missing-samples"]:
        return "Every cycle holds a missing sample (NaN or an empty cell)."
    if flags["anticlockwise"]:
        if flags["negative-stiffness"]:
            return (
                "The loops run anticlockwise with stick sides sloping down: the force is "
                "recorded positive against the displacement. If so, read it with the other "
                "sign: flip_force=True (on the command line, --flip-force)."
            )
        return (
            "The loops run anticlockwise with stick sides sloping up: the recording runs "
            "backwards in time, or the displacement and force columns are swapped."
        )
    if flags["constant-force"]:
        return "The force does not vary: is the force channel connected?"
    return (
        "Is it a recording of fretting loops, with the displacement and the force in their "
        "own columns?"
    )


# --- the public function ------------------------------------------------------------------


class MissingSampleError(ValueError):
    """A missing sample where ``nan_policy='raise'``: ``sample`` is its 0-based index."""

    def __init__(self, sample: int, message: str):
        self.sample = int(sample)
        super().__init__(message)


def _missing_error(sample: int) -> MissingSampleError:
    return MissingSampleError(
        sample,
        f"sample {sample} is missing (NaN or empty); nan_policy='skip' analyses the cycles "
        "without missing samples and reports the others as skipped",
    )


def _series(name, values, size=None, dtype=np.float64):
    """``values`` as a 1-D array (NumPy, or dask as it is) of ``size`` samples."""
    if hasattr(values, "dims"):  # an xarray DataArray: its NumPy or dask data
        values = values.data
    array = values if is_lazy(values) else np.asarray(values, dtype=dtype)
    if array.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional (one value per sample)")
    if size is not None and array.shape[0] != size:
        raise ValueError(
            f"{name} must have one value per sample: {array.shape[0]} values for {size} samples"
        )
    if is_lazy(array) and array.dtype.kind not in "fiub":
        raise ValueError(f"{name} must hold numbers; got dtype {array.dtype}")
    return array


def check_options(
    load, hysteresis, stick_window, crossing_window, gross_slip_threshold, flip_force
):
    """The options of :func:`analyze_loops`, checked (a ValueError naming the one that is
    not valid), as keyword arguments of :func:`measure_cycles`."""
    check("load", load, "positive", "N")
    if np.ndim(load) != 0:
        raise ValueError("load must be a single value [N]")
    if not 0.0 < hysteresis < 1.0:
        raise ValueError(f"hysteresis must satisfy 0 < hysteresis < 1; got {hysteresis!r}")
    low, high = (float(share) for share in stick_window)
    if not 0.0 <= low < high <= 1.0:
        raise ValueError(f"stick_window must satisfy 0 <= low < high <= 1; got {stick_window!r}")
    if not crossing_window > 0.0:
        raise ValueError(
            f"crossing_window must satisfy crossing_window > 0; got {crossing_window!r}"
        )
    if not 0.0 < gross_slip_threshold < 1.0:
        raise ValueError(
            "gross_slip_threshold must satisfy 0 < gross_slip_threshold < 1; "
            f"got {gross_slip_threshold!r}"
        )
    if not isinstance(flip_force, bool | np.bool_):
        raise ValueError(f"flip_force must be True or False; got {flip_force!r}")
    return {
        "hysteresis": float(hysteresis),
        "stick_window": (low, high),
        "crossing_window": float(crossing_window),
        "gross_slip_threshold": float(gross_slip_threshold),
        "flip_force": bool(flip_force),
    }


@si_units
def analyze_loops(
    displacement,
    force,
    load,
    cycle=None,
    *,
    hysteresis=0.5,
    stick_window=(0.05, 0.45),
    crossing_window=0.7,
    gross_slip_threshold=GROSS_SLIP_THRESHOLD,
    flip_force=False,
    resolve=False,
    keep_loops=False,
    missing=None,
    nan_policy="skip",
    scheduler=None,
    workers=None,
) -> xr.Dataset:
    r"""Per-cycle friction quantities of a recording of fretting loops, each checked.

    Parameters
    ----------
    displacement : array_like, dask.array.Array or xarray.DataArray
        Applied displacement :math:`\Delta` at each sample, in time order. Offsets and a
        slow drift are removed; the sampling need not be uniform. A dask array (or an
        xarray object backed by one) is analysed out of core, block by block (Notes). [m]
    force : array_like, dask.array.Array or xarray.DataArray
        Tangential force :math:`Q` at each sample, positive in the direction of positive
        displacement (the loops then run clockwise); offsets are removed. [N]
    load : float
        Normal load :math:`P`. [N]
    cycle : array_like, optional
        Cycle number of each sample: each run of equal numbers is one loop (the loops may
        be recorded now and then during a test). Without it the recording is cut at its
        displacement reversals, or read as a single loop. [1]
    hysteresis : float
        Half-width of the reversal detector's band, as a share of the displacement's
        half-range (0 < hysteresis < 1); see :mod:`ecofmaps.measured.cycles`. [1]
    stick_window : tuple of float
        Shares of a branch's force swing, away from its reversal, between which the
        stick segment is first sought (0 <= low < high <= 1). [1]
    crossing_window : float
        Half-width of the window fitted at each GICoF crossing, in contact position, as a
        share of the slip amplitude (> 0). [1]
    gross_slip_threshold : float
        Energy ratio :math:`A` above which a loop is gross slip (0 < threshold < 1). [1]
    flip_force : bool
        Read the force with the other sign: for a rig whose force is recorded positive
        against the displacement (its loops run anticlockwise, with stick sides sloping
        down).
    resolve : bool
        Also read each loop along the stroke (:func:`ecofmaps.resolve_loops`) and add
        ``mu_resolved``, ``mu_resolved_se`` and ``aspect_ratio`` (the equivalent parabolic
        groove), with that reading's reasons in ``quality``. About ten times the work.
    keep_loops : bool
        Also return the centred loops, ``loop_displacement`` and ``loop_force`` over
        ``(cycle, point)`` (NaN-padded), for plotting (recordings in memory only).
    missing : array_like of bool, optional
        True for samples to treat as missing besides the non-finite ones (NaN, inf in
        any of the displacement, force and cycle number).
    nan_policy : {'skip', 'raise'}
        A cycle that holds a missing sample is skipped: its values are NaN and its
        ``quality`` is ``'missing-samples'`` (``'skip'``); or any missing sample is an
        error, :class:`MissingSampleError` naming it (``'raise'``).
    scheduler : {None, 'threads', 'processes'}, str or distributed.Client
        Where a dask recording's blocks run: the current ``distributed`` client if there
        is one, else threads of this process (None); threads; a ``LocalCluster`` of
        ``workers`` processes; the dask scheduler at an address (``'tcp://host:8786'``),
        whose workers must reach the recording's file; or a client.
    workers : int, optional
        Threads, or processes of the local cluster (default: one per core; 2).

    Returns
    -------
    results : xarray.Dataset
        Over ``cycle``: amplitude [m], slip_amplitude [m], max_force [N],
        dissipated_energy [J], ecof, cof_max, energy_ratio, stiffness [N/m], gicof,
        gicof_forward, gicof_backward, crossing_displacement_forward and
        crossing_displacement_backward [m] (in the centred loop), displacement_offset [m]
        and force_offset [N] (the centres removed, of the force as read), regime
        (:class:`ecofmaps.Regime` codes: GROSS_SLIP, NO_GROSS_SLIP for partial slip, INVALID
        for a refused cycle; int32 with CF flag attributes), stick_residual [m] (root
        mean square displacement off the stick lines) and quality ('ok', or why values
        are NaN: :mod:`ecofmaps.measured.quality`); the load is a scalar coordinate. The
        attributes ``incomplete_cycles`` and ``dropped_samples`` count what was dropped,
        ``missing_samples``, ``skipped_cycles`` and ``first_missing_sample`` (or -1) what
        was missing; ``quality_summary`` is one line on what was flagged and skipped. With
        ``resolve``, also mu_resolved, mu_resolved_se and aspect_ratio.
        ``results.to_dataframe()`` gives a table.

    Raises
    ------
    ValueError
        For inputs of the wrong shape, a load that is not positive, options out of
        range, a recording without a complete cycle, or one whose every cycle is refused
        (not a loop that can be read as recorded); :class:`MissingSampleError` for a
        missing sample with ``nan_policy='raise'``.

    Warns
    -----
    LoopQualityWarning
        When cycles were flagged (other than for partial slip), with the one-line summary;
        and when the displacement amplitude is below 0.1 µm or above 10 mm (a displacement
        not in metres).

    Notes
    -----
    The methods are in the documentation of :mod:`ecofmaps.measured.analysis`,
    :mod:`ecofmaps.measured.cycles` and :mod:`ecofmaps.measured.centring`; the checks in
    :mod:`ecofmaps.measured.quality`. The ECoF is eq. 1; the GICoF is the paper's Section 5
    (eq. 17-18), and equals :math:`\mu` for the model's loop whatever the groove.

    A dask recording (a long test read lazily by :func:`ecofmaps.read_recording`) is never
    held whole: its cycles are found by passes a block at a time
    (:mod:`ecofmaps.measured.cycles`), then measured in tasks of whole cycles, each with
    two whole cycles on either side for the centring's drift
    (:mod:`ecofmaps.measured.out_of_core`). The results are those of the same recording in
    memory.

    Examples
    --------
    >>> import numpy as np, ecofmaps
    >>> displacement, force = ecofmaps.fretting_loop(50e-6, 450.0, 35e6, 0.8, 0.2)
    >>> results = ecofmaps.analyze_loops(np.asarray(displacement), np.asarray(force), 450.0)
    >>> print(f"{float(results.gicof[0]):.6f} {float(results.ecof[0]):.3f}")
    0.800000 0.831
    >>> print(results.quality.values[0], "|", results.attrs["quality_summary"])
    ok | 1 cycles: 1 ok
    """
    options = check_options(
        load, hysteresis, stick_window, crossing_window, gross_slip_threshold, flip_force
    )
    if nan_policy not in NAN_POLICIES:
        raise ValueError(f"nan_policy must be one of {NAN_POLICIES}; got {nan_policy!r}")
    load = float(load)
    x = _series("displacement", displacement)
    q = _series("force", force, x.shape[0])
    label = None if cycle is None else _series("cycle", cycle, x.shape[0], dtype=None)
    mask = None if missing is None else _series("missing", missing, x.shape[0], dtype=bool)
    if x.shape[0] < MIN_SAMPLES:
        raise ValueError(
            f"too few samples for one cycle: {x.shape[0]} (a cycle needs at least {MIN_SAMPLES})"
        )
    if any(is_lazy(a) for a in (x, q, label, mask)):
        if keep_loops:
            raise ValueError(
                "keep_loops needs the recording in memory: give NumPy arrays (a long "
                "recording's loops would not fit)"
            )
        from ecofmaps.measured.out_of_core import LongAnalysis

        with runner_for(scheduler, workers) as runner:
            analysis = LongAnalysis(
                x,
                q,
                load,
                label,
                missing=mask,
                runner=runner,
                nan_policy=nan_policy,
                resolve=resolve,
                **options,
            )
            parts = [part for _, part in analysis.parts()]
        return analysis.finish(xr.concat(parts, "cycle") if parts else parts)
    if nan_policy == "raise":
        bad = ~np.isfinite(x) | ~np.isfinite(q)
        if label is not None and label.dtype.kind not in "iub":
            bad |= ~np.isfinite(label)
        if mask is not None:
            bad |= mask
        if bad.any():
            raise _missing_error(int(np.argmax(bad)))
    cycles = find_cycles(x, label, hysteresis, force=q, missing=mask)
    if cycles.label.size == 0:
        raise no_cycle_error(x.shape[0])
    kept = keep_loops or resolve  # the reading along the stroke reads the kept loops
    values, flags, loops = measure_cycles(cycles, x, q, load, keep_loops=kept, **options)
    results = cycle_results(values, flags, cycles.label, load, options)
    tally = Tally()
    tally.add(results)
    if kept:
        results = with_loops(results, loops)
    results = tally.finish(
        results, cycles, "displacement reversals" if cycle is None else "cycle numbers", options
    )
    if resolve:
        results = with_read_along_stroke(results)
    if not keep_loops:
        results = results.drop_vars(["loop_displacement", "loop_force", "point"], errors="ignore")
    return results


def with_loops(results: xr.Dataset, loops) -> xr.Dataset:
    """``results`` with the centred loops of :func:`measure_cycles` (``keep_loops=True``)."""
    results["loop_displacement"] = (("cycle", "point"), loops[0], _attrs("loop_displacement"))
    results["loop_force"] = (("cycle", "point"), loops[1], _attrs("loop_force"))
    results.coords["point"] = ("point", np.arange(loops[0].shape[1]), _attrs("point"))
    return results


def with_read_along_stroke(results: xr.Dataset) -> xr.Dataset:
    """``results`` (with its loops) with the values read along the stroke
    (:data:`ecofmaps.measured.resolved.REPORTED`), and that reading's quality."""
    from ecofmaps.measured.resolved import resolve_analyzed_loops, with_resolved  # built on this

    return with_resolved(results, resolve_analyzed_loops(results, positions=None))


def no_cycle_error(samples: int) -> ValueError:
    """The error for a recording without a complete cycle."""
    return ValueError(
        f"too few samples for one cycle: no complete cycle in {samples} samples "
        "(the loop does not close, or the recording does not oscillate)"
    )


def runner_for(scheduler, workers):
    """The :class:`ecofmaps._parallel.Runner` for :func:`analyze_loops`' ``scheduler`` and
    ``workers`` (see there)."""
    from ecofmaps._parallel import Runner

    if scheduler is None:
        try:
            from distributed import default_client

            return Runner(client=default_client())
        except (ImportError, ValueError):  # no client: threads
            return Runner(workers)
    if scheduler == "threads":
        return Runner(workers)
    if scheduler == "processes":
        return Runner(workers or 2, cluster=True)
    if isinstance(scheduler, str):
        return Runner(scheduler=scheduler)
    return Runner(client=scheduler)


def cycle_results(values: dict, flags: dict, label, load: float, options: dict) -> xr.Dataset:
    """The per-cycle Dataset of :func:`analyze_loops` for some cycles, without the
    recording's attributes: ``values`` and ``flags`` from :func:`measure_cycles`.

    The raw amplitudes and whether each cycle is refused ride along as ``_amplitude`` and
    ``_refused`` until :meth:`Tally.finish` takes them off.
    """
    size = label.size
    quality = quality_strings(flags, size)
    refused = np.zeros(size, dtype=bool)
    for reason, flag in flags.items():
        refused |= flag & (REASONS[reason][1] == ALL)
    raw_amplitude = values["amplitude"]
    values = apply_quality(values, flags)
    sliding = values["energy_ratio"] > options["gross_slip_threshold"]
    regime = np.where(refused, INVALID, np.where(sliding, GROSS_SLIP, NO_GROSS_SLIP))
    names = [name for name in values if name != "stick_residual"]
    data = {name: ("cycle", values[name], _attrs(name)) for name in names}
    data["regime"] = ("cycle", regime.astype(np.int32), _attrs("regime") | Regime.flag_attrs())
    data["stick_residual"] = ("cycle", values["stick_residual"], _attrs("stick_residual"))
    data["quality"] = ("cycle", quality, _attrs("quality"))
    data["_amplitude"] = ("cycle", raw_amplitude)
    data["_refused"] = ("cycle", refused)
    hints = {
        "missing-samples": flags["missing-samples"],
        "anticlockwise": flags["anticlockwise"],
        "constant-force": flags["constant-force"],
    }
    for reason, flag in hints.items():
        data[f"_{reason}"] = ("cycle", flag)
    data["_negative-stiffness"] = ("cycle", flags["negative-stiffness"])
    coords = {"cycle": ("cycle", label, _attrs("cycle")), "load": ((), load, _attrs("load"))}
    return xr.Dataset(data, coords=coords)


class Tally:
    """What :func:`analyze_loops` says about a whole recording, gathered from its parts
    (:func:`cycle_results`) as they come: the quality summary, whether every cycle was
    refused, and the typical amplitude."""

    def __init__(self):
        self.counts: dict = {}
        self.cycles = self.refused = self.flagged = 0
        self.every = {"missing-samples": True, "anticlockwise": True, "constant-force": True}
        self.negative_stiffness = False
        self.amplitudes: list = []

    def add(self, part: xr.Dataset) -> xr.Dataset:
        """Count the cycles of ``part``; return it without its riders."""
        texts, counts = np.unique(part.quality.values, return_counts=True)
        for text, count in zip(texts.tolist(), counts.tolist(), strict=True):
            self.counts[text] = self.counts.get(text, 0) + count
            if text not in ("ok", "not-gross-slip"):
                self.flagged += count
        self.cycles += part.cycle.size
        self.refused += int(part["_refused"].sum())
        for reason in self.every:
            self.every[reason] &= bool(part[f"_{reason}"].all())
        self.negative_stiffness |= bool(part["_negative-stiffness"].any())
        self.amplitudes.append(part["_amplitude"].values)
        return strip(part)

    @property
    def summary(self) -> str:
        """The one-line quality summary so far."""
        return summary_of_counts(self.counts)

    def finish(self, results, cycles: Cycles, cycles_from: str, options: dict) -> xr.Dataset:
        """Check the whole recording and give ``results`` (the parts, joined) its
        attributes.

        Raises
        ------
        ValueError
            If every cycle was refused.
        """
        summary = self.summary
        _check_units(np.concatenate(self.amplitudes) if self.amplitudes else np.zeros(0))
        if self.cycles and self.refused == self.cycles:
            hint = dict(self.every, **{"negative-stiffness": self.negative_stiffness})
            raise ValueError(
                f"no plausible cycle in the recording ({summary}). {_refusal_hint(hint)}"
            )
        if self.flagged:
            warn(f"cycles flagged: {summary}", LoopQualityWarning)
        results = strip(results)
        results.attrs.update(
            {
                "title": "Fretting loops analysed cycle by cycle (ecofmaps.analyze_loops)",
                "cycles_from": cycles_from,
                "incomplete_cycles": cycles.incomplete_cycles,
                "dropped_samples": cycles.dropped_samples,
                "missing_samples": cycles.missing_samples,
                "first_missing_sample": cycles.first_missing,
                "skipped_cycles": int(self.counts_of("missing-samples")),
                "gross_slip_threshold": options["gross_slip_threshold"],
                "flip_force": int(options["flip_force"]),
                "quality_summary": summary,
            }
        )
        return results

    def counts_of(self, reason: str) -> int:
        """Cycles whose quality lists ``reason``."""
        return sum(c for text, c in self.counts.items() if reason in text.split("+"))


def strip(part: xr.Dataset) -> xr.Dataset:
    """``part`` without the riders of :func:`cycle_results`."""
    return part.drop_vars([name for name in part.data_vars if str(name).startswith("_")])


def _check_units(amplitude):
    """Warn when the displacement amplitudes look like another unit than metres."""
    finite = amplitude[np.isfinite(amplitude)]
    typical = float(np.median(finite)) if finite.size else np.nan
    low, high = _AMPLITUDE_RANGE
    if np.isfinite(typical) and not low <= typical <= high:
        warn(
            f"the displacement amplitude is {typical:.3g} m (median over the cycles), outside "
            "0.1 µm to 10 mm: is the displacement in metres? analyze_loops takes SI units; "
            "on the command line, --displacement-unit gives the unit of the column",
            LoopQualityWarning,
        )
