r"""The public entry points of the loop analysis: :func:`analyze_loops` and :func:`resolve_loops`
check their inputs and options and run the recording through :mod:`ecofmaps.measured.pipeline`
(the method: ``docs/method-loops.md``)."""

from __future__ import annotations

import sys

import numpy as np
import xarray as xr

from ecofmaps._inputs import si_units
from ecofmaps._parallel import check_workers
from ecofmaps.measured import pipeline
from ecofmaps.measured.cycles import MIN_SAMPLES
from ecofmaps.measured.resolve import ReadingOptions
from ecofmaps.measured.samples import MissingSampleError, is_lazy

#: What the analysis does with missing samples: skip their cycles, or raise.
NAN_POLICIES = ("skip", "raise")


def _series(name, values, size=None, dtype=np.float64):
    """``values`` as a 1-D array (NumPy, or dask as it is) of ``size`` samples."""
    if hasattr(values, "dims"):  # an xarray DataArray: its NumPy or dask data
        values = values.data
    if np.ma.isMaskedArray(getattr(values, "_meta", values)):  # masked: missing, as NaN is
        ma = sys.modules["dask.array"].ma if is_lazy(values) else np.ma
        kind, fill = (bool, True) if dtype is bool else (np.float64, np.nan)
        values = ma.filled(values.astype(kind), fill)
    try:
        array = values if is_lazy(values) else np.asarray(values, dtype=dtype)
    except (ValueError, TypeError, OverflowError) as error:
        raise ValueError(f"{name} cannot be read as numbers, one per sample ({error})") from None
    if array.dtype == object:  # Python integers too large for any integer type, say
        raise ValueError(f"{name} must hold numbers of at most 64 bits; got {array.dtype}")
    if array.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional (one value per sample)")
    if size is not None and array.shape[0] != size:
        raise ValueError(
            f"{name} must have one value per sample: {array.shape[0]} values for {size} samples"
        )
    if is_lazy(array) and array.dtype.kind not in "fiub":
        raise ValueError(f"{name} must hold numbers; got dtype {array.dtype}")
    return array


