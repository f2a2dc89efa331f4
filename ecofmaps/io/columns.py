"""Column names as labs write them: the unit a name carries, a column found by name or usual
name (:data:`SYNONYMS`), and its factor to SI; the rules are in ``docs/formats.md``."""

from __future__ import annotations

import difflib
import functools
import itertools
import math
import re

#: The kind of quantity of each column role, as :func:`ecofmaps.units.parse_quantity` names it:
#: a recording's displacement, force and normal load, a scar profile's position x and height z.
KINDS = {"displacement": "length", "force": "force", "load": "force", "x": "length", "z": "length"}

#: The unit of a column whose name, metadata and options say none.
DEFAULT_UNITS = {"displacement": "um", "force": "N", "load": "N", "x": "um", "z": "um"}

#: The usual names of a recording's columns by role, compared with a column's base (its
#: name without unit) without regard to case, blanks and punctuation (``Friction_Force``
#: is ``friction force``, ``Disp.`` is ``disp``).
SYNONYMS = {
    "displacement": (
        "displacement",
        "disp",
        "delta",
        "stroke",
        "position",
        "x",
        "s",
        "displ",
        "dx",
        "delta x",
        "Δ",
        "Δx",
        "pos",
        "travel",
        "relative displacement",
        "tangential displacement",
        "sliding displacement",
    ),
    "force": (
        "force",
        "Fx",
        "Ft",
        "Q",
        "Ftr",
        "tangential force",
        "friction force",
        "F",
        "tangential",
        "tangential load",
        "friction",
        "Ff",
        "Fr",
        "shear force",
        "traction",
    ),
    "load": ("load", "Fz", "Fn", "normal load", "normal force", "P", "normal", "applied load"),
    "cycle": (
        "cycle",
        "cycles",
        "n",
        "cycle number",
        "cycle no",
        "cycle nr",
        "cycle count",
        "cycle index",
        "n cycle",
        "n cycles",
        "cyc",
        "number of cycles",
    ),
}

#: How the user chooses a role's column: the keyword of the Python API and the option of
#: the command line, for messages.
_CHOOSE = {role: f"{role}_column (--{role}-col)" for role in ("displacement", "force", "cycle")}
_CHOOSE |= {"load": "load_column (--load COLUMN)"}
_CHOOSE |= {role: f"{role}_column (--{role}-column)" for role in ("x", "z")}

# The factors to SI of the lengths and forces rigs write most, read without starting pint
# (whose registry takes a good part of a second to build); any other unit goes to pint.
_LENGTHS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "nm": 1e-9, "in": 0.0254}
_FORCES = {"N": 1.0, "kN": 1e3, "mN": 1e-3, "kip": 4448.221615260501}
#: Those units, with their kind and factor to SI.
COMMON_UNITS = {unit: ("length", factor) for unit, factor in _LENGTHS.items()} | {
    unit: ("force", factor) for unit, factor in _FORCES.items()
}

_BRACKETED = re.compile(r"^(?P<base>.*?)\s*(?:\[(?P<square>[^\[\]]*)\]|\((?P<round>[^()]*)\))$")
_SLASHED = re.compile(r"^(?P<base>[^/]*?)\s*/\s*(?P<unit>[^/]+?)$")
_SUFFIXED = re.compile(r"^(?P<base>.*?[^_\s])[_\s]+(?P<unit>[^_\s]+)$")
#: How alike (difflib's ratio, 0 to 1) a name must be to the one sought to be suggested.
_NEAR = 0.75
_POSITION = re.compile(r"^#(\d+)$")
_IN_UNIT = re.compile(r"^(?P<base>.*?\S)\s+in\s+(?P<unit>\S+)$", re.IGNORECASE)


class ColumnError(ValueError):
    """A column that cannot be found or whose unit cannot be trusted (no file position)."""


