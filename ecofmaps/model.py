r"""The compliant wear-scar interaction model: traction, slip amplitude, energy, ECoF.

A rigid round-ended pad slides in a parabolic groove :math:`z = z_o (x/x_o)^2` under a
normal load :math:`P`; a spring of stiffness :math:`S` (the rig's compliance) links it
to the actuator, which imposes the displacement :math:`\Delta`. Coulomb friction
:math:`\mu` acts at the contact point.

The dimensionless core
----------------------
Lengths are measured in units of a reference length :math:`L` (the displacement
amplitude :math:`\Delta^*` for the steady loop, the groove half-width :math:`x_o` for a
time history). Three numbers then fix everything:

* ``mu``: the contact coefficient of friction :math:`\mu`;
* ``kappa``: the curvature number :math:`\kappa = k L` with :math:`k = 2 z_o/x_o^2`
  the groove's slope per unit length (eq. 7), so the slope at :math:`\xi = x/L` is
  :math:`\kappa\xi`;
* ``lam``: the compliance ratio :math:`\lambda = P/(S L)`, the rig's deflection at
  :math:`Q = P` over :math:`L` (0 for a rigid rig).

The core functions (:func:`traction_ratio`, :func:`slip_position`, :func:`slip_ratio`,
:func:`locking_margin`, :func:`ecof_ratio`, :func:`normalized_max_force`, :func:`normalized_energy`,
:func:`regime_code`) are pure ``jax.numpy`` functions of these numbers that broadcast
and work under ``jit``, ``vmap`` and ``grad``; they do no input checking. The SI-unit
functions (:func:`slip_amplitude`, :func:`dissipated_energy`, :func:`energy_cof`,
:func:`max_force`, :func:`regime`) validate concrete inputs, are jit-compiled, and
always compute in float64.
"""

from __future__ import annotations

import enum

import jax
import jax.numpy as jnp

from ecofmaps._inputs import as_float64, check, float64, is_concrete, warn_nan

__all__ = [
    "GROSS_SLIP",
    "INVALID",
    "NO_GROSS_SLIP",
    "SELF_LOCKING",
    "Regime",
    "compliance_ratio",
    "curvature_number",
    "dissipated_energy",
    "ecof_ratio",
    "energy_cof",
    "locking_margin",
    "max_force",
    "normalized_energy",
    "normalized_max_force",
    "regime",
    "regime_code",
    "slip_amplitude",
    "slip_position",
    "slip_ratio",
    "traction_ratio",
]


class Regime(enum.IntEnum):
    """Regime codes returned by :func:`regime` and stored in maps.

    Attributes
    ----------
    GROSS_SLIP
        :math:`\\mu\\lambda < 1`: the contact slips over part of every cycle.
    NO_GROSS_SLIP
        :math:`\\mu\\lambda \\ge 1`: the rig's deflection takes all of the amplitude;
        the contact sticks, :math:`\\delta^* = 0`, :math:`E_d = 0`, :math:`\\mu_E` undefined.
    SELF_LOCKING
        Rigid rig (:math:`\\lambda = 0`) and :math:`\\mu\\kappa \\ge 1`: the pad jams on the
        groove flank before the end of the stroke; no solution.
    INVALID
        An input outside its valid range (or NaN).
    """

    GROSS_SLIP = 0
    NO_GROSS_SLIP = 1
    SELF_LOCKING = 2
    INVALID = 3


GROSS_SLIP = Regime.GROSS_SLIP
NO_GROSS_SLIP = Regime.NO_GROSS_SLIP
SELF_LOCKING = Regime.SELF_LOCKING
INVALID = Regime.INVALID

_NAN_REASONS = {
    int(NO_GROSS_SLIP): "no gross slip (mu * load / (stiffness * amplitude) >= 1), "
    "so the energy coefficient of friction is undefined",
    int(SELF_LOCKING): "self-locking (rigid rig with mu * curvature number >= 1: the pad "
    "jams on the groove flank)",
    int(INVALID): "invalid input",
}