@si_units(rig_stiffness="stiffness")
def analyze_loops(
    displacement,
    force,
    load,
    cycle=None,
    *,
    hysteresis=pipeline.LoopOptions.hysteresis,
    stick_window=pipeline.LoopOptions.stick_window,
    crossing_window=pipeline.LoopOptions.crossing_window,
    gross_slip_threshold=pipeline.LoopOptions.gross_slip_threshold,
    rig_stiffness=None,
    flip_force=False,
    resolve=False,
    keep_loops=False,
    missing=None,
    nan_policy="skip",
    scheduler=None,
    workers=None,
) -> xr.Dataset:
    r"""Per-cycle friction quantities of a recording of fretting loops, each checked (the
    method, the checks and the reading out of core: ``docs/method-loops.md``).

    Parameters
    ----------
    displacement : array_like, dask.array.Array or xarray.DataArray
        Applied displacement :math:`\Delta` at each sample, in time order (dask: out of core). [m]
    force : array_like, dask.array.Array or xarray.DataArray
        Tangential force :math:`Q` at each sample, positive along positive displacement. [N]
    load : float or array_like
        Normal load :math:`P`, or the load at each sample (then each cycle at its own). [N]
    cycle : array_like, optional
        Cycle number of each sample (a run of equal numbers is one loop; default: reversals). [1]
    hysteresis : float
        Half-width of the reversal band, as a share of the displacement's half-range (< 1). [1]
    stick_window : tuple of float
        Shares of a branch's force swing, from its reversal, where the stick segment is
        first sought (0 <= low < high <= 1). [1]
    crossing_window : float
        Half-width of the fit at each GICoF crossing, as a share of the slip amplitude. [1]
    gross_slip_threshold : float
        Energy ratio :math:`A` above which a loop is gross slip (0 < threshold < 1). [1]
    rig_stiffness : float, optional
        Rig stiffness :math:`S`, if known: the regime is then read on :math:`\Delta - Q/S`. [N/m]
    flip_force : bool
        Read the force with the other sign (loops that run anticlockwise).
    resolve : bool
        Also read each loop along the stroke (``mu_resolved``; about ten times the work).
    keep_loops : bool
        Also return the centred loops, ``loop_displacement`` and ``loop_force`` over
        ``(cycle, point)`` (NaN-padded; recordings in memory only).
    missing : array_like of bool, optional
        True for samples to treat as missing besides the non-finite ones.
    nan_policy : {'skip', 'raise'}
        Skip a cycle with a missing sample (``'missing-samples'``), or raise at the first one.
    scheduler : {None, 'threads', 'processes'}, str or distributed.Client
        Where a dask recording's blocks run: the current ``distributed`` client, else threads
        (None); threads; a local cluster of ``workers`` processes; a scheduler's address.
    workers : int, optional
        Threads, or processes of the local cluster (default: one per core; 2).

    Returns
    -------
    results : xarray.Dataset
        Over ``cycle``, the columns and attributes of ``docs/loops.md`` in SI units (``regime``
        as :class:`ecofmaps.Regime` codes, ``quality`` 'ok' or why values are NaN); the load is
        a scalar coordinate.

    Raises
    ------
    ValueError
        For inputs of the wrong shape, options out of range, a load nowhere positive, or a
        recording without a usable cycle; :class:`MissingSampleError` with ``nan_policy='raise'``.

    Warns
    -----
    LoopQualityWarning
        When cycles were flagged (other than for partial slip) or have a coefficient of
        friction outside 0.01 to 3, with the one-line summary.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 1, 9, 10, 17-18.

    Examples
    --------
    >>> import numpy as np, ecofmaps
    >>> displacement, force = ecofmaps.fretting_loop(50e-6, 450.0, 35e6, 0.8, 0.2)
    >>> results = ecofmaps.analyze_loops(np.asarray(displacement), np.asarray(force), 450.0)
    >>> print(f"{float(results.gicof[0]):.6f} {float(results.ecof[0]):.3f}")
    0.800000 0.831
    """
    force, load, loads = _at_mean_load(force, load)
    loop = (load, hysteresis, stick_window, crossing_window, gross_slip_threshold, flip_force)
    options = pipeline.LoopOptions(*loop, rig_stiffness)
    reading = pipeline.Reading(resolve=bool(resolve), keep_loops=bool(keep_loops))
    settings = (loads, missing, nan_policy, scheduler, workers)
    return _run(displacement, force, cycle, options, reading, *settings)[0]


def _run(
    x,
    q,
    cycle,
    options,
    reading,
    recorded=None,
    missing=None,
    nan_policy="skip",
    scheduler=None,
    workers=None,
):
    """The recording checked, through the pipeline: the results and the reading handed back."""
    if nan_policy not in NAN_POLICIES:
        raise ValueError(f"nan_policy must be one of {NAN_POLICIES}; got {nan_policy!r}")
    if scheduler in (None, "threads", "processes"):  # on this machine: checked before any work
        check_workers(workers, processes=scheduler == "processes")
    x = _series("displacement", x)
    q = _series("force", q, x.shape[0])
    label = None if cycle is None else _series("cycle", cycle, x.shape[0], dtype=None)
    mask = None if missing is None else _series("missing", missing, x.shape[0], dtype=bool)
    if x.shape[0] < MIN_SAMPLES:
        raise ValueError(f"too few samples for one cycle: {x.shape[0]} (at least {MIN_SAMPLES})")
    settings = dict(missing=mask, recorded_load=recorded, nan_policy=nan_policy, reading=reading)
    if not any(is_lazy(a) for a in (x, q, label, mask)):
        if nan_policy == "raise":  # the first missing sample (a load not positive: its cycle)
            bad = ~np.isfinite(x) | ~np.isfinite(q)
            if label is not None and label.dtype.kind not in "iub":
                bad |= ~np.isfinite(label)
            if mask is not None:
                bad |= mask
            sample = int(np.argmax(bad))
            if bad[sample] and not (recorded is not None and recorded[sample] <= 0.0):
                raise MissingSampleError(sample)
        return pipeline.Analysis(x, q, label, options=options, one_chunk=True, **settings).run()
    if reading.keep_loops:
        raise ValueError("keep_loops needs the recording in memory: give NumPy arrays")
    with pipeline.runner_for(scheduler, workers) as runner:
        return pipeline.Analysis(x, q, label, options=options, runner=runner, **settings).run()


