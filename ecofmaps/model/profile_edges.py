"""The edges of a measured scar for :func:`ecofmaps.model.profiles.scar_profile`: the unworn
surface's line, the groove, the disturbed band and its pile-up ridges, and the warnings of
ambiguous or uncertain edges. The rules are explained in ``docs/profiles.md``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: The edges are ambiguous when an edge of the band between the ridges lies beyond the
#: groove's by more than this fraction of the groove's half-width. [1]
AMBIGUOUS_EDGES = 0.1
#: On a rough surface the groove's edges are uncertain when reading them within 3 times the
#: shoulders' noise of the line, rather than within 5 % of the depth, moves one by more
#: than this fraction of the groove's half-width. [1]
UNCERTAIN_EDGES = 0.05

# The rules these numbers set are in docs/profiles.md.
# Shoulders: beyond these many half-widths from the centre, at least _MIN_SHOULDER a side.
_SHOULDER_FACTORS = (1.5, 1.25, 1.1)
_MIN_SHOULDER = 5
# A scar is deeper than this many times the shoulders' noise and this share of the relief.
_NOISE_FACTOR = 5.0
_MIN_RELIEF = 0.05
# The disturbed band: beyond this share of the depth, with no quiet stretch longer than
# this share of the groove's half-width and than _BAND_GAP sample spacings.
_BAND_FLOOR = 0.02
_BAND_GAP_WIDTH = 0.25
_BAND_GAP = 10
# Pile-up ridges: within _RIDGE_REACH half-widths or _RIDGE_SPAN of the trace's span, at
# distances within the ratio _RIDGE_PAIR, all else on their side below _RIDGE_PROMINENCE.
_RIDGE_REACH = 5.0
_RIDGE_SPAN = 0.25
_RIDGE_PAIR = 1.5
_RIDGE_PROMINENCE = 0.5
# Narrow ridges: samples wide, height over the threshold, likeness and mirror tolerance.
_NARROW_SAMPLES = 5
_NARROW_HEIGHT = 2.0
_NARROW_ALIKE = 1.5
_NARROW_MIRROR = 0.5
# The profile reaches the line within this share of the depth, or this many times the
# shoulders' noise but at most _LINE_SHARE of the depth.
_LINE_TOLERANCE = 1e-9
_LINE_NOISE = 3.0
_LINE_SHARE = 0.05


class ScarProfileWarning(UserWarning):
    """What reading a measured profile decided that its user must see."""

    def __init__(self, summary: str, samples=(), details=(), alternative=None, alternative_name=""):
        self.summary, self.samples = summary, tuple(int(i) for i in samples)
        self.details, self.alternative = tuple(details), alternative
        self.alternative_name = alternative_name
        text = self.text([f"sample {i}" for i in self.samples])
        if alternative is not None:
            text += f"; half_width={alternative:.6g} (m) takes the {alternative_name}"
        super().__init__(text)

    def text(self, labels) -> str:
        """The finding with each sample named by ``labels`` (at most 10 listed)."""
        if not self.samples:
            return self.summary
        shown = [f"{label} ({detail})" for label, detail in zip(labels, self.details, strict=True)]
        more = len(shown) - 10
        listed = "; ".join(shown[:10]) + (f"; and {more} more" if more > 0 else "")
        return f"{self.summary}: {listed}"


def _line(x, z, mask):
    """Least-squares offset and tilt of ``z`` over ``x[mask]``, as a function and a pair."""
    xm = x[mask]
    centre = xm.mean()
    tilt, offset = np.polyfit(xm - centre, z[mask], 1)
    return (lambda at: offset + tilt * (at - centre)), tilt


def _crossing(x, r, start, step, tolerance, reach):
    """Where ``r`` first reaches 0 (to ``tolerance``) from ``start`` in direction ``step``."""
    found = np.flatnonzero((r[:start] if step < 0 else r[start:]) >= -tolerance)
    if found.size == 0:
        return None
    outer = found[-1] if step < 0 else start + found[0]
    last = outer - step  # the sample inside next to it
    bound, wall = (min, start) if step < 0 else (max, start - 1)
    inner = bound(last - step * reach, wall)
    second = bound(inner - step, wall)
    rise = (r[inner] - r[second]) / (x[inner] - x[second]) if second != inner else 0.0
    beyond = x[outer]
    if rise * (x[outer] - x[last]) > 0.0:  # the wall climbs towards the line
        edge = x[inner] - r[inner] / rise
        if tolerance > 0.0:  # it reached -tolerance, not 0, by ``outer``: the wall's line
            edge, rise = _wall_line_edge(x, r, start, inner, step, tolerance, edge, rise)
            beyond = beyond + tolerance / rise
    else:
        edge = x[last] + r[last] / (r[last] - r[outer]) * (x[outer] - x[last])
    return float(np.clip(edge, *sorted((x[inner], beyond)))), int(outer)


def _wall_line_edge(x, r, start, inner, step, tolerance, edge, rise):
    """Where the wall's least-squares line reaches 0, and its slope (else ``edge``, ``rise``)."""
    deep = r < min(-4.0 * tolerance, r[inner] - 2.0 * tolerance)
    if step > 0:
        below = np.flatnonzero(deep[start : inner + 1])
        first = start + int(below[-1]) if below.size else start
        span = slice(first, inner + 1)
    else:
        below = np.flatnonzero(deep[inner : start + 1])
        last = inner + int(below[0]) if below.size else start
        span = slice(inner, last + 1)
    if span.stop - span.start >= 3:
        slope, offset = np.polyfit(x[span], r[span], 1)
        if slope * rise > 0.0:
            return -offset / slope, slope
    return edge, rise