# ---------------------------------------------------------------------------------------
# The dimensionless core
# ---------------------------------------------------------------------------------------


def curvature_number(length, aspect_ratio, groove_half_width):
    r"""Curvature number :math:`\kappa = 2 (z_o/x_o)(L/x_o)`.

    Parameters
    ----------
    length : array_like
        The reference length :math:`L` (the amplitude :math:`\Delta^*`). [m]
    aspect_ratio : array_like
        Groove depth over half-width :math:`z_o/x_o`. [1]
    groove_half_width : array_like
        Groove half-width :math:`x_o`. [m]

    Returns
    -------
    kappa : jax.Array
        The groove slope at :math:`x = L`, eq. 7. [1]
    """
    return 2.0 * aspect_ratio * length / groove_half_width


def compliance_ratio(length, load, stiffness):
    r"""Compliance ratio :math:`\lambda = P/(S L)`; 0 for a rigid rig (``stiffness=inf``).

    Parameters
    ----------
    length : array_like
        The reference length :math:`L` (the amplitude :math:`\Delta^*`). [m]
    load : array_like
        Normal load :math:`P`. [N]
    stiffness : array_like
        Rig stiffness :math:`S`. [N/m]

    Returns
    -------
    lam : jax.Array
        The rig's deflection at :math:`Q = P` in units of :math:`L`. [1]
    """
    return load / (stiffness * length)


def traction_ratio(position, mu, kappa, direction=1.0):
    r"""Tangential force over normal load while slipping, :math:`Q/P` (eq. 9).

    .. math:: \frac{Q_s}{P} = \frac{s\mu + \kappa\xi}{1 - s\mu\kappa\xi}

    Parameters
    ----------
    position : array_like
        Contact position :math:`\xi = x/L`. [1]
    mu : array_like
        Contact coefficient of friction. [1]
    kappa : array_like
        Curvature number. [1]
    direction : array_like
        Sign :math:`s` of the slip velocity, +1 or -1. [1]

    Returns
    -------
    q : jax.Array
        :math:`Q/P`; infinite at the locking point :math:`s\mu\kappa\xi = 1`. [1]
    """
    slope = kappa * position
    return (direction * mu + slope) / (1.0 - direction * mu * slope)


def _slip_roots(target, mu, kappa, lam):
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
    r"""Contact position reached by forward slip when the actuator is at ``target``.

    Solves :math:`\xi + \lambda\, Q_+(\xi)/P = D` (eq. 9 with eq. 10) for the root below
    the locking point :math:`\mu\kappa\xi = 1`; with :math:`D = 1` this is eq. 16.
    Multiplying out gives :math:`a\xi^2 - b\xi + c = 0` with :math:`a = \mu\kappa`,
    :math:`b = 1 + \mu\kappa D + \lambda\kappa`, :math:`c = D - \lambda\mu`. The root is
    taken as :math:`2c/(b + \sqrt{b^2 - 4ac})` (no cancellation when :math:`b > 0`, finite
    as :math:`\kappa \to 0`), and the discriminant is summed from non-negative terms,
    :math:`b^2 - 4ac = (aD + \lambda\kappa - 1)^2 + 4\lambda\kappa(1 + \mu^2)`.

    Parameters
    ----------
    target : array_like
        Actuator displacement :math:`D = \Delta/L`. [1]
    mu, kappa, lam : array_like
        Friction coefficient, curvature number, compliance ratio. [1]

    Returns
    -------
    xi : jax.Array
        The contact position :math:`x/L`; it equals the locking point :math:`1/(\mu\kappa)`
        when a rigid rig (``lam = 0``) is pushed beyond it. [1]
    """
    return _slip_roots(target, mu, kappa, lam)[0]