def _at_mean_load(force, load):
    """The force and load as the pipeline takes them, and the load at each sample (or None)."""
    if np.ndim(load) == 0 and not is_lazy(load):
        return force, load, None
    force = _series("force", force)
    recorded = _series("load", load, force.shape[0])
    return *pipeline.force_at_mean_load(force, recorded), recorded


@si_units
def resolve_loops(
    displacement,
    force,
    load,
    stiffness=None,
    cycle=None,
    *,
    force_offset=None,
    positions=ReadingOptions.positions,
    central=ReadingOptions.central,
    slip_threshold=ReadingOptions.slip_threshold,
    stick_window=ReadingOptions.stick_window,
    hysteresis=pipeline.LoopOptions.hysteresis,
    gross_slip_threshold=pipeline.LoopOptions.gross_slip_threshold,
) -> xr.Dataset:
    r"""Friction and groove slope read along the whole stroke of every loop of a recording (the
    method and the quality flags: ``docs/method-loops.md``).

    Parameters
    ----------
    displacement, force, load, cycle
        As for :func:`ecofmaps.analyze_loops`. [m], [N], [N], [1]
    stiffness : float, optional
        Rig stiffness :math:`S` (``numpy.inf``: rigid); by default measured on each loop. [N/m]
    force_offset : float, optional
        The force sensor's offset, subtracted from the force; by default each loop is centred
        on its own force, which also levels a tilted groove (give it to read the tilt). [N]
    positions : int or array_like or None
        An odd count (>= 5) of positions common to all cycles, over the widest resolved range;
        or the positions, increasing, 0 among them; or None for per-cycle values only. [1], [m]
    central : float
        Share of the resolved half-range about :math:`\xi = 0` averaged for ``mu_resolved``
        and fitted for ``aspect_ratio`` (0 < central <= 1). [1]
    slip_threshold : float
        Noise standard deviations of :math:`\xi` beyond the stick level that are slip. [1]
    stick_window, hysteresis, gross_slip_threshold
        As for :func:`ecofmaps.analyze_loops`. [1]

    Returns
    -------
    resolved : xarray.Dataset
        Over ``(cycle, position)`` (``position``: :math:`\xi` [m]): ``mu``, ``slope``,
        ``felt_profile`` [m], ``force_forward``, ``force_backward`` [N], NaN where a branch does not
        slip. Over ``cycle``: ``mu_resolved``, ``mu_resolved_se``, ``aspect_ratio``, ``tilt``,
        ``stiffness`` [N/m], ``position_offset``, ``position_min``, ``position_max``, ``amplitude``
        [m] and ``quality``; the load is a scalar coordinate.

    Raises
    ------
    ValueError
        For bad inputs or options (those of :func:`ecofmaps.analyze_loops` too).

    See Also
    --------
    resolve_analyzed_loops : the same from :func:`ecofmaps.analyze_loops`'s result.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 7, 9, 10, 17-18.

    Examples
    --------
    >>> import numpy as np, ecofmaps
    >>> displacement, force = ecofmaps.fretting_loop(50e-6, 450.0, 35e6, 0.8, 0.2)
    >>> resolved = ecofmaps.resolve_loops(np.asarray(displacement), np.asarray(force), 450.0)
    >>> print(f"{float(resolved.mu_resolved[0]):.9f} {float(resolved.aspect_ratio[0]):.9f}")
    0.800000000 0.200000000
    """
    opts = ReadingOptions(stiffness, force_offset, positions, central, slip_threshold, stick_window)
    reading = pipeline.Reading(resolve=True, along_stroke=opts, hand_back=True)
    force, load, recorded = _at_mean_load(force, load)
    options = pipeline.LoopOptions(
        load, hysteresis, stick_window, gross_slip_threshold=gross_slip_threshold
    )
    return _run(displacement, force, cycle, options, reading, recorded)[1]
