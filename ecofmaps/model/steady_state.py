r"""The model in SI units: slip amplitude, energy, ECoF, peak force and regime of the steady loop,
from the dimensionless core (:mod:`ecofmaps.model.core`) with :math:`L = \Delta^*`, or on a scar
profile (:mod:`ecofmaps.model.on_profile`).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from ecofmaps._codes import warn_nan
from ecofmaps._inputs import as_float64, float64, is_concrete
from ecofmaps.model import core
from ecofmaps.model.core import valid_geometry
from ecofmaps.model.on_profile import steady_numbers, steady_values
from ecofmaps.model.regimes import INVALID, Regime

#: The quantities' names among :func:`ecofmaps.model.on_profile.steady_values`, where other.
_ON_PROFILE = {"energy_cof": "ecof"}


def dimensionless(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width):
    """The core numbers ``(mu, kappa, lam)`` of SI inputs, and their regime."""
    kappa = core.curvature_number(amplitude, aspect_ratio, groove_half_width)
    lam = core.compliance_ratio(amplitude, load, stiffness)
    valid = valid_geometry(amplitude, load, stiffness, aspect_ratio, groove_half_width)
    code = jnp.where(valid, core.regime_code(mu, kappa, lam), int(INVALID)).astype(jnp.int32)
    return mu, kappa, lam, code


@jax.jit(static_argnames="quantity")
def _steady_state(quantity, amplitude, load, stiffness, mu, aspect_ratio, groove_half_width):
    """One steady-loop quantity and the regime, NaN where the input is invalid."""
    mu, kappa, lam, code = dimensionless(
        amplitude, load, stiffness, mu, aspect_ratio, groove_half_width
    )
    if quantity == "slip_regime":
        return code, code
    numbers = {
        name: getattr(core, name)(mu, kappa, lam)
        for name in ("slip_ratio", "ecof_ratio", "normalized_energy", "normalized_max_force")
    }
    value = steady_values(numbers, amplitude, load, mu)[_ON_PROFILE.get(quantity, quantity)]
    return jnp.where(code == int(INVALID), jnp.nan, value), code


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


@jax.jit(static_argnames="quantity")
def _profile_quantity(quantity, numbers, amplitude, load, mu):
    if quantity == "slip_regime":
        value = numbers["regime"]
    else:
        value = steady_values(numbers, amplitude, load, mu)[_ON_PROFILE.get(quantity, quantity)]
    return jnp.broadcast_to(value, numbers["regime"].shape)


def _steady_quantity(quantity: str, summary: str, returns: str, equations: str):
    """The public function ``quantity`` of the steady loop, with its docstring."""

    def steady_quantity(
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
        one_geometry(aspect_ratio, profile, mapping)
        if profile is None:
            arguments = (amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
            result, code = _steady_state(quantity, *core.steady_inputs(*arguments))
            concrete = is_concrete(*arguments)
        else:
            numbers = steady_numbers(
                profile, amplitude, load, stiffness, mu, groove_half_width, mapping
            )
            si = (as_float64(v) for v in (amplitude, load, mu))
            result, code = _profile_quantity(quantity, numbers, *si), numbers["regime"]
            concrete = is_concrete(result)
        if concrete and quantity != "slip_regime":
            warn_nan(result, code, Regime, quantity)
        return result

    steady_quantity.__name__ = steady_quantity.__qualname__ = quantity
    steady_quantity.__doc__ = f"""{summary}

    Parameters
    ----------
    amplitude, load, stiffness, mu : array_like
        Displacement amplitude imposed by the actuator :math:`\\Delta^*` [m], normal load
        :math:`P` [N], rig stiffness :math:`S` (``numpy.inf``: a rigid rig) [N/m] and contact
        coefficient of friction :math:`\\mu` [1].
    aspect_ratio : array_like, optional
        Groove depth over half-width :math:`z_o/x_o` of a parabolic groove (eq. 11: scar
        depth over half-width :math:`D/W`). Give this or ``profile``. [1]
    groove_half_width : array_like, optional
        Groove half-width :math:`x_o`; defaults to ``amplitude`` as in the paper. On a
        profile it sets the mapping :math:`X = xW/x_o` of eq. 11. [m]
    profile : ScarProfile, optional
        A scar profile of any shape instead of ``aspect_ratio`` (``docs/model.md``); a
        parabolic one reproduces the closed forms with ``aspect_ratio=D/W``.
    mapping : {{'scaled', 'physical'}}
        On a profile: :math:`X = xW/x_o` (eq. 11, the paper's) or :math:`X = x`.

    Returns
    -------
    {returns}

    Raises
    ------
    ValueError
        For a concrete input out of its range (amplitude, load, mu, groove_half_width finite
        and > 0, stiffness > 0 or inf, aspect_ratio finite and >= 0, each within
        :data:`ecofmaps.units.DOMAIN`); for both or neither of aspect_ratio and profile, or a
        bad mapping. A traced value is not checked: out of range, it gives NaN and ``INVALID``.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. {equations}.
"""
    return float64(steady_quantity)


slip_amplitude = _steady_quantity(
    "slip_amplitude",
    """Slip amplitude :math:`\\delta^*` of the steady fretting loop, the root of
    :math:`\\delta^* + Q_+(\\delta^*)/S = \\Delta^*` (eq. 9, 10, 16; :func:`slip_position`).""",
    """slip_amplitude : jax.Array of float64
        :math:`\\delta^*`, the loop's half-width at :math:`Q = 0` (flat groove:
        :math:`\\Delta^* - \\mu P/S`; rigid rig: :math:`\\Delta^*`); 0 with no gross slip,
        NaN when self-locking. [m]""",
    "9, 10, 11, 16",
)
slip_amplitude.__doc__ += """
    Examples
    --------
    >>> round(float(slip_amplitude(50e-6, 450.0, 35e6, 0.8, 0.2)) * 1e6, 3)  # Example 2 [um]
    32.73
