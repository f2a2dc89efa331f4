"""The public entry points' inputs: pint Quantities to SI by parameter name, float64, concrete
inputs checked (tracers left to the kernels' NaN and ``INVALID``), huge broadcasts refused."""

import contextlib
import functools
import inspect
import itertools
import math
import os
import sys

import numpy as np

from ecofmaps._nomenclature import QUANTITIES, RANGES
from ecofmaps.units import DIMENSIONS, DOMAIN


def _is_quantity(value) -> bool:
    """Whether ``value`` is a pint Quantity of any registry (without importing pint)."""
    return type(value).__module__.split(".")[0] == "pint" and hasattr(value, "magnitude")


def to_si(name: str, value, quantity: str | None = None):
    """``value`` in SI units: a pint Quantity converted, plain numbers and arrays as they are."""
    if not is_concrete(value):  # a tracer, or a tuple (an interval) holding one
        return value
    described = QUANTITIES.get(quantity or name)
    kind = quantity if quantity in DIMENSIONS else getattr(described, "kind", "dimensionless")
    _, si_unit, example = DIMENSIONS[kind]
    if _is_quantity(value):
        try:
            return value.to(si_unit).magnitude
        except Exception:  # pint's DimensionalityError, or an offset unit
            raise ValueError(
                f"{name} must be a {kind.replace('_', ' ')} [{si_unit}], e.g. {example}; got "
                f"{value!r} of dimension {value.dimensionality}"
            ) from None
    try:
        array = np.asarray(value)
    except ValueError:  # a ragged sequence: left to the function's own checks
        return value
    if array.dtype.kind == "O" and all(
        isinstance(item, int | float | np.integer | np.floating) and not isinstance(item, bool)
        for item in array.ravel()
    ):
        try:  # Python integers, which may be beyond float64
            array.astype(np.float64)
        except OverflowError:
            raise ValueError(
                f"{name} holds an integer beyond float64's largest number, 1.8e308 [{si_unit}]"
            ) from None
    elif array.dtype.kind in "bUSO":  # booleans, text, None
        raise ValueError(
            f"{name} must be a real number or array of them [{si_unit}] (or a pint "
            f"Quantity), got {value!r}"
        )
    return value


def _clashes(shapes: list):
    for (first, one), (second, other) in itertools.combinations(shapes, 2):
        try:
            np.broadcast_shapes(one, other)
        except ValueError:
            yield f"{first} {one} and {second} {other}"


def si_units(function=None, **kinds):
    """``function`` taking pint Quantities, in SI by parameter name (or by ``kinds``), and
    refusing a broadcast of them too large for memory."""
    if function is None:
        return functools.partial(si_units, **kinds)
    parameters = inspect.signature(function)

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        bound = parameters.bind_partial(*args, **kwargs)
        shapes = []  # (name, shape) of each quantity of QUANTITIES
        for name, value in bound.arguments.items():
            quantity = kinds.get(name, name)
            if isinstance(value, tuple) and any(_is_quantity(item) for item in value):
                value = bound.arguments[name] = tuple(to_si(name, i, quantity) for i in value)
            elif value is not None and (_is_quantity(value) or name in QUANTITIES or name in kinds):
                value = bound.arguments[name] = to_si(name, value, quantity)
            if name in QUANTITIES and name not in kinds:
                for item in value if isinstance(value, tuple) else (value,):
                    with contextlib.suppress(TypeError, ValueError):  # ragged: checked elsewhere
                        shapes.append((name, tuple(np.shape(item))))
        check_broadcast_size(function.__name__, [shape for _, shape in shapes])
        try:
            return function(*bound.args, **bound.kwargs)
        except (TypeError, ValueError) as error:
            clash = "broadcast" in str(error) and next(_clashes(shapes), None)
            if not clash:
                raise
            raise ValueError(
                f"ecofmaps.{function.__name__}: the shapes of {clash} do not broadcast together: "
                "give arrays of one shape, or shapes NumPy broadcasts (equal or 1 in each "
                "trailing axis)"
            ) from None

    return wrapper


