r"""Measured fretting loops, cycle by cycle: ECoF, GICoF, rig stiffness and the rest.

:func:`analyze_loops` reads a recording of the actuator displacement :math:`\Delta` and the
tangential force :math:`Q` (many cycles, or a single loop), cuts it into cycles and
removes the offsets and a slow drift (:mod:`ecofmaps.measured.cycles`), and measures each loop. The
work is done on padded arrays with one row per cycle, with no Python loop over samples or
cycles: a recording of :math:`10^4` cycles of 200 samples takes a second or two.

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
* regime: 'gross slip' when the energy ratio :math:`A` exceeds ``gross_slip_threshold``
  (default 0.2, the sliding transition of Fouvry, Kapsa and Vincent), else
  'partial slip'. ECoF and GICoF describe sliding: they are NaN in partial slip. Like
  Fouvry's criterion, this also calls partial slip a gross-slip loop that slips over less
  than about a fifth of the stroke (for the model, :math:`A \approx \delta^*/\Delta^*`
  times :math:`\mu_E P/Q^*`); lower the threshold to read such loops.

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

from ecofmaps._inputs import check
from tests.measured.reference.cycles import MIN_SAMPLES, labelled_cycles, masked_sum, split_cycles

__all__ = ["GROSS_SLIP_THRESHOLD", "analyze_loops"]

#: Energy ratio :math:`A = E_d/(4\Delta^* Q^*)` above which a loop is gross slip (the
#: sliding transition of Fouvry, Kapsa and Vincent).
GROSS_SLIP_THRESHOLD = 0.2

#: Samples with :math:`|Q|` below this share of :math:`Q^*` locate a zero-force crossing
#: that is not on a stick segment.
_ZERO_FORCE_BAND = 0.25

#: A stick segment grows until two samples in a row are this many standard deviations off.
_STICK_SPREAD = 3.0

#: Fewest samples in the window of the curve fitted at a GICoF crossing.
_FIT_SAMPLES = 5

_ATTRS = {
    "cycle": ("cycle number", "1"),
    "amplitude": ("displacement amplitude Δ*", "m"),
    "slip_amplitude": ("slip amplitude δ* (loop half-width at Q = 0)", "m"),
    "max_force": ("peak tangential force Q*", "N"),
    "dissipated_energy": ("dissipated energy per cycle E_d (loop area)", "J"),
    "ecof": ("energy coefficient of friction μ_E = E_d/(4Pδ*)", "1"),
    "cof_max": ("peak coefficient of friction Q*/P", "1"),
    "energy_ratio": ("energy ratio A = E_d/(4Δ*Q*)", "1"),
    "stiffness": ("rig stiffness S (slope of the stick segments)", "N/m"),
    "gicof": ("geometry-independent coefficient of friction (GICoF)", "1"),
    "gicof_forward": ("GICoF on the rising-displacement branch", "1"),
    "gicof_backward": ("GICoF on the falling-displacement branch", "1"),
    "crossing_displacement_forward": ("displacement where Q = SΔ, rising branch", "m"),
    "crossing_displacement_backward": ("displacement where Q = SΔ, falling branch", "m"),
    "displacement_offset": ("displacement offset removed (loop centre)", "m"),
    "force_offset": ("force offset removed (loop centre)", "N"),
    "regime": ("fretting regime (gross slip or partial slip)", ""),
    "load": ("normal load P", "N"),
    "point": ("point round the loop", "1"),
    "loop_displacement": ("displacement Δ, centred", "m"),
    "loop_force": ("tangential force Q, centred", "N"),
}


def _attrs(name: str) -> dict:
    long_name, units = _ATTRS[name]
    return {"long_name": long_name, "units": units}


# --- per-cycle kernels ---------------------------------------------------------------------
# Each takes arrays of shape (cycles, width) whose rows run once round a loop from its
# lowest displacement; ``valid`` marks the points of each loop, the rest is padding (NaN).


def _branches(x, valid):
    """Masks of the rising branch (start to top) and the falling one (top to the end)."""
    top = np.argmax(np.where(valid, x, -np.inf), axis=1)
    j = np.arange(x.shape[1])[None, :]
    rising = valid & (j <= top[:, None])
    falling = valid & (j >= top[:, None])
    return rising, falling, top


def _dissipated_energy(x, y, valid):
    r"""The loop's area :math:`\oint Q\,d\Delta` by the trapezoidal rule."""
    return masked_sum(0.5 * (y[:, 1:] + y[:, :-1]) * np.diff(x, axis=1), valid[:, 1:])


