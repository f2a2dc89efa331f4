r"""A correction's outcomes: each point's status, the contact CoFs of an aspect-ratio interval, and
where :math:`\mu_E(\mu)` falls (docs/model.md, "Correcting a reported ECoF")."""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from ecofmaps import model
from ecofmaps._codes import Code
from ecofmaps._inputs import as_float64, check

#: :math:`\lambda_\infty`: :math:`\mu_E(\mu)` falls over part of its range only where
#: :math:`\lambda = P/(S\Delta^*)` is below this (its :math:`\kappa \to \infty` limit). [1]
LAMBDA_INFINITY = 0.07102

#: No ECoF below this is ever ambiguous: the infimum of a falling :math:`\mu_E(\mu)`'s local
#: minimum, reached as :math:`\kappa \to \infty` and :math:`\lambda \to \lambda_\infty`. [1]
AMBIGUOUS_ECOF_MIN = 1.6


class CorrectionStatus(Code):
    """Outcome of a correction, per point (``return_status=True``); each code's ``reason``
    says why, docs/model.md ("Correcting a reported ECoF") when.

    Attributes
    ----------
    CORRECTED, NO_GROSS_SLIP, AMBIGUOUS
        One contact CoF gives the ECoF (returned); the ECoF is at or above
        :math:`S\\Delta^*/P`; several contact CoFs give it.
    INVALID
        An input out of range or NaN (under ``jax.jit``/``jax.vmap``; else ``ValueError``).
    OUTSIDE_MAP, UNREACHABLE
        :func:`lookup_correction`: off the map; on a scar profile: no contact CoF gives it.
    """

    CORRECTED = 0, "corrected"
    NO_GROSS_SLIP = (
        1,
        "no gross slip",
        "the ECoF is at or above stiffness * amplitude / load, the largest energy CoF of any "
        "gross-slip loop with these test conditions",
    )
    AMBIGUOUS = (
        2,
        "ambiguous",
        "several contact CoFs give the ECoF (deep groove and stiff rig, where the ECoF falls "
        "as mu rises over part of its range)",
    )
    INVALID = 3, "invalid", "invalid input"
    OUTSIDE_MAP = 4, "outside the map", "the point or the ECoF is outside the map"
    UNREACHABLE = (
        5,
        "unreachable",
        "no contact CoF gives the ECoF on this scar profile (it falls in a jump of the ECoF as "
        "mu rises, or needs a slip beyond the trace)",
    )


class Interval(NamedTuple):
    """The contact CoFs (or correction factors) allowed by an ECoF: ``low <= high``."""

    low: jax.Array
    high: jax.Array


# mu_E(mu) can fall only for kappa > _FALL_KAPPA and 0 < lam < _FALL_LAMBDA; the fall is
# scanned on _FALL_GRID points and located to _FALL_BISECTIONS halvings of a grid step.
_FALL_KAPPA = 1.0
_FALL_LAMBDA = 0.075  # a margin above LAMBDA_INFINITY
_FALL_GRID = 256
_FALL_BISECTIONS = 48


def check_test(ecof, amplitude, load, stiffness) -> None:
    """``ValueError`` for a concrete ECoF or test condition out of its range."""
    check("ecof", ecof, "positive", "1")
    check("amplitude", amplitude, "positive", "m")
    check("load", load, "positive", "N")
    check("stiffness", stiffness, "positive_or_inf", "N/m")


def ecof_and_slope(mu, kappa, lam):
    """:math:`\\mu_E` and :math:`d\\mu_E/d\\mu` at each point (forward mode, elementwise)."""
    return jax.jvp(lambda m: m * model.ecof_ratio(m, kappa, lam), (mu,), (jnp.ones_like(mu),))


def may_fall(kappa, lam):
    """Where :math:`\\mu_E(\\mu)` may fall over part of its range."""
    return (kappa > _FALL_KAPPA) & (lam > 0.0) & (lam < _FALL_LAMBDA)


def ecof_fall(kappa, lam):
    r"""Where :math:`\mu_E(\mu)` falls: its local maximum and minimum, or NaN where it rises
    (only for :math:`\kappa > 1` and :math:`0 < \lambda <` :data:`LAMBDA_INFINITY`; how it is
    found: docs/model.md, "Correcting a reported ECoF").

    Parameters
    ----------
    kappa, lam
        As for :func:`contact_cof`. [1]

    Returns
    -------
    high : jax.Array
        :math:`\mu_E` at the local maximum, where the fall starts (NaN where it rises). [1]
    low : jax.Array
        :math:`\mu_E` at the local minimum, where it ends. An ECoF in ``[low, high]``
        comes from three contact CoFs (two at the ends). [1]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 13-15, 16.
    """
    kappa, lam = jnp.broadcast_arrays(as_float64(kappa), as_float64(lam))
    falls = may_fall(kappa, lam)
    kappa = jnp.where(falls, kappa, 2.0)[..., None]  # harmless values elsewhere
    lam = jnp.where(falls, lam, 0.01)[..., None]
    log_mu = -jnp.log(kappa) * (1.0 - jnp.linspace(0.0, 1.0, _FALL_GRID))  # from 1/kappa to 1
    _, slope = ecof_and_slope(jnp.exp(log_mu), kappa, lam)
    falling = slope <= 0.0
    found = falls & jnp.any(falling, axis=-1)
    first = jnp.clip(jnp.argmax(falling, axis=-1), 1, _FALL_GRID - 2)
    last = jnp.clip(_FALL_GRID - 1 - jnp.argmax(falling[..., ::-1], axis=-1), 1, _FALL_GRID - 2)

    # Brackets of the slope's sign changes: rising at `rise`, falling at `fall`.
    ends = jnp.stack([first, last], axis=-1)
    rise = jnp.take_along_axis(log_mu, ends + jnp.array([-1, 1]), axis=-1)
    fall = jnp.take_along_axis(log_mu, ends, axis=-1)

    def halve(_, bracket):
        rise, fall = bracket
        middle = 0.5 * (rise + fall)
        _, slope = ecof_and_slope(jnp.exp(middle), kappa, lam)
        up = slope > 0.0
        return jnp.where(up, middle, rise), jnp.where(up, fall, middle)

    rise, fall = jax.lax.fori_loop(0, _FALL_BISECTIONS, halve, (rise, fall))
    value, _ = ecof_and_slope(jnp.exp(0.5 * (rise + fall)), kappa, lam)
    return jnp.where(found, value[..., 0], jnp.nan), jnp.where(found, value[..., 1], jnp.nan)
