r"""Reported energy coefficients of friction corrected to the contact one: :math:`\mu_E(\mu)`
inverted by bracketed Newton steps in the dimensionless core, or on a scar profile by a scan and
the Illinois method (NumPy): docs/model.md, "Correcting a reported ECoF"."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from ecofmaps import model
from ecofmaps._codes import warn_nan
from ecofmaps._inputs import as_float64, check, float64, is_concrete
from ecofmaps.correction import outcomes
from ecofmaps.correction.outcomes import CorrectionStatus
from ecofmaps.model.on_profile import as_profile, check_mapping, steady_numbers
from ecofmaps.model.steady_state import valid_geometry

_EPS = float(np.finfo(np.float64).eps)
_MAX_STEPS = 300  # the bracket [0, mu_E] halves at least every two steps
_PROFILE_GRID = 400  # contact CoFs scanned per point on a profile
_PROFILE_SPAN = 0.02  # the grid runs from this fraction of the smallest ECoF ...
_PROFILE_STEPS = 200  # at most this many Illinois steps (each at least halves every two)


@jax.custom_jvp
def _root(ecof, kappa, lam):
    r"""The :math:`\mu` with :math:`\mu_E(\mu) =` ``ecof``, by bracketed Newton."""
    mu_max = jnp.where(lam > 0.0, 1.0 / lam, 1.0 / kappa)
    high = jnp.minimum(ecof, mu_max)
    start = jnp.where(ecof < mu_max, ecof, 0.5 * high)

    def unfinished(state):
        *_, done, step = state
        return (step < _MAX_STEPS) & ~jnp.all(done)

    def newton(state):
        mu, low, high, previous, done, step = state
        value, slope = outcomes.ecof_and_slope(mu, kappa, lam)
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

    state = (start, jnp.zeros_like(ecof), high, high, jnp.zeros(ecof.shape, dtype=bool), 0)
    return jax.lax.while_loop(unfinished, newton, state)[0]


@_root.defjvp
def _root_tangent(primals, tangents):
    """The root's derivative by the implicit function theorem, not through the iterations."""
    ecof, kappa, lam = primals
    d_ecof, d_kappa, d_lam = tangents
    mu = _root(ecof, kappa, lam)
    _, slope = outcomes.ecof_and_slope(mu, kappa, lam)
    _, moved = jax.jvp(lambda k, m: mu * model.ecof_ratio(mu, k, m), (kappa, lam), (d_kappa, d_lam))
    return mu, (d_ecof - moved) / slope


def _root_and_status(ecof, kappa, lam):
    """The root and status without the ambiguity check, NaN wherever it is not corrected."""
    ecof, kappa, lam = jnp.broadcast_arrays(ecof, kappa, lam)
    valid = (ecof > 0.0) & jnp.isfinite(ecof)
    for value in (kappa, lam):
        valid &= (value >= 0.0) & jnp.isfinite(value)
    code = jnp.where(
        ecof * lam < 1.0, int(CorrectionStatus.CORRECTED), int(CorrectionStatus.NO_GROSS_SLIP)
    )
    status = jnp.where(valid, code, int(CorrectionStatus.INVALID)).astype(jnp.int32)
    corrected = status == int(CorrectionStatus.CORRECTED)
    mu = _root(
        jnp.where(corrected, ecof, 0.5),
        jnp.where(corrected, kappa, 0.0),
        jnp.where(corrected, lam, 0.0),
    )
    return jnp.where(corrected, mu, jnp.nan), status


def _ambiguity_marked(mu, status, ecof, high, low):
    """The contact CoF and status, NaN and ``AMBIGUOUS`` where ``ecof`` lies in the fall."""
    ambiguous = (status == int(CorrectionStatus.CORRECTED)) & (ecof >= low) & (ecof <= high)
    status = jnp.where(ambiguous, int(CorrectionStatus.AMBIGUOUS), status).astype(jnp.int32)
    return jnp.where(ambiguous, jnp.nan, mu), status


def _ecof_fall_where_needed(status, kappa, lam):
    """:func:`ecof_fall` at every point, scanned only if a corrected point may fall."""
    kappa, lam = jax.lax.stop_gradient(kappa), jax.lax.stop_gradient(lam)
    needed = jnp.any(outcomes.may_fall(kappa, lam) & (status == int(CorrectionStatus.CORRECTED)))
    nan = jnp.full(status.shape, jnp.nan)
    return jax.lax.cond(needed, lambda: outcomes.ecof_fall(kappa, lam), lambda: (nan, nan))


