"""Step 5 of the loop pipeline, friction and groove slope read along the stroke: its options, its
Dataset and flags (numerics: ``resolve_branches``); ``docs/method-loops.md``."""

from __future__ import annotations

import dataclasses

import numpy as np
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps._inputs import check
from ecofmaps.measured.quality import ALL, REASONS, RESOLVED, add_reason, has_reason
from ecofmaps.measured.resolve_branches import along_stroke_values

# How this module reads the quantities that have a general meaning elsewhere (netCDF comment).
_COMMENTS = {
    "mu": "read along the stroke: tan((atan(Q+/P) - atan(Q-/P))/2) at each position",
    "aspect_ratio": "of the parabola that fits the felt slope, g ≈ g0 + kξ, z_o/x_o = kΔ*/2",
    "stiffness": "the rig stiffness used for the contact position",
    "tilt": "levelled off the slope when the force is centred",
}


def resolved_attrs(name: str) -> dict:
    """The attributes of the variable ``name`` of the reading along the stroke."""
    return nomenclature.attrs(name, _COMMENTS)


def single_value(name: str, value, kind: str, unit: str) -> float:
    """``value`` checked as one number of ``kind`` (:func:`ecofmaps._inputs.check`)."""
    check(name, value, kind, unit)
    if np.ndim(value) != 0:
        raise ValueError(f"{name} must be a single value [{unit}]")
    return float(value)


def within(name: str, value, high=None, *, inclusive=False) -> float:
    """``value`` as a float if ``0 < value`` (``< high``, or ``<= high`` if ``inclusive``)."""
    if high is None:
        holds, condition = value > 0.0, f"{name} > 0"
    else:
        holds = 0.0 < value <= high if inclusive else 0.0 < value < high
        condition = f"0 < {name} {'<=' if inclusive else '<'} {high:g}"
    if not holds:
        raise ValueError(f"{name} must satisfy {condition}; got {value!r}")
    return float(value)


def checked_stick_window(window) -> tuple:
    """The shares ``(low, high)`` of a stick window, checked."""
    low, high = (float(share) for share in window)
    if not 0.0 <= low < high <= 1.0:
        raise ValueError(f"stick_window must satisfy 0 <= low < high <= 1; got {window!r}")
    return low, high


def settle(options, *checked) -> None:
    """Set the ``checked`` values of the fields of the frozen dataclass ``options``, in order."""
    for field, value in zip(dataclasses.fields(options), checked, strict=True):
        object.__setattr__(options, field.name, value)


def _grid_positions(positions):
    """``positions`` checked: None, an odd count >= 5, or increasing positions with 0. [m]"""
    if positions is None:
        return None
    if np.ndim(positions) == 0:
        count = isinstance(positions, int | np.integer) and not isinstance(positions, bool)
        if not (count and positions >= 5 and positions % 2):
            raise ValueError(
                f"positions must be an odd integer >= 5 or an array of positions; got {positions!r}"
            )
        return int(positions)
    check("positions", positions, "finite", "m")
    positions = np.asarray(positions, dtype=np.float64)
    if positions.ndim != 1 or positions.size < 3 or np.any(np.diff(positions) <= 0.0):
        raise ValueError("positions must be one-dimensional and increasing, >= 3 of them [m]")
    if not np.any(positions == 0.0):
        raise ValueError("positions must include 0 (the centre, where the profile is zero) [m]")
    return positions


@dataclasses.dataclass(frozen=True)
class ReadingOptions:
    """The options of :func:`ecofmaps.resolve_loops`' reading along the stroke, checked."""

    stiffness: float | None = None
    force_offset: float | None = None
    positions: object = 201
    central: float = 0.8
    slip_threshold: float = 4.0
    stick_window: tuple = (0.05, 0.45)

    def __post_init__(self):
        stiffness, force_offset = self.stiffness, self.force_offset
        if stiffness is not None:
            stiffness = single_value("stiffness", stiffness, "positive_or_inf", "N/m")
        if force_offset is not None:
            force_offset = single_value("force_offset", force_offset, "finite", "N")
        positions = _grid_positions(self.positions)
        central = within("central", self.central, 1.0, inclusive=True)
        threshold = within("slip_threshold", self.slip_threshold)
        window = checked_stick_window(self.stick_window)
        settle(self, stiffness, force_offset, positions, central, threshold, window)


