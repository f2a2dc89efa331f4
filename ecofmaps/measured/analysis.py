r"""The public entry points of the loop analysis: :func:`analyze_loops` and :func:`resolve_loops`
check their inputs and options and run the recording through :mod:`ecofmaps.measured.pipeline`.
The method is explained in ``docs/method-loops.md``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ecofmaps._inputs import si_units
from ecofmaps._parallel import check_workers
from ecofmaps.measured.cycles import MIN_SAMPLES, missing_sample_error
from ecofmaps.measured.pipeline import (
    NAN_POLICIES,
    Analysis,
    LoopOptions,
    Reading,
    force_at_mean_load,
    runner_for,
)
from ecofmaps.measured.resolve import ReadingOptions
from ecofmaps.measured.samples import is_lazy

__all__ = ["analyze_loops", "resolve_loops"]


def _series(name, values, size=None, dtype=np.float64):
    """``values`` as a 1-D array (NumPy, or dask as it is) of ``size`` samples."""
    if hasattr(values, "dims"):  # an xarray DataArray: its NumPy or dask data
        values = values.data
    if np.ma.isMaskedArray(values):  # masked samples are missing, as NaN is
        values = values.astype(bool).filled(True) if dtype is bool else values.filled(np.nan)
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
    hysteresis=LoopOptions.hysteresis,
    stick_window=LoopOptions.stick_window,
    crossing_window=LoopOptions.crossing_window,
    gross_slip_threshold=LoopOptions.gross_slip_threshold,
    rig_stiffness=None,
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
    load : float or array_like
        Normal load :math:`P`; or the load recorded at each sample (a load cell's
        channel), which scales the force to the mean load, so every coefficient of
        friction is read with the load of its samples
        (:func:`ecofmaps.measured.pipeline.force_at_mean_load`); each cycle's forces,
        energy and stiffness are then given at its own load, ``normal_load``. [N]
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
        Energy ratio :math:`A` above which a loop is gross slip (0 < threshold < 1); on the
        contact's displacement with ``rig_stiffness``. [1]
    rig_stiffness : float, optional
        The rig's own stiffness :math:`S`, when known (the loops' stick slope is the rig and
        the contact in series). The loops' ratios are then also read on the contact's
        displacement :math:`\Delta - Q/S` (``opening_ratio``, ``contact_amplitude``,
        ``contact_energy_ratio``, ``contact_opening_ratio``), and the regime is decided
        there, where Mindlin's :math:`A_t = 0.2` holds for a sphere on a flat. [N/m]
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
        and force_offset [N] (the centres removed, of the force as read),
        force_drift_se [N] (standard error of the offset between the loop's branches
        that the drift correction between neighbouring centres leaves), regime
        (:class:`ecofmaps.Regime` codes: GROSS_SLIP, PARTIAL_SLIP, INVALID
        for a refused cycle; int32 with CF flag attributes), stick_residual [m] (root
        mean square displacement off the stick lines) and quality ('ok', or why values
        are NaN: :mod:`ecofmaps.measured.quality`); the load is a scalar coordinate. The
        attributes ``incomplete_cycles`` and ``dropped_samples`` count what was dropped,
        ``missing_samples``, ``skipped_cycles`` and ``first_missing_sample`` (or -1) what
        was missing; ``quality_summary`` is one line on what was flagged and skipped;
        ``motion`` is ``'fretting'``, or ``'reciprocating sliding'`` for a median amplitude
        above 300 µm (analysed the same way). With ``resolve``, also mu_resolved,
        mu_resolved_se and aspect_ratio; with a recorded load, normal_load [N] (its mean
        over the cycle).
        ``results.to_dataframe()`` gives a table.

    Raises
    ------
    ValueError
        For inputs of the wrong shape, a load that is not positive, options out of
        range, a recording without a complete cycle, or one whose every cycle is refused
        (not a loop that can be read as recorded, or an amplitude outside 0.5 µm to 50 mm:
        a displacement not in metres; the message says what to do);
        :class:`MissingSampleError` for a
        missing sample with ``nan_policy='raise'``.

    Warns
    -----
    LoopQualityWarning
        When cycles were flagged (other than for partial slip), with the one-line summary;
        and when cycles have a coefficient of friction outside 0.01 to 3
        (``implausible-cof``: the load or the force's unit is wrong), naming the load.

    Notes
    -----
    The method and the checks are explained in ``docs/method-loops.md``. The ECoF is
    eq. 1; the GICoF is the paper's Section 5
    (eq. 17-18), and equals :math:`\mu` for the model's loop whatever the groove.

    A dask recording (a long test read lazily by :func:`ecofmaps.read_recording`) is never
    held whole: its cycles are found by passes a block at a time
    (:mod:`ecofmaps.measured.cycles`), then measured in tasks of whole cycles, each with
    two whole cycles on either side for the centring's drift
    (:mod:`ecofmaps.measured.pipeline`). The results are those of the same recording in
    memory.

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
    >>> print(results.quality.values[0], "|", results.attrs["quality_summary"])
    ok | 1 cycle: 1 ok
    """
    force, load, recorded = _at_mean_load(force, load)
    options = LoopOptions(
        load, hysteresis, stick_window, crossing_window, gross_slip_threshold, flip_force,
        rig_stiffness,
    )  # fmt: skip
    reading = Reading(resolve=bool(resolve), keep_loops=bool(keep_loops))
    results, _ = _run(
        displacement,
        force,
        cycle,
        options,
        reading,
        missing=missing,
        recorded_load=recorded,
        nan_policy=nan_policy,
        scheduler=scheduler,
        workers=workers,
    )
    return results


