r"""The model in SI units: slip amplitude, energy, ECoF, peak force and regime of the steady loop.

Each function validates concrete inputs (a ``ValueError`` names the parameter and its
range), is jit-compiled and always computes in float64; under ``jit``/``vmap`` invalid
points are NaN with the ``INVALID`` regime. The numbers come from the dimensionless core
(:mod:`ecofmaps.model.core`) with :math:`L = \Delta^*`.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from ecofmaps._codes import warn_nan
from ecofmaps._inputs import as_float64, check, float64, is_concrete
from ecofmaps.model.core import (
    compliance_ratio,
    curvature_number,
    ecof_ratio,
    normalized_energy,
    normalized_max_force,
    regime_code,
    slip_ratio,
)
from ecofmaps.model.on_profile import steady_numbers, steady_values
from ecofmaps.model.regimes import INVALID, Regime

#: The quantities' names among :func:`ecofmaps.model.on_profile.steady_values`, where other.
_ON_PROFILE = {"energy_cof": "ecof"}

__all__ = [
    "check_model_inputs",
    "dimensionless",
    "dissipated_energy",
    "energy_cof",
    "max_force",
    "slip_amplitude",
    "slip_regime",
    "valid_geometry",
]


_CORE = {
    "slip_amplitude": lambda mu, kappa, lam, length, load: length * slip_ratio(mu, kappa, lam),
    "dissipated_energy": lambda mu, kappa, lam, length, load: (
        load * length * normalized_energy(mu, kappa, lam)
    ),
    "energy_cof": lambda mu, kappa, lam, length, load: mu * ecof_ratio(mu, kappa, lam),
    "max_force": lambda mu, kappa, lam, length, load: load * normalized_max_force(mu, kappa, lam),
}


def dimensionless(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width):
    """The core numbers ``(mu, kappa, lam)`` of SI inputs, and their regime."""
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


def one_geometry(aspect_ratio, profile, mapping="scaled") -> None:
    """``ValueError`` unless exactly one of ``aspect_ratio`` and ``profile`` is given."""
    if (aspect_ratio is None) == (profile is None):
        raise ValueError(
            "give the groove exactly one way: aspect_ratio (a parabolic groove, z_o/x_o = D/W, "
            "eq. 11) or profile (a ScarProfile of any shape), "
            + ("not both" if profile is not None else "got neither")
        )
    if profile is None and mapping != "scaled":
        raise ValueError("mapping applies to a profile only (profile=...)")


def _evaluate_on_profile(quantity, arguments, profile, mapping):
    amplitude, load, stiffness, mu, _, groove_half_width = arguments
    numbers = steady_numbers(profile, amplitude, load, stiffness, mu, groove_half_width, mapping)
    result = _profile_quantity(quantity, numbers, *(as_float64(v) for v in (amplitude, load, mu)))
    if is_concrete(result) and quantity != "regime":
        warn_nan(result, numbers["regime"], Regime, quantity)
    return result


@jax.jit(static_argnames="quantity")
def _profile_quantity(quantity, numbers, amplitude, load, mu):
    if quantity == "regime":
        value = numbers["regime"]
    else:
        value = steady_values(numbers, amplitude, load, mu)[_ON_PROFILE.get(quantity, quantity)]
    return jnp.broadcast_to(value, numbers["regime"].shape)


def _evaluate(quantity, arguments, profile=None, mapping="scaled"):
    one_geometry(arguments[4], profile, mapping)
    if profile is not None:
        return _evaluate_on_profile(quantity, arguments, profile, mapping)
    values = check_model_inputs(*arguments)
    result, code = _steady_state(quantity, *values)
    if is_concrete(*arguments) and quantity != "regime":
        warn_nan(result, code, Regime, quantity)
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
    aspect_ratio : array_like, optional
        Groove depth over half-width :math:`z_o/x_o` of a parabolic groove (eq. 11: scar
        depth over half-width :math:`D/W`). Give this or ``profile``. [1]
    groove_half_width : array_like, optional
        Groove half-width :math:`x_o`; defaults to ``amplitude`` as in the paper. On a
        profile it sets the mapping :math:`X = xW/x_o` of eq. 11. [m]
    profile : ScarProfile, optional
        A wear-scar profile of any shape (:func:`ecofmaps.scar_profile`,
        :func:`ecofmaps.read_scar_profile`, the profile families), instead of
        ``aspect_ratio``: the pad at contact position :math:`x` feels its slope at
        :math:`X = xW/x_o` (eq. 9 pointwise). A parabolic profile reproduces the closed
        forms with ``aspect_ratio=D/W``.
    mapping : {'scaled', 'physical'}
        On a profile: ``'scaled'``, :math:`X = xW/x_o` (eq. 11, the paper's); or
        ``'physical'``, :math:`X = x`.
"""