def _band_end(x, r, outer, step, threshold, gap):
    """Index of the disturbed band's outermost sample beyond ``outer`` (``outer`` if none)."""
    if step > 0:
        index = outer + np.flatnonzero(np.abs(r[outer:]) > threshold)
    else:
        index = np.flatnonzero(np.abs(r[: outer + 1]) > threshold)[::-1]
    gaps = np.abs(np.diff(np.concatenate([[x[outer]], x[index]])))
    far = np.flatnonzero(gaps > gap)
    count = int(far[0]) if far.size else index.size
    return int(index[count - 1]) if count else outer


def _forward_minimum(values, count):
    """Minimum of each full window ``values[j : j + count]`` (van Herk-Gil-Werman)."""
    size = values.size - count + 1
    if size <= 0:
        return np.empty(0)
    padded = np.concatenate([values, np.full(-values.size % count, np.inf)]).reshape(-1, count)
    prefix = np.minimum.accumulate(padded, axis=1).ravel()
    suffix = np.minimum.accumulate(padded[:, ::-1], axis=1)[:, ::-1].ravel()
    return np.minimum(suffix[:size], prefix[count - 1 : count - 1 + size])


def _crest(x, r, index, drop):
    """Position of a ridge's crest: a parabola's vertex fitted within ``drop`` of its top. [m]"""
    low = np.flatnonzero(r < r[index] - drop)
    after = np.searchsorted(low, index)
    first = low[after - 1] + 1 if after else 0
    last = low[after] if after < low.size else x.size
    if last - first < 3:
        return float(x[index])
    u = x[first:last] - x[index]
    curvature, slope, _ = np.polyfit(u, r[first:last], 2)
    vertex = -slope / (2.0 * curvature) if curvature < 0.0 else 0.0
    return float(x[index] + np.clip(vertex, u[0], u[-1]))


def _band_edge(x, r, outer, end, step, threshold, level):
    """The inner foot of the band's pile-up ridge on one side [m], and its crest's index."""
    inward = np.arange(end, outer - step, -step)
    s = r[inward]
    above = np.flatnonzero(s > threshold)
    if above.size == 0:
        return (float(x[end]) if end != outer else None), None
    first = int(above[0])
    fallen = np.flatnonzero(s[first:] < np.maximum.accumulate(s[first:]) - threshold)
    crest = first + int(np.argmax(s[first : first + fallen[0]] if fallen.size else s[first:]))
    flank = s[crest:]
    rise = np.flatnonzero(flank > np.minimum.accumulate(flank) + threshold)
    lowest = _forward_minimum(flank, level)
    floor = np.flatnonzero(lowest >= flank[: lowest.size] - threshold)
    if rise.size and (floor.size == 0 or rise[0] <= floor[0] + level):
        foot = inward[crest + int(np.argmin(flank[: rise[0]]))]
    elif floor.size:
        foot = inward[crest + int(floor[0])]
    else:
        return None, int(inward[crest])
    return float(x[foot]), int(inward[crest])


class _Ridge(NamedTuple):
    """The highest run above the band's threshold on one side of the groove."""

    crest: int  # index of its highest sample
    run: tuple  # indices of its first and last samples above the threshold
    width: float  # from the last sample below the threshold to the next one [m]
    distance: float  # of the crest from the groove's centre [m]
    rest: float  # the highest sample on that side outside the ridge [m]


