r"""Legacy energy coefficients of friction corrected to the contact one.

Much of the fretting literature reports the energy coefficient of friction
:math:`\mu_E = E_d/(4P\delta^*)` (eq. 1). With the rig's compliance and a wear scar shaped
like a groove it is not the contact :math:`\mu` (Figures 8 and 11). Given the test
conditions (:math:`\Delta^*`, :math:`P`, :math:`S`) and the scar's aspect ratio
:math:`z_o/x_o = D/W` (eq. 11, with :math:`x_o = \Delta^*` as in the paper),
:func:`correct_ecof` inverts the model's :math:`\mu_E(\mu)` exactly and
:func:`lookup_correction` reads the same inversion off a map from
:func:`ecofmaps.compute_map`.

The inversion, in the dimensionless core of :mod:`ecofmaps.model` (:math:`\mu`,
:math:`\kappa = 2 z_o/x_o`, :math:`\lambda = P/(S\Delta^*)`):

* :math:`\mu_E(\mu)` is continuous on the gross-slip range :math:`0 < \mu < \mu_{max}`,
  with :math:`\mu_{max} = 1/\lambda` (:math:`1/\kappa` for a rigid rig, where the pad
  locks), and :math:`\mu \le \mu_E`. It runs from 0 (:math:`\mu \to 0`) to :math:`1/\lambda`
  (:math:`\mu \to 1/\lambda`, where :math:`\delta^* \to 0`; to :math:`\infty` for a rigid
  rig), and :math:`\mu_E < (1 - \delta^*/\Delta^*)/\lambda < 1/\lambda` throughout, since
  :math:`\mu_E P` is the mean of :math:`Q_+` over the slip and :math:`Q_+` rises to its
  peak :math:`S(\Delta^* - \delta^*)` (eq. 9, 10, 12). So every ECoF in
  :math:`(0, S\Delta^*/P)` comes from some :math:`\mu`, and no other does: a larger one
  would need a contact CoF that stops gross slip (status ``NO_GROSS_SLIP``).
* :math:`\mu_E(\mu)` rises monotonically unless the groove is deep and the rig stiff:
  it falls over part of its range only when :math:`\kappa > 1` and
  :math:`\lambda < \lambda_\infty \approx 0.07102` (:math:`\lambda_\infty` is the
  :math:`\kappa \to \infty` limit of the largest such :math:`\lambda`; at :math:`\kappa = 10`
  it is 0.0248, and the smallest :math:`\kappa` grows from 1 as :math:`\lambda` grows from
  0, e.g. 2.5 at :math:`\lambda = 10^{-4}`). The fall lies in :math:`1/\kappa < \mu < 1`,
  where :math:`\mu_E/\mu > 4`. There, an ECoF between the local minimum and maximum of
  :math:`\mu_E(\mu)` comes from three contact CoFs (status ``AMBIGUOUS``); the local
  minimum is above 1.6 (its infimum, reached as :math:`\kappa \to \infty` and
  :math:`\lambda \to \lambda_\infty`), so no ECoF below 1.6 is ever ambiguous. The tests
  check these bounds on dense grids.
* :math:`\mu_E` rises with :math:`z_o/x_o` at fixed :math:`\mu` (:math:`\kappa\delta^*`
  rises with :math:`\kappa`, and :math:`\mu_E` is the mean of a convex function over
  :math:`[-\kappa\delta^*, \kappa\delta^*]` in the slope), so for an aspect ratio known
  only to lie in :math:`[a, b]` the contact CoFs the ECoF allows are exactly
  :math:`[\mu(b), \mu(a)]` wherever the inversion at both ends is unique.

The root is found by Newton's method on :math:`\mu_E(\mu) - \mu_E^{given}` with the slope
from ``jax.jvp``, kept inside a bracket that shrinks at every step (a bisection when a
Newton step leaves it), under ``jax.lax.while_loop`` over whole arrays: about five steps
from the start :math:`\mu = \mu_E^{given}`, an upper bound.
"""

from __future__ import annotations

import enum
import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ecofmaps import model
from ecofmaps._inputs import as_float64, check, float64, is_concrete, warn_nan
from ecofmaps.model.steady_state import valid_geometry

__all__ = [
    "CorrectionStatus",
    "Interval",
    "contact_cof",
    "correct_ecof",
    "correction_factor",
    "ecof_fall",
    "lookup_correction",
]


class CorrectionStatus(enum.IntEnum):
    """Outcome of a correction, per point (``return_status=True``).

    Attributes
    ----------
    CORRECTED
        One contact CoF gives the ECoF; it is returned.
    NO_GROSS_SLIP
        The ECoF is at or above :math:`S\\Delta^*/P`, above every gross-slip
        :math:`\\mu_E` of these test conditions: a contact CoF high enough to give it would
        stop gross slip (:math:`\\mu P \\ge S\\Delta^*`), and with no gross slip there is
        no ECoF. The value cannot come from the model with these conditions.
    AMBIGUOUS
        Several contact CoFs give the ECoF (deep groove, :math:`\\kappa > 1`, and stiff rig,
        :math:`\\lambda < 0.0711`, where :math:`\\mu_E(\\mu)` falls over part of its range).
    INVALID
        An input out of its range or NaN (only under ``jax.jit``/``jax.vmap``: concrete
        inputs raise ``ValueError``).
    OUTSIDE_MAP
        :func:`lookup_correction` only: the point, or the ECoF, is outside the map.
    UNREACHABLE
        On a scar profile only: no contact CoF gives the ECoF although it is below
        :math:`S\\Delta^*/P`: it falls in a jump of :math:`\\mu_E(\\mu)` (the loop's ends
        jump where the pad starts to jump) or would need the pad to slip off the trace.
    """

    CORRECTED = 0
    NO_GROSS_SLIP = 1
    AMBIGUOUS = 2
    INVALID = 3
    OUTSIDE_MAP = 4
    UNREACHABLE = 5


