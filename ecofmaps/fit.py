r"""The model's steady loop fitted to a measured fretting loop (the paper's Figure 10).

:func:`fit_loop` finds the contact coefficient of friction :math:`\mu`, the rig stiffness
:math:`S` and the groove depth :math:`z_o` (with the paper's choice :math:`x_o = \Delta^*`)
whose steady loop passes closest, in the least-squares sense, to the measured samples
:math:`(\Delta_i, Q_i)`. The model force at each sample is the steady loop's force at the
same actuator displacement on the same branch (rising or falling :math:`\Delta`), in closed
form, so the residual has exact JAX derivatives; SciPy's trust-region least squares uses
them with bounds :math:`\mu > 0`, :math:`S > 0`, :math:`z_o \ge 0`.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
from scipy.optimize import least_squares

from ecofmaps._inputs import check, float64
from ecofmaps.loop import fretting_loop
from ecofmaps.model import slip_position, traction_ratio

__all__ = ["LoopFit", "fit_loop"]

#: Fewest samples accepted for one loop: six parameters, two branches, stick and slip.
MIN_SAMPLES = 20

# Share of the force swing after a reversal read as the stick segment for the starting
# stiffness; the stick segment covers more than half of it unless the groove is so deep
# that Q* > 1.7 P.
_STICK_SHARE = 0.4
# Contact positions within this share of the slip amplitude are read as slipping for the
# starting mu and groove slope.
_SLIP_SHARE = 0.6
# A loop whose area is negative by more than this share of its bounding box runs
# anticlockwise; a smaller negative area is noise on a loop without gross slip.
_ORIENTATION_SHARE = 0.05
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
        Displacement amplitude :math:`\Delta^*` of the fitted loop, which is also the groove
        half-width :math:`x_o`. [m]
    displacement_offset : float
        Centre of the loop in displacement, subtracted before the fit. [m]
    force_offset : float
        Centre of the loop in force (a load-cell offset). [N]
    load : float
        Normal load :math:`P`, as given. [N]
    rms_residual : float
        Root mean square of measured minus model force over the samples. [N]
    r_squared : float
        Coefficient of determination :math:`1 - \sum r_i^2 / \sum (Q_i - \bar Q)^2`. [1]
    success : bool
        True when the least squares converged to a loop in gross slip.
    evaluations : int
        Residual evaluations the least squares used. [1]
    message : str
        How the least squares ended.
    displacement, force : numpy.ndarray
        The measured samples fitted (one cycle). [m], [N]
    model_force : numpy.ndarray
        The fitted model's force at each sample, on that sample's branch. [N]
    rising : numpy.ndarray of bool
        True for samples on the rising-displacement branch.
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
    success: bool
    evaluations: int
    message: str
    displacement: np.ndarray
    force: np.ndarray
    model_force: np.ndarray
    rising: np.ndarray

    def model_loop(self, num=201):
        """The fitted steady loop, offsets included, for plotting.

        Parameters
        ----------
        num : int
            Points on each slip branch (see :func:`ecofmaps.fretting_loop`). [1]

        Returns
        -------
        displacement, force : numpy.ndarray
            One closed cycle of the fitted model loop. [m], [N]
        """
        displacement, force = fretting_loop(
            self.amplitude, self.load, self.stiffness, self.mu, self.aspect_ratio, num=num
        )
        return (
            np.asarray(displacement) + self.displacement_offset,
            np.asarray(force) + self.force_offset,
        )


def _rising_branch(target, mu, kappa, lam):
    r""":math:`Q/P` of the steady loop's rising branch at actuator position ``target``.

    After the reversal at :math:`(-1, -q^*)` the contact sticks at :math:`\xi = -d`, so
    :math:`q = (D + d)/\lambda`, until the forward-slip force
    :math:`Q_+(\xi_+(D))` (eq. 9 at the root of eq. 10) is lower; it is the smaller of the two.
    """
    d = slip_position(1.0, mu, kappa, lam)
    stick = (target + d) / lam
    slip = traction_ratio(slip_position(target, mu, kappa, lam), mu, kappa)
    return jnp.minimum(stick, slip)


def _model_force(parameters, displacement, rising):
    """Model Q/P at each scaled sample; parameters (mu, s, a, A, c, q) as in :func:`fit_loop`."""
    mu, s, a, amplitude, centre, offset = parameters
    lam = 1.0 / (s * amplitude)
    kappa = 2.0 * a / amplitude
    target = (displacement - centre) / amplitude
    up = _rising_branch(target, mu, kappa, lam)
    down = -_rising_branch(-target, mu, kappa, lam)
    return jnp.where(rising, up, down) + offset


def _residual(parameters, displacement, force, rising):
    return _model_force(parameters, displacement, rising) - force


_residual_jit = jax.jit(_residual)
_jacobian_jit = jax.jit(jax.jacfwd(_residual))


def _branches(displacement):
    """True for samples on the rising branch of one cycle (reversals at the extremes)."""
    low, high = int(np.argmin(displacement)), int(np.argmax(displacement))
    index = np.arange(displacement.size)
    if low < high:
        return (index >= low) & (index <= high)
    return (index >= low) | (index <= high)


def _starting_values(x, y, rising):
    r"""Scaled starting parameters from the loop itself (centred, :math:`\Delta/L`, Q/P).

    The stick segments after the reversals give :math:`S` (their slope) and :math:`\delta^*`
    (their offset); the contact position :math:`x = \Delta - Q/S` (eq. 10) on the slip
    segments gives :math:`\mu` and the groove slope from :math:`Q_\pm/P \approx \pm\mu +
    k(1 + \mu^2) x` (eq. 9 to first order in :math:`x`).
    """
    low, high = y.min(), y.max()
    swing = high - low
    # ∮ Q dΔ over the closed loop is the dissipated energy, > 0 clockwise (eq. 12)
    energy = np.trapezoid(np.append(y, y[0]), np.append(x, x[0]))
    if energy < -_ORIENTATION_SHARE * swing * (x.max() - x.min()):
        raise ValueError(
            "the loop runs anticlockwise (its area ∮Q dΔ is negative): force and "
            "displacement must be positive in the same direction"
        )
    stick_up = rising & (y < low + _STICK_SHARE * swing)
    stick_down = ~rising & (y > high - _STICK_SHARE * swing)
    if min(np.count_nonzero(stick_up), np.count_nonzero(stick_down)) < 2:
        raise ValueError(
            "too few samples on the stick segments after the reversals to read the rig "
            "stiffness; give at least a few samples between each reversal and slip"
        )
    stick = stick_up | stick_down
    design = np.stack([x[stick], stick_up[stick], stick_down[stick]], axis=1).astype(float)
    (s, up, down), *_ = np.linalg.lstsq(design, y[stick], rcond=None)
    slip_half_width = (up - down) / (2.0 * s) if s > 0 else 0.0
    contact = x - y / s if s > 0 else x
    slipping = np.abs(contact) < _SLIP_SHARE * slip_half_width
    if (
        s <= 0
        or slip_half_width <= 0
        or min(np.count_nonzero(slipping & rising), np.count_nonzero(slipping & ~rising)) < 2
    ):
        raise ValueError(
            "the loop shows no gross slip (it has no slip segment between the stick "
            "segments), so mu and the groove depth cannot be fitted"
        )
    sign = np.where(rising, 1.0, -1.0)
    design = np.stack([sign[slipping], contact[slipping]], axis=1)
    (mu, slope), *_ = np.linalg.lstsq(design, y[slipping], rcond=None)
    if mu <= 0:
        raise ValueError("the loop's slip segments give mu <= 0: it is not a fretting loop")
    groove_slope = max(slope, 0.0) / (1.0 + mu * mu)
    return np.array([mu, s, groove_slope / 2.0, 1.0, 0.0, 0.0])


@float64
def fit_loop(displacement, force, load):
    r"""Fit the model's steady loop to one measured fretting loop (the paper's Figure 10).

    Parameters
    ----------
    displacement : array_like
        Actuator displacement :math:`\Delta_i` of one cycle, in time order: the samples
        between (and including) two successive maxima, or any stretch of exactly one
        period. [m]
    force : array_like
        Tangential force :math:`Q_i` at the same instants, positive in the direction of
        positive displacement. [N]
    load : float
        Normal load :math:`P`. [N]

    Returns
    -------
    fit : LoopFit
        The fitted :math:`\mu`, :math:`S`, :math:`z_o`, :math:`\Delta^*` (= :math:`x_o`),
        the loop's centre, the residual and convergence information.

    Raises
    ------
    ValueError
        If ``load`` is not positive and finite, the arrays are not one-dimensional of the
        same length with at least :data:`MIN_SAMPLES` finite samples, the displacement does
        not vary, or the loop shows no gross slip or runs anticlockwise.

    Notes
    -----
    Each sample is on the rising branch (between the minimum and the maximum of
    :math:`\Delta`) or the falling one. On the rising branch of the steady loop the contact
    sticks at :math:`x = -\delta^*` after the reversal, :math:`Q = S(\Delta + \delta^*)`,
    then slips forward with :math:`Q = Q_+(x)`, :math:`x + Q_+(x)/S = \Delta` (eq. 9, 10,
    16); the falling branch is its image under :math:`(\Delta, Q) \to (-\Delta, -Q)`. The
    loop may be shifted by an offset in displacement and in force, fitted with the rest.
    Six parameters are fitted, in scaled form (:math:`\mu`, :math:`SL/P`, :math:`z_o/L`,
    :math:`\Delta^*/L` and the offsets in units of :math:`L` and :math:`P`, with :math:`L`
    half the measured peak-to-peak displacement), by ``scipy.optimize.least_squares``
    (trust region reflective, bounds :math:`\mu > 0`, :math:`S > 0`, :math:`z_o \ge 0`)
    with the Jacobian from ``jax.jacfwd``. Starting values come from the loop itself
    (stick slopes, and :math:`Q/P` against the contact position on the slip segments).
    The paper sets :math:`\mu` to the loop's GICoF and reads :math:`S` off the loop (Section
    4.2, Figure 10); for the model loop both equal the fitted values.
    """
    check("load", load, "positive", "N")
    if np.ndim(load) != 0:
        raise ValueError(f"load must be a single number [N], got shape {np.shape(load)}")
    load = float(load)
    x = np.asarray(displacement, dtype=np.float64)
    y = np.asarray(force, dtype=np.float64)
    for name, values in (("displacement", x), ("force", y)):
        if values.ndim != 1:
            raise ValueError(f"{name} must be one-dimensional, got shape {values.shape}")
    if x.size != y.size:
        raise ValueError(
            f"displacement and force must have the same length, got {x.size} and {y.size}"
        )
    if x.size < MIN_SAMPLES:
        raise ValueError(f"a loop needs at least {MIN_SAMPLES} samples, got {x.size}")
    check("displacement", x, "finite", "m")
    check("force", y, "finite", "N")
    length = (x.max() - x.min()) / 2.0
    if not length > 0:
        raise ValueError("displacement does not vary: a loop needs a displacement stroke")

    rising = _branches(x)
    centre = (x.max() + x.min()) / 2.0
    offset = (y.max() + y.min()) / 2.0
    scaled_x = (x - centre) / length
    scaled_y = (y - offset) / load
    start = _starting_values(scaled_x, scaled_y, rising)

    arguments = (jnp.asarray(scaled_x), jnp.asarray(scaled_y), jnp.asarray(rising))
    tiny = np.finfo(np.float64).tiny
    solution = least_squares(
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
    mu, s, a, amplitude, shift, force_shift = (float(v) for v in solution.x)
    model_force = y + load * solution.fun
    residual = y - model_force
    gross_slip = mu / (s * amplitude) < 1.0
    message = solution.message
    if not gross_slip:
        message = f"{message} (but the fitted loop has no gross slip: mu * P / (S Δ*) >= 1)"
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
        success=bool(solution.success and gross_slip),
        evaluations=int(solution.nfev),
        message=message,
        displacement=x,
        force=y,
        model_force=model_force,
        rising=rising,
    )