def _highest_run(x, r, outer, step, centre, reach, threshold, gap):
    """The :class:`_Ridge` around the highest sample above ``threshold`` on one side, or None."""
    side = (x < x[outer]) if step < 0 else (x > x[outer])
    high = np.flatnonzero(side & (r > threshold))
    near = high[np.abs(x[high] - centre) <= reach]
    if near.size == 0:
        return None
    crest = int(near[np.argmax(r[near])])
    low = np.flatnonzero(r <= threshold)
    foot = np.searchsorted(low, crest)  # the run above the threshold around the crest
    run = (
        int(low[foot - 1]) + 1 if foot else 0,
        int(low[foot]) - 1 if foot < low.size else x.size - 1,
    )
    width = float(x[min(run[1] + 1, x.size - 1)] - x[max(run[0] - 1, 0)])
    breaks = np.flatnonzero(np.diff(x[high]) > gap)  # high[k] and high[k + 1] far apart
    at = int(np.searchsorted(high, crest))
    first = high[breaks[breaks < at][-1] + 1] if np.any(breaks < at) else high[0]
    last = high[breaks[breaks >= at][0]] if np.any(breaks >= at) else high[-1]
    line = np.flatnonzero(r <= 0.0)  # and its flanks down to the line
    before, after = line[line < first], line[line > last]
    side[(before[-1] if before.size else 0) : (after[0] if after.size else x.size)] = False
    rest = float(np.max(r[side])) if side.any() else -np.inf
    return _Ridge(crest, run, width, abs(float(x[crest]) - centre), rest)


def _paired_ridges(x, r, sides, centre, threshold, gap):
    """The band's outer ends (indices) at a pair of pile-up ridges, or None if there is none."""
    reach = max(_RIDGE_REACH * 0.5 * (x[sides[1]] - x[sides[0]]), _RIDGE_SPAN * (x[-1] - x[0]))
    ridges = [
        _highest_run(x, r, outer, step, centre, reach, threshold, gap)
        for outer, step in zip(sides, (-1, +1), strict=True)
    ]
    if None in ridges:
        return None
    heights = [float(r[ridge.crest]) for ridge in ridges]
    if any(ridge.rest >= _RIDGE_PROMINENCE * h for ridge, h in zip(ridges, heights, strict=True)):
        return None
    distances = [ridge.distance for ridge in ridges]
    widths = [ridge.width for ridge in ridges]
    if all(width >= gap for width in widths):
        paired = max(distances) <= _RIDGE_PAIR * min(distances)
    else:  # two narrow outstanding runs: a pair of pile-up ridges, or two asperities
        paired = (
            all(ridge.run[1] - ridge.run[0] + 1 >= _NARROW_SAMPLES for ridge in ridges)
            and min(heights) > _NARROW_HEIGHT * threshold
            and max(heights) < _NARROW_ALIKE * min(heights)
            and max(widths) < _NARROW_ALIKE * min(widths)
            and abs(distances[1] - distances[0]) < _NARROW_MIRROR * (widths[0] + widths[1])
        )
    if not paired:
        return None
    return [
        _band_end(x, r, ridge.crest, step, threshold, gap)
        for ridge, step in zip(ridges, (-1, +1), strict=True)
    ]


def _shoulders(x, centre, half_width, band, quiet):
    """Samples of the unworn surface for the reference line, or None if too few."""
    for outside in (band, (np.inf, -np.inf)):
        for factor in _SHOULDER_FACTORS:
            left = x < min(centre - factor * half_width, outside[0])
            right = x > max(centre + factor * half_width, outside[1])
            for keep in (quiet, True):
                if (left & keep).sum() >= _MIN_SHOULDER and (right & keep).sum() >= _MIN_SHOULDER:
                    return (left | right) & keep
    return None