def _bracket(value, branch, first, sign):
    """Index of the sample just past the sign change of ``value`` on a branch.

    ``value`` runs from the sign ``sign`` to ``-sign`` along the branch, which starts at
    index ``first``. The change is placed after as many samples as the branch has on the
    starting side, so a few noisy samples on the wrong side do not move it far.
    """
    count = np.count_nonzero(branch & (sign * value > 0.0), axis=1)
    last = first + np.count_nonzero(branch, axis=1) - 1
    return np.clip(first + count, first + 1, last)


def _crossing(x, value, branch, first, sign):
    """``x`` where ``value`` changes sign on a branch, interpolated between two samples."""
    after = _bracket(value, branch, first, sign)[:, None]
    x0, x1 = (np.take_along_axis(x, after - k, axis=1)[:, 0] for k in (1, 0))
    v0, v1 = (np.take_along_axis(value, after - k, axis=1)[:, 0] for k in (1, 0))
    change = v0 - v1
    share = np.divide(v0, change, out=np.full_like(v0, 0.5), where=change != 0.0)
    return x0 + share * (x1 - x0)


def _zero_force_crossing(x, y, branch, first, sign, stick, intercept):
    r"""Displacement where a branch crosses :math:`Q = 0`.

    Where the stick segment ``stick`` reaches across zero force, it is the intercept of
    the line fitted to it, :math:`\Delta = c + Q/S`. Elsewhere a straight line
    :math:`\Delta = a + bQ` is fitted to the two samples around the crossing and the
    branch's samples with :math:`|Q|` below ``_ZERO_FORCE_BAND`` times :math:`Q^*`, and
    gives :math:`a`.
    """
    after = _bracket(y, branch, first, sign)[:, None]
    j = np.arange(x.shape[1])[None, :]
    band = _ZERO_FORCE_BAND * 0.5 * (np.nanmax(y, axis=1) - np.nanmin(y, axis=1))
    near = branch & ((np.abs(y) <= band[:, None]) | (j == after) | (j == after - 1))
    local = _common_slope(y, x, [near])[1][0]
    across = np.any(stick & (y < 0.0), axis=1) & np.any(stick & (y > 0.0), axis=1)
    return np.where(across, intercept, local)


def _stick_mask(y, branch, window):
    """The stick segment after the reversal at the start of ``branch`` (module notes)."""
    low, high = window
    span = np.max(np.where(branch, y, -np.inf), axis=1) - np.min(
        np.where(branch, y, np.inf), axis=1
    )
    start = np.take_along_axis(y, np.argmax(branch, axis=1)[:, None], axis=1)
    moved = np.abs(y - start) / span[:, None]
    beyond = np.maximum.accumulate(branch & (moved > high), axis=1)
    mask = branch & (moved >= low) & ~beyond
    # Sparse sampling (a model loop draws each stick segment as one straight line): the
    # chord from the reversal to the first sample past the lower share.
    j = np.arange(y.shape[1])[None, :]
    chord = (j == np.argmax(branch, axis=1)[:, None]) | (
        j == np.argmax(branch & (moved >= low), axis=1)[:, None]
    )
    return np.where(np.count_nonzero(mask, axis=1)[:, None] < 2, chord, mask)


def _common_slope(x, y, masks):
    """Least-squares slope common to lines through each mask's points, and their intercepts."""
    covariance = np.zeros(x.shape[0])
    variance = np.zeros(x.shape[0])
    means = []
    for mask in masks:
        count = np.count_nonzero(mask, axis=1)
        mean_x, mean_y = masked_sum(x, mask) / count, masked_sum(y, mask) / count
        dx, dy = x - mean_x[:, None], y - mean_y[:, None]
        covariance += masked_sum(dx * dy, mask)
        variance += masked_sum(dx * dx, mask)
        means.append((mean_x, mean_y))
    slope = covariance / variance
    return slope, [mean_y - slope * mean_x for mean_x, mean_y in means]


def _stick_lines(x, y, branches, window):
    r"""Lines :math:`\Delta = c + Q/S` through the stick segments after the two reversals.

    A first line is fitted to the samples in the force window; each segment then grows
    along its branch until two samples in a row lie more than ``_STICK_SPREAD`` standard
    deviations off its line (the slip that follows bends away from it; a single noisy
    sample does not stop it), and the lines are fitted again to the grown segments.
    Returns the common compliance :math:`1/S`, the intercept :math:`c` of each line and
    the mask of each segment.
    """
    masks = [_stick_mask(y, branch, window) for branch in branches]
    compliance, intercepts = _common_slope(y, x, masks)
    residuals = [x - intercept[:, None] - compliance[:, None] * y for intercept in intercepts]
    squares = sum(masked_sum(r * r, m) for r, m in zip(residuals, masks, strict=True))
    points = sum(np.count_nonzero(m, axis=1) for m in masks)
    spread = np.sqrt(squares / np.maximum(points - 3, 1))
    span = np.nanmax(x, axis=1) - np.nanmin(x, axis=1)
    tolerance = np.maximum(_STICK_SPREAD * spread, 1e-9 * span)[:, None]
    grown = []
    for branch, mask, residual in zip(branches, masks, residuals, strict=True):
        after = np.maximum.accumulate(mask, axis=1) & branch
        outside = after & (np.abs(residual) > tolerance)
        outside[:, :-1] &= outside[:, 1:]
        off = np.maximum.accumulate(outside, axis=1)
        grown.append(mask | (after & ~off))
    compliance, intercepts = _common_slope(y, x, grown)
    return compliance, intercepts, grown