def locking_margin(target, mu, kappa, lam):
    r"""Margin :math:`w = 1 - \mu\kappa\xi` of the forward-slip position to the locking point.

    The denominator of eq. 9 at the position :func:`slip_position` returns, computed
    without cancellation: :math:`w` solves :math:`w^2 + (aD + \lambda\kappa - 1)w -
    \lambda\kappa(1 + \mu^2) = 0` (the quadratic of eq. 16 in :math:`w`), whose positive
    root is taken in the form that never subtracts nearly equal numbers. It keeps its
    relative accuracy when a stiff rig drives a deep groove close to locking, where
    :math:`1 - \mu\kappa\xi` computed from :math:`\xi` would lose every digit.

    Parameters
    ----------
    target : array_like
        Actuator displacement :math:`D = \Delta/L`. [1]
    mu, kappa, lam : array_like
        Friction coefficient, curvature number, compliance ratio. [1]

    Returns
    -------
    w : jax.Array
        In :math:`(0, \infty)`; 0 at or beyond the locking point of a rigid rig. [1]
    """
    return _slip_roots(target, mu, kappa, lam)[1]


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
    """
    valid = (
        (mu > 0.0)
        & jnp.isfinite(mu)
        & (kappa >= 0.0)
        & jnp.isfinite(kappa)
        & (lam >= 0.0)
        & jnp.isfinite(lam)
    )
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
        Friction coefficient, curvature number :math:`2 (z_o/x_o)(\Delta^*/x_o)` and
        compliance ratio :math:`P/(S\Delta^*)`. [1]

    Returns
    -------
    d : jax.Array
        In :math:`(0, 1]` in gross slip, 0 with no gross slip, NaN when self-locking or
        invalid. Flat groove: :math:`1 - \mu\lambda`; rigid rig: 1. [1]
    """
    code = regime_code(mu, kappa, lam)
    d = slip_position(1.0, mu, kappa, lam)
    d = jnp.where(code == int(NO_GROSS_SLIP), 0.0, d)
    return jnp.where((code == int(GROSS_SLIP)) | (code == int(NO_GROSS_SLIP)), d, jnp.nan)


# Coefficients 1/(2n+1), n = 1..28, of artanh(u)/u - 1 = sum u^(2n)/(2n+1). At |u| < 1/2
# the first omitted term is below 1e-17 of the sum.
_SERIES_LIMIT = 0.5
_SERIES = tuple(1.0 / (2 * n + 1) for n in range(28, 0, -1))