class Interval(NamedTuple):
    """The contact CoFs (or correction factors) allowed by an ECoF: ``low <= high``."""

    low: jax.Array
    high: jax.Array


_REASONS = {
    int(CorrectionStatus.NO_GROSS_SLIP): "the ECoF is at or above stiffness * amplitude / "
    "load, the largest energy CoF of any gross-slip loop with these test conditions",
    int(CorrectionStatus.AMBIGUOUS): "several contact CoFs give the ECoF (deep groove and "
    "stiff rig, where the ECoF falls as mu rises over part of its range)",
    int(CorrectionStatus.OUTSIDE_MAP): "the point or the ECoF is outside the map",
    int(CorrectionStatus.UNREACHABLE): "no contact CoF gives the ECoF on this scar profile "
    "(it falls in a jump of the ECoF as mu rises, or needs a slip beyond the trace)",
}

# ---------------------------------------------------------------------------------------
# The dimensionless core: mu from mu_E at (kappa, lam)
# ---------------------------------------------------------------------------------------

_EPS = float(np.finfo(np.float64).eps)
_MAX_STEPS = 300  # the bracket [0, mu_E] halves at least every two steps

# mu_E(mu) can fall only for kappa > _FALL_KAPPA and 0 < lam < _FALL_LAMBDA (module
# docstring); the fall lies in 1/kappa < mu < 1, scanned on _FALL_GRID points in log(mu)
# and located to _FALL_BISECTIONS halvings of a grid step.
_FALL_KAPPA = 1.0
_FALL_LAMBDA = 0.075
_FALL_GRID = 256
_FALL_BISECTIONS = 48


def _ecof_and_slope(mu, kappa, lam):
    """:math:`\\mu_E` and :math:`d\\mu_E/d\\mu` at each point (forward mode, elementwise)."""
    return jax.jvp(lambda m: m * model.ecof_ratio(m, kappa, lam), (mu,), (jnp.ones_like(mu),))


def _root(ecof, kappa, lam):
    """The :math:`\\mu` with :math:`\\mu_E(\\mu) =` ``ecof`` by bracketed Newton (see module).

    The bracket starts as :math:`(0, \\min(\\mu_E, \\mu_{max}))`; :math:`\\mu_E - ecof` is
    negative at its lower end and positive (or NaN, past the gross-slip or locking limit)
    at its upper one, and every step keeps it so. A Newton step is taken only if it stays
    inside the bracket and is less than half the step before it; otherwise the bracket is
    bisected (as in Numerical Recipes' ``rtsafe``), so the bracket at least halves every
    two steps even where Newton's method would cycle (the steep rise of :math:`\\mu_E`
    near the locking point of a stiff rig).
    """
    mu_max = jnp.where(lam > 0.0, 1.0 / lam, 1.0 / kappa)
    low = jnp.zeros_like(ecof)
    high = jnp.minimum(ecof, mu_max)
    start = jnp.where(ecof < mu_max, ecof, 0.5 * high)

    def unfinished(state):
        *_, done, step = state
        return (step < _MAX_STEPS) & ~jnp.all(done)

    def newton(state):
        mu, low, high, previous, done, step = state
        value, slope = _ecof_and_slope(mu, kappa, lam)
        residual = value - ecof
        above = ~(residual <= 0.0)  # NaN: beyond the gross-slip (or locking) limit
        low = jnp.where(above, low, mu)
        high = jnp.where(above, mu, high)
        change = residual / slope
        proposal = mu - change
        small = (residual == 0.0) | (jnp.abs(change) <= 4.0 * _EPS * mu)
        fast = (proposal > low) & (proposal < high) & (jnp.abs(change) < 0.5 * previous)
        following = jnp.where(small | fast, proposal, 0.5 * (low + high))
        converged = small | (high - low <= 4.0 * _EPS * high)
        following = jnp.where(done, mu, following)
        return following, low, high, jnp.abs(following - mu), done | converged, step + 1

    done = jnp.zeros(ecof.shape, dtype=bool)
    state = (start, low, high, high - low, done, 0)
    mu, *_ = jax.lax.while_loop(unfinished, newton, state)
    return mu


def _status(ecof, kappa, lam):
    """``CORRECTED``, ``NO_GROSS_SLIP`` (:math:`\\mu_E \\ge 1/\\lambda`) or ``INVALID``."""
    valid = (
        (ecof > 0.0)
        & jnp.isfinite(ecof)
        & (kappa >= 0.0)
        & jnp.isfinite(kappa)
        & (lam >= 0.0)
        & jnp.isfinite(lam)
    )
    reachable = ecof * lam < 1.0
    code = jnp.where(
        valid,
        jnp.where(reachable, int(CorrectionStatus.CORRECTED), int(CorrectionStatus.NO_GROSS_SLIP)),
        int(CorrectionStatus.INVALID),
    )
    return code.astype(jnp.int32)


def _may_fall(kappa, lam):
    """Where :math:`\\mu_E(\\mu)` may fall over part of its range (module docstring)."""
    return (kappa > _FALL_KAPPA) & (lam > 0.0) & (lam < _FALL_LAMBDA)


