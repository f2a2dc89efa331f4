"""Quantities with units on the command line (ecofmaps.units)."""

import subprocess
import sys

import numpy as np
import pytest

from ecofmaps.units import TEXT_LIMIT, bare_number_warning, parse_quantity, parse_values


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
        ("1e4um**3/J", "wear_rate", 1e-14),
        ("1e-6 mm**3/(N*m)", "archard", 1e-15),
        ("1e-400 N", "force", 0.0),
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
        ("", "length", "cannot read '' as a length: give a number with a plain unit, e.g. 50um"),
        ("1" * (TEXT_LIMIT + 1), "length", f"as a length: more than {TEXT_LIMIT} characters"),
        ("1e400 N", "force", r"'1e400 N' is beyond the largest number, 1.8e308 N"),
        ("1e999999999999 N", "force", "is beyond the largest number"),
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


@pytest.mark.parametrize(
    ("text", "kind"),
    [
        ("9**9**9 N", "force"),  # pint would compute 9**387420489
        ("10**400 N", "force"),  # pint would overflow
        ("1 m**9**9**9", "volume"),
        ("(35MN/m)/(450N)", "stiffness_ratio"),
        ("2*25um", "length"),
        ("50 um + 1 m", "length"),
        ("5 (um", "length"),
    ],
)
def test_expressions_are_refused(text, kind):
    """Only a plain number with a plain unit: pint evaluates nothing typed."""
    with pytest.raises(ValueError, match="give a number with a plain unit"):
        parse_quantity(text, kind)


@pytest.mark.parametrize("load", ["9**9**9 N", "10**400 N"])
def test_an_expression_on_the_command_line_is_refused_at_once(load):
    """One line naming the option, exit 2: no hang, no OverflowError traceback."""
    done = subprocess.run(
        [sys.executable, "-m", "ecofmaps.cli", "model", "--load", load],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert f"argument --load: cannot read {load!r} as a force: give a number" in done.stderr


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
        ("0:inf:3", "must start and stop at finite values"),
    ],
)
def test_parse_values_rejects(text, message):
    with pytest.raises(ValueError, match=message):
        parse_values(text, "dimensionless")


@pytest.mark.parametrize(
    ("name", "text", "kind", "said"),
    [
        ("amplitude", "50", "length", "50 is 50 m; did you mean 50um?"),
        ("stiffness", "35", "stiffness", "35 is 35 N/m; did you mean 35MN/m?"),
        ("load", "450000", "force", "450000 is 450000 N; did you mean 450000mN?"),
        ("amplitude", "50um", "length", None),
        ("amplitude", "5e-5", "length", None),
    ],
)
def test_bare_number_warning(name, text, kind, said):
    assert bare_number_warning(name, text, kind) == said


def test_bare_number_warning_of_the_longest_text():
    """The units tried make the text longer than TEXT_LIMIT: still a warning, no error."""
    warning = bare_number_warning("amplitude", "1" * TEXT_LIMIT, "length")
    assert warning.endswith("is 1.11111e+63 m; a fretting test's is 1e-07 to 0.005 m")