def contact_cof(ecof, kappa, lam):
    r"""The contact CoF :math:`\mu` whose energy CoF is ``ecof`` (eq. 13-15, 16 inverted), in the
    dimensionless core: pure ``jax.numpy`` (``jax.jit``, ``jax.vmap``); it checks nothing.

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
        The contact CoF, within a few ulp of the exact root (as :func:`correct_ecof`); NaN
        unless the status is ``CORRECTED``. [1]
    status : jax.Array of int32
        :class:`CorrectionStatus` codes.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 13-15, 16.
    """
    ecof, kappa, lam = jnp.broadcast_arrays(*(as_float64(v) for v in (ecof, kappa, lam)))
    mu, status = _root_and_status(ecof, kappa, lam)
    return _ambiguity_marked(mu, status, ecof, *_ecof_fall_where_needed(status, kappa, lam))


@jax.jit
def _si_root(ecof, amplitude, load, stiffness, aspect_ratio):
    """Root, status, kappa and lam over the broadcast shape; no ambiguity check."""
    kappa = model.curvature_number(1.0, aspect_ratio, 1.0)  # x_o = Δ*: κ = 2 z_o/x_o
    lam = model.compliance_ratio(amplitude, load, stiffness)
    valid = valid_geometry(amplitude, load, stiffness, aspect_ratio, amplitude)
    mu, status = _root_and_status(ecof, kappa, lam)
    status = jnp.where(valid, status, int(CorrectionStatus.INVALID)).astype(jnp.int32)
    mu = jnp.where(valid, mu, jnp.nan)
    return mu, status, *jnp.broadcast_arrays(kappa, lam, mu)[:2]


_ecof_fall = jax.jit(outcomes.ecof_fall)


def _si_correct(ecof, amplitude, load, stiffness, aspect_ratio):
    """μ, status and the fall (high, low) at concrete or traced SI inputs."""
    mu, status, kappa, lam = _si_root(ecof, amplitude, load, stiffness, aspect_ratio)
    if not is_concrete(mu):
        high, low = _ecof_fall_where_needed(status, kappa, lam)
    else:  # only the few points where mu_E(mu) may fall are scanned, in one padded batch
        where = np.flatnonzero(
            np.asarray(outcomes.may_fall(kappa, lam) & (status == int(CorrectionStatus.CORRECTED)))
        )
        high, low = np.full((2, mu.size), np.nan)
        if where.size:
            size = max(8, 1 << (where.size - 1).bit_length())  # few distinct shapes to compile
            padded = np.pad(where, (0, size - where.size), mode="edge")
            fall = _ecof_fall(kappa.ravel()[padded], lam.ravel()[padded])
            high[where], low[where] = (np.asarray(v)[: where.size] for v in fall)
        high, low = high.reshape(mu.shape), low.reshape(mu.shape)
    mu, status = _ambiguity_marked(mu, status, ecof, jnp.asarray(high), jnp.asarray(low))
    return mu, status, (kappa, lam, high, low)


def groove_aspect_ratio(aspect_ratio, scar_depth, scar_half_width):
    """The groove's aspect ratio from either way of giving it, checked."""
    if aspect_ratio is None:
        if scar_depth is None or scar_half_width is None:
            raise ValueError(
                "give the groove aspect ratio: aspect_ratio, or both scar_depth and "
                "scar_half_width (z_o/x_o = D/W, eq. 11)"
            )
        check("scar_depth", scar_depth, "non_negative", "m")
        check("scar_half_width", scar_half_width, "positive", "m")
        return as_float64(scar_depth) / as_float64(scar_half_width)
    if scar_depth is not None or scar_half_width is not None:
        raise ValueError(
            "give the groove aspect ratio one way: aspect_ratio, or scar_depth and "
            "scar_half_width (z_o/x_o = D/W, eq. 11), not both"
        )
    if not isinstance(aspect_ratio, tuple):
        check("aspect_ratio", aspect_ratio, "non_negative", "1")
        return as_float64(aspect_ratio)
    if len(aspect_ratio) != 2:
        raise ValueError(
            "aspect_ratio as a tuple is an interval (low, high) of two values or arrays, got "
            f"{len(aspect_ratio)} items (use a list or an array for per-point values)"
        )
    low, high = aspect_ratio
    for end, value in (("low", low), ("high", high)):
        check(f"aspect_ratio {end}", value, "non_negative", "1")
    if is_concrete(low, high) and np.any(np.asarray(low) > np.asarray(high)):
        raise ValueError(f"aspect_ratio interval must have low <= high, got ({low!r}, {high!r})")
    return as_float64(low), as_float64(high)


