"""Step 5 of the loop pipeline: friction and groove slope read along the whole stroke of each
loop, with the flags of its checks (its numerics in ``resolve_branches``);
``docs/method-loops.md`` ("Reading the loop along the stroke")."""

from __future__ import annotations

import dataclasses

import numpy as np
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps._inputs import check
from ecofmaps._interrupts import check_interrupted
from ecofmaps.measured.quality import (
    ALL,
    GICOF_WIGGLE,
    READING_REASONS,
    REASONS,
    RESOLVED,
    SCATTER_BLOCKS,
    SLIP_SAMPLES,
    VARIATION,
    VARIATION_SIGNIFICANCE,
    add_reason,
    has_reason,
)
from ecofmaps.measured.resolve_branches import (
    branch_noise,
    masked_median,
    masked_sum,
    read_branches,
    sample_weights,
    slip_branches,
)

__all__ = [
    "ReadingOptions",
    "checked_stick_window",
    "read_along_stroke",
    "resolve_analyzed_loops",
    "resolved_attrs",
    "settle",
    "single_value",
    "within",
]


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
    """``value`` as a float if ``0 < value`` (and ``< high``, or ``<= high`` if ``inclusive``),
    else a ValueError that says so."""
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
    """The options of the reading along the stroke (see :func:`ecofmaps.resolve_loops`),
    checked: a ValueError names the one out of range."""

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
    options = ReadingOptions(
        stiffness, force_offset, positions, central, slip_threshold, stick_window
    )
    return read_along_stroke(loops, options)[0]