def _artanh_excess(u, margin):
    r""":math:`\operatorname{artanh}(u)/u - 1` for :math:`u = 1 - w` in :math:`[0, 1)`.

    A series at :math:`u < 1/2` (no cancellation as :math:`u \to 0`); above, the logarithm
    of :math:`(2 - w)/w` with the margin :math:`w` itself, so the digits of :math:`1 - u`
    are not lost near the locking point.
    """
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
    r"""Energy coefficient of friction over the contact one, :math:`\mu_E/\mu`.

    The corrected eq. 13-15 (the printed coefficient :math:`(1 + 1/\mu)` of the logarithm
    must read :math:`(1 + 1/\mu^2)`), with :math:`u = \mu\kappa d`:

    .. math:: \frac{\mu_E}{\mu} = 1 + \frac{1 + \mu^2}{\mu^2}
              \left(\frac{\operatorname{artanh} u}{u} - 1\right)

    Parameters
    ----------
    mu, kappa, lam : array_like
        Friction coefficient, curvature number, compliance ratio. [1]

    Returns
    -------
    ratio : jax.Array
        :math:`\ge 1`; exactly 1 for a flat groove; NaN with no gross slip, when
        self-locking, or for invalid input. [1]
    """
    d = slip_ratio(mu, kappa, lam)
    excess = _artanh_excess(mu * kappa * d, locking_margin(1.0, mu, kappa, lam))
    ratio = 1.0 + (1.0 + mu * mu) / (mu * mu) * excess
    return jnp.where(d > 0.0, ratio, jnp.nan)


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
    """
    d = slip_ratio(mu, kappa, lam)
    energy = 4.0 * d * mu * ecof_ratio(mu, kappa, lam)
    return jnp.where(d == 0.0, 0.0, energy)


# ---------------------------------------------------------------------------------------
# SI-unit API
# ---------------------------------------------------------------------------------------

_CORE = {
    "slip_amplitude": lambda mu, kappa, lam, length, load: length * slip_ratio(mu, kappa, lam),
    "dissipated_energy": lambda mu, kappa, lam, length, load: (
        load * length * normalized_energy(mu, kappa, lam)
    ),
    "energy_cof": lambda mu, kappa, lam, length, load: mu * ecof_ratio(mu, kappa, lam),
    "max_force": lambda mu, kappa, lam, length, load: load * normalized_max_force(mu, kappa, lam),
}


def dimensionless(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width):
    """The core numbers ``(mu, kappa, lam)`` of SI inputs, and their regime.

    Any input out of its range (NaN included) gives the ``INVALID`` code.
    """
    kappa = curvature_number(amplitude, aspect_ratio, groove_half_width)
    lam = compliance_ratio(amplitude, load, stiffness)
    valid = valid_geometry(amplitude, load, stiffness, aspect_ratio, groove_half_width)
    code = jnp.where(valid, regime_code(mu, kappa, lam), int(INVALID)).astype(jnp.int32)
    return mu, kappa, lam, code


def valid_geometry(amplitude, load, stiffness, aspect_ratio, groove_half_width):
    """True where the SI inputs other than mu are in range (traced-input counterpart of
    :func:`check_model_inputs`): all finite and > 0, stiffness may be inf, aspect ratio >= 0.
    """
    return (
        (amplitude > 0.0)
        & jnp.isfinite(amplitude)
        & (load > 0.0)
        & jnp.isfinite(load)
        & (stiffness > 0.0)
        & ~jnp.isnan(stiffness)
        & (aspect_ratio >= 0.0)
        & jnp.isfinite(aspect_ratio)
        & (groove_half_width > 0.0)
        & jnp.isfinite(groove_half_width)
    )


@jax.jit(static_argnames="quantity")
def _steady_state(quantity, amplitude, load, stiffness, mu, aspect_ratio, groove_half_width):
    """One steady-loop quantity and the regime, NaN where the input is invalid."""
    mu, kappa, lam, code = dimensionless(
        amplitude, load, stiffness, mu, aspect_ratio, groove_half_width
    )
    if quantity == "regime":
        return code, code
    value = _CORE[quantity](mu, kappa, lam, amplitude, load)
    return jnp.where(code == int(INVALID), jnp.nan, value), code


def check_model_inputs(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width):
    """Raise ``ValueError`` for concrete inputs out of range; return them as float64."""
    check("amplitude", amplitude, "positive", "m")
    check("load", load, "positive", "N")
    check("stiffness", stiffness, "positive_or_inf", "N/m")
    check("mu", mu, "positive", "1")
    check("aspect_ratio", aspect_ratio, "non_negative", "1")
    if groove_half_width is not None:
        check("groove_half_width", groove_half_width, "positive", "m")
    values = [as_float64(v) for v in (amplitude, load, stiffness, mu, aspect_ratio)]
    values.append(values[0] if groove_half_width is None else as_float64(groove_half_width))
    return values


def _evaluate(quantity, arguments):
    values = check_model_inputs(*arguments)
    result, code = _steady_state(quantity, *values)
    if is_concrete(*arguments) and quantity != "regime":
        warn_nan(result, code, _NAN_REASONS, quantity)
    return result


_PARAMETERS = """
    Parameters
    ----------
    amplitude : array_like
        Displacement amplitude imposed by the actuator, :math:`\\Delta^*`. [m]
    load : array_like
        Normal load :math:`P`. [N]
    stiffness : array_like
        Rig stiffness :math:`S`; ``numpy.inf`` for a rigid rig. [N/m]
    mu : array_like
        Contact coefficient of friction :math:`\\mu`. [1]
    aspect_ratio : array_like
        Groove depth over half-width :math:`z_o/x_o` (eq. 11: scar depth over half-width
        :math:`D/W`). [1]
    groove_half_width : array_like, optional
        Groove half-width :math:`x_o`; defaults to ``amplitude`` as in the paper. [m]