def _correct(factor, ecof, amplitude, load, stiffness, scar, profile, mapping, return_status):
    """correct_ecof, or correction_factor if ``factor``; ``scar``: the three ways to give it."""
    caller = "correction_factor" if factor else "correct_ecof"
    if profile is not None:
        if any(value is not None for value in scar):
            raise ValueError(
                "give the groove one way: aspect_ratio, scar_depth and scar_half_width, or "
                "profile, not several"
            )
        rig = (ecof, amplitude, load, stiffness)
        values, status, failure = _correct_on_profile(rig, profile, mapping, factor, caller)
    elif mapping != "scaled":
        raise ValueError("mapping applies to a profile only (profile=...)")
    else:
        values, status, failure = _correct_on_groove(factor, ecof, amplitude, load, stiffness, scar)
    if return_status:
        return values, status
    if is_concrete(status, values):  # under jax.grad the values alone are traced
        codes = np.asarray(status)
        if codes.ndim == 0 and codes != CorrectionStatus.CORRECTED:
            raise ValueError(failure())
        first = values[0] if isinstance(values, outcomes.Interval) else values
        warn_nan(first, codes, CorrectionStatus, caller)
    return values


def _correct_on_groove(factor, ecof, amplitude, load, stiffness, scar):
    """Values, status and the reason a single point failed, on a parabolic groove."""
    outcomes.check_test(ecof, amplitude, load, stiffness)
    ratio = groove_aspect_ratio(*scar)
    ecof, amplitude, load, stiffness = (as_float64(v) for v in (ecof, amplitude, load, stiffness))
    ends = ratio if isinstance(ratio, tuple) else (ratio,)
    results = [_si_correct(ecof, amplitude, load, stiffness, end) for end in ends]
    values = [mu / ecof if factor else mu for mu, _, _ in results]
    status = results[0][1]
    if len(results) == 2:  # the larger aspect ratio allows the smaller mu (docs/model.md)
        status = jnp.where(status == int(CorrectionStatus.CORRECTED), results[1][1], status)
        both = status == int(CorrectionStatus.CORRECTED)
        values = outcomes.Interval(*(jnp.where(both, v, jnp.nan) for v in (values[1], values[0])))
    else:
        values = values[0]

    def failure() -> str:
        failed = next(r for r in results if np.asarray(r[1]) != CorrectionStatus.CORRECTED)
        kappa, lam, high, low = (float(np.asarray(v)) for v in failed[2])
        if int(status) == CorrectionStatus.NO_GROSS_SLIP:
            return (
                f"ecof = {float(ecof):.6g} cannot be corrected: it is at or above stiffness * "
                f"amplitude / load = {1.0 / lam:.6g}, and every gross-slip loop with these test "
                "conditions has a smaller energy CoF (a contact CoF that high would stop gross "
                "slip). Check the amplitude, load and stiffness."
            )
        return (
            f"ecof = {float(ecof):.6g} cannot be corrected uniquely: with this deep groove "
            f"(z_o/x_o = {kappa / 2.0:.6g}) and stiff rig (load / (stiffness * amplitude) = "
            f"{lam:.6g}) the energy CoF falls from {high:.6g} to {low:.6g} as mu rises, and "
            "three contact CoFs give any value between."
        )

    return values, status, failure


def _residual(profile, mu, target, rig, mapping):
    """mu_E(mu) - target at concrete points; NaN beyond gross slip or the trace."""
    with np.errstate(invalid="ignore"):
        numbers = steady_numbers(profile, *rig, mu, mapping=mapping)
        return np.asarray(numbers["ecof_ratio"]) * np.asarray(mu) - target


def _correct_on_profile(test, profile, mapping, factor, caller):
    """Values, status and why one point failed, for ``test`` (ecof, amplitude, load, stiffness)."""
    check_mapping(mapping, None)
    profile = as_profile(profile)
    outcomes.check_test(*test)
    if not is_concrete(*test, *profile):
        raise ValueError(
            f"{caller} on a profile needs concrete inputs: it does not run under "
            "jax.jit or jax.vmap"
        )
    test = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in test))
    shape = test[0].shape
    ecof, amplitude, load, stiffness = (v.ravel() for v in test)
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
        above = ~(_residual(profile, grid[None, :], target[:, None], rig, mapping) <= 0.0)
        rises = ~above[:, :-1] & above[:, 1:]
        ambiguous = rises.sum(axis=1) + above[:, 0] > 1
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

    def failure() -> str:
        code = CorrectionStatus(int(status[0]))
        detail = code.reason
        if code == CorrectionStatus.NO_GROSS_SLIP:
            detail = f"it is at or above stiffness * amplitude / load = {1.0 / lam[0]:.6g}"
        return f"ecof = {float(ecof[0]):.6g} cannot be corrected on this profile: {detail}"

    return values.reshape(shape), status.reshape(shape), failure


def _illinois(profile, target, low, high, rig, mapping):
    """Roots of mu_E(mu) = target in the brackets [low, high] (Illinois method)."""
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
        active &= ~((value == 0.0) | (high - low <= 4.0 * _EPS * high))
    root = np.where(np.abs(f_low) <= np.abs(np.nan_to_num(f_high, nan=np.inf)), low, high)
    return root, np.abs(_residual(profile, root, target, rig, mapping)) <= 1e-9 * target