_NEEDED = (
    "loop_displacement",
    "loop_force",
    "stiffness",
    "amplitude",
    "regime",
    "displacement_offset",
    "force_offset",
    "force_drift_se",
)


def resolve_analyzed_loops(
    loops,
    stiffness=None,
    *,
    force_offset=None,
    positions=ReadingOptions.positions,
    central=ReadingOptions.central,
    slip_threshold=ReadingOptions.slip_threshold,
    stick_window=ReadingOptions.stick_window,
) -> xr.Dataset:
    r"""Friction and groove slope along the stroke of the loops :func:`analyze_loops` kept:
    :func:`ecofmaps.resolve_loops` for a recording already analysed.

    Parameters
    ----------
    loops : xarray.Dataset
        The result of :func:`ecofmaps.analyze_loops` with ``keep_loops=True``.
    stiffness, force_offset, positions, central, slip_threshold, stick_window
        As for :func:`ecofmaps.resolve_loops`.

    Returns
    -------
    resolved : xarray.Dataset
        As for :func:`ecofmaps.resolve_loops`.

    Raises
    ------
    ValueError
        If ``loops`` lacks the loops (``keep_loops=False``), or for options out of range.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 7, 9, 10, 17-18.
    """
    if not isinstance(loops, xr.Dataset) or any(name not in loops for name in _NEEDED):
        raise ValueError(
            "loops must be the Dataset of analyze_loops(..., keep_loops=True), with "
            + ", ".join(_NEEDED)
        )
    opts = ReadingOptions(stiffness, force_offset, positions, central, slip_threshold, stick_window)
    return read_along_stroke(loops, opts)[0]


#: The reasons that leave the resolved values NaN.
_REACHING = [r for r, (_, scope) in REASONS.items() if scope == ALL or set(RESOLVED) & set(scope)]


def read_along_stroke(loops: xr.Dataset, options: ReadingOptions):
    """:func:`resolve_analyzed_loops` on options checked, and its flags (reason -> per cycle)."""

    def values(name):
        return np.asarray(loops[name].values, dtype=np.float64)

    load = float(loops["load"])
    x, q, removed = map(values, ("loop_displacement", "loop_force", "force_offset"))
    if options.force_offset is not None:  # the force as recorded, less the given offset
        q = q + (removed - options.force_offset)[:, None]
        removed = np.full_like(removed, options.force_offset)
    given = options.stiffness is not None
    rig = np.full(x.shape[0], options.stiffness) if given else values("stiffness")
    quality, amplitude = loops["quality"].values, values("amplitude")
    inherited = np.logical_or.reduce([has_reason(quality, reason) for reason in _REACHING])
    with np.errstate(divide="ignore", invalid="ignore"):
        per_position, per_cycle, flags, grid = along_stroke_values(
            x, q, load, rig, amplitude, inherited, options, values("force_drift_se")
        )
        per_cycle["position_offset"] = (
            loops["displacement_offset"].values - removed / per_cycle["stiffness"]
        )
        per_cycle["amplitude"] = loops["amplitude"].values  # the x_o of aspect_ratio
    data = {name: (("cycle", "position"), value) for name, value in per_position.items()}
    data |= {name: ("cycle", value) for name, value in per_cycle.items()}
    for reason, flag in flags.items():
        quality = add_reason(quality, flag, reason)
    data["quality"] = ("cycle", quality)
    coords = {"cycle": ("cycle", loops["cycle"].values), "load": ((), load)}
    if grid is not None:
        coords["position"] = ("position", grid)
    data, coords = (
        {name: (*value, resolved_attrs(name)) for name, value in mapping.items()}
        for mapping in (data, coords)
    )
    attrs = {
        "title": "Fretting loops read along the stroke (ecofmaps.resolve_loops)",
        "stiffness_from": "given" if given else "the stick sets of each loop",
        "force_from": ("loops centred" if options.force_offset is None else "given force offset"),
        "central": options.central,
        "slip_threshold": options.slip_threshold,
        "stick_window": list(options.stick_window),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs), flags
