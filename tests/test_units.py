"""Quantities with units on the command line (ecofmaps.units)."""

import numpy as np
import pytest

from ecofmaps.units import parse_quantity, parse_values


@pytest.mark.parametrize(
    ("text", "kind", "expected"),
    [
        ("50um", "length", 50e-6),
        ("50 µm", "length", 50e-6),
        ("50μm", "length", 50e-6),
        ("0.05mm", "length", 50e-6),
        ("5e-5", "length", 5e-5),
        ("450N", "force", 450.0),
        ("0.45 kN", "force", 450.0),
        ("35MN/m", "stiffness", 35e6),
        ("35 N/um", "stiffness", 35e6),
        ("inf", "stiffness", np.inf),
        ("0.08/um", "stiffness_ratio", 8e4),
        ("48.9mJ", "energy", 0.0489),
        ("0.8", "dimensionless", 0.8),
    ],
)
def test_parse_quantity(text, kind, expected):
    assert parse_quantity(text, kind) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize(
    ("text", "kind", "message"),
    [
        ("35MN/m", "length", r"'35MN/m' is not a length: .* expected \[length\]"),
        ("50um", "force", "is not a force"),
        ("fifty", "length", "cannot read 'fifty' as a length"),
        ("50 parsecs per fortnight", "length", "is not a length"),
        ("50 blorgs", "length", "cannot read"),
        ("3 m", "dimensionless", "is not a dimensionless"),
    ],
)
def test_parse_quantity_rejects(text, kind, message):
    with pytest.raises(ValueError, match=message):
        parse_quantity(text, kind)


@pytest.mark.parametrize(
    ("text", "kind", "expected"),
    [("25um", "length", 25e-6), ("3.3um", "length", 3.3e-6), ("70MN/m", "stiffness", 70e6),
     ("0.1mm", "length", 1e-4), ("48.9mJ", "energy", 0.0489),
     ("77.8/mm", "stiffness_ratio", 77.8e3)],
)  # fmt: skip
def test_typed_decimals_are_the_nearest_float(text, kind, expected):
    """'25um' is exactly the float 25e-6 (so .sel(amplitude=25e-6) finds it)."""
    assert parse_quantity(text, kind) == expected


def test_unit_expressions():
    assert parse_quantity("(35MN/m)/(450N)", "stiffness_ratio") == pytest.approx(35e6 / 450)


def test_parse_values_lists_and_ranges():
    np.testing.assert_allclose(parse_values("25um,50um", "length"), [25e-6, 50e-6])
    np.testing.assert_allclose(parse_values("0:0.3:4", "dimensionless"), [0, 0.1, 0.2, 0.3])
    np.testing.assert_allclose(parse_values("1um:3um:3", "length"), [1e-6, 2e-6, 3e-6])
    np.testing.assert_allclose(parse_values("35MN/m, inf", "stiffness"), [35e6, np.inf])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("0:1", "a range is start:stop:num"),
        ("0:1:1", "must be an integer >= 2"),
        ("0:1:x", "must be an integer >= 2"),
        (",", "no value"),
        ("nan", "holds a NaN"),
    ],
)
def test_parse_values_rejects(text, message):
    with pytest.raises(ValueError, match=message):
        parse_values(text, "dimensionless")
