"""Column names that carry their unit, finding columns, and deciding a column's unit."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from ecofmaps.io.columns import COMMON_UNITS, ColumnError, column_scale, find_column, split_unit
from ecofmaps.units import parse_quantity

LENGTHS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "micron": 1e-6, "nm": 1e-9}
FORCES = {"N": 1.0, "kN": 1e3, "mN": 1e-3}
STYLES = ["{base} [{unit}]", "{base} ({unit})", "{base}/{unit}", "{base} / {unit}", "{base}_{unit}"]


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("delta_mm", ("delta", "mm")),
        ("Ftr_kN", ("Ftr", "kN")),
        ("force [N]", ("force", "N")),
        ("force[N]", ("force", "N")),
        ("displacement (um)", ("displacement", "um")),
        ("Displacement/µm", ("Displacement", "µm")),
        ("F / kN", ("F", "kN")),
        ('"Disp. [µm]"', ("Disp.", "µm")),
        ("force [V]", ("force", "V")),  # a unit, of another kind: split, judged later
        ("time_s", ("time_s", None)),  # a suffix that is neither a length nor a force
        ("cycle_no", ("cycle_no", None)),
        ("Force (tangential)", ("Force (tangential)", None)),
        ("Tangential Force", ("Tangential Force", None)),
        ("Force_1", ("Force_1", None)),
        ("x", ("x", None)),
    ],
)
def test_split_unit(name, expected):
    assert split_unit(name) == expected


@given(
    base=st.from_regex(r"[A-Za-z][A-Za-z0-9 .]{0,12}[A-Za-z]", fullmatch=True),
    unit=st.sampled_from(sorted({**LENGTHS, **FORCES})),
    style=st.sampled_from(STYLES),
)
def test_split_unit_finds_every_style(base, unit, style):
    """Any name in any style gives back its base and unit; finding the base finds it."""
    if style.endswith("_{unit}"):
        base = base.replace(" ", "")
    name = style.format(base=base, unit=unit)
    assert split_unit(name) == (base.strip(), unit)
    assert find_column(["other", name], base.upper(), "force") == 1


def test_find_column_prefers_the_whole_name():
    names = ["Force", "force [kN]", "Displacement [um]", "displacement_mm"]
    assert find_column(names, "force", "force") == 0
    assert find_column(names, "FORCE [kN]", "force") == 1
    with pytest.raises(ColumnError, match="several displacement columns match 'displacement'"):
        find_column(names, "displacement", "displacement")
    assert find_column(names, "cycle", "cycle", required=False) is None


@pytest.mark.parametrize(
    ("role", "option", "carried", "expected"),
    [
        ("displacement", None, [], (1e-6, "um")),  # the default
        ("force", None, [], (1.0, "N")),
        ("displacement", None, ["mm"], (1e-3, "mm")),  # the file's unit
        ("displacement", "mm", [], (1e-3, "mm")),  # the option
        ("displacement", "mm", ["millimetre"], (1e-3, "mm")),  # the same unit twice
        ("force", "kN", ["V"], (1e3, "kN")),  # an option overrules another kind
        ("force", None, ["kN", "kN"], (1e3, "kN")),
    ],
)
def test_column_scale(role, option, carried, expected):
    factor, unit = column_scale(role, option, carried, "column")
    assert factor == pytest.approx(expected[0], rel=1e-15) and unit == expected[1]


@pytest.mark.parametrize(
    ("role", "option", "carried", "error", "message"),
    [
        ("displacement", "um", ["mm"], ColumnError, r"is in 'mm', but displacement_unit='um'"),
        ("force", None, ["N", "kN"], ColumnError, r"is in 'N', but 'kN' says otherwise"),
        ("force", None, ["V"], ColumnError, "is in 'V', which is not a force unit; give force_"),
        ("displacement", "kN", [], ValueError, "displacement_unit='kN' is not a length unit"),
        ("force", "furlong", [], ValueError, "force_unit='furlong' is not a force unit"),
    ],
)
def test_column_scale_errors(role, option, carried, error, message):
    with pytest.raises(error, match=message):
        column_scale(role, option, carried, "column")


@pytest.mark.parametrize("unit", sorted(COMMON_UNITS))
def test_common_units_agree_with_pint(unit):
    """The table read without pint gives exactly pint's factor (ecofmaps.units)."""
    kind, factor = COMMON_UNITS[unit]
    assert parse_quantity(f"1 {unit}", kind) == factor
