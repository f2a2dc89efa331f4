"""The model's steady loop fitted to a measured fretting loop (the paper's Figure 10):
:func:`fit_loop`; ``docs/method-loops.md`` ("Fitting the model's loop")."""

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from ecofmaps._inputs import check, float64
from ecofmaps.measured.cycles import MIN_SAMPLES, find_cycles
from ecofmaps.measured.measure import measure_cycles
from ecofmaps.measured.pipeline import LoopOptions
from ecofmaps.measured.quality import ALL, ANTICLOCKWISE_SHARE, REASONS, SEPARATOR
from ecofmaps.measured.resolve import within
from ecofmaps.model.core import slip_position, traction_ratio
from ecofmaps.model.simulation import fretting_loop

#: The stick windows of the loop's own analysis: the one with the steeper stick sides starts.
_STICK_WINDOWS = ((0.05, 0.45), (0.0, 0.15))
#: Contact positions within this share of the slip amplitude slip, for the starting values.
_SLIP_SHARE = 0.6
#: A slip amplitude below this share of the amplitude is rounding: the loop does not slip.
_NO_SLIP = 1e-9
#: Samples are padded to a multiple of this for the compiled residual.
_BUCKET = 64
_TOLERANCE = 1e-12
_MAX_EVALUATIONS = 200


@dataclasses.dataclass(frozen=True, eq=False)
class LoopFit:
    r"""The model fitted to one measured loop, returned by :func:`fit_loop`.

    Attributes
    ----------
    mu : float
        Contact coefficient of friction :math:`\mu`. [1]
    stiffness : float
        Rig stiffness :math:`S`. [N/m]
    groove_depth : float
        Groove depth :math:`z_o`. [m]
    aspect_ratio : float
        Groove aspect ratio :math:`z_o/x_o` with :math:`x_o = \Delta^*`. [1]
    amplitude : float
        Displacement amplitude :math:`\Delta^*` of the fitted loop. [m]
    displacement_offset, force_offset : float
        Centre of the fitted loop in displacement [m] and in force [N] (sensor offsets).
    load : float
        Normal load :math:`P`, as given. [N]
    rms_residual : float
        Root mean square of measured minus model force over the samples. [N]
    r_squared : float
        Coefficient of determination :math:`1 - \sum r_i^2 / \sum (Q_i - \bar Q)^2`. [1]
    standard_errors : dict of str to float
        Standard error of each quantity above, by name, in its unit (linearised; method-loops.md).
    success : bool
        True when the least squares converged to a loop in gross slip.
    evaluations : int
        Residual evaluations the least squares used. [1]
    message : str
        How the least squares ended.
    displacement, force : numpy.ndarray
        The measured samples fitted: one cycle, from its lowest displacement on. [m], [N]
    model_force : numpy.ndarray
        The fitted model's force at each sample, on that sample's branch. [N]
    rising : numpy.ndarray of bool
        True for samples on the rising-displacement branch.
    cycle : int
        Number of the cycle fitted, as in :func:`ecofmaps.analyze_loops`. [1]
    """

    mu: float
    stiffness: float
    groove_depth: float
    aspect_ratio: float
    amplitude: float
    displacement_offset: float
    force_offset: float
    load: float
    rms_residual: float
    r_squared: float
    standard_errors: dict
    success: bool
    evaluations: int
    message: str
    displacement: np.ndarray
    force: np.ndarray
    model_force: np.ndarray
    rising: np.ndarray
    cycle: int

    def model_loop(self, num=201):
        """The fitted steady loop, offsets included, for plotting."""
        x, q = fretting_loop(
            self.amplitude, self.load, self.stiffness, self.mu, self.aspect_ratio, num=num
        )
        return np.asarray(x) + self.displacement_offset, np.asarray(q) + self.force_offset


def _rising_branch(target, mu, kappa, lam):
    r""":math:`Q/P` of the steady loop's rising branch at actuator position ``target``."""
    stick = (target + slip_position(1.0, mu, kappa, lam)) / lam
    slip = traction_ratio(slip_position(target, mu, kappa, lam), mu, kappa)
    return jnp.minimum(stick, slip)


def _residual(parameters, displacement, force, rising, weight):
    """Weighted model less measured Q/P at each scaled sample; parameters (mu, s, a, A, c, q)."""
    mu, s, a, amplitude, centre, offset = parameters
    lam, kappa = 1.0 / (s * amplitude), 2.0 * a / amplitude
    target = (displacement - centre) / amplitude
    up = _rising_branch(target, mu, kappa, lam)
    down = -_rising_branch(-target, mu, kappa, lam)
    return weight * (jnp.where(rising, up, down) + offset - force)


_residual_jit = jax.jit(_residual)
_jacobian_jit = jax.jit(jax.jacfwd(_residual))