_PARAMETERS = """
    Parameters
    ----------
    ecof : array_like
        The reported energy coefficient of friction :math:`\\mu_E = E_d/(4P\\delta^*)`. [1]
    amplitude : array_like
        Displacement amplitude :math:`\\Delta^*` (also the groove half-width :math:`x_o`). [m]
    load : array_like
        Normal load :math:`P`. [N]
    stiffness : array_like
        Rig stiffness :math:`S`; ``numpy.inf`` for a rigid rig. [N/m]
    aspect_ratio : array_like or tuple (low, high), optional
        The scar's depth over half-width, :math:`z_o/x_o = D/W` (eq. 11); a ``tuple`` of two
        is an interval for a scar known only roughly (per-point values: a list or array). [1]
    scar_depth, scar_half_width : array_like, optional
        Wear scar depth :math:`D` and half-width :math:`W`, both instead of ``aspect_ratio``. [m]
    profile : ScarProfile, optional
        The scar's profile, of any shape, instead of an aspect ratio (concrete inputs only,
        not under ``jax.jit``/``jax.vmap``).
    mapping : {'scaled', 'physical'}
        With a profile: :math:`X = xW/\\Delta^*` (eq. 11) or :math:`X = x`.
    return_status : bool
        Also return each point's :class:`CorrectionStatus`, and never raise or warn; without
        it, a concrete array's points that cannot be corrected are NaN with a
        :class:`~ecofmaps.RegimeWarning` naming the reasons.
"""

_STATUS_RAISES_REFERENCES = """    status : jax.Array of int32
        Only with ``return_status=True``: :class:`CorrectionStatus` codes (for an interval,
        the first failure of its two ends).

    Raises
    ------
    ValueError
        For a concrete input out of range (ecof, amplitude, load, scar_half_width > 0;
        stiffness > 0, inf allowed; aspect_ratio, scar_depth >= 0; an interval's low <= high;
        all within :data:`ecofmaps.units.DOMAIN`; traced: NaN and ``INVALID``), the aspect
        ratio given neither or both ways, and (without ``return_status``) a single point
        that cannot be corrected (the message says why).

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 11, 13-15, 16.
"""


@float64
def correct_ecof(
    ecof,
    amplitude,
    load,
    stiffness,
    aspect_ratio=None,
    scar_depth=None,
    scar_half_width=None,
    *,
    profile=None,
    mapping="scaled",
    return_status=False,
):
    scar = (aspect_ratio, scar_depth, scar_half_width)
    return _correct(False, ecof, amplitude, load, stiffness, scar, profile, mapping, return_status)


correct_ecof.__doc__ = f"""The contact CoF :math:`\\mu` behind a reported energy CoF :math:`\\mu_E`.

    The model's :math:`\\mu_E(\\mu)` inverted exactly (docs/model.md, "Correcting a reported
    ECoF"), under ``jax.grad``, ``jax.jit`` and ``jax.vmap`` too without a profile (docs/api.md).
{_PARAMETERS}
    Returns
    -------
    mu : jax.Array of float64, or Interval
        The contact CoF, within a few ulp of the exact root; NaN where it cannot be
        corrected. With ``aspect_ratio=(low, high)``, an :class:`Interval` of arrays: every
        contact CoF that gives ``ecof`` with an aspect ratio in the interval. [1]
{_STATUS_RAISES_REFERENCES}
    Examples
    --------
    >>> import ecofmaps
    >>> mu = ecofmaps.correct_ecof(0.8308, amplitude=50e-6, load=450.0, stiffness=35e6,
    ...                            aspect_ratio=0.2)  # the paper's Example 2
    >>> round(float(mu), 3)
    0.8
"""


@float64
def correction_factor(
    ecof,
    amplitude,
    load,
    stiffness,
    aspect_ratio=None,
    scar_depth=None,
    scar_half_width=None,
    *,
    profile=None,
    mapping="scaled",
    return_status=False,
):
    scar = (aspect_ratio, scar_depth, scar_half_width)
    return _correct(True, ecof, amplitude, load, stiffness, scar, profile, mapping, return_status)


correction_factor.__doc__ = f"""The ratio :math:`\\mu/\\mu_E` of contact CoF to reported ECoF: the
    reciprocal of the :math:`\\mu_E/\\mu` of Figures 8 and 11, read at the reported ECoF.
{_PARAMETERS}
    Returns
    -------
    factor : jax.Array of float64, or Interval
        :math:`\\mu/\\mu_E \\le 1` (1 for a flat scar), with :math:`\\mu` from
        :func:`correct_ecof`; an :class:`Interval` for an aspect-ratio interval. [1]
{_STATUS_RAISES_REFERENCES}"""