def _edges(x, r, deepest, depth, noise, reach):
    """The groove's and the band's edges, the ridges' crests, the band's outer ends, its threshold
    and on a rough surface the edges read within the roughness (else None)."""
    tolerance = max(_LINE_TOLERANCE * depth, min(_LINE_NOISE * noise, _LINE_SHARE * depth))
    left = _crossing(x, r, deepest, -1, tolerance, reach)
    right = _crossing(x, r, deepest + 1, +1, tolerance, reach)
    rough = None
    if _LINE_NOISE * noise > tolerance:  # the roughness dips below the tolerance
        rough = [
            _crossing(x, r, deepest + (step > 0), step, _LINE_NOISE * noise, reach)
            for step in (-1, +1)
        ]
        rough = None if None in rough else (rough[0][0], rough[1][0])
    if left is None or right is None:
        side = "left" if left is None else "right"
        raise ValueError(
            f"x: the scar reaches the {side} end of the trace (no unworn surface beside "
            "it): the trace must extend beyond both edges of the scar"
        )
    threshold = max(_NOISE_FACTOR * noise, _BAND_FLOOR * depth)
    gap = max(_BAND_GAP_WIDTH * 0.5 * (right[0] - left[0]), _BAND_GAP * np.median(np.diff(x)))
    ends = [
        _band_end(x, r, side[1], step, threshold, gap) for side, step in ((left, -1), (right, +1))
    ]
    paired = _paired_ridges(x, r, (left[1], right[1]), 0.5 * (left[0] + right[0]), threshold, gap)
    if paired is not None:  # the ridges beyond a quiet floor, unless the band reaches farther
        ends = [min(ends[0], paired[0]), max(ends[1], paired[1])]
    level = max(int(np.ceil(gap / np.median(np.diff(x)))), 1)
    found = [
        _band_edge(x, r, side[1], end, step, threshold, level)
        for side, end, step in ((left, ends[0], -1), (right, ends[1], +1))
    ]
    groove = (left[0], right[0])
    near = AMBIGUOUS_EDGES * 0.5 * (groove[1] - groove[0])
    # The track lies between the ridges: the band reaches their crests, where the counterbody
    # sliding up their inner flanks stopped; the groove's edge where the ridge's foot is not
    # beyond it (its wall runs up into the ridge).
    band = tuple(
        groove[i]
        if foot is None or abs(foot - groove[i]) <= near
        else (foot if crest is None else _crest(x, r, crest, threshold))
        for i, (foot, crest) in enumerate(found)
    )
    outer = (min(float(x[ends[0]]), band[0]), max(float(x[ends[1]]), band[1]))
    return groove, band, tuple(crest for _, crest in found), outer, threshold, rough


def _micrometres(length) -> str:
    """``length`` [m] in µm, to 4 significant digits."""
    return f"{float(length) * 1e6 + 0.0:.4g} µm"  # + 0.0: no "-0 µm"


def _too_short_message(x, centre, width, given: bool) -> str:
    """Why the trace leaves too little unworn surface beside the scar, and the remedies."""
    span = x[-1] - x[0]
    scar = "given" if given else "detected"
    message = (
        f"x: the trace is too short for levelling: the {scar} scar is centred at "
        f"x = {_micrometres(centre)} with a half-width of {_micrometres(width)} "
        f"({2 * width / span:.0%} of the trace, which spans {_micrometres(x[0])} to "
        f"{_micrometres(x[-1])}), and levelling needs at least {_MIN_SHOULDER} samples of "
        "unworn surface beyond 1.1 half-widths from the scar centre on each side"
    )
    if given:
        return message + ": give a longer trace or a smaller half_width"
    return message + (
        ". If the scar is narrower than that (on a rough surface its edges may have been "
        "read within the roughness), give its half-width: half_width= (on the command line "
        "--profile-half-width); else give a longer trace"
    )


def _ambiguity(r, groove, band, ridges, wide: bool):
    """The warning of ambiguous edges (or None) and the half-width not taken. [m]"""
    if band == groove:
        return None, np.nan
    apart = [b != g for b, g in zip(band, groove, strict=True)]
    ridged = [crest is not None and far for crest, far in zip(ridges, apart, strict=True)]
    what = "the band between its pile-up ridges' crests" if all(ridged) else "the disturbed band"
    if not all(apart):
        what = f"the groove and the disturbed band on its {'right' if apart[1] else 'left'}"
    marks = [
        f" (a crest {r[crest] * 1e6:.3g} µm high)" if ridge else ""
        for crest, ridge in zip(ridges, ridged, strict=True)
    ]

    def candidate(edges, words, taken, notes=("", "")):
        width = 0.5 * (edges[1] - edges[0])
        where = (
            f"edges at x = {edges[0] * 1e6:.6g} µm{notes[0]} and {edges[1] * 1e6:.6g} µm{notes[1]}"
        )
        return width, f"{width * 1e6:.6g} µm for {words} ({'returned; ' if taken else ''}{where})"

    band = candidate(band, what, wide, marks)
    groove = candidate(groove, "the groove below the unworn surface's line", not wide)
    first, second = (band, groove) if wide else (groove, band)
    summary = (
        f"ambiguous scar edges: half-width {first[1]} or {second[1]}: which the model needs "
        "is a judgement"
    )
    name = "groove" if wide else "band"
    finding = ScarProfileWarning(summary, alternative=second[0], alternative_name=name)
    return finding, second[0]