def ecof_fall(kappa, lam):
    r"""Where :math:`\mu_E(\mu)` falls: its local maximum and minimum, or NaN where it rises.

    Parameters
    ----------
    kappa : array_like
        Curvature number :math:`\kappa = 2 z_o/x_o` (with :math:`x_o = \Delta^*`). [1]
    lam : array_like
        Compliance ratio :math:`\lambda = P/(S\Delta^*)`. [1]

    Returns
    -------
    high : jax.Array
        :math:`\mu_E` at the local maximum, where the fall starts; NaN where
        :math:`\mu_E(\mu)` rises over the whole gross-slip range. [1]
    low : jax.Array
        :math:`\mu_E` at the local minimum, where it ends. An ECoF in ``[low, high]``
        comes from three contact CoFs (two at the ends). [1]

    Notes
    -----
    The fall exists only for :math:`\kappa > 1` and :math:`0 < \lambda < 0.0711` and lies in
    :math:`1/\kappa < \mu < 1` (module docstring); there the slope
    :math:`d\mu_E/d\mu` (``jax.jvp`` of the corrected eq. 13-15 with eq. 16) is sampled at
    256 points evenly spaced in :math:`\log\mu`, and its two sign changes are bisected. A
    fall narrower than one grid step (:math:`\ln\kappa/255` in :math:`\log\mu`), at the very
    edge of the region where it exists, is not seen: the contact CoFs it would make
    ambiguous then lie within about two grid steps of each other.
    """
    kappa, lam = jnp.broadcast_arrays(as_float64(kappa), as_float64(lam))
    may_fall = _may_fall(kappa, lam)
    kappa = jnp.where(may_fall, kappa, 2.0)[..., None]  # harmless values elsewhere
    lam = jnp.where(may_fall, lam, 0.01)[..., None]
    fraction = jnp.linspace(0.0, 1.0, _FALL_GRID)
    log_mu = -jnp.log(kappa) * (1.0 - fraction)  # from 1/kappa to 1
    _, slope = _ecof_and_slope(jnp.exp(log_mu), kappa, lam)
    falling = slope <= 0.0
    found = may_fall & jnp.any(falling, axis=-1)
    first = jnp.clip(jnp.argmax(falling, axis=-1), 1, _FALL_GRID - 2)
    last = jnp.clip(_FALL_GRID - 1 - jnp.argmax(falling[..., ::-1], axis=-1), 1, _FALL_GRID - 2)

    # Brackets of the slope's sign changes: rising at `rise`, falling at `fall`.
    def at(index):
        return jnp.take_along_axis(log_mu, index[..., None], axis=-1)[..., 0]

    rise = jnp.stack([at(first - 1), at(last + 1)], axis=-1)
    fall = jnp.stack([at(first), at(last)], axis=-1)

    def halve(_, bracket):
        rise, fall = bracket
        middle = 0.5 * (rise + fall)
        _, slope = _ecof_and_slope(jnp.exp(middle), kappa, lam)
        up = slope > 0.0
        return jnp.where(up, middle, rise), jnp.where(up, fall, middle)

    rise, fall = jax.lax.fori_loop(0, _FALL_BISECTIONS, halve, (rise, fall))
    extremum = jnp.exp(0.5 * (rise + fall))
    value, _ = _ecof_and_slope(extremum, kappa, lam)
    high = jnp.where(found, value[..., 0], jnp.nan)
    low = jnp.where(found, value[..., 1], jnp.nan)
    return high, low


def _mark_ambiguous(mu, status, ecof, high, low):
    """NaN and ``AMBIGUOUS`` where ``ecof`` lies in the fall ``[low, high]``."""
    ambiguous = (status == int(CorrectionStatus.CORRECTED)) & (ecof >= low) & (ecof <= high)
    status = jnp.where(ambiguous, int(CorrectionStatus.AMBIGUOUS), status).astype(jnp.int32)
    return jnp.where(ambiguous, jnp.nan, mu), status


def _fall_if_needed(status, kappa, lam):
    """:func:`ecof_fall` at every point, scanned only if a corrected point may fall."""
    needed = jnp.any(_may_fall(kappa, lam) & (status == int(CorrectionStatus.CORRECTED)))
    nan = jnp.full(status.shape, jnp.nan)
    return jax.lax.cond(needed, lambda: ecof_fall(kappa, lam), lambda: (nan, nan))


def _root_and_status(ecof, kappa, lam):
    """The root and status without the ambiguity check, NaN wherever it is not corrected."""
    ecof, kappa, lam = jnp.broadcast_arrays(ecof, kappa, lam)
    status = _status(ecof, kappa, lam)
    corrected = status == int(CorrectionStatus.CORRECTED)
    mu = _root(
        jnp.where(corrected, ecof, 0.5),
        jnp.where(corrected, kappa, 0.0),
        jnp.where(corrected, lam, 0.0),
    )
    return jnp.where(corrected, mu, jnp.nan), status


def contact_cof(ecof, kappa, lam):
    r"""The contact CoF :math:`\mu` whose energy CoF is ``ecof``: the dimensionless core.

    A pure ``jax.numpy`` function of the core numbers of :mod:`ecofmaps.model`; it
    broadcasts and works under ``jax.jit`` and ``jax.vmap``, and checks nothing.

    Parameters
    ----------
    ecof : array_like
        Energy coefficient of friction :math:`\mu_E`. [1]
    kappa : array_like
        Curvature number :math:`\kappa = 2 z_o/x_o` (with :math:`x_o = \Delta^*`). [1]
    lam : array_like
        Compliance ratio :math:`\lambda = P/(S\Delta^*)`, 0 for a rigid rig. [1]

    Returns
    -------
    mu : jax.Array
        The contact CoF, within a few ulp of the exact root: :math:`|\mu_E(\mu) -
        \mu_E^{given}| \le 10^{-12}\mu_E^{given}` wherever one ulp of :math:`\mu` moves
        :math:`\mu_E` by less (everywhere but a rigid rig next to locking,
        :math:`1 - \mu\kappa < 10^{-5}`); NaN unless the status is ``CORRECTED``. [1]
    status : jax.Array of int32
        :class:`CorrectionStatus` codes.

    Notes
    -----
    Inverts the corrected eq. 13-15 with eq. 16 (module docstring).
    """
    ecof, kappa, lam = jnp.broadcast_arrays(*(as_float64(v) for v in (ecof, kappa, lam)))
    mu, status = _root_and_status(ecof, kappa, lam)
    return _mark_ambiguous(mu, status, ecof, *_fall_if_needed(status, kappa, lam))


