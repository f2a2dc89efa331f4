r"""The correction of a reported ECoF on a wear-scar profile of any shape.

:func:`ecofmaps.correct_ecof` and :func:`ecofmaps.correction_factor` with ``profile=``: a
scan of :math:`\mu_E(\mu)` over a grid of contact CoFs, narrowed by the Illinois method.
NumPy on concrete inputs only; the method is in ``docs/model.md`` (correcting a reported ECoF).
"""

from __future__ import annotations

import numpy as np

from ecofmaps._codes import warn_nan
from ecofmaps._inputs import is_concrete
from ecofmaps.correction.outcomes import CorrectionStatus, check_test
from ecofmaps.model.on_profile import as_profile, check_mapping, steady_numbers

__all__ = ["correct_on_profile"]


_EPS = float(np.finfo(np.float64).eps)
_PROFILE_GRID = 400  # contact CoFs scanned per point
_PROFILE_SPAN = 0.02  # the grid runs from this fraction of the smallest ECoF ...
_PROFILE_STEPS = 200  # at most this many Illinois steps (each at least halves every two)


def _residual(profile, mu, target, rig, mapping):
    """mu_E(mu) - target at concrete points; NaN beyond gross slip or the trace."""
    with np.errstate(invalid="ignore"):
        numbers = steady_numbers(profile, *rig, mu, mapping=mapping)
        return np.asarray(numbers["ecof_ratio"]) * np.asarray(mu) - target


def correct_on_profile(
    ecof, amplitude, load, stiffness, profile, mapping, return_status, factor, caller
):
    """correct_ecof / correction_factor on a profile (see correct_ecof's Notes)."""
    check_mapping(mapping, None)
    profile = as_profile(profile)
    check_test(ecof, amplitude, load, stiffness)
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
        above = ~(_residual(profile, grid[None, :], target[:, None], rig, mapping) <= 0.0)
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
                detail = code.reason
            raise ValueError(
                f"ecof = {float(ecof[0]):.6g} cannot be corrected on this profile: {detail}"
            )
        warn_nan(values, status, CorrectionStatus, caller)
    return (values, status) if return_status else values


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
        done = (value == 0.0) | (high - low <= 4.0 * _EPS * high)
        active &= ~done
    root = np.where(np.abs(f_low) <= np.abs(np.nan_to_num(f_high, nan=np.inf)), low, high)
    check_value = _residual(profile, root, target, rig, mapping) + target
    reached = np.abs(check_value - target) <= 1e-9 * target
    return root, reached