def read_along_stroke(loops: xr.Dataset, options: ReadingOptions):
    """:func:`resolve_analyzed_loops` on options checked, and the flags of its reasons
    (reason -> per cycle) besides the Dataset."""

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
        per_position, per_cycle, flags, grid = _along_stroke_values(
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


#: The reasons this reading adds to a cycle's ``quality`` that leave its values NaN, in the
#: order they are tested (``'gicof-varies'``, which reaches the GICoF only, comes besides).
_QUALITY_FLAGS = READING_REASONS[:4]
#: Values of μ(ξ) beyond this many robust standard deviations of the median are clipped.
_WINSOR = 3.0
#: The largest lag-one autocorrelation of the block means that is believed.
_R1 = 0.8
#: Cycles analysed together: a block's arrays stay in the processor's cache.
_BLOCK = 512
#: Points of each cycle's own grid over its central part, for the per-cycle values.
_CENTRAL_POINTS = 201
#: The median absolute deviation of a normal distribution over its standard deviation.
_MAD = 1.482602218505602


def _central_values(forward, backward, central, load):
    """mu_resolved, its variance, k and g0 of g ≈ g0 + kξ, the sensitivity to 1/S."""
    width = forward[0].shape[1]
    unit = np.linspace(-1.0, 1.0, _CENTRAL_POINTS)
    at = central[:, None] * unit[None, :]
    inside = np.broadcast_to(np.isfinite(central)[:, None], at.shape)
    q_forward, q_backward, mu, slope, lines = read_branches(
        forward, backward, unit, central, inside, load
    )
    finite = np.isfinite(mu)
    points = np.count_nonzero(finite, axis=1)
    middle = masked_median(mu, finite)
    bound = (_WINSOR * _MAD * masked_median(np.abs(mu - middle[:, None]), finite))[:, None]
    clipped = np.clip(mu, middle[:, None] - bound, middle[:, None] + bound)
    mu_resolved = masked_sum(clipped, finite) / points
    # The noise variance: each branch's noise through the weights of its samples. The same
    # for the difference between the means over the inner and the outer half of the part.
    kept = finite & (np.abs(mu - middle[:, None]) <= bound)
    inner = kept & (np.abs(unit) <= 0.5)
    outer = kept & ~inner
    inner_points = np.count_nonzero(inner, axis=1)[:, None]
    outer_points = np.count_nonzero(outer, axis=1)[:, None]
    contrast = np.where(inner, 1.0 / inner_points, np.where(outer, -1.0 / outer_points, 0.0))
    variation = masked_sum(mu * contrast, kept)
    factor = 0.5 * (1.0 + mu**2) / load
    variance, variation_variance = np.zeros((2, central.size))
    for branch, force, (left, share), sign in zip(
        (forward, backward), (q_forward, q_backward), lines, (1.0, -1.0), strict=True
    ):
        gain = np.where(kept, sign * factor / (1.0 + (force / load) ** 2), 0.0)
        noise = branch_noise(*branch, central) ** 2
        weight = sample_weights(left, share, gain / points[:, None], width)
        variance += noise * np.sum(weight**2, axis=1)
        weight = sample_weights(left, share, gain * contrast, width)
        variation_variance += noise * np.sum(weight**2, axis=1)
    varies = (np.abs(variation) > VARIATION * np.abs(mu_resolved)) & (
        np.abs(variation) > VARIATION_SIGNIFICANCE * np.sqrt(variation_variance)
    )
    mean_xi, mean_g = masked_sum(at, finite) / points, masked_sum(slope, finite) / points
    dxi = at - mean_xi[:, None]
    k = masked_sum(dxi * (slope - mean_g[:, None]), finite) / masked_sum(dxi**2, finite)
    # The sensitivities of mu_resolved to the compliance 1/S and to a shift of the rising
    # branch against the falling one along ξ.
    turning = k[:, None] / (1.0 + slope**2)
    factor = 0.5 * (1.0 + mu_resolved**2) / points
    sensitivity = factor * masked_sum(turning * (q_forward - q_backward), finite)
    shifting = -factor * masked_sum(turning, finite)
    # An offset ε of the falling branch's force against the rising one's moves Q± by ∓ε/2.
    lifts = 1.0 / (1.0 + (q_forward / load) ** 2) + 1.0 / (1.0 + (q_backward / load) ** 2)
    offsetting = 0.5 * factor * masked_sum(lifts, finite) / load
    # The scatter of μ(ξ) beyond the noise: correlated residuals, the model's misfit.
    scatter, wiggle = _scatter_variance(mu, finite, unit)
    # μ(ξ) wiggles along the stroke beyond the noise: the GICoF, read at one position,
    # is not the mean friction (a straight trend is the same at the centre).
    excess = np.sqrt(np.maximum(wiggle - variance * SCATTER_BLOCKS, 0.0))
    wavers = excess > GICOF_WIGGLE * np.abs(mu_resolved)
    variance = np.fmax(variance, scatter)  # the noise alone where too few blocks
    tilt = mean_g - k * mean_xi
    return mu_resolved, variance, k, tilt, sensitivity, varies, shifting, wavers, offsetting


def _scatter_variance(mu, kept, unit):
    r"""Variance of the mean of ``mu`` over ``kept`` from the scatter of its block means."""
    member = np.minimum((0.5 * (unit + 1.0) * SCATTER_BLOCKS).astype(int), SCATTER_BLOCKS - 1)
    blocks = member[:, None] == np.arange(SCATTER_BLOCKS)[None, :]
    counts = kept.astype(np.float64) @ blocks
    means = (np.where(kept, mu, 0.0) @ blocks) / np.maximum(counts, 1.0)
    used = counts > 0
    number = np.count_nonzero(used, axis=1)
    centre = masked_sum(means, used) / number
    residual = np.where(used, means - centre[:, None], 0.0)
    squares = np.sum(residual**2, axis=1)
    lagged = np.sum(residual[:, 1:] * residual[:, :-1], axis=1)
    r1 = np.clip(np.divide(lagged, squares, out=np.zeros_like(squares), where=squares > 0), 0, _R1)
    spread = squares / np.maximum(number - 1, 1) / np.maximum(number, 1)
    place = np.where(used, np.arange(SCATTER_BLOCKS)[None, :], 0.0)
    place = np.where(used, place - (masked_sum(place, used) / number)[:, None], 0.0)
    trend = np.sum(residual * place, axis=1) / np.sum(place**2, axis=1)
    wiggle = np.sum((residual - trend[:, None] * place) ** 2, axis=1) / (number - 2)
    few = number < 3
    return np.where(few, np.nan, spread * (1.0 + r1) / (1.0 - r1)), np.where(few, np.nan, wiggle)


def _along_stroke(part, grid, tilt, load, level):
    """Q±, μ, g (levelled by ``tilt`` if ``level``) and h of a block over the common ``grid``."""
    lowest, highest = part["lowest"][:, None], part["highest"][:, None]
    cycles = tilt.size
    inside = np.isfinite(tilt)[:, None] & (grid >= lowest) & (grid <= highest)
    q_forward, q_backward, mu, slope, _ = read_branches(
        part["forward"], part["backward"], grid, np.ones(cycles), inside, load
    )
    if level:
        slope = slope - tilt[:, None]
    # The felt profile: trapezoidal integral of g, zero at ξ = 0.
    pieces = np.nan_to_num(0.5 * (slope[:, 1:] + slope[:, :-1]) * np.diff(grid))
    profile = np.concatenate([np.zeros((cycles, 1)), np.cumsum(pieces, axis=1)], axis=1)
    profile -= profile[:, np.searchsorted(grid, 0.0)][:, None]
    return mu, slope, np.where(inside, profile, np.nan), q_forward, q_backward


#: The values along the stroke, over (cycle, position), as :func:`_along_stroke` returns them.
_ALONG = ("mu", "slope", "felt_profile", "force_forward", "force_backward")
#: The reasons that leave the resolved values NaN.
_REACHING = [r for r, (_, scope) in REASONS.items() if scope == ALL or set(RESOLVED) & set(scope)]


def _along_stroke_values(x, q, load, stiffness, amplitude, inherited, options, drift_se):
    """Every resolved quantity of the centred loops ``x``, ``q``."""
    cycles, valid = x.shape[0], np.isfinite(x) & np.isfinite(q)
    blocks = [slice(start, start + _BLOCK) for start in range(0, max(cycles, 1), _BLOCK)]
    parts = []
    for block in blocks:
        check_interrupted()
        part = slip_branches(*(a[block] for a in (x, q, valid, stiffness, amplitude)), options)
        lowest, highest = part["lowest"], part["highest"]
        overlap = (lowest < 0.0) & (highest > 0.0)
        usable = ~inherited[block] & ~part["mismatch"] & overlap
        central = np.where(usable, options.central * np.minimum(highest, -lowest), np.nan)
        values = _central_values(part["forward"], part["backward"], central, load)
        samples = [
            np.count_nonzero(np.abs(np.where(np.isfinite(xs), xs, np.inf)) <= central[:, None], 1)
            for xs, _, _ in (part["forward"], part["backward"])
        ]
        few = (np.minimum(*samples) < SLIP_SAMPLES) | ~np.isfinite(values[0])
        flags = (part["mismatch"], ~overlap, few, values[5])
        part["flags"] = np.where(inherited[block], 0, np.select(flags, range(1, 5), 0))
        part["values"] = values
        if options.positions is None:  # the branches are not read again: not held
            del part["forward"], part["backward"]
        parts.append(part)

    def joined(name):
        return np.concatenate([part[name] for part in parts])

    flag = joined("flags")
    flags = {reason: flag == code for code, reason in enumerate(_QUALITY_FLAGS, start=1)}
    ok = ~inherited & (flag == 0)
    mu_resolved, variance, k, tilt, sensitivity, _, shifting, wavers, offsetting = (
        np.concatenate(values) for values in zip(*(part["values"] for part in parts), strict=True)
    )
    flags["gicof-varies"] = wavers & ((flag == 0) | (flag == 4)) & ~inherited
    lowest, highest = joined("lowest"), joined("highest")
    nan = np.where(ok, 1.0, np.nan)
    per_cycle = {
        "mu_resolved": mu_resolved * nan,
        "mu_resolved_se": np.sqrt(
            variance
            + (sensitivity * joined("compliance_se")) ** 2
            + (shifting * joined("shift")) ** 2
            + (offsetting * drift_se) ** 2
        )
        * nan,
        "aspect_ratio": 0.5 * k * amplitude * nan,
        "tilt": tilt * nan,
        "stiffness": 1.0 / joined("compliance"),
        "position_min": lowest * nan,
        "position_max": highest * nan,
    }
    grid = options.positions
    if grid is None:
        return {}, per_cycle, flags, None
    if np.ndim(grid) == 0:  # over the widest resolved range, or the stroke if none is
        reach = np.maximum(highest, -lowest)[ok]
        half = reach.max() if reach.size else np.max(amplitude, initial=0.0, where=amplitude > 0)
        grid = np.linspace(-1.0, 1.0, grid) * (half if half > 0.0 else 1.0)
    level = options.force_offset is None
    along = [
        _along_stroke(part, grid, per_cycle["tilt"][block], load, level)
        for part, block in zip(parts, blocks, strict=True)
    ]
    per_position = {name: np.concatenate([a[i] for a in along]) for i, name in enumerate(_ALONG)}
    return per_position, per_cycle, flags, grid