def _line_crossing(x, y, branch, first, sign, compliance, half_width, load):
    r"""Displacement and force where a branch crosses :math:`Q = S\Delta` (module notes).

    On the line the contact position :math:`\xi = \Delta - Q/S` (eq. 10) is zero. The
    branch's samples with :math:`|\xi|` below ``half_width`` are fitted by least squares
    with :math:`Q = a + b\xi + c\xi Q`, which is eq. 9 for any groove slope
    (:math:`a = \mu P`, :math:`b = kP`, :math:`c = \mu k`) and a smooth three-parameter
    curve otherwise; the crossing is :math:`Q = a`. With fewer than ``_FIT_SAMPLES``
    samples in the window, :math:`Q` is interpolated linearly at :math:`\xi = 0` between
    the two samples around the crossing.
    """
    position = x - y * compliance[:, None]  # the contact position (eq. 10)
    guess = _crossing(y, position, branch, first, sign)  # Q there, interpolated
    scaled = position / half_width[:, None]
    window = branch & (np.abs(scaled) <= 1.0)
    enough = np.count_nonzero(window, axis=1) >= _FIT_SAMPLES
    regressors = (np.ones_like(x), scaled, scaled * y / load)
    normal = np.stack(
        [np.stack([masked_sum(p * q, window) for q in regressors], axis=-1) for p in regressors],
        axis=-2,
    )
    moments = np.stack([masked_sum(p * y, window) for p in regressors], axis=-1)
    normal[~enough] = np.eye(3)
    intercept = (np.linalg.pinv(normal) @ moments[..., None])[:, 0, 0]
    force = np.where(enough, intercept, guess)
    return force * compliance, force


# --- the public function ------------------------------------------------------------------


def _loop_quantities(x, q, valid, load, options):
    """Every per-cycle quantity of the centred loops ``x``, ``q`` (module notes)."""
    amplitude = 0.5 * (np.nanmax(x, axis=1) - np.nanmin(x, axis=1))
    max_force = 0.5 * (np.nanmax(q, axis=1) - np.nanmin(q, axis=1))
    rising, falling, top = _branches(x, valid)
    start = np.zeros_like(top)
    compliance, intercepts, sticks = _stick_lines(x, q, (rising, falling), options["stick_window"])
    stiffness = 1.0 / compliance
    left = _zero_force_crossing(x, q, rising, start, -1.0, sticks[0], intercepts[0])
    right = _zero_force_crossing(x, q, falling, top, 1.0, sticks[1], intercepts[1])
    slip = 0.5 * (right - left)
    energy = _dissipated_energy(x, q, valid)
    half_width = options["crossing_window"] * np.abs(slip)
    rising_x, rising_q = _line_crossing(x, q, rising, start, 1.0, compliance, half_width, load)
    falling_x, falling_q = _line_crossing(x, q, falling, top, -1.0, compliance, half_width, load)
    energy_ratio = energy / (4.0 * amplitude * max_force)
    gross = energy_ratio > options["gross_slip_threshold"]
    sliding = np.where(gross, 1.0, np.nan)  # NaN for the coefficients in partial slip
    values = {
        "amplitude": amplitude,
        "slip_amplitude": slip,
        "max_force": max_force,
        "dissipated_energy": energy,
        "ecof": sliding * energy / (4.0 * load * slip),
        "cof_max": max_force / load,
        "energy_ratio": energy_ratio,
        "stiffness": stiffness,
        "gicof": sliding * (rising_q - falling_q) / (2.0 * load),
        "gicof_forward": sliding * rising_q / load,
        "gicof_backward": -sliding * falling_q / load,
        "crossing_displacement_forward": sliding * rising_x,
        "crossing_displacement_backward": sliding * falling_x,
    }
    return values, np.where(gross, "gross slip", "partial slip")


