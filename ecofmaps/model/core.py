r"""The dimensionless core of the model: pure ``jax.numpy`` functions of ``mu``, the curvature
number ``kappa`` and the compliance ratio ``lam`` that broadcast, work under ``jit``, ``vmap``
and ``grad`` and check nothing (``docs/model.md``); and the checks of the SI inputs.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from ecofmaps._inputs import as_float64, check
from ecofmaps.model.regimes import GROSS_SLIP, INVALID, NO_GROSS_SLIP, SELF_LOCKING

#: The rule and unit of each SI input, for :func:`ecofmaps._inputs.check`, in the order of
#: :func:`steady_inputs`' arguments.
_RULES = {
    "amplitude": ("positive", "m"),
    "load": ("positive", "N"),
    "stiffness": ("positive_or_inf", "N/m"),
    "mu": ("positive", "1"),
    "aspect_ratio": ("non_negative", "1"),
    "groove_half_width": ("positive", "m"),
}


def checked(**inputs) -> list:
    """The SI inputs given (not None) as float64; ``ValueError`` for a concrete one out of range."""
    for name, value in inputs.items():
        if value is not None:
            check(name, value, *_RULES[name])
    return [as_float64(value) for value in inputs.values() if value is not None]


def steady_inputs(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width) -> list:
    """:func:`checked` inputs of a steady loop; x_o defaults to the amplitude."""
    inputs = (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    values = checked(**dict(zip(_RULES, inputs, strict=True)))
    return values if groove_half_width is not None else [*values, values[0]]


def _positive(value):
    return (value > 0.0) & jnp.isfinite(value)


def valid_geometry(amplitude, load, stiffness, aspect_ratio, groove_half_width):
    """True where the SI inputs other than mu are in range (:func:`checked` for traced inputs)."""
    rig = (stiffness > 0.0) & ~jnp.isnan(stiffness)
    groove = (aspect_ratio >= 0.0) & jnp.isfinite(aspect_ratio) & _positive(groove_half_width)
    return _positive(amplitude) & _positive(load) & rig & groove


def curvature_number(length, aspect_ratio, groove_half_width):
    r"""Curvature number :math:`\kappa = 2 (z_o/x_o)(L/x_o)`.

    Parameters
    ----------
    length, aspect_ratio, groove_half_width : array_like
        The reference length :math:`L` (the amplitude :math:`\Delta^*`) [m], groove depth
        over half-width :math:`z_o/x_o` [1] and groove half-width :math:`x_o` [m].

    Returns
    -------
    kappa : jax.Array
        The groove slope at :math:`x = L`, eq. 7. [1]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 7.
    """
    return 2.0 * aspect_ratio * length / groove_half_width


def compliance_ratio(length, load, stiffness):
    r"""Compliance ratio :math:`\lambda = P/(S L)`; 0 for a rigid rig (``stiffness=inf``).

    Parameters
    ----------
    length, load, stiffness : array_like
        The reference length :math:`L` (the amplitude :math:`\Delta^*`) [m], normal load
        :math:`P` [N] and rig stiffness :math:`S` [N/m].

    Returns
    -------
    lam : jax.Array
        The rig's deflection at :math:`Q = P` in units of :math:`L`. [1]
    """
    # Double where: at S = inf the quotient's derivative would be (load/inf^2) * inf = NaN.
    # NumPy in, NumPy out: concrete float64 stays float64 with JAX's 64-bit mode off.
    xp = jnp if any(isinstance(v, jax.Array) for v in (length, load, stiffness)) else np
    rigid = xp.isposinf(stiffness)
    return xp.where(rigid, 0.0, load / (xp.where(rigid, 1.0, stiffness) * length))


def traction_ratio(position, mu, kappa, direction=1.0):
    r"""Tangential force over normal load while slipping, :math:`Q/P = (s\mu + \kappa\xi)/(1 -
    s\mu\kappa\xi)` (eq. 9).

    Parameters
    ----------
    position, mu, kappa, direction : array_like
        Contact position :math:`\xi = x/L`, friction coefficient, curvature number and the
        sign :math:`s` (+1 or -1) of the slip velocity. [1]

    Returns
    -------
    q : jax.Array
        :math:`Q/P`; infinite at the locking point :math:`s\mu\kappa\xi = 1`. [1]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 9.
    """
    slope = kappa * position
    return (direction * mu + slope) / (1.0 - direction * mu * slope)


def slip_roots(target, mu, kappa, lam):
    """Forward-slip equilibrium: the position and its margin to the locking point."""
    a = mu * kappa
    h = a * target + lam * kappa - 1.0
    g = lam * kappa * (1.0 + mu * mu)
    root = jnp.sqrt(h * h + 4.0 * g)
    # Each jnp.where evaluates both branches: feed the unused one a harmless value so that
    # neither produces inf/NaN that would poison gradients.
    h_positive = h > 0.0
    margin = jnp.where(h_positive, 2.0 * g / jnp.where(h_positive, h + root, 1.0), (root - h) / 2.0)
    b = h + 2.0
    c = target - lam * mu
    b_positive = b > 0.0
    position = jnp.where(
        b_positive,
        2.0 * c / jnp.where(b_positive, b + root, 1.0),
        (b - root) / (2.0 * jnp.where(b_positive, 1.0, a)),
    )
    return position, margin


def slip_position(target, mu, kappa, lam):
    r"""Contact position reached by forward slip with the actuator at ``target``: the root of
    :math:`\xi + \lambda\, Q_+(\xi)/P = D` below the locking point (eq. 9, 10, 16).

    Parameters
    ----------
    target, mu, kappa, lam : array_like
        Actuator displacement :math:`D = \Delta/L`, friction coefficient, curvature number,
        compliance ratio. [1]

    Returns
    -------
    xi : jax.Array
        :math:`x/L`; the locking point :math:`1/(\mu\kappa)` for a rigid rig pushed beyond it. [1]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 9, 10, 16.
    """
    return slip_roots(target, mu, kappa, lam)[0]


def locking_margin(target, mu, kappa, lam):
    r"""Margin :math:`w = 1 - \mu\kappa\xi` of :func:`slip_position` to the locking point, the
    denominator of eq. 9, with its digits kept close to locking (``docs/model.md``).

    Parameters
    ----------
    target, mu, kappa, lam : array_like
        As in :func:`slip_position`. [1]

    Returns
    -------
    w : jax.Array
        In :math:`(0, \infty)`; 0 at or beyond the locking point of a rigid rig. [1]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 9, 16.
    """
    return slip_roots(target, mu, kappa, lam)[1]


def regime_code(mu, kappa, lam):
    r"""Regime of each point, as :class:`Regime` integer codes.

    Parameters
    ----------
    mu, kappa, lam : array_like
        Friction coefficient (> 0), curvature number (>= 0), compliance ratio (>= 0). [1]

    Returns
    -------
    code : jax.Array of int32
        ``INVALID`` for inputs out of range or NaN; else ``NO_GROSS_SLIP`` where
        :math:`\mu\lambda \ge 1`; ``SELF_LOCKING`` where :math:`\lambda = 0` and
        :math:`\mu\kappa \ge 1`; ``GROSS_SLIP`` elsewhere.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 9, 16.
    """
    valid = _positive(mu) & (kappa >= 0.0) & jnp.isfinite(kappa) & (lam >= 0.0) & jnp.isfinite(lam)
    code = jnp.where(
        mu * lam >= 1.0,
        int(NO_GROSS_SLIP),
        jnp.where((lam == 0.0) & (mu * kappa >= 1.0), int(SELF_LOCKING), int(GROSS_SLIP)),
    )
    return jnp.where(valid, code, int(INVALID)).astype(jnp.int32)


def slip_ratio(mu, kappa, lam):
    r"""Slip amplitude over displacement amplitude, :math:`d = \delta^*/\Delta^*` (eq. 16).

    Parameters
    ----------
    mu, kappa, lam : array_like
        Friction coefficient, curvature number, compliance ratio. [1]

    Returns
    -------
    d : jax.Array
        In :math:`(0, 1]` in gross slip (flat groove: :math:`1 - \mu\lambda`; rigid rig: 1), 0
        with no gross slip, NaN when self-locking or invalid. [1]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 16.
    """
    code = regime_code(mu, kappa, lam)
    d = jnp.where(code == int(NO_GROSS_SLIP), 0.0, slip_position(1.0, mu, kappa, lam))
    return jnp.where((code == int(GROSS_SLIP)) | (code == int(NO_GROSS_SLIP)), d, jnp.nan)


# Coefficients 1/(2n+1), n = 1..28, of artanh(u)/u - 1 = sum u^(2n)/(2n+1). At |u| < 1/2
# the first omitted term is below 1e-17 of the sum.
_SERIES_LIMIT = 0.5
_SERIES = tuple(1.0 / (2 * n + 1) for n in range(28, 0, -1))


def _artanh_excess(u, margin):
    r""":math:`\operatorname{artanh}(u)/u - 1` for :math:`u = 1 - w` in :math:`[0, 1)`."""
    small = u < _SERIES_LIMIT
    u_small = jnp.where(small, u, 0.0)
    w_large = jnp.where(small, 0.25, margin)
    u2 = u_small * u_small
    series = jnp.zeros_like(u2)
    for coefficient in _SERIES:  # Horner's rule, unrolled at trace time
        series = (series + coefficient) * u2
    direct = 0.5 * jnp.log((2.0 - w_large) / w_large) / (1.0 - w_large) - 1.0
    return jnp.where(small, series, direct)


def ecof_ratio(mu, kappa, lam):
    r"""Energy coefficient of friction over the contact one, :math:`\mu_E/\mu = 1 + (1 + 1/\mu^2)
    (\operatorname{artanh}(u)/u - 1)`, :math:`u = \mu\kappa d`: eq. 13-15, whose printed
    :math:`(1 + 1/\mu)` must read :math:`(1 + 1/\mu^2)`.

    Parameters
    ----------
    mu, kappa, lam : array_like
        Friction coefficient, curvature number, compliance ratio. [1]

    Returns
    -------
    ratio : jax.Array
        :math:`\ge 1` (1 for a flat groove); NaN with no gross slip, self-locking or invalid. [1]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 1, 13-15, 16.
    """
    d = slip_ratio(mu, kappa, lam)
    return jnp.where(d > 0.0, _ratio_at(d, mu, kappa, lam), jnp.nan)


def _ratio_at(d, mu, kappa, lam):
    r""":math:`\mu_E/\mu` at slip ratio ``d``: finite, its gradient too, also at d = 0."""
    excess = _artanh_excess(mu * kappa * d, locking_margin(1.0, mu, kappa, lam))
    return 1.0 + (1.0 + mu * mu) / (mu * mu) * excess


def normalized_max_force(mu, kappa, lam):
    r"""Peak tangential force over normal load, :math:`Q^*/P` (eq. 9 at :math:`x = \delta^*`).

    Parameters
    ----------
    mu, kappa, lam : array_like
        Friction coefficient, curvature number, compliance ratio. [1]

    Returns
    -------
    q_max : jax.Array
        :math:`Q_+(\delta^*)/P` in gross slip; :math:`1/\lambda` (the stick line at
        :math:`\Delta^*`) with no gross slip; NaN when self-locking or invalid. [1]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 9, 16.
    """
    d = slip_ratio(mu, kappa, lam)
    stick = d == 0.0
    q = (mu + kappa * d) / locking_margin(1.0, mu, kappa, lam)  # eq. 9, digits kept
    return jnp.where(stick, 1.0 / jnp.where(stick, lam, 1.0), q)


def normalized_energy(mu, kappa, lam):
    r"""Dissipated energy per cycle over :math:`P\Delta^*`: :math:`4 d\,\mu_E` (eq. 1, 12).

    Parameters
    ----------
    mu, kappa, lam : array_like
        Friction coefficient, curvature number, compliance ratio. [1]

    Returns
    -------
    e : jax.Array
        :math:`E_d/(P\Delta^*)`; 0 with no gross slip; NaN when self-locking or invalid. [1]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 1, 12.
    """
    d = slip_ratio(mu, kappa, lam)
    energy = 4.0 * d * mu * _ratio_at(d, mu, kappa, lam)  # no NaN for where's gradient at d = 0
    return jnp.where(d == 0.0, 0.0, energy)