# ---------------------------------------------------------------------------------------
# SI-unit API
# ---------------------------------------------------------------------------------------


def _core_numbers(amplitude, load, stiffness, aspect_ratio):
    """:math:`\\kappa` and :math:`\\lambda` with :math:`x_o = \\Delta^*`, and SI validity."""
    kappa = model.curvature_number(1.0, aspect_ratio, 1.0)  # x_o = Δ*: κ = 2 z_o/x_o
    lam = model.compliance_ratio(amplitude, load, stiffness)
    valid = valid_geometry(amplitude, load, stiffness, aspect_ratio, amplitude)
    return kappa, lam, valid


@jax.jit
def _si_root(ecof, amplitude, load, stiffness, aspect_ratio):
    """Root, status, kappa and lam over the broadcast shape; no ambiguity check."""
    kappa, lam, valid = _core_numbers(amplitude, load, stiffness, aspect_ratio)
    mu, status = _root_and_status(ecof, kappa, lam)
    status = jnp.where(valid, status, int(CorrectionStatus.INVALID)).astype(jnp.int32)
    mu = jnp.where(valid, mu, jnp.nan)
    return mu, status, *jnp.broadcast_arrays(kappa, lam, mu)[:2]


_ecof_fall = jax.jit(ecof_fall)


def _si_correct(ecof, amplitude, load, stiffness, aspect_ratio):
    """μ, status and the fall (high, low) at concrete or traced SI inputs."""
    mu, status, kappa, lam = _si_root(ecof, amplitude, load, stiffness, aspect_ratio)
    if not is_concrete(mu):
        high, low = _fall_if_needed(status, kappa, lam)
    else:
        # Only the few points where mu_E(mu) may fall are scanned, in one padded batch.
        where = np.flatnonzero(
            np.asarray(_may_fall(kappa, lam) & (status == int(CorrectionStatus.CORRECTED)))
        )
        high = np.full(mu.size, np.nan)
        low = np.full(mu.size, np.nan)
        if where.size:
            size = max(8, 1 << (where.size - 1).bit_length())  # few distinct shapes to compile
            padded = np.pad(where, (0, size - where.size), mode="edge")
            fall = _ecof_fall(kappa.ravel()[padded], lam.ravel()[padded])
            high[where], low[where] = (np.asarray(v)[: where.size] for v in fall)
        high, low = high.reshape(mu.shape), low.reshape(mu.shape)
    ecof = jnp.broadcast_to(ecof, mu.shape)
    mu, status = _mark_ambiguous(mu, status, ecof, jnp.asarray(high), jnp.asarray(low))
    return mu, status, (kappa, lam, high, low)


def _aspect_ratio(aspect_ratio, scar_depth, scar_half_width):
    """The aspect ratio (or a ``(low, high)`` tuple of them) from either way of giving it."""
    if aspect_ratio is not None:
        if scar_depth is not None or scar_half_width is not None:
            raise ValueError(
                "give the groove aspect ratio one way: aspect_ratio, or scar_depth and "
                "scar_half_width (z_o/x_o = D/W, eq. 11), not both"
            )
        if isinstance(aspect_ratio, tuple):
            if len(aspect_ratio) != 2:
                raise ValueError(
                    "aspect_ratio as a tuple is an interval (low, high) of two values or "
                    f"arrays, got {len(aspect_ratio)} items (use a list or an array for "
                    "per-point values)"
                )
            low, high = aspect_ratio
            check("aspect_ratio low", low, "non_negative", "1")
            check("aspect_ratio high", high, "non_negative", "1")
            if is_concrete(low, high) and np.any(np.asarray(low) > np.asarray(high)):
                raise ValueError(
                    f"aspect_ratio interval must have low <= high, got ({low!r}, {high!r})"
                )
            return as_float64(low), as_float64(high)
        check("aspect_ratio", aspect_ratio, "non_negative", "1")
        return as_float64(aspect_ratio)
    if scar_depth is None or scar_half_width is None:
        raise ValueError(
            "give the groove aspect ratio: aspect_ratio, or both scar_depth and "
            "scar_half_width (z_o/x_o = D/W, eq. 11)"
        )
    check("scar_depth", scar_depth, "non_negative", "m")
    check("scar_half_width", scar_half_width, "positive", "m")
    return as_float64(scar_depth) / as_float64(scar_half_width)


def _failure_message(status, ecof, details) -> str:
    """The reason a concrete single-point correction failed, with the numbers."""
    kappa, lam, high, low = (float(np.asarray(v)) for v in details)
    if status == CorrectionStatus.NO_GROSS_SLIP:
        return (
            f"ecof = {ecof:.6g} cannot be corrected: it is at or above stiffness * amplitude "
            f"/ load = {1.0 / lam:.6g}, and every gross-slip loop with these test conditions "
            "has a smaller energy CoF (a contact CoF that high would stop gross slip). "
            "Check the amplitude, load and stiffness."
        )
    return (
        f"ecof = {ecof:.6g} cannot be corrected uniquely: with this deep groove "
        f"(z_o/x_o = {kappa / 2.0:.6g}) and stiff rig (load / (stiffness * amplitude) = "
        f"{lam:.6g}) the energy CoF falls from {high:.6g} to {low:.6g} as mu rises, and "
        "three contact CoFs give any value between."
    )