"""
dissipated_energy = _steady_quantity(
    "dissipated_energy",
    "Energy dissipated per cycle :math:`E_d`, the loop's area (eq. 12), as :math:`4 P \\delta^*"
    "\\mu_E` (eq. 14 corrected).",
    """dissipated_energy : jax.Array of float64
        :math:`E_d = 2\\int_{-\\delta^*}^{\\delta^*} Q_+\\,dx = \\oint Q\\,d\\Delta`; 0 with
        no gross slip, NaN when self-locking. [J]""",
    "9, 11, 12, 14",
)
energy_cof = _steady_quantity(
    "energy_cof",
    "Energy coefficient of friction :math:`\\mu_E = E_d/(4P\\delta^*)` (eq. 1; eq. 13-15 "
    "corrected as :func:`ecofmaps.model.ecof_ratio` says).",
    """energy_cof : jax.Array of float64
        :math:`\\mu_E \\ge \\mu`; NaN with no gross slip (a :class:`RegimeWarning` says so
        for concrete inputs) and when self-locking. [1]""",
    "1, 9, 11, 13-15",
)
max_force = _steady_quantity(
    "max_force",
    "Peak tangential force :math:`Q^*` of the steady loop (eq. 9).",
    """max_force : jax.Array of float64
        :math:`Q^* = Q_+(\\delta^*)`; :math:`S\\Delta^*` with no gross slip; NaN when
        self-locking. On a profile, the largest tangential force over the loop (with no
        gross slip, the rig's force at :math:`\\Delta^*` on the stuck pad). [N]""",
    "9, 11, 16",
)
slip_regime = _steady_quantity(
    "slip_regime",
    "Regime of each point as :class:`Regime` codes.",
    """regime : jax.Array of int32
        ``GROSS_SLIP`` (0), ``NO_GROSS_SLIP`` (1), ``SELF_LOCKING`` (2), ``INVALID`` (3,
        only under ``jit``/``vmap``: concrete invalid input raises) or, on a profile,
        ``BEYOND_PROFILE`` (4). Compare with the :class:`Regime` members.""",
    "9, 11, 16",
)
