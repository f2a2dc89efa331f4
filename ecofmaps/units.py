"""Quantities typed with units (``50um``, ``35MN/m``, ``450 N``: a plain number and a plain
unit, no arithmetic) read as SI floats with pint, the dimension checked; a bare number is SI."""

import functools
import math
import re
from decimal import Decimal, localcontext

import numpy as np

__all__ = [
    "DIMENSIONS",
    "DOMAIN",
    "PLAIN_QUANTITY",
    "PLAUSIBLE",
    "TEXT_LIMIT",
    "bare_number_warning",
    "parse_quantity",
    "parse_values",
]

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

#: The values [SI] a bare (SI) number plausibly takes in a fretting test (low, high; None: no
#: bound), and the units, in order, it was probably meant in if not (:func:`bare_number_warning`).
PLAUSIBLE = {
    "amplitude": (0.1e-6, 5e-3, ("um", "mm")),
    "groove_half_width": (0.1e-6, 5e-3, ("um", "mm")),
    "scar_half_width": (0.1e-6, 5e-3, ("um", "mm")),
    "scar_depth": (None, 5e-3, ("um",)),
    "load": (None, 100e3, ("mN",)),
    "stiffness": (0.1e6, None, ("MN/m", "N/um")),
    "stiffness_ratio": (100.0, None, ("/um", "/mm")),
}

#: The values [SI] the model takes (low, high), a rigid rig's inf apart: far wider than any
#: fretting test, and narrow enough that the model's products of them stay finite. The command
#: line, the explorer and the Python API (:func:`ecofmaps._inputs.check`) refuse others.
DOMAIN = {
    **dict.fromkeys(("amplitude", "groove_half_width", "scar_half_width"), (1e-12, 1e3)),
    **dict.fromkeys(("scar_depth", "smoothing"), (0.0, 1e3)),
    "load": (1e-9, 1e9),
    "stiffness": (1e-3, 1e290),
    "stiffness_ratio": (1e-12, 1e299),  # the stiffness's over the load's
    "mu": (1e-6, 1e3),
    "ecof": (1e-6, 1e3),
    "aspect_ratio": (0.0, 1e6),
}


def bare_number_warning(name: str, text: str, kind: str) -> str | None:
    """Why ``text``, a bare (SI) number for ``name``, is implausible (:data:`PLAUSIBLE`), with the
    unit probably meant (``'50 is 50 m; did you mean 50um?'``); None if it is plausible."""
    if name not in PLAUSIBLE:
        return None
    try:
        value = float(text)
    except ValueError:  # a unit given
        return None
    low, high, meant = PLAUSIBLE[name]

    def plausible(value: float) -> bool:
        return (low is None or value >= low) and (high is None or value <= high)

    if not math.isfinite(value) or value == 0 or plausible(value):
        return None
    said = f"{text.strip()} is {value:g} {DIMENSIONS[kind][1]}"
    for unit in meant:
        if plausible(value * parse_quantity(f"1{unit}", kind)):  # text and unit may be too long
            return f"{said}; did you mean {text.strip()}{unit}?"
    if high is None:
        span = f"at least {low:g}"
    else:
        span = f"at most {high:g}" if low is None else f"{low:g} to {high:g}"
    return f"{said}; a fretting test's is {span} {DIMENSIONS[kind][1]}"


#: A decimal with an optional exponent, inf or nan.
_NUMBER = r"[+-]?(?:(?i:inf|nan)|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"
#: A unit's name (um, MN, parsecs, %) with an optional power of one digit (mm**3, s^-1).
_NAME = r"[A-Za-zµμ°%_]+(?:\s*(?:\*\*|\^)\s*[+-]?\d)?"
#: Names joined by '*', '/' or a space (MN/m, parsecs per fortnight).
_NAMES = rf"{_NAME}(?:(?:\s*[*/]\s*|\s+){_NAME})*"
#: A unit: names, or names in parentheses, so joined, after an optional '/' (mm**3/(N*m), /um).
_TERM = rf"(?:{_NAME}|\(\s*{_NAMES}\s*\))"
_UNIT = rf"/?\s*{_TERM}(?:(?:\s*[*/]\s*|\s+){_TERM})*"

#: The longest text a quantity may be (parsing a unit's name takes superlinear time). [1]
TEXT_LIMIT = 64

#: What a quantity's text may be: a plain number and an optional plain unit ('25um', '3.3 MN/m',
#: '0.08/um', 'inf'); no arithmetic for pint ('9**9**9 N' takes forever, '10**400 N' overflows).
PLAIN_QUANTITY = re.compile(rf"\s*(?P<number>{_NUMBER})\s*(?P<unit>{_UNIT})?\s*")


@functools.cache
def _registry():
    """pint's unit registry, imported on first use (most commands parse no unit)."""
    import pint

    return pint.UnitRegistry()


def parse_quantity(text: str, kind: str) -> float:
    """``text`` (:data:`PLAIN_QUANTITY`: ``'5e-5'``, ``'inf'``, ``'35 MN/m'``) as an SI float of
    ``kind`` (:data:`DIMENSIONS`), nearest the typed decimal times the unit (``'25um'``: 25e-6)."""
    dimension, si_unit, example = DIMENSIONS[kind]
    if len(text) > TEXT_LIMIT:
        raise ValueError(
            f"cannot read {text[:TEXT_LIMIT]!r}... as a {kind}: more than {TEXT_LIMIT} "
            f"characters; give a number with a plain unit, e.g. {example}"
        )
    match = PLAIN_QUANTITY.fullmatch(text)
    if match is None:
        raise ValueError(
            f"cannot read {text!r} as a {kind}: give a number with a plain unit, e.g. {example}"
        )
    number = Decimal(match["number"])
    if match["unit"] is None:
        value = float(number)
    else:
        registry = _registry()
        try:
            unit = registry.Quantity("1 " + match["unit"].replace("µ", "u").replace("μ", "u"))
        except Exception:  # pint raises many kinds of error for an unknown unit
            raise ValueError(
                f"cannot read {text!r} as a {kind}: unknown unit {match['unit']!r} (e.g. {example})"
            ) from None
        if unit.dimensionality != registry.Quantity(1, si_unit).dimensionality:
            raise ValueError(
                f"{text.strip()!r} is not a {kind}: its unit {unit.units:~} has dimension "
                f"{unit.dimensionality}, expected {dimension or 'none'} (e.g. {example})"
            )
        # The typed decimal scaled by the unit's factor in decimal arithmetic, so that '25um'
        # is the float nearest 25e-6 (pint's float product gives 2.4999999999999998e-05).
        factor = Decimal(repr(float(unit.to(si_unit).magnitude)))
        with localcontext(traps=[]):  # beyond Decimal's exponents: inf or 0, as a float
            value = float(number * factor)
    if math.isinf(value) and number.is_finite():
        raise ValueError(f"{text.strip()!r} is beyond the largest number, 1.8e308 {si_unit}")
    return value


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
        if not (math.isfinite(start) and math.isfinite(stop)):
            raise ValueError(f"the range {text!r} must start and stop at finite values")
        return np.linspace(start, stop, num)
    values = [parse_quantity(item, kind) for item in text.split(",") if item.strip()]
    if not values:
        raise ValueError(f"no value in {text!r}")
    if not all(math.isfinite(v) or v == math.inf for v in values):
        raise ValueError(f"{text!r} holds a NaN")
    return np.asarray(values, dtype=np.float64)
