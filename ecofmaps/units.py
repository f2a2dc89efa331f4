"""Quantities with units, as the command line reads and prints them.

The Python API speaks SI; people type ``50um``, ``35MN/m`` or ``450 N``. These helpers
turn such text into SI floats with pint, and check the dimension, so ``--amplitude 35MN/m``
is an error that says what was expected. A bare number is taken as SI.
"""

from __future__ import annotations

import functools
import math
import re
from decimal import Decimal

import numpy as np

__all__ = ["DIMENSIONS", "PLAUSIBLE", "bare_number_warning", "parse_quantity", "parse_values"]

#: Physical dimension of each kind of quantity, with its SI unit and an example.
DIMENSIONS = {
    "length": ("[length]", "m", "50um"),
    "force": ("[force]", "N", "450N"),
    "stiffness": ("[force] / [length]", "N/m", "35MN/m"),
    "stiffness_ratio": ("1 / [length]", "1/m", "0.08/um"),
    "energy": ("[energy]", "J", "0.05J"),
    "volume": ("[length] ** 3", "m**3", "0.01mm**3"),
    "wear_rate": ("[length] ** 3 / [energy]", "m**3/J", "1e4um**3/J"),
    "archard": ("[length] / [force]", "m**2/N", "1e-6mm**3/(N*m)"),
    "dimensionless": ("", "1", "0.8"),
}


#: The values [SI] a quantity typed as a bare number (which is SI) plausibly takes in a
#: fretting test, (low, high; None: no bound), and the units, in the order tried, that such a
#: number outside them was probably meant in (:func:`bare_number_warning`).
PLAUSIBLE = {
    "amplitude": (0.1e-6, 5e-3, ("um", "mm")),
    "groove_half_width": (0.1e-6, 5e-3, ("um", "mm")),
    "scar_half_width": (0.1e-6, 5e-3, ("um", "mm")),
    "scar_depth": (None, 5e-3, ("um",)),
    "load": (None, 100e3, ("mN",)),
    "stiffness": (0.1e6, None, ("MN/m", "N/um")),
    "stiffness_ratio": (100.0, None, ("/um", "/mm")),
}


def bare_number_warning(name: str, text: str, kind: str) -> str | None:
    """Why ``text``, a bare number for quantity ``name`` (of ``kind``, a key of
    :data:`DIMENSIONS`), is implausible in SI, with the unit probably meant; None if ``text``
    has a unit or is plausible (:data:`PLAUSIBLE`).

    Examples
    --------
    >>> bare_number_warning("amplitude", "50", "length")
    '50 is 50 m; did you mean 50um?'
    >>> bare_number_warning("amplitude", "50um", "length") is None
    True
    """
    if name not in PLAUSIBLE:
        return None
    try:
        value = float(text)
    except ValueError:  # a unit given
        return None
    low, high, meant = PLAUSIBLE[name]
    plausible = functools.partial(_within, low, high)
    if not math.isfinite(value) or value == 0 or plausible(value):
        return None
    said = f"{text.strip()} is {value:g} {DIMENSIONS[kind][1]}"
    for unit in meant:
        if plausible(parse_quantity(f"{text.strip()}{unit}", kind)):
            return f"{said}; did you mean {text.strip()}{unit}?"
    if high is None:
        span = f"at least {low:g}"
    else:
        span = f"at most {high:g}" if low is None else f"{low:g} to {high:g}"
    return f"{said}; a fretting test's is {span} {DIMENSIONS[kind][1]}"


def _within(low, high, value: float) -> bool:
    return (low is None or value >= low) and (high is None or value <= high)


# A plain decimal number followed by a unit name, e.g. "25um", "3.3 MN/m", "1e-3 m".
_NUMBER_AND_UNIT = re.compile(r"([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*([^\d\s(].*)")


@functools.cache
def _registry():
    """pint's unit registry (pint imported on first use: most commands parse no unit)."""
    import pint

    return pint.UnitRegistry()


def parse_quantity(text: str, kind: str) -> float:
    """One quantity as an SI float."""
    dimension, si_unit, example = DIMENSIONS[kind]
    text = text.strip()
    try:
        return float(text)
    except ValueError:
        pass
    registry = _registry()
    try:
        quantity = registry.Quantity(text.replace("µ", "u").replace("μ", "u"))
    except Exception:  # pint raises many kinds of error for bad text
        raise ValueError(
            f"cannot read {text!r} as a {kind} (expected a number with a unit, e.g. {example})"
        ) from None
    if not isinstance(quantity, registry.Quantity):
        return float(quantity)
    if quantity.dimensionality != registry.Quantity(1, si_unit).dimensionality:
        raise ValueError(
            f"{text!r} is not a {kind}: its unit {quantity.units:~} has dimension "
            f"{quantity.dimensionality}, expected {dimension or 'none'} (e.g. {example})"
        )
    # Scale a typed decimal by its unit's factor in decimal arithmetic, so that '25um' is the
    # float nearest 25e-6 (pint's float product gives 2.4999999999999998e-05). Expressions
    # such as '(35MN/m)/(450N)' are left to pint's own arithmetic.
    match = _NUMBER_AND_UNIT.fullmatch(text.replace("µ", "u").replace("μ", "u"))
    try:
        unit = registry.parse_units(match.group(2)) if match else None
    except Exception:  # the rest is not a plain unit
        unit = None
    if unit is None or unit != quantity.units:
        return float(quantity.to(si_unit).magnitude)
    factor = registry.Quantity(1, unit).to(si_unit).magnitude
    return float(Decimal(match.group(1)) * Decimal(repr(float(factor))))


def parse_values(text: str, kind: str) -> np.ndarray:
    """A list or a range of quantities as a 1-D float64 array in SI."""
    if ":" in text and not text.strip().startswith(":"):
        parts = text.split(":")
        if len(parts) != 3:
            raise ValueError(f"a range is start:stop:num, got {text!r}")
        start, stop = (parse_quantity(part, kind) for part in parts[:2])
        try:
            num = int(parts[2])
        except ValueError:
            num = -1
        if num < 2:
            raise ValueError(f"the number of points in {text!r} must be an integer >= 2")
        return np.linspace(start, stop, num)
    values = [parse_quantity(item, kind) for item in text.split(",") if item.strip()]
    if not values:
        raise ValueError(f"no value in {text!r}")
    if not all(math.isfinite(v) or v == math.inf for v in values):
        raise ValueError(f"{text!r} holds a NaN")
    return np.asarray(values, dtype=np.float64)