@float64
def _correct(ecof, amplitude, load, stiffness, aspect_ratio, scar_depth, scar_half_width,
             return_status, factor, caller, profile=None, mapping="scaled"):  # fmt: skip
    if profile is not None:
        if aspect_ratio is not None or scar_depth is not None or scar_half_width is not None:
            raise ValueError(
                "give the groove one way: aspect_ratio, scar_depth and scar_half_width, or "
                "profile, not several"
            )
        return _correct_on_profile(ecof, amplitude, load, stiffness, profile, mapping,
                                   return_status, factor, caller)  # fmt: skip
    if mapping != "scaled":
        raise ValueError("mapping applies to a profile only (profile=...)")
    check("ecof", ecof, "positive", "1")
    check("amplitude", amplitude, "positive", "m")
    check("load", load, "positive", "N")
    check("stiffness", stiffness, "positive_or_inf", "N/m")
    ratio = _aspect_ratio(aspect_ratio, scar_depth, scar_half_width)
    ecof, amplitude, load, stiffness = (as_float64(v) for v in (ecof, amplitude, load, stiffness))
    ends = ratio if isinstance(ratio, tuple) else (ratio,)
    results = [_si_correct(ecof, amplitude, load, stiffness, end) for end in ends]
    values = [mu / ecof if factor else mu for mu, _, _ in results]
    status = results[0][1]
    if len(results) == 2:  # the larger aspect ratio allows the smaller mu (module docstring)
        high_end = results[1][1]
        status = jnp.where(status == int(CorrectionStatus.CORRECTED), high_end, status)
        both = status == int(CorrectionStatus.CORRECTED)
        values = Interval(*(jnp.where(both, v, jnp.nan) for v in (values[1], values[0])))
    else:
        values = values[0]
    concrete = is_concrete(status)
    if concrete and not return_status:
        codes = np.asarray(status)
        if codes.ndim == 0 and codes != CorrectionStatus.CORRECTED:
            failed = next(r for r in results if np.asarray(r[1]) != CorrectionStatus.CORRECTED)
            raise ValueError(_failure_message(CorrectionStatus(int(codes)), float(ecof), failed[2]))
        first = values[0] if isinstance(values, Interval) else values
        warn_nan(first, codes, _REASONS, caller)
    return (values, status) if return_status else values


_PARAMETERS = """
    Parameters
    ----------
    ecof : array_like
        The reported energy coefficient of friction :math:`\\mu_E = E_d/(4P\\delta^*)`. [1]
    amplitude : array_like
        Displacement amplitude :math:`\\Delta^*` of the test (also the groove half-width
        :math:`x_o`, as in the paper). [m]
    load : array_like
        Normal load :math:`P`. [N]
    stiffness : array_like
        Rig stiffness :math:`S`; ``numpy.inf`` for a rigid rig. [N/m]
    aspect_ratio : array_like or tuple (low, high), optional
        The wear scar's depth over half-width, :math:`z_o/x_o = D/W` (eq. 11). A ``tuple``
        of two values (or arrays) is an interval for a scar known only roughly; give
        per-point values as a list or an array. [1]
    scar_depth : array_like, optional
        Wear scar depth :math:`D`, instead of ``aspect_ratio`` (with ``scar_half_width``). [m]
    scar_half_width : array_like, optional
        Wear scar half-width :math:`W`. [m]
    profile : ScarProfile, optional
        The wear scar's profile, of any shape, instead of an aspect ratio (the correction
        then inverts the model on that profile; concrete inputs only, not under
        ``jax.jit``/``jax.vmap``).
    mapping : {'scaled', 'physical'}
        With a profile: :math:`X = xW/\\Delta^*` (eq. 11) or :math:`X = x`.
    return_status : bool
        Also return the :class:`CorrectionStatus` of every point, and never raise or warn
        for a point that cannot be corrected.
"""

_RAISES = """
    Raises
    ------
    ValueError
        For a concrete input out of its range (ecof, amplitude, load and scar_half_width
        finite and > 0, stiffness > 0 with inf allowed, aspect_ratio and scar_depth finite
        and >= 0, an interval with low <= high), for the aspect ratio given neither or both
        ways, and, without ``return_status``, for a single point that cannot be corrected
        (the message says why). Under ``jax.jit``/``jax.vmap`` such points are NaN with the
        status ``INVALID``.

    Warns
    -----
    ecofmaps.RegimeWarning
        For concrete arrays (without ``return_status``) with points that cannot be
        corrected, naming the reasons; those points are NaN.
"""


def correct_ecof(ecof, amplitude, load, stiffness, aspect_ratio=None, scar_depth=None,
                 scar_half_width=None, *, profile=None, mapping="scaled",
                 return_status=False):  # fmt: skip
    return _correct(ecof, amplitude, load, stiffness, aspect_ratio, scar_depth,
                    scar_half_width, return_status, False, "correct_ecof", profile,
                    mapping)  # fmt: skip