@functools.lru_cache(maxsize=1024)
def _unit_kind(unit: str) -> str | None:
    """'length' or 'force' if ``unit`` reads as one, 'other' for another unit, else None."""
    text = unit.strip()
    if text in COMMON_UNITS:
        return COMMON_UNITS[text][0]
    if not text or text[0].isdigit():
        return None
    from ecofmaps.units import parse_quantity  # pint, imported only when needed

    for kind in ("length", "force"):
        try:
            parse_quantity(f"1 {text}", kind)
            return kind
        except ValueError as error:
            if "is not a" not in str(error):
                return None  # not a unit at all
    return "other"


def _normal(name: str) -> str:
    """A name without case, surrounding quotes or repeated blanks."""
    return " ".join(name.strip().strip("\"'").split()).lower()


def _plain(text: str) -> str:
    """Text without case, blanks or punctuation: ``Friction_Force`` -> ``frictionforce``."""
    return re.sub(r"[\W_]+", "", text.casefold())


_SYNONYM_KEYS = {role: frozenset(map(_plain, names)) for role, names in SYNONYMS.items()}


def split_unit(name: str) -> tuple[str, str | None]:
    """A column name's base (without unit, quotes and surrounding blanks) and the unit it
    carries as written (``'force [N]'``, ``'Displacement/µm'``, ``'Ftr_kN'``), or None."""
    text = name.strip().strip("\"'").strip()
    match = _BRACKETED.match(text)
    if match and match.group("base"):
        unit = (match.group("square") or match.group("round") or "").strip()
        if _unit_kind(unit) is not None:
            return match.group("base").strip(), unit
    for pattern in (_SLASHED, _IN_UNIT, _SUFFIXED):
        match = pattern.match(text)
        if match and match.group("base") and _unit_kind(match.group("unit")) in KINDS.values():
            return match.group("base").strip(), match.group("unit").strip()
    return text, None


def find_column(names, wanted: str, role: str, *, required: bool = True) -> int | None:
    """The index among ``names`` of the column ``wanted`` (as :func:`matching_columns`); None if
    not found and not ``required``, else a :class:`ColumnError`."""
    matches = matching_columns(names, wanted, role)
    if len(matches) > 1:
        found = listed_names([names[k] for k in matches])
        choose = f"choose one with {_CHOOSE.get(role, role)}"
        if len({_normal(names[k]) for k in matches}) < len(matches):  # named alike
            found = listed_names([f"{names[k]!r} (#{k + 1})" for k in matches], quote=False)
            choose += f" by its position, e.g. '#{matches[0] + 1}'"
        raise ColumnError(f"several {role} columns match {wanted!r}: {found}; {choose}")
    if matches or not required:
        return matches[0] if matches else None
    raise ColumnError(_missing_message(names, wanted, role))


def matching_columns(names, wanted: str, role: str | None = None) -> list[int]:
    """The indices of the names matching ``wanted`` (case and blanks aside): the one equal to it,
    else those of its base (:func:`split_unit`), else (``wanted`` the ``role``) its synonyms."""
    target = _normal(wanted)
    whole = [k for k, name in enumerate(names) if _normal(name) == target]
    if len(whole) == 1:
        return whole
    if not whole and (position := _POSITION.match(target)):  # '#3': the third column
        return [int(position[1]) - 1] if 0 < int(position[1]) <= len(names) else []
    # its base, or the whole name when that ends in a word that reads as a unit ('A N')
    bases = {_normal(split_unit(wanted)[0]), target}
    by_base = [k for k, name in enumerate(names) if _normal(split_unit(name)[0]) in bases]
    if whole or by_base or role not in SYNONYMS or target != role:
        return whole if len(whole) > 1 else by_base
    usual = _SYNONYM_KEYS[role]
    return [k for k, name in enumerate(names) if _plain(split_unit(name)[0]) in usual]