def _run(
    displacement,
    force,
    cycle,
    options: LoopOptions,
    reading: Reading,
    *,
    missing=None,
    recorded_load=None,
    nan_policy="skip",
    scheduler=None,
    workers=None,
):
    """The recording checked and through the pipeline: in this process as one chunk when it
    is in memory, else on the runner of ``scheduler`` and ``workers``. Returns the results
    and the reading along the stroke handed back (or None)."""
    if nan_policy not in NAN_POLICIES:
        raise ValueError(f"nan_policy must be one of {NAN_POLICIES}; got {nan_policy!r}")
    if scheduler in (None, "threads", "processes"):  # on this machine: checked before any work
        check_workers(workers, processes=scheduler == "processes")
    x = _series("displacement", displacement)
    q = _series("force", force, x.shape[0])
    label = None if cycle is None else _series("cycle", cycle, x.shape[0], dtype=None)
    mask = None if missing is None else _series("missing", missing, x.shape[0], dtype=bool)
    if x.shape[0] < MIN_SAMPLES:
        raise ValueError(
            f"too few samples for one cycle: {x.shape[0]} (a cycle needs at least {MIN_SAMPLES})"
        )
    arrays = dict(
        options=options,
        missing=mask,
        recorded_load=recorded_load,
        nan_policy=nan_policy,
        reading=reading,
    )
    if not any(is_lazy(a) for a in (x, q, label, mask)):
        if nan_policy == "raise":
            _raise_at_missing(x, q, label, mask)
        analysis = Analysis(x, q, label, one_chunk=True, **arrays)
        return analysis.run()
    if reading.keep_loops:
        raise ValueError(
            "keep_loops needs the recording in memory: give NumPy arrays (a long "
            "recording's loops would not fit)"
        )
    with runner_for(scheduler, workers) as runner:
        analysis = Analysis(x, q, label, runner=runner, **arrays)
        return analysis.run()


def _at_mean_load(force, load):
    """``force`` and ``load`` as the pipeline takes them, and the load at each sample (or
    None): a load given sample by sample (a recorded channel) scales the force to the mean
    load (:func:`force_at_mean_load`)."""
    if np.ndim(load) == 0 and not is_lazy(load):
        return force, load, None
    force = _series("force", force)
    recorded = _series("load", load, force.shape[0])
    return *force_at_mean_load(force, recorded), recorded