correct_ecof.__doc__ = f"""The contact CoF :math:`\\mu` behind a reported energy CoF :math:`\\mu_E`.

    The exact inversion of the model's :math:`\\mu_E(\\mu; \\Delta^*, P, S, z_o/x_o)`, with
    :math:`x_o = \\Delta^*`, vectorised and jit-compiled, in float64.
{_PARAMETERS}
    Returns
    -------
    mu : jax.Array of float64, or Interval
        The contact CoF, within a few ulp of the exact root, so that :math:`|\\mu_E(\\mu) - `
        ``ecof`` :math:`| \\le 10^{{-12}}` ``ecof`` except on a rigid rig next to locking
        (:math:`1 - \\mu\\kappa < 10^{{-5}}`), where one ulp of :math:`\\mu` moves :math:`\\mu_E` by
        more; NaN where it cannot be corrected. With ``aspect_ratio=(low, high)``, an
        :class:`Interval` ``(low, high)`` of arrays: every contact CoF that gives ``ecof``
        with an aspect ratio in the interval (``low`` from the deeper scar). [1]
    status : jax.Array of int32
        Only with ``return_status=True``: :class:`CorrectionStatus` codes (for an interval,
        the first failure of its two ends).
{_RAISES}
    Notes
    -----
    Inverts the corrected eq. 13-15 with eq. 16 by bracketed Newton steps (see
    :mod:`ecofmaps.correction` for the domain: which ECoFs can be reached, where the
    inversion is unique, and why the interval is exact). :math:`\\mu \\le \\mu_E`, with
    equality for a flat scar.

    On a profile :math:`\\mu_E(\\mu)` is scanned on a grid of 400 contact CoFs, log-spaced
    from a fiftieth of the smallest ECoF to the largest (:math:`\\mu \\le \\mu_E` on every
    profile), to bracket the root and to find several (``AMBIGUOUS``); then the bracket is
    narrowed by the Illinois method to a few ulp. A fall of :math:`\\mu_E(\\mu)` narrower
    than one grid step (1 % of :math:`\\mu` for one ECoF; the steps widen with the spread of
    the ECoFs corrected together), or below the grid, is not seen.

    Examples
    --------
    >>> import ecofmaps
    >>> mu = ecofmaps.correct_ecof(0.8308, amplitude=50e-6, load=450.0, stiffness=35e6,
    ...                            aspect_ratio=0.2)  # the paper's Example 2
    >>> round(float(mu), 3)
    0.8
"""


def correction_factor(ecof, amplitude, load, stiffness, aspect_ratio=None, scar_depth=None,
                      scar_half_width=None, *, profile=None, mapping="scaled",
                      return_status=False):  # fmt: skip
    return _correct(ecof, amplitude, load, stiffness, aspect_ratio, scar_depth,
                    scar_half_width, return_status, True, "correction_factor", profile,
                    mapping)  # fmt: skip


correction_factor.__doc__ = f"""The ratio :math:`\\mu/\\mu_E` of contact CoF to reported ECoF.
{_PARAMETERS}
    Returns
    -------
    factor : jax.Array of float64, or Interval
        :math:`\\mu/\\mu_E \\le 1` (1 for a flat scar), with :math:`\\mu` from
        :func:`correct_ecof`; an :class:`Interval` for an aspect-ratio interval. [1]
    status : jax.Array of int32
        Only with ``return_status=True``: :class:`CorrectionStatus` codes.
{_RAISES}
    Notes
    -----
    The reciprocal of the :math:`\\mu_E/\\mu` of Figures 8 and 11, read at the contact CoF
    that gives the reported :math:`\\mu_E` rather than at a chosen :math:`\\mu`.
"""


# ---------------------------------------------------------------------------------------
# The same correction read off a map
# ---------------------------------------------------------------------------------------


def _map_axes(ecof_map):
    """The map's grid axes as ``(name, sorted values, order)`` and its fixed coordinates."""
    axes, fixed = [], {}
    for name in ("stiffness_ratio", "aspect_ratio", "amplitude"):
        if name in ecof_map.dims and ecof_map.sizes[name] > 1:
            values = np.asarray(ecof_map[name], dtype=np.float64)
            if name == "stiffness_ratio":
                values = 1.0 / values  # interpolate in P/S: finite for a rigid rig
            order = np.argsort(values)
            if np.any(np.diff(values[order]) <= 0.0):
                raise ValueError(f"the map's {name} coordinate has repeated values")
            axes.append((name, values[order], order))
        elif name in ecof_map.coords:
            fixed[name] = float(np.asarray(ecof_map[name], dtype=np.float64).reshape(-1)[0])
        else:
            raise ValueError(f"map_dataset has no {name!r} coordinate (from compute_map)")
    return axes, fixed