def _starting_values(x, y, rising, analysis, length, load):
    """Scaled starting parameters (Δ/L, Q/P, centred) from the loop's ``analysis``."""
    stiffness = analysis["stiffness"] * length / load
    slip_half_width = analysis["slip_amplitude"] / length
    if analysis["energy_ratio"] < -ANTICLOCKWISE_SHARE:
        raise ValueError(
            "the loop runs anticlockwise (its area ∮Q dΔ is negative): force and "
            "displacement must be positive in the same direction"
        )
    if stiffness == np.inf:
        raise ValueError(
            "the loop's stick segments are vertical (a rigid rig, S = inf): the model's "
            "stiffness cannot be fitted"
        )
    slipping = np.zeros_like(rising)
    if stiffness > 0 and slip_half_width > _NO_SLIP:
        contact = x - y / stiffness
        slipping = np.abs(contact) < _SLIP_SHARE * slip_half_width
    if min(np.count_nonzero(slipping & rising), np.count_nonzero(slipping & ~rising)) < 2:
        raise ValueError(
            "the loop shows no gross slip (no slip segment between the stick segments, or "
            "too few samples on it), so mu and the groove depth cannot be fitted"
        )
    design = np.stack([np.where(rising, 1.0, -1.0)[slipping], contact[slipping]], axis=1)
    (mu, slope), *_ = np.linalg.lstsq(design, y[slipping], rcond=None)
    if mu <= 0:
        raise ValueError("the loop's slip segments give mu <= 0: it is not a fretting loop")
    groove_slope = max(slope, 0.0) / (1.0 + mu * mu)
    return np.array([mu, stiffness, groove_slope / 2.0, 1.0, 0.0, 0.0])


@float64
def fit_loop(displacement, force, load, cycle=None, *, cycle_number=None, hysteresis=0.5):
    r"""Fit the model's steady loop to a measured fretting loop (the paper's Figure 10), by the
    method of ``docs/method-loops.md`` ("Fitting the model's loop").

    Parameters
    ----------
    displacement : array_like
        Applied displacement :math:`\Delta` at each sample, in time order: one loop (starting
        anywhere on it) or a recording of many cycles. [m]
    force : array_like
        Tangential force :math:`Q` at each sample, positive along positive displacement. [N]
    load : float
        Normal load :math:`P`. [N]
    cycle : array_like, optional
        Cycle number of each sample, as in :func:`ecofmaps.analyze_loops`. [1]
    cycle_number : int, optional
        The ``cycle`` of :func:`ecofmaps.analyze_loops`'s result to fit; default the last. [1]
    hysteresis : float
        The reversal detector's band, as in :func:`ecofmaps.analyze_loops`. [1]

    Returns
    -------
    fit : LoopFit
        The fitted model, its residual and convergence, and the samples fitted.

    Raises
    ------
    ValueError
        If ``load`` is not positive and finite; the arrays are not one-dimensional of one
        length, or not finite; there is no complete cycle (numbered ``cycle_number``) of
        :data:`MIN_SAMPLES` samples; or the loop shows no gross slip, runs anticlockwise, has
        vertical stick segments (a rigid rig), or is refused by the checks of
        :func:`ecofmaps.analyze_loops`.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 10, 16.
    """
    load, all_x, all_y, cycle = _checked_samples(displacement, force, cycle, load, hysteresis)
    index, number, analysis = _measured_cycle(all_x, all_y, load, cycle, cycle_number, hysteresis)
    # The last point closes the loop (the next cycle's first, or the first again): fit it once.
    x, y = all_x[index[:-1]], all_y[index[:-1]]
    if x.size < MIN_SAMPLES:
        raise ValueError(f"a loop needs at least {MIN_SAMPLES} samples, got {x.size}")
    rising = np.arange(x.size) <= np.argmax(x)
    length, centre, offset = map(analysis.get, ("amplitude", "displacement_offset", "force_offset"))
    scaled_x, scaled_y = (x - centre) / length, (y - offset) / load
    start = _starting_values(scaled_x, scaled_y, rising, analysis, length, load)
    solution = _solution(scaled_x, scaled_y, rising, start)
    mu, s, a, amplitude, shift, force_shift = (float(v) for v in solution.x)
    model_force = y + load * solution.fun[: x.size]
    residual = y - model_force
    gross_slip = mu / (s * amplitude) < 1.0
    message = solution.message + (
        "" if gross_slip else " (but the fitted loop has no gross slip: mu * P / (S Δ*) >= 1)"
    )
    return LoopFit(
        mu=mu,
        stiffness=float(s * load / length),
        groove_depth=float(a * length),
        aspect_ratio=a / amplitude,
        amplitude=float(amplitude * length),
        displacement_offset=float(centre + shift * length),
        force_offset=float(offset + force_shift * load),
        load=load,
        rms_residual=float(np.sqrt(np.mean(residual**2))),
        r_squared=float(1.0 - np.sum(residual**2) / np.sum((y - y.mean()) ** 2)),
        standard_errors=_standard_errors(solution, x.size, load, length),
        success=bool(solution.success and gross_slip),
        evaluations=int(solution.nfev),
        message=message,
        displacement=x,
        force=y,
        model_force=model_force,
        rising=rising,
        cycle=number,
    )


