"""Column names that carry their unit, finding columns, and deciding a column's unit."""

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from ecofmaps.io.columns import (
    COMMON_UNITS,
    SYNONYMS,
    ColumnError,
    column_scale,
    find_column,
    listed_names,
    split_unit,
)
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
@example(base="A N", unit="N", style="{base} [{unit}]")  # a base that ends in a unit's word
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
    factor, unit, _ = column_scale(role, "column", option, carried)
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
        column_scale(role, "column", option, carried)


@pytest.mark.parametrize("unit", sorted(COMMON_UNITS))
def test_common_units_agree_with_pint(unit):
    """The table read without pint gives exactly pint's factor (ecofmaps.units)."""
    kind, factor = COMMON_UNITS[unit]
    assert parse_quantity(f"1 {unit}", kind) == factor


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("Displacement in mm", ("Displacement", "mm")),
        ("Force in kN", ("Force", "kN")),
        ("x_in", ("x", "in")),
        ("Disp (in)", ("Disp", "in")),
        ("Fx [kip]", ("Fx", "kip")),
        ("F_mN", ("F", "mN")),
        ("Disp [µm]", ("Disp", "µm")),
        ("Load in N", ("Load", "N")),
    ],
)
def test_split_unit_inches_kips_and_in(name, expected):
    assert split_unit(name) == expected


@pytest.mark.parametrize(
    ("names", "role", "expected"),
    [
        (["delta_mm", "Ftr_kN"], "displacement", 0),
        (["delta_mm", "Ftr_kN"], "force", 1),
        (["Disp [um]", "Fx [N]"], "displacement", 0),
        (["Disp [um]", "Fx [N]"], "force", 1),
        (["Displacement (mm)", "Tangential force (kN)"], "force", 1),
        (["stroke_um", "friction_force_N"], "displacement", 0),
        (["stroke_um", "friction_force_N"], "force", 1),
        (["time [s]", "Position/µm", "Q / N", "Fz [kN]"], "load", 3),
        (["t", "X", "Fx", "Fn_N", "Cycle #"], "cycle", 4),
        (["t", "X", "Fx", "Fn_N", "N° cycle"], "cycle", 4),
        (["x", "Displacement [um]"], "displacement", 1),  # the role's own name first
        (["Force", "Fx"], "force", 0),
    ],
)
def test_usual_names_are_found_by_the_role(names, role, expected):
    assert find_column(names, role, role) == expected
    assert find_column(names, role.upper(), role) == expected


def test_an_explicit_name_finds_no_synonym():
    assert find_column(["delta_mm", "Ftr_kN"], "disp", "displacement", required=False) is None
    assert find_column(["t", "n"], "cycle no", "cycle", required=False) is None


def test_two_usual_names_are_an_error_naming_both():
    with pytest.raises(ColumnError) as raised:
        find_column(["stroke [mm]", "t", "Disp [um]", "Fx"], "displacement", "displacement")
    message = str(raised.value)
    assert (
        "several displacement columns match 'displacement': 'stroke [mm]', 'Disp [um]'" in message
    )
    assert "displacement_column (--displacement-col)" in message


@pytest.mark.parametrize(
    ("names", "wanted", "role", "suggested"),
    [
        (["Dsplacement [um]", "Fx"], "displacement", "displacement", "Dsplacement [um]"),
        (["Displ_um", "Frc"], "force", "force", "Frc"),
        (["t", "Forse_N"], "Force", "force", "Forse_N"),
        (["t", "Tangential_kN"], "Tangental force", "force", "Tangential_kN"),
        (["t", "Tangential_kN"], "Q", "force", None),
        (["a", "b"], "displacement", "displacement", None),
    ],
)
def test_no_match_lists_the_columns_and_suggests_the_nearest(names, wanted, role, suggested):
    with pytest.raises(ColumnError) as raised:
        find_column(names, wanted, role)
    message = str(raised.value)
    assert f"no {role} column {wanted!r}" in message
    assert "(columns: " + ", ".join(repr(name) for name in names) + ")" in message
    assert (f"Did you mean {suggested!r}?" in message) == (suggested is not None)
    assert ("Did you mean" in message) == (suggested is not None)
    assert f"{role}_column (--{role}-col)" in message


@given(
    role=st.sampled_from(["displacement", "force", "load", "cycle"]),
    pick=st.integers(0, 100),
    style=st.sampled_from(["{base}", *STYLES]),
    join=st.sampled_from([" ", "_", "-", ""]),
    upper=st.booleans(),
    position=st.integers(0, 3),
)
def test_every_usual_name_in_every_style_is_found(role, pick, style, join, upper, position):
    """Any usual name of a role, in any case, words joined any way, with a unit of the
    role's kind in any style, is found by the role's own name among columns of the other
    roles (each under its own usual name)."""
    synonyms = SYNONYMS[role]
    base = synonyms[pick % len(synonyms)].replace(" ", join)
    base = base.upper() if upper else base
    unit = {"displacement": "mm", "force": "kN", "load": "N", "cycle": None}[role]
    name = base if unit is None or not base.strip("-") else style.format(base=base, unit=unit)
    others = {"displacement": "Disp [um]", "force": "Ftr_kN", "load": "Fz", "cycle": "Cycle No"}
    names = [other for key, other in others.items() if key != role]
    names.insert(position, name)
    assert find_column(names, role, role) == position


def test_columns_named_alike_are_chosen_by_their_position():
    names = ["displacement [m]", "force [N]", "force [N]"]
    with pytest.raises(ColumnError) as raised:
        find_column(names, "force [N]", "force")
    assert str(raised.value) == (
        "several force columns match 'force [N]': 'force [N]' (#2), 'force [N]' (#3); choose "
        "one with force_column (--force-col) by its position, e.g. '#2'"
    )
    assert find_column(names, "#3", "force") == 2
    assert find_column(names, " #2 ", "force") == 1
    assert find_column(names, "#4", "force", required=False) is None
    assert find_column(["#2", "x"], "#2", "force") == 0  # a column named so comes first


@pytest.mark.parametrize("name", ["displacement [foo]", "Displacement/foo", "disp [qq]"])
def test_an_unknown_unit_is_named_as_such(name):
    with pytest.raises(ColumnError) as raised:
        find_column([name, "force [N]"], "displacement", "displacement")
    unit = name.split("[")[-1].split("/")[-1].strip("]")
    assert str(raised.value).startswith(
        f"the displacement column {name!r} is in {unit!r}, which is not a known unit "
        "(known: m, mm, um, µm, μm, nm, in and the others pint reads)"
    )
    assert "displacement_unit (--displacement-unit)" in str(raised.value)


def test_column_lists_in_messages_are_cut():
    names = ["x" * 200_000, *(f"c{k}" for k in range(30))]
    with pytest.raises(ColumnError) as raised:
        find_column(names, "displacement", "displacement")
    message = str(raised.value)
    assert len(message) < 600 and "and 21 more" in message
    assert f"'{'x' * 36}..." in message
    assert listed_names(["a", "b"]) == "'a', 'b'"
