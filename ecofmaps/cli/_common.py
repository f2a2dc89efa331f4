"""What the subcommands share: quantities read with units, user errors, printed tables."""

from __future__ import annotations

import argparse
import math

from ecofmaps._nomenclature import QUANTITIES
from ecofmaps.units import parse_quantity, parse_values

__all__ = ["CommandError", "print_rows", "quantities", "quantity", "row"]


class CommandError(Exception):
    """A user error found after parsing (bad file, bad value): reported in one line."""


def quantity(kind: str):
    """An argparse ``type`` reading one quantity of ``kind`` with units (see ecofmaps.units)."""

    def parse(text: str) -> float:
        try:
            return parse_quantity(text, kind)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None

    parse.__name__ = kind
    return parse


def quantities(kind: str):
    """An argparse ``type`` reading a list ``a,b,c`` or a range ``start:stop:num``."""

    def parse(text: str):
        try:
            return parse_values(text, kind)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None

    parse.__name__ = kind
    return parse


def row(name: str, value, note: str = "") -> tuple[str, str, str]:
    """One printed row: the quantity's words and symbol, and ``value`` [SI] in its display unit.

    ``value`` may be text (printed as it is); a NaN prints as ``undefined``, an infinite
    stiffness as ``inf (rigid)``. ``note`` follows the words, e.g. ``'(reported)'``.
    """
    quantity = QUANTITIES[name]
    words = f"{quantity.words} {note}".strip()
    if isinstance(value, str):
        return words, quantity.symbol, value
    if math.isnan(value):
        return words, quantity.symbol, "undefined"
    if name == "stiffness" and math.isinf(value):
        return words, quantity.symbol, "inf (rigid)"
    shown = f"{value * quantity.display_factor:.6g}"
    return words, quantity.symbol, f"{shown} {quantity.display_unit}".strip()


def print_rows(title: str, rows) -> None:
    """Print ``title`` and aligned rows of :func:`row` (``None`` prints an empty line)."""
    print(title)
    for item in rows:
        print("" if item is None else f"  {item[0]:<32} {item[1]:<8} {item[2]}".rstrip())
