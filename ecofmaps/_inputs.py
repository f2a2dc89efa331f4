"""Input handling shared by the public entry points: float64 and validation.

The public functions accept anything array-like, including JAX tracers (under
``jax.jit``, ``jax.vmap`` and ``jax.grad``). Concrete inputs are checked here and
bad values raise a :class:`ValueError` that names the parameter and its valid
range; traced inputs cannot be inspected, so the kernels turn them into NaN plus
the ``INVALID`` regime code instead.
"""

from __future__ import annotations

import functools
import warnings

import jax
import jax.numpy as jnp
import numpy as np

__all__ = ["RegimeWarning", "as_float64", "check", "float64", "is_concrete", "warn_nan"]


class RegimeWarning(RuntimeWarning):
    """A concrete call returned NaN because a point is outside the gross-slip regime."""


def float64(function):
    """Run ``function`` with JAX's 64-bit mode on, whatever the caller's configuration.

    Concrete calls compute and return float64 whether or not the caller switched JAX's
    64-bit mode on; importing ecofmaps does not switch it on. Traced calls (inside the
    caller's ``jax.jit``, ``jax.vmap`` or ``jax.grad``) receive arrays whose precision the
    caller's mode has already fixed, so they require the mode on and raise a ``ValueError``
    that says how, instead of silently computing in float32.
    """

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        if not jax.config.jax_enable_x64 and not is_concrete(*args, *kwargs.values()):
            raise ValueError(
                f"ecofmaps.{function.__name__} under jax.jit, jax.vmap or jax.grad needs JAX's "
                "64-bit mode (the model needs float64): call "
                "jax.config.update('jax_enable_x64', True) at start-up, or trace inside "
                "'with jax.enable_x64(True):'"
            )
        with jax.enable_x64(True):
            return function(*args, **kwargs)

    return wrapper


def is_concrete(*values) -> bool:
    """True when none of ``values`` is a JAX tracer (so they can be inspected)."""
    return not any(isinstance(value, jax.core.Tracer) for value in values)


def as_float64(value):
    """``value`` as a float64 JAX array (call inside :func:`float64`)."""
    return jnp.asarray(value, dtype=jnp.float64)


_RULES = {
    "positive": (lambda a: a > 0, "0 < {name} < inf"),
    "positive_or_inf": (lambda a: a > 0, "0 < {name} <= inf"),
    "non_negative": (lambda a: a >= 0, "0 <= {name} < inf"),
    "finite": (lambda a: np.ones(np.shape(a), dtype=bool), "-inf < {name} < inf"),
}


def check(name: str, value, rule: str, unit: str = "") -> None:
    """Raise ``ValueError`` if a concrete ``value`` breaks ``rule``; do nothing for tracers.

    Parameters
    ----------
    name : str
        The parameter's keyword name, quoted in the message.
    value : array_like
        The value to check.
    rule : {'positive', 'positive_or_inf', 'non_negative', 'finite'}
        The valid range. Every rule rejects NaN; only ``'positive_or_inf'`` admits +inf.
    unit : str
        Unit shown with the range, e.g. ``'m'``.
    """
    if not is_concrete(value):
        return
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number or array of them, got {value!r}") from None
    test, valid = _RULES[rule]
    allowed_inf = rule == "positive_or_inf"
    ok = test(array) & (np.isfinite(array) | (allowed_inf & (array == np.inf)))
    if np.all(ok):
        return
    bad = np.argwhere(~ok)[0] if array.ndim else ()
    where = f" at index {tuple(int(i) for i in bad)}" if array.ndim else ""
    count = "" if array.size <= 1 else f" ({np.count_nonzero(~ok)} of {array.size} values)"
    suffix = f" [{unit}]" if unit else ""
    raise ValueError(
        f"{name} must satisfy {valid.format(name=name)}{suffix}; "
        f"got {array[tuple(bad)].item()!r}{where}{count}"
    )


def warn_nan(values, regimes, reasons: dict[int, str], quantity: str) -> None:
    """Warn when a concrete result holds NaN for a physical reason (a regime), naming it."""
    values = np.asarray(values)
    regimes = np.asarray(regimes)
    nan = np.isnan(values)
    if not nan.any():
        return
    for code, reason in reasons.items():
        count = int(np.count_nonzero(nan & (regimes == code)))
        if count:
            warnings.warn(
                f"{quantity} is NaN at {count} of {values.size} point(s): {reason}",
                RegimeWarning,
                stacklevel=3,
            )