def _crossing(curves, mu_grid, ecof):
    """Invert each curve ``ecof(mu)`` by linear interpolation; count its crossings."""
    above = curves > ecof[:, None]
    finite = np.isfinite(curves)
    pair = finite[:, :-1] & finite[:, 1:]
    crossing = pair & (above[:, :-1] != above[:, 1:])
    count = crossing.sum(axis=1)
    index = np.argmax(crossing, axis=1)
    rows = np.arange(curves.shape[0])
    c0, c1 = curves[rows, index], curves[rows, index + 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = (ecof - c0) / (c1 - c0)
    mu = mu_grid[index] + fraction * (mu_grid[index + 1] - mu_grid[index])
    return mu, count


@float64
def lookup_correction(map_dataset, ecof, amplitude, load, stiffness, aspect_ratio=None,
                      scar_depth=None, scar_half_width=None, *, return_status=False):  # fmt: skip
    r"""The contact CoF behind a reported ECoF, read off a map by interpolation.

    The same correction as :func:`correct_ecof`, for users who work from the maps: the
    map's :math:`\mu_E` is interpolated linearly to the test conditions, giving a curve
    :math:`\mu_E(\mu)` over the map's :math:`\mu` grid, and that curve is inverted
    linearly.

    Parameters
    ----------
    map_dataset : xarray.Dataset
        A map from :func:`ecofmaps.compute_map` with a ``mu`` dimension of at least two
        values and the variable ``ecof``; ``stiffness_ratio``, ``aspect_ratio`` and
        ``amplitude`` are dimensions or scalar coordinates.
    ecof, amplitude, load, stiffness, aspect_ratio, scar_depth, scar_half_width
        As for :func:`correct_ecof` (no interval). [1], [m], [N], [N/m], [1], [m], [m]
    return_status : bool
        Also return the :class:`CorrectionStatus` of every point (and do not raise or warn).

    Returns
    -------
    mu : numpy.ndarray of float64
        The contact CoF; NaN where it cannot be read off the map. [1]
    status : numpy.ndarray of int32
        Only with ``return_status=True``: :class:`CorrectionStatus` codes, among them
        ``OUTSIDE_MAP`` for test conditions outside the map's grid (or off a scalar
        coordinate, by more than 1e-9 relative) and for an ECoF beyond the map's
        :math:`\mu` range; ``AMBIGUOUS`` where the interpolated curve crosses the ECoF more
        than once; ``NO_GROSS_SLIP`` as for :func:`correct_ecof`.

    Raises
    ------
    ValueError
        As for :func:`correct_ecof`, and for a map without the coordinates above.

    Warns
    -----
    ecofmaps.RegimeWarning
        For arrays (without ``return_status``) with points that cannot be read off the map.

    Notes
    -----
    The interpolation is multilinear in :math:`P/S` (so a rigid rig, :math:`S/P = \infty`,
    is a grid point like any other), :math:`z_o/x_o` and :math:`\Delta^*`, then linear in
    :math:`\mu`: its error is second order in the grid steps, about
    :math:`\sum_i h_i^2 |\partial_i^2\mu_E|/8` in :math:`\mu_E`, divided by
    :math:`d\mu_E/d\mu` in :math:`\mu`.
    """
    from scipy.interpolate import RegularGridInterpolator

    if isinstance(aspect_ratio, tuple):
        raise ValueError("lookup_correction takes no aspect_ratio interval; use correct_ecof")
    for name, value, rule, unit in (
        ("ecof", ecof, "positive", "1"),
        ("amplitude", amplitude, "positive", "m"),
        ("load", load, "positive", "N"),
        ("stiffness", stiffness, "positive_or_inf", "N/m"),
    ):
        check(name, value, rule, unit)
    ratio = np.asarray(_aspect_ratio(aspect_ratio, scar_depth, scar_half_width))
    ecof, amplitude, load, stiffness, ratio = np.broadcast_arrays(
        *(np.asarray(v, dtype=np.float64) for v in (ecof, amplitude, load, stiffness)), ratio
    )
    shape = ecof.shape
    if "ecof" not in map_dataset or "mu" not in map_dataset["ecof"].dims:
        raise ValueError("map_dataset must hold the variable 'ecof' over a 'mu' dimension")
    ecof_map = map_dataset["ecof"]
    if ecof_map.sizes["mu"] < 2:
        raise ValueError("map_dataset's 'mu' dimension must have at least 2 values")
    axes, fixed = _map_axes(ecof_map)
    query = {
        "stiffness_ratio": (stiffness / load).ravel(),
        "aspect_ratio": ratio.ravel(),
        "amplitude": amplitude.ravel(),
    }
    inside = np.ones(ecof.size, dtype=bool)
    for name, value in fixed.items():
        if math.isfinite(value):
            inside &= np.abs(query[name] - value) <= 1e-9 * abs(value)
        else:  # a rigid rig
            inside &= query[name] == value
    points = []
    for name, values, _ in axes:
        coordinate = 1.0 / query[name] if name == "stiffness_ratio" else query[name]
        inside &= (coordinate >= values[0]) & (coordinate <= values[-1])
        points.append(np.clip(coordinate, values[0], values[-1]))
    mu_grid = np.asarray(ecof_map["mu"], dtype=np.float64)
    mu_order = np.argsort(mu_grid)
    names = [name for name, _, _ in axes]
    table = ecof_map.transpose(*names, "mu", ...).values.reshape(
        [ecof_map.sizes[n] for n in names] + [mu_grid.size]
    )
    for axis, (_, _, order) in enumerate(axes):
        table = np.take(table, order, axis=axis)
    table = np.take(table, mu_order, axis=-1).astype(np.float64)
    if axes:
        interpolate = RegularGridInterpolator([v for _, v, _ in axes], table)
        curves = interpolate(np.stack(points, axis=-1))
    else:
        curves = np.broadcast_to(table, (ecof.size, mu_grid.size))
    mu, count = _crossing(curves, mu_grid[mu_order], ecof.ravel())
    lam = load.ravel() / (stiffness.ravel() * amplitude.ravel())
    status = np.select(
        [ecof.ravel() * lam >= 1.0, ~inside | (count == 0), count > 1],
        [CorrectionStatus.NO_GROSS_SLIP, CorrectionStatus.OUTSIDE_MAP, CorrectionStatus.AMBIGUOUS],
        CorrectionStatus.CORRECTED,
    ).astype(np.int32)
    mu = np.where(status == CorrectionStatus.CORRECTED, mu, np.nan)
    mu, status = mu.reshape(shape), status.reshape(shape)
    if not return_status:
        if status.ndim == 0 and status != CorrectionStatus.CORRECTED:
            reason = _REASONS[int(status)]
            raise ValueError(f"ecof = {float(ecof):.6g} cannot be read off the map: {reason}")
        warn_nan(mu, status, _REASONS, "lookup_correction")
    return (mu, status) if return_status else mu


# ---------------------------------------------------------------------------------------
# On a scar profile
# ---------------------------------------------------------------------------------------

_PROFILE_GRID = 400  # contact CoFs scanned per point
_PROFILE_SPAN = 0.02  # the grid runs from this fraction of the smallest ECoF ...
_PROFILE_STEPS = 200  # at most this many Illinois steps (each at least halves every two)


def _ecof_on_profile(profile, mu, amplitude, load, stiffness, mapping):
    """mu_E at concrete points (NaN outside gross slip), as a NumPy array."""
    from ecofmaps.model.on_profile import steady_numbers

    numbers = steady_numbers(profile, amplitude, load, stiffness, mu, mapping=mapping)
    return np.asarray(numbers["ecof_ratio"]) * np.asarray(mu)


def _correct_on_profile(ecof, amplitude, load, stiffness, profile, mapping, return_status,
                        factor, caller):  # fmt: skip
    """correct_ecof / correction_factor on a profile (see correct_ecof's Notes).

    The bracket [a, b] keeps mu_E(a) <= ecof < mu_E(b) (NaN, beyond gross slip or the
    trace, counts as above); a point whose narrowed bracket still misses the ECoF by more
    than 1e-9 of it lies at a jump of mu_E(mu) (``UNREACHABLE``).
    """
    from ecofmaps.model.on_profile import as_profile, check_mapping

    check_mapping(mapping, None)
    profile = as_profile(profile)
    for name, value, rule, unit in (
        ("ecof", ecof, "positive", "1"),
        ("amplitude", amplitude, "positive", "m"),
        ("load", load, "positive", "N"),
        ("stiffness", stiffness, "positive_or_inf", "N/m"),
    ):
        check(name, value, rule, unit)
    if not is_concrete(ecof, amplitude, load, stiffness, *profile):
        raise ValueError(
            f"{caller} on a profile needs concrete inputs: it does not run under "
            "jax.jit or jax.vmap"
        )
    ecof, amplitude, load, stiffness = np.broadcast_arrays(
        *(np.asarray(v, dtype=np.float64) for v in (ecof, amplitude, load, stiffness))
    )
    shape = ecof.shape
    ecof, amplitude, load, stiffness = (v.ravel() for v in (ecof, amplitude, load, stiffness))
    lam = load / (stiffness * amplitude)
    status = np.where(ecof * lam < 1.0, CorrectionStatus.CORRECTED, CorrectionStatus.NO_GROSS_SLIP)
    status = status.astype(np.int32)
    mu = np.full(ecof.size, np.nan)
    todo = np.flatnonzero(status == CorrectionStatus.CORRECTED)
    if todo.size:
        target = ecof[todo]
        rig = (amplitude[todo, None], load[todo, None], stiffness[todo, None])
        top = target.max() * (1.0 + 1e-9)  # mu_E(mu) >= mu: every root is below the largest ECoF
        grid = np.geomspace(_PROFILE_SPAN * target.min(), top, _PROFILE_GRID)
        with np.errstate(invalid="ignore"):
            values = _ecof_on_profile(profile, grid[None, :], *rig, mapping)
        above = ~(values <= target[:, None])  # NaN: beyond gross slip or the trace
        rises = ~above[:, :-1] & above[:, 1:]
        count = rises.sum(axis=1) + above[:, 0]
        ambiguous = count > 1
        first = np.argmax(rises, axis=1)
        low = np.where(above[:, 0], 0.0, grid[first])
        high = np.where(above[:, 0], grid[0], grid[first + 1])
        status[todo[ambiguous]] = CorrectionStatus.AMBIGUOUS
        keep = ~ambiguous
        root, reached = _illinois(
            profile, target[keep], low[keep], high[keep], tuple(v[keep, 0] for v in rig), mapping
        )
        mu[todo[keep]] = np.where(reached, root, np.nan)
        status[todo[keep][~reached]] = CorrectionStatus.UNREACHABLE
    values = mu / ecof if factor else mu
    values, status = values.reshape(shape), status.reshape(shape)
    if not return_status:
        if status.ndim == 0 and status != CorrectionStatus.CORRECTED:
            code = CorrectionStatus(int(status))
            if code == CorrectionStatus.NO_GROSS_SLIP:
                detail = f"it is at or above stiffness * amplitude / load = {1.0 / lam[0]:.6g}"
            else:
                detail = _REASONS[int(code)]
            raise ValueError(f"ecof = {float(ecof[0]):.6g} cannot be corrected on this "
                             f"profile: {detail}")  # fmt: skip
        warn_nan(values, status, _REASONS, caller)
    return (jnp.asarray(values), jnp.asarray(status)) if return_status else jnp.asarray(values)


def _illinois(profile, target, low, high, rig, mapping):
    """Roots of mu_E(mu) = target in the brackets [low, high] (Illinois method).

    Returns the roots and whether mu_E reaches the target there (within 1e-9 of it).
    """
    f_low = np.where(low > 0.0, _residual(profile, low, target, rig, mapping), -target)
    f_high = _residual(profile, high, target, rig, mapping)  # may be NaN: above
    side = np.zeros(target.size, dtype=np.int8)  # which end moved last (-1 low, +1 high)
    active = np.ones(target.size, dtype=bool)
    for _ in range(_PROFILE_STEPS):  # every point every step: one shape to compile
        if not active.any():
            break
        a, b, fa, fb = low, high, f_low, f_high
        secant = np.isfinite(fb) & (fb > fa)
        with np.errstate(invalid="ignore", divide="ignore"):
            trial = np.where(secant, (a * fb - b * fa) / (fb - fa), 0.5 * (a + b))
        trial = np.where((trial > a) & (trial < b), trial, 0.5 * (a + b))
        value = _residual(profile, trial, target, rig, mapping)
        up = ~(value <= 0.0) & active
        down = (value <= 0.0) & active
        # Illinois: halve the residual kept at the end that stays twice running.
        f_high = np.where(up, value, np.where(down & (side == -1) & np.isfinite(fb), 0.5 * fb, fb))
        f_low = np.where(down, value, np.where(up & (side == 1), 0.5 * fa, fa))
        high = np.where(up, trial, b)
        low = np.where(down, trial, a)
        side = np.where(up, 1, np.where(down, -1, side))
        done = (value == 0.0) | (high - low <= 4.0 * _EPS * high)
        active &= ~done
    root = np.where(np.abs(f_low) <= np.abs(np.nan_to_num(f_high, nan=np.inf)), low, high)
    check_value = _residual(profile, root, target, rig, mapping) + target
    reached = np.abs(check_value - target) <= 1e-9 * target
    return root, reached


def _residual(profile, mu, target, rig, mapping):
    with np.errstate(invalid="ignore"):
        return _ecof_on_profile(profile, mu, *rig, mapping) - target