def _uncertainty(groove, other, wide: bool):
    """The warning of uncertain groove edges (or None) and the other half-width. [m]"""
    if wide or other is None:
        return None, np.nan
    width = 0.5 * (groove[1] - groove[0])
    moved = max(abs(a - b) for a, b in zip(groove, other, strict=True))
    if not moved > UNCERTAIN_EDGES * width:
        return None, np.nan
    alternative = 0.5 * (other[1] - other[0])
    summary = (
        f"uncertain groove edges on a rough surface: half-width {width * 1e6:.6g} µm (returned; "
        f"edges at x = {groove[0] * 1e6:.6g} and {groove[1] * 1e6:.6g} µm, where the wall "
        f"reaches the unworn surface's line) or {alternative * 1e6:.6g} µm (edges at x = "
        f"{other[0] * 1e6:.6g} and {other[1] * 1e6:.6g} µm, where it comes within "
        f"{_LINE_NOISE:g} times the roughness of it): an edge moves by {moved * 1e6:.3g} µm, "
        f"more than {UNCERTAIN_EDGES:.0%} of the half-width"
    )
    name = "edges read within the roughness"
    return ScarProfileWarning(summary, alternative=alternative, alternative_name=name), alternative


def scar_extent(x, zs, half_width, reach):
    """The scar in the smoothed heights ``zs``: its reference line (a function), tilt, centre,
    half-width and the residual ``zs - line(x)``; the half-width not taken [m] (NaN if none)
    and the warnings."""
    span = x[-1] - x[0]
    mask = (x < x[0] + span / 5.0) | (x > x[-1] - span / 5.0)
    previous = None
    for _ in range(20):
        line, tilt = _line(x, zs, mask)
        r = zs - line(x)
        noise = 1.4826 * np.median(np.abs(r[mask] - np.median(r[mask])))
        deepest = int(np.argmin(r))
        depth = -r[deepest]
        if not depth > max(_NOISE_FACTOR * noise, _MIN_RELIEF * (r.max() - r.min())):
            raise ValueError(
                "z: no depression found: the deepest point is "
                f"{_micrometres(depth)} below the unworn surface (a straight line fitted to "
                f"the trace's ends): not more than {_NOISE_FACTOR:g} times its noise "
                f"({_micrometres(noise)}) and {_MIN_RELIEF:.0%} of the trace's relief "
                f"({_micrometres(r.max() - r.min())}). Heights must increase upwards (the scar "
                "is a depression), in metres."
            )
        groove, band, ridges, outer, threshold, rough = _edges(x, r, deepest, depth, noise, reach)
        tolerance = AMBIGUOUS_EDGES * 0.5 * (groove[1] - groove[0])
        apart = [abs(b - g) > tolerance for b, g in zip(band, groove, strict=True)]
        wide = all(apart)  # one side apart alone is most often debris beside the groove
        if any(apart) and half_width is not None:  # the centre of the edges nearer that width
            wide = abs(band[1] - band[0] - 2 * half_width) < abs(
                groove[1] - groove[0] - 2 * half_width
            )
        edges = band if wide else groove
        centre = 0.5 * (edges[0] + edges[1])
        width = 0.5 * (edges[1] - edges[0]) if half_width is None else half_width
        if half_width is not None and (centre - width < x[0] or centre + width > x[-1]):
            raise ValueError(
                f"half_width = {half_width:g} m does not fit the trace: {_micrometres(width)} "
                f"either side of the scar centre at x = {_micrometres(centre)} reaches beyond "
                f"the trace, which spans {_micrometres(x[0])} to {_micrometres(x[-1])}"
            )
        mask = _shoulders(x, centre, width, outer, np.abs(r) <= threshold)
        if mask is None:
            raise ValueError(_too_short_message(x, centre, width, given=half_width is not None))
        if edges == previous:
            break
        previous = edges
    finding, alternative = None, np.nan
    if half_width is None:
        finding, alternative = _ambiguity(r, groove, band if any(apart) else groove, ridges, wide)
        if finding is None:
            finding, alternative = _uncertainty(groove, rough, wide)
    return (line, tilt, centre, width, r), alternative, [] if finding is None else [finding]