def _checked_samples(displacement, force, cycle, load, hysteresis):
    """The load and the samples of :func:`fit_loop` (and their cycle numbers), checked."""
    check("load", load, "positive", "N")
    if np.ndim(load) != 0:
        raise ValueError(f"load must be a single number [N], got shape {np.shape(load)}")
    within("hysteresis", hysteresis, 1.0)
    all_x, all_y = (np.asarray(values, dtype=np.float64) for values in (displacement, force))
    arrays = {"displacement": all_x, "force": all_y, "cycle": cycle}
    for name, values in ((k, np.asarray(v)) for k, v in arrays.items() if v is not None):
        if values.ndim != 1:
            raise ValueError(f"{name} must be one-dimensional, got shape {values.shape}")
        if values.size != all_x.size:
            raise ValueError(
                f"displacement and {name} must have the same length, got {all_x.size} and "
                f"{values.size}"
            )
    check("displacement", all_x, "finite", "m")
    check("force", all_y, "finite", "N")
    if all_x.size < MIN_SAMPLES:
        raise ValueError(f"a loop needs at least {MIN_SAMPLES} samples, got {all_x.size}")
    if not np.ptp(all_x) > 0:
        raise ValueError("displacement does not vary: a loop needs a displacement stroke")
    return float(load), all_x, all_y, None if cycle is None else np.asarray(cycle)


def _measured_cycle(all_x, all_y, load, cycle, cycle_number, hysteresis):
    """The indices round the loop to fit, its number and its analysis (stiffest stick window)."""
    cycles = find_cycles(all_x, cycle, hysteresis)
    if cycles.label.size == 0:
        raise ValueError(
            f"no complete cycle in {all_x.size} samples: too few samples for one cycle, or the "
            "loop does not close"
        )
    row = cycles.label.size - 1
    if cycle_number is not None:
        (rows,) = np.nonzero(cycles.label == cycle_number)
        if rows.size == 0:
            raise ValueError(
                f"cycle_number {cycle_number!r} is not a complete cycle of the recording; "
                f"complete cycles are numbered {cycles.label[0]} to {cycles.label[-1]}"
            )
        row = int(rows[0])
    index, number, chosen = cycles.indices([row])[0][0], int(cycles.label[row]), slice(row, row + 1)
    options = (LoopOptions(load, stick_window=window) for window in _STICK_WINDOWS)
    measured = (measure_cycles(cycles, all_x, all_y, o, rows=chosen) for o in options)
    analysis, flags, _ = max(measured, key=lambda values: float(values[0]["stiffness"][0]))
    analysis = {name: float(value[0]) for name, value in analysis.items()}
    refusing = [r for r, (_, scope) in REASONS.items() if scope == ALL and r != "anticlockwise"]
    refusals = [reason for reason in refusing if reason in flags and flags[reason][0]]
    if refusals and not flags["anticlockwise"][0]:
        raise ValueError(
            f"cycle {number} is no fretting loop that can be read as recorded: "
            f"{SEPARATOR.join(refusals)} ({'; '.join(REASONS[r][0] for r in refusals)})"
        )
    return index, number, analysis


def _solution(scaled_x, scaled_y, rising, start):
    """The least-squares fit of the model's loop to the scaled samples (scipy's result)."""
    # Padded with zero-weight samples so that loops of about one length share the compiled code.
    padded = (scaled_x, scaled_y, rising, np.ones(scaled_x.size))
    arguments = tuple(jnp.asarray(np.pad(v, (0, -scaled_x.size % _BUCKET))) for v in padded)
    # scipy.optimize costs 0.4 s to import: load it when a fit runs, not with `import ecofmaps`.
    from scipy.optimize import least_squares

    tiny = np.finfo(np.float64).tiny
    return least_squares(
        lambda p: np.asarray(_residual_jit(jnp.asarray(p), *arguments)),
        start,
        jac=lambda p: np.asarray(_jacobian_jit(jnp.asarray(p), *arguments)),
        bounds=([tiny, tiny, 0.0, tiny, -np.inf, -np.inf], np.inf),
        method="trf",
        x_scale="jac",
        ftol=_TOLERANCE,
        xtol=_TOLERANCE,
        gtol=_TOLERANCE,
        max_nfev=_MAX_EVALUATIONS,
    )


def _standard_errors(solution, samples: int, load: float, length: float) -> dict:
    """Standard errors of the fitted parameters in SI units, from the covariance s² (JᵀJ)⁻¹."""
    _, _, a, amplitude, _, _ = (float(v) for v in solution.x)
    jacobian = solution.jac[:samples]
    variance = np.sum(solution.fun[:samples] ** 2) / (samples - solution.x.size)
    covariance = variance * np.linalg.pinv(jacobian.T @ jacobian)
    deviation = np.sqrt(np.diag(covariance))
    ratio_gradient = np.array([0.0, 0.0, 1.0 / amplitude, -a / amplitude**2, 0.0, 0.0])
    return {
        "mu": float(deviation[0]),
        "stiffness": float(deviation[1] * load / length),
        "groove_depth": float(deviation[2] * length),
        "aspect_ratio": float(np.sqrt(ratio_gradient @ covariance @ ratio_gradient)),
        "amplitude": float(deviation[3] * length),
        "displacement_offset": float(deviation[4] * length),
        "force_offset": float(deviation[5] * load),
    }