"""

_RAISES = """
    Raises
    ------
    ValueError
        For a concrete input out of its range: amplitude, load, mu and groove_half_width
        must be finite and > 0, stiffness > 0 (inf allowed), aspect_ratio finite and >= 0.
        Under ``jax.jit``/``jax.vmap`` such points give NaN and the ``INVALID`` regime.
"""


@float64
def slip_amplitude(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width=None):
    return _evaluate(
        "slip_amplitude", (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    )


slip_amplitude.__doc__ = f"""Slip amplitude :math:`\\delta^*` of the steady fretting loop (eq. 16).
{_PARAMETERS}
    Returns
    -------
    slip_amplitude : jax.Array of float64
        :math:`\\delta^*`, the loop's half-width at :math:`Q = 0`; 0 with no gross slip,
        NaN when self-locking. [m]
{_RAISES}
    Notes
    -----
    Solves :math:`\\delta^* + Q_+(\\delta^*)/S = \\Delta^*` (eq. 9, 10, 16) in closed form;
    see :func:`slip_position`. Flat groove: :math:`\\Delta^* - \\mu P/S`; rigid rig:
    :math:`\\Delta^*`.

    Examples
    --------
    >>> float(slip_amplitude(50e-6, 450.0, 35e6, 0.8, 0.2))  # Example 2 of the paper
    4.00...e-05
"""


@float64
def dissipated_energy(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width=None):
    return _evaluate(
        "dissipated_energy", (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    )


dissipated_energy.__doc__ = f"""Energy dissipated per cycle :math:`E_d`, the loop's area (eq. 12).
{_PARAMETERS}
    Returns
    -------
    dissipated_energy : jax.Array of float64
        :math:`E_d = 2\\int_{{-\\delta^*}}^{{\\delta^*}} Q_+\\,dx = \\oint Q\\,d\\Delta`; 0 with
        no gross slip, NaN when self-locking. [J]
{_RAISES}
    Notes
    -----
    Evaluated as :math:`4 P \\delta^* \\mu_E` with the corrected eq. 14.
"""


@float64
def energy_cof(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width=None):
    return _evaluate(
        "energy_cof", (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    )


energy_cof.__doc__ = f"""Energy coefficient of friction :math:`\\mu_E = E_d/(4P\\delta^*)` (eq. 1).
{_PARAMETERS}
    Returns
    -------
    energy_cof : jax.Array of float64
        :math:`\\mu_E \\ge \\mu`; NaN with no gross slip (a :class:`RegimeWarning` says so
        for concrete inputs) and when self-locking. [1]
{_RAISES}
    Notes
    -----
    The paper's eq. 13-15 print the coefficient of the logarithm as
    :math:`(x_o^2/2z_o)(1 + 1/\\mu)`; it must be :math:`(x_o^2/2z_o)(1 + 1/\\mu^2)`.
    With :math:`u = \\mu k \\delta^*`, :math:`\\mu_E = \\mu + ((1+\\mu^2)/\\mu)
    (\\operatorname{{artanh}}(u)/u - 1)`, summed as a series at small :math:`u`.
"""


@float64
def max_force(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width=None):
    return _evaluate("max_force", (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width))


max_force.__doc__ = f"""Peak tangential force :math:`Q^*` of the steady loop (eq. 9).
{_PARAMETERS}
    Returns
    -------
    max_force : jax.Array of float64
        :math:`Q^* = Q_+(\\delta^*)`; :math:`S\\Delta^*` with no gross slip; NaN when
        self-locking. [N]
{_RAISES}"""


@float64
def regime(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width=None):
    return _evaluate("regime", (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width))


regime.__doc__ = f"""Regime of each point as :class:`Regime` codes.
{_PARAMETERS}
    Returns
    -------
    regime : jax.Array of int32
        ``GROSS_SLIP`` (0), ``NO_GROSS_SLIP`` (1), ``SELF_LOCKING`` (2) or ``INVALID`` (3,
        only under ``jit``/``vmap``: concrete invalid input raises). Compare with the
        :class:`Regime` members.
{_RAISES}"""