def available_memory() -> int | None:
    """The memory available to a new array (``MemAvailable``, else physical; or None). [B]"""
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None


def check_broadcast_size(caller: str, shapes: list) -> None:
    """Raise ``MemoryError`` before a broadcast of ``shapes`` that would not fit in memory."""
    try:
        shape = np.broadcast_shapes(*shapes)
    except ValueError:  # axes of a grid, or a clash the function reports
        return
    points = math.prod(shape)
    if points <= max((math.prod(s) for s in shapes), default=1):
        return
    memory, size = available_memory(), 8 * points  # one float64 result
    if memory is None or size <= memory:
        return
    raise MemoryError(
        f"ecofmaps.{caller}: the inputs broadcast to shape {shape}, {points:.3g} points: "
        f"{size / 1e9:.3g} GB for one float64 result, more than the {memory / 1e9:.3g} GB of "
        "memory available. Compute such a grid in chunks with "
        "ecofmaps.compute_map(..., chunks=...), or pass fewer points at a time."
    )


def float64(function):
    """A public JAX entry point: pint Quantities in SI (:func:`si_units`), then float64."""
    import jax

    @si_units
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        concrete = is_concrete(*args, *kwargs.values())
        if not concrete and not jax.config.jax_enable_x64:
            raise ValueError(
                f"ecofmaps.{function.__name__} under jax.jit, jax.vmap or jax.grad needs JAX's "
                "64-bit mode (the model needs float64): call "
                "jax.config.update('jax_enable_x64', True) at start-up, or trace inside "
                "'with jax.enable_x64(True):'"
            )
        with jax.enable_x64(True):
            result = function(*args, **kwargs)
            return jax.tree_util.tree_map(_to_numpy, result) if concrete else result

    return wrapper


def _to_numpy(leaf):
    """A JAX array as a read-only NumPy view; anything else as it is."""
    return np.asarray(leaf) if isinstance(leaf, sys.modules["jax"].Array) else leaf


def is_concrete(*values) -> bool:
    """Whether no leaf of the pytrees ``values`` is a JAX tracer."""
    jax = sys.modules.get("jax")
    if jax is None:  # no tracer exists before JAX is imported
        return True
    return not any(isinstance(leaf, jax.core.Tracer) for leaf in jax.tree_util.tree_leaves(values))


def as_float64(value):
    """``value`` as a float64 JAX array (call inside :func:`float64`)."""
    import jax.numpy as jnp

    return jnp.asarray(value, dtype=jnp.float64)


def check(name: str, value, rule: str | None = None, unit: str | None = None) -> None:
    """``ValueError`` if a concrete ``value`` breaks ``rule`` or lies beyond the model's
    :data:`ecofmaps.units.DOMAIN` for ``name``'s first word; tracers pass unchecked."""
    if not is_concrete(value):
        return
    described = QUANTITIES.get(name)
    rule = rule or described.valid
    unit = unit if unit is not None else ("" if described is None else described.units)
    to_si(name, value, name if described else "mu")  # None, strings, booleans: refused
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number or array of them, got {value!r}") from None
    test, valid = RANGES[rule]
    ok, domain = test(array), ""
    if np.all(ok):  # in range: within the domain too (inf, where the rule allows it)
        low, high = DOMAIN.get(name.partition(" ")[0], (-math.inf, math.inf))
        ok = ((array >= low) & (array <= high)) | (array == math.inf)
        if np.all(ok):
            return
        valid = f"{low:g} <= {{name}} <= {high:g}"
        rigid = ", or inf: a rigid rig" if rule == "positive_or_inf" else ""
        domain = f" (the model's domain{rigid})"
    bad = np.argwhere(~ok)[0] if array.ndim else ()
    where = f" at index {tuple(int(i) for i in bad)}" if array.ndim else ""
    count = "" if array.size <= 1 else f" ({np.count_nonzero(~ok)} of {array.size} values)"
    suffix = f" [{unit}]" if unit else ""
    raise ValueError(
        f"{name} must satisfy {valid.format(name=name)}{suffix}{domain}; "
        f"got {array[tuple(bad)].item()!r}{where}{count}"
    )