_RAISES = """
    Raises
    ------
    ValueError
        For a concrete input out of its range: amplitude, load, mu and groove_half_width
        must be finite and > 0, stiffness > 0 (inf allowed), aspect_ratio finite and >= 0;
        for both or neither of aspect_ratio and profile, or a bad mapping. Under
        ``jax.jit``/``jax.vmap`` such points give NaN and the ``INVALID`` regime.
"""

_PROFILE_NOTES = """
    On a profile the steady loop's ends solve :math:`x + Q_\\pm(x)/S = \\pm\\Delta^*` by
    first passage from where the last stroke ended, the pad jumping where
    :math:`x + Q_+(x)/S` falls; :math:`\\delta^* = (x_+ - x_-)/2` and :math:`E_d` is the
    area of the loop the return map draws (:mod:`ecofmaps.model.first_passage`). The regime
    ``BEYOND_PROFILE`` marks a stroke that runs off the trace.
"""


@float64
def slip_amplitude(
    amplitude,
    load,
    stiffness,
    mu,
    aspect_ratio=None,
    groove_half_width=None,
    *,
    profile=None,
    mapping="scaled",
):
    arguments = (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    return _evaluate("slip_amplitude", arguments, profile, mapping)


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
{_PROFILE_NOTES}
    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 10, 11, 16.

    Examples
    --------
    >>> round(float(slip_amplitude(50e-6, 450.0, 35e6, 0.8, 0.2)) * 1e6, 3)  # Example 2 [um]
    32.73
"""


@float64
def dissipated_energy(
    amplitude,
    load,
    stiffness,
    mu,
    aspect_ratio=None,
    groove_half_width=None,
    *,
    profile=None,
    mapping="scaled",
):
    arguments = (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    return _evaluate("dissipated_energy", arguments, profile, mapping)


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
{_PROFILE_NOTES}
    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 11, 12, 14.
"""


@float64
def energy_cof(
    amplitude,
    load,
    stiffness,
    mu,
    aspect_ratio=None,
    groove_half_width=None,
    *,
    profile=None,
    mapping="scaled",
):
    arguments = (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    return _evaluate("energy_cof", arguments, profile, mapping)


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
{_PROFILE_NOTES}
    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 1, 9, 11, 13-15.
"""


@float64
def max_force(
    amplitude,
    load,
    stiffness,
    mu,
    aspect_ratio=None,
    groove_half_width=None,
    *,
    profile=None,
    mapping="scaled",
):
    arguments = (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    return _evaluate("max_force", arguments, profile, mapping)


max_force.__doc__ = f"""Peak tangential force :math:`Q^*` of the steady loop (eq. 9).
{_PARAMETERS}
    Returns
    -------
    max_force : jax.Array of float64
        :math:`Q^* = Q_+(\\delta^*)`; :math:`S\\Delta^*` with no gross slip; NaN when
        self-locking. On a profile, the largest tangential force over the loop (with no
        gross slip, the rig's force at :math:`\\Delta^*` on the stuck pad). [N]
{_RAISES}
    Notes
    -----{_PROFILE_NOTES}
    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 11, 16.
"""


@float64
def slip_regime(
    amplitude,
    load,
    stiffness,
    mu,
    aspect_ratio=None,
    groove_half_width=None,
    *,
    profile=None,
    mapping="scaled",
):
    arguments = (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    return _evaluate("regime", arguments, profile, mapping)


slip_regime.__doc__ = f"""Regime of each point as :class:`Regime` codes.
{_PARAMETERS}
    Returns
    -------
    regime : jax.Array of int32
        ``GROSS_SLIP`` (0), ``NO_GROSS_SLIP`` (1), ``SELF_LOCKING`` (2), ``INVALID`` (3,
        only under ``jit``/``vmap``: concrete invalid input raises) or, on a profile,
        ``BEYOND_PROFILE`` (4). Compare with the :class:`Regime` members.
{_RAISES}
    Notes
    -----{_PROFILE_NOTES}
    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 11, 16.
"""