def _missing_message(names, wanted: str, role: str) -> str:
    """The error for a column not found: the columns there are, and the nearest name."""
    usual = role in SYNONYMS and _normal(wanted) == role
    sought = [_plain(split_unit(wanted)[0])]
    if usual:
        sought += [key for key in _SYNONYM_KEYS[role] if len(key) >= 4]
    if (unknown := _unknown_unit(names, sought, role)) is not None:
        known = ", ".join(unit for unit, (kind, _) in COMMON_UNITS.items() if kind == KINDS[role])
        return (
            f"the {role} column {unknown[0]!r} is in {unknown[1]!r}, which is not a known unit "
            f"(known: {known} and the others pint reads): write a known unit in the header, "
            f"or name the column with {_CHOOSE[role]} and give its unit with {role}_unit "
            f"(--{role}-unit)"
        )
    message = f"no {role} column {wanted!r}"
    if usual:
        message += f" nor one of its usual names ({', '.join(SYNONYMS[role][1:7])}, ...)"
    message += f" (columns: {listed_names(names)})."
    bases = [_plain(split_unit(name)[0]) for name in names]
    ratios = [
        max(difflib.SequenceMatcher(None, key, base).ratio() for key in sought) if base else 0.0
        for base in bases
    ]
    if ratios and max(ratios) >= _NEAR:
        message += f" Did you mean {names[ratios.index(max(ratios))]!r}?"
    return f"{message} Name the column with {_CHOOSE.get(role, role)}"


def _unknown_unit(names, sought, role: str) -> tuple[str, str] | None:
    """The first (name, unit) whose base is ``sought`` and whose unit is not a unit at all."""
    for name in names:
        text = name.strip().strip("\"'").strip()
        match = _BRACKETED.match(text) or _SLASHED.match(text)
        if match is None or role not in KINDS or _plain(match["base"] or "") not in sought:
            continue
        unit = next(part for part in match.groups()[1:] if part is not None).strip()
        if _unit_kind(unit) is None:
            return name, unit
    return None


def listed_names(names, quote: bool = True, count: int = 10, width: int = 40) -> str:
    """The first ``count`` of ``names``, cut to ``width`` characters, and how many more."""
    shown = [repr(name) if quote else name for name in itertools.islice(names, count)]
    text = ", ".join(name if len(name) <= width else f"{name[: width - 3]}..." for name in shown)
    more = len(names) - count
    return f"{text} and {more} more" if more > 0 else text


def _factor(unit: str, kind: str, option: str | None) -> float:
    if unit.strip() in COMMON_UNITS and COMMON_UNITS[unit.strip()][0] == kind:
        return COMMON_UNITS[unit.strip()][1]
    from ecofmaps.units import parse_quantity  # pint, imported only when needed

    try:
        return parse_quantity(f"1 {unit}", kind)
    except ValueError as error:
        if option is None:
            raise
        raise ValueError(f"{option}={unit!r} is not a {kind} unit ({error})") from None


def column_scale(role: str, name: str, option_unit, metadata=(), column=None) -> tuple:
    """The factor to SI of column ``name``, its unit and whether that was assumed: the unit
    ``option_unit``, else those its name and the file's ``metadata`` carry, else
    :data:`DEFAULT_UNITS` (1 for a cycle number); a :class:`ColumnError` naming ``column``."""
    if role == "cycle":
        return 1.0, "1", False
    carried = [unit for unit in dict.fromkeys([split_unit(name)[1], *metadata]) if unit is not None]
    column = column or name
    kind = KINDS[role]
    option = f"{role}_unit"
    given = None if option_unit is None else (option_unit, _factor(option_unit, kind, option))
    readable = [(u, _factor(u, kind, None)) for u in carried if _unit_kind(u) == kind]
    for unit in carried:
        if _unit_kind(unit) != kind and given is None:
            raise ColumnError(
                f"the {role} column {column!r} is in {unit!r}, which is not a {kind} unit; "
                f"give {option} to say how to read it"
            )
    for unit, factor in readable:
        for other, other_factor in readable if given is None else [given]:
            if not math.isclose(factor, other_factor, rel_tol=1e-12):
                told = f"{option}={other!r}" if given is not None else repr(other)
                raise ColumnError(
                    f"the {role} column {column!r} is in {unit!r}, but {told} says otherwise "
                    f"(a factor {factor / other_factor:.6g}); remove one or make them agree"
                )
    if given is None and not carried:  # none readable: an error above
        return _factor(DEFAULT_UNITS[role], kind, None), DEFAULT_UNITS[role], True
    unit, factor = given or readable[0]
    return factor, unit, False