def _series(name, values, size=None):
    """``values`` as a finite 1-D float64 array of ``size`` samples."""
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional (one value per sample)")
    if size is not None and array.size != size:
        raise ValueError(
            f"{name} must have one value per sample: {array.size} values for {size} samples"
        )
    check(name, array, "finite")
    return array


def _check_options(load, hysteresis, stick_window, crossing_window, gross_slip_threshold):
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
    return {
        "stick_window": (low, high),
        "crossing_window": float(crossing_window),
        "gross_slip_threshold": float(gross_slip_threshold),
    }


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
    keep_loops=False,
) -> xr.Dataset:
    r"""Per-cycle friction quantities of a recording of fretting loops.

    Parameters
    ----------
    displacement : array_like
        Applied displacement :math:`\Delta` at each sample, in time order. Offsets and a
        slow drift are removed; the sampling need not be uniform. [m]
    force : array_like
        Tangential force :math:`Q` at each sample; offsets are removed. [N]
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
    keep_loops : bool
        Also return the centred loops, ``loop_displacement`` and ``loop_force`` over
        ``(cycle, point)`` (NaN-padded), for plotting.

    Returns
    -------
    results : xarray.Dataset
        Over ``cycle``: amplitude [m], slip_amplitude [m], max_force [N],
        dissipated_energy [J], ecof, cof_max, energy_ratio, stiffness [N/m], gicof,
        gicof_forward, gicof_backward, crossing_displacement_forward and
        crossing_displacement_backward [m] (in the centred loop), displacement_offset [m]
        and force_offset [N] (the centres removed), and regime ('gross slip' or
        'partial slip'); the load is a scalar coordinate. The attributes
        ``incomplete_cycles`` and ``dropped_samples`` count what was dropped.
        ``results.to_dataframe()`` gives a table.

    Raises
    ------
    ValueError
        For inputs of the wrong shape, non-finite samples, a load that is not positive,
        options out of range, or a recording without a complete cycle.

    Notes
    -----
    The methods are in the documentation of :mod:`ecofmaps.measured.analysis` and
    :mod:`ecofmaps.measured.cycles`. The ECoF is eq. 1; the GICoF is the paper's Section 5
    (eq. 17-18), and equals :math:`\mu` for the model's loop whatever the groove.

    Examples
    --------
    >>> import numpy as np, ecofmaps
    >>> displacement, force = ecofmaps.fretting_loop(50e-6, 450.0, 35e6, 0.8, 0.2)
    >>> results = ecofmaps.analyze_loops(np.asarray(displacement), np.asarray(force), 450.0)
    >>> print(f"{float(results.gicof[0]):.6f} {float(results.ecof[0]):.3f}")
    0.800000 0.831
    """
    options = _check_options(load, hysteresis, stick_window, crossing_window, gross_slip_threshold)
    load = float(load)
    x = _series("displacement", displacement)
    q = _series("force", force, x.size)
    if x.size < MIN_SAMPLES:
        raise ValueError(
            f"too few samples for one cycle: {x.size} (a cycle needs at least {MIN_SAMPLES})"
        )
    if cycle is None:
        cycles = split_cycles(x, hysteresis)
    else:
        cycles = labelled_cycles(x, _series("cycle", cycle, x.size))
    if cycles.label.size == 0:
        raise ValueError(
            f"too few samples for one cycle: no complete cycle in {x.size} samples "
            "(the loop does not close, or the recording does not oscillate)"
        )
    loop_x, loop_q, centre_x, centre_q = cycles.centred_loops(x, q)
    with np.errstate(divide="ignore", invalid="ignore"):  # degenerate cycles give NaN
        values, regime = _loop_quantities(loop_x, loop_q, cycles.valid, load, options)
    values.update(displacement_offset=centre_x, force_offset=centre_q)
    data = {name: ("cycle", value, _attrs(name)) for name, value in values.items()}
    data["regime"] = ("cycle", regime, _attrs("regime"))
    coords = {"cycle": ("cycle", cycles.label, _attrs("cycle")), "load": ((), load, _attrs("load"))}
    if keep_loops:
        data["loop_displacement"] = (("cycle", "point"), loop_x, _attrs("loop_displacement"))
        data["loop_force"] = (("cycle", "point"), loop_q, _attrs("loop_force"))
        coords["point"] = ("point", np.arange(loop_x.shape[1]), _attrs("point"))
    attrs = {
        "title": "Fretting loops analysed cycle by cycle (ecofmaps.analyze_loops)",
        "cycles_from": "displacement reversals" if cycle is None else "cycle numbers",
        "incomplete_cycles": cycles.incomplete_cycles,
        "dropped_samples": cycles.dropped_samples,
        "gross_slip_threshold": options["gross_slip_threshold"],
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)