def _raise_at_missing(x, q, label, mask) -> None:
    """:class:`MissingSampleError` naming the first missing sample of a recording in memory."""
    bad = ~np.isfinite(x) | ~np.isfinite(q)
    if label is not None and label.dtype.kind not in "iub":
        bad |= ~np.isfinite(label)
    if mask is not None:
        bad |= mask
    if bad.any():
        raise missing_sample_error(int(np.argmax(bad)))


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
    hysteresis=LoopOptions.hysteresis,
    gross_slip_threshold=LoopOptions.gross_slip_threshold,
) -> xr.Dataset:
    r"""Friction and groove slope read along the whole stroke of every loop of a recording.

    Parameters
    ----------
    displacement : array_like
        Applied displacement :math:`\Delta` at each sample, in time order. Offsets and a
        slow drift are removed (:func:`ecofmaps.analyze_loops`). [m]
    force : array_like
        Tangential force :math:`Q` at each sample. [N]
    load : float or array_like
        Normal load :math:`P`, or the load recorded at each sample (as for
        :func:`analyze_loops`: the forces read along the stroke and the stiffness are then
        at each cycle's own load). [N]
    stiffness : float, optional
        Rig stiffness :math:`S` (``numpy.inf`` for a rigid rig); by default measured on
        each loop. [N/m]
    cycle : array_like, optional
        Cycle number of each sample, as for :func:`ecofmaps.analyze_loops`. [1]
    force_offset : float, optional
        The force sensor's offset, subtracted from the recorded force. By default each
        loop is centred on its own force instead, which also takes away the force a
        tilted groove adds to both branches: give the offset (0 for a zeroed sensor) to
        read a groove's tilt. [N]
    positions : int or array_like or None
        Points of the grid of contact positions common to all cycles, odd (>= 5) so that
        :math:`\xi = 0` is one, spread over the widest resolved range; or the positions
        themselves, increasing and with 0 among them (to compare recordings, or blocks of
        one); or None for the per-cycle values alone (the values along the stroke take
        8 kB per cycle at 201 positions). [1] or [m]
    central : float
        Share of the resolved half-range, about :math:`\xi = 0`, averaged for
        ``mu_resolved`` and fitted for ``aspect_ratio`` (0 < central <= 1). [1]
    slip_threshold : float
        How many noise standard deviations of :math:`\xi` a sample must lie beyond the
        stick level to count as slipping (> 0). [1]
    stick_window : tuple of float
        Shares of a branch's force swing, away from its reversal, that bound the first
        stick window (0 <= low < high <= 1); also passed to
        :func:`ecofmaps.analyze_loops`. [1]
    hysteresis, gross_slip_threshold : float
        Passed to :func:`ecofmaps.analyze_loops`: the reversal detector's band, and the
        energy ratio above which a loop is gross slip. [1]

    Returns
    -------
    resolved : xarray.Dataset
        Over ``(cycle, position)``: ``mu`` :math:`\mu(\xi)`, ``slope`` :math:`g(\xi)`,
        ``felt_profile`` :math:`h(\xi)` [m], ``force_forward`` and ``force_backward``
        :math:`Q_\pm(\xi)` [N]; NaN outside the range where both branches slip. Over
        ``cycle``: ``mu_resolved``, ``mu_resolved_se``, ``aspect_ratio``, ``tilt``
        (:math:`g_0`), ``stiffness`` (the one used) [N/m], ``position_offset`` (where
        :math:`\xi = 0` lies in the recording's contact position), ``position_min``,
        ``position_max`` [m], ``amplitude`` (:math:`\Delta^*`, the :math:`x_o` of
        ``aspect_ratio``) [m] and ``quality`` (``'ok'`` or the reason the values are NaN).
        With the force centred (``force_offset=None``), ``slope`` and ``felt_profile`` are
        levelled (``tilt`` taken off). The ``position``
        coordinate is :math:`\xi` [m], common to all cycles; the load is a scalar
        coordinate. ``resolved.sel(cycle=...).mu.plot()`` labels itself.

    Raises
    ------
    ValueError
        For bad inputs or options (those of :func:`ecofmaps.analyze_loops` too).

    See Also
    --------
    resolve_analyzed_loops : the same from :func:`ecofmaps.analyze_loops`'s result.

    Notes
    -----
    The method and the quality flags are explained in ``docs/method-loops.md``. It rests on
    eq. 9 (the slip traction at any local
    groove slope) and eq. 10 (the contact position); the GICoF (eq. 17-18) is its value at
    :math:`\xi = 0`, and eq. 7 with :math:`x_o = \Delta^*` gives the equivalent
    parabolic groove.

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
    along_stroke = ReadingOptions(
        stiffness, force_offset, positions, central, slip_threshold, stick_window
    )
    reading = Reading(resolve=True, along_stroke=along_stroke, hand_back=True)
    force, load, recorded = _at_mean_load(force, load)
    options = LoopOptions(load, hysteresis, stick_window, gross_slip_threshold=gross_slip_threshold)
    return _run(displacement, force, cycle, options, reading, recorded_load=recorded)[1]
