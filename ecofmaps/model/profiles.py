r"""Wear-scar profiles: the groove of any shape that the pad slides in.

A :class:`ScarProfile` holds a scar as the model uses it: sample positions :math:`X`
relative to the scar centre, heights :math:`z`, and the slope :math:`g = dz/dX` at each
sample, with the scar's depth :math:`D`, half-width :math:`W` and worn area. It is a JAX
pytree (a ``NamedTuple`` of float64 arrays), so profiles of equal sample count stack into
a batch that ``jax.vmap`` maps over.

Profiles come from measured arrays (:func:`scar_profile`; files are read by
:func:`ecofmaps.read_scar_profile`) or from the analytic families used in studies
(:mod:`ecofmaps.model.profile_families`).

The slope between samples
-------------------------
The model takes :math:`g(X)` piecewise linear between the samples (so the height it feels
is piecewise quadratic). That is exact for a parabola, whatever the sampling; other shapes
are approximated to second order in the sample spacing, and a kink (a jump of the slope,
like the edge of a parabolic scar cut into a flat surface) is spread over one sample
spacing.

The scar's edges, levelling and smoothing (measured profiles)
--------------------------------------------------------------
*Smoothing.* Slopes are taken from a local quadratic least-squares fit at every sample
with Gaussian weights of standard deviation ``smoothing``, cut off at 4 standard deviations
(a Savitzky-Golay filter for uneven spacing). A quadratic is reproduced exactly, so the
smoothing removes noise and features much narrower than ``smoothing`` without bending a
parabolic scar. The default,
:data:`AUTO_SMOOTHING` of the half-width (2 %: 10 µm on a 500 µm half-width scar, several
times the radius of a profilometer stylus tip and the spacing of its samples), leaves the
slope of a real trace with about 1 % noise; ``smoothing=0`` uses the exact slope of the
parabola through each sample and its two neighbours. The edges and the worn area are
read on heights smoothed only over one sample spacing (not at all with ``smoothing=0``),
since heavier smoothing would move an edge where the slope jumps.

*Reference line (the unworn surface).* A straight line (offset and tilt) fitted by least
squares to the *shoulders*: the samples farther than 1.5 half-widths from the scar centre
(1.25 or 1.1 when the trace is too short to leave 5 samples on each side there). It starts
from the outer fifths of the trace and is refitted with the edges it gives until they
settle.

*Edges.* From the deepest point below the reference line, the first samples on either side
that reach the line (to within :math:`10^{-9}` of the depth); the edge is where the wall,
extended by a straight line, reaches it. The straight line runs through two samples of the
wall beyond the reach of the light smoothing from the last sample below the line (the last
two without smoothing): exact for a straight wall cut into a flat surface, second order in
that distance for a curved one. The half-width is half the distance of the two
edges, the centre their midpoint; ``half_width=`` overrides the half-width (the centre
stays the detected one). The depth is the largest depth of the smoothed profile below the
line between the edges, and the worn area the area between the line and the profile
there. A depression no deeper
than 5 times the shoulders' noise (1.4826 times their median absolute deviation), or than
5 % of the trace's relief about the line (so a bump is not taken for a scar), is not a scar.

*Levelling* (``level=True``) subtracts the reference line from the heights and its tilt
from the slopes; without it the tilt stays in the slopes (a genuinely tilted scar), and the
line is kept in ``reference_height`` and ``reference_slope``.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

__all__ = [
    "AUTO_SMOOTHING",
    "MIN_SCAR_SAMPLES",
    "ScarProfile",
    "scar_profile",
]

#: Default smoothing length as a fraction of the scar's half-width. [1]
AUTO_SMOOTHING = 0.02
#: Fewest samples a measured profile must have between the scar's edges.
MIN_SCAR_SAMPLES = 20

# Shoulders for the reference line: farther than these many half-widths from the centre
# (the first that leaves _MIN_SHOULDER samples on each side).
_SHOULDER_FACTORS = (1.5, 1.25, 1.1)
_MIN_SHOULDER = 5
# A depression is a scar only if it is deeper than this many times the shoulders' noise,
# and than this fraction of the relief (highest minus lowest) about the reference line.
_NOISE_FACTOR = 5.0
_MIN_RELIEF = 0.05
# Local quadratic fits reach this many standard deviations of their Gaussian weights, which
# are lowered to reach zero there (so a sample's weight never jumps as positions move).
_REACH = 4.0
_EDGE_WEIGHT = float(np.exp(-0.5 * _REACH**2))
# Edges and depth are read on heights smoothed over this many sample spacings (at most).
_EDGE_SMOOTHING = 1.0
# The profile reaches the reference line when within this fraction of the depth of it.
_LINE_TOLERANCE = 1e-9
# Elements per block of the local fits (bounds their memory).
_CHUNK = 2**21


class ScarProfile(NamedTuple):
    """A wear-scar profile as the model uses it (a JAX pytree of float64 arrays).

    Attributes
    ----------
    position : jax.Array, shape (N,)
        Sample positions :math:`X` along the fretting direction, relative to the scar
        centre, strictly increasing. [m]
    height : jax.Array, shape (N,)
        Heights :math:`z` at the samples (levelled when asked). [m]
    slope : jax.Array, shape (N,)
        Slope :math:`g = dz/dX` at the samples, after smoothing; the model takes it
        piecewise linear between samples. [1]
    depth : jax.Array, shape ()
        Scar depth :math:`D` below the unworn surface. [m]
    half_width : jax.Array, shape ()
        Scar half-width :math:`W`. [m]
    worn_area : jax.Array, shape ()
        Area between the unworn surface and the profile, between the edges. [m²]
    centre : jax.Array, shape ()
        Position of the scar centre in the coordinates of the trace as given. [m]
    reference_height : jax.Array, shape ()
        Height of the unworn surface at the centre, in the frame of ``height`` (0 when
        levelled). [m]
    reference_slope : jax.Array, shape ()
        Tilt of the unworn surface, in the frame of ``slope`` (0 when levelled). [1]

    Notes
    -----
    The scar is ``position`` in ``[-half_width, half_width]``; its edges in the trace's own
    coordinates are :attr:`edges`. A batch of profiles is a ``ScarProfile`` whose arrays
    have a leading batch axis (``jax.tree.map(lambda *a: jnp.stack(a), *profiles)``).
    """

    position: jax.Array
    height: jax.Array
    slope: jax.Array
    depth: jax.Array
    half_width: jax.Array
    worn_area: jax.Array
    centre: jax.Array
    reference_height: jax.Array
    reference_slope: jax.Array

    @property
    def aspect_ratio(self):
        """Depth over half-width :math:`D/W`, the paper's :math:`z_o/x_o` (eq. 11). [1]"""
        return self.depth / self.half_width

    @property
    def edges(self):
        """The scar's edges ``(left, right)`` in the coordinates of the trace as given. [m]"""
        return jnp.stack([self.centre - self.half_width, self.centre + self.half_width], -1)


def _profile(position, height, slope, depth, half_width, worn_area, centre=0.0,
             reference_height=0.0, reference_slope=0.0) -> ScarProfile:  # fmt: skip
    values = (position, height, slope, depth, half_width, worn_area, centre,
              reference_height, reference_slope)  # fmt: skip
    # JAX's 64-bit mode is on only inside the public entry points (importing ecofmaps does
    # not switch it on): without it these arrays would be float32.
    with jax.enable_x64(True):
        return ScarProfile(*(jnp.asarray(v, dtype=jnp.float64) for v in values))


# ---------------------------------------------------------------------------------------
# Measured profiles
# ---------------------------------------------------------------------------------------


def _array(name: str, value) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a 1-D array of numbers, got {value!r}") from None
    if array.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got shape {array.shape}")
    bad = ~np.isfinite(array)
    if bad.any():
        index = int(np.argmax(bad))
        raise ValueError(
            f"{name} must be finite; {name}[{index}] = {float(array[index])!r} "
            f"({np.count_nonzero(bad)} of {array.size} values)"
        )
    return array


def _check_positions(x: np.ndarray) -> None:
    steps = np.diff(x)
    if np.any(steps <= 0.0):
        i = int(np.argmax(steps <= 0.0)) + 1
        kind = "repeated" if steps[i - 1] == 0.0 else "decreasing"
        raise ValueError(
            f"x must be strictly increasing; x[{i}] = {x[i]!r} after x[{i - 1}] = {x[i - 1]!r} "
            f"({kind}); sort the trace and drop repeated positions"
        )


def local_quadratic(x: np.ndarray, z: np.ndarray, smoothing: float):
    """Heights and slopes of a Gaussian-weighted local quadratic fit at every sample.

    Parameters
    ----------
    x, z : numpy.ndarray
        Positions (strictly increasing) and heights. [m]
    smoothing : float
        Standard deviation of the Gaussian weights; 0 returns ``z`` itself and the slope of
        the parabola through each sample and its neighbours (``numpy.gradient``, second
        order at the ends). [m]

    Returns
    -------
    height, slope : numpy.ndarray
        [m], [1]

    Notes
    -----
    The weights are :math:`e^{-d^2/2} - e^{-8}` for samples within :math:`d = 4` standard
    deviations (continuous, zero at the reach). Where the samples are sparse the standard
    deviation is widened so that the nearest two samples on each side (three on one side at
    the ends) lie within 80 % of the reach: each fit is defined for any spacing. Quadratics
    are reproduced exactly.
    """
    if smoothing == 0.0:
        return z.copy(), np.gradient(z, x, edge_order=2)
    n = x.size
    rows = np.arange(n)
    # Widen the weights where samples are sparse: the nearest two on each side (three on
    # one side at the ends) within 80 % of the reach.
    span = np.maximum(x - x[np.clip(rows - 2, 0, n - 5)], x[np.clip(rows + 2, 4, n - 1)] - x)
    sigma = np.maximum(smoothing, span / (0.8 * _REACH))
    left = np.searchsorted(x, x - _REACH * sigma, side="left")
    right = np.searchsorted(x, x + _REACH * sigma, side="right")
    width = int(np.max(right - left))
    height, slope = np.empty(n), np.empty(n)
    chunk = max(1, _CHUNK // width)
    for start in range(0, n, chunk):
        block = slice(start, min(start + chunk, n))
        index = left[block, None] + np.arange(width)[None, :]
        valid = index < right[block, None]
        index = np.minimum(index, n - 1)
        d = (x[index] - x[block, None]) / sigma[block, None]
        weight = np.where(valid, np.maximum(np.exp(-0.5 * d * d) - _EDGE_WEIGHT, 0.0), 0.0)
        # Weighted normal equations of z ~ a + b d + c d^2 (d in units of the smoothing).
        powers = [np.sum(weight * d**k, axis=1) for k in range(5)]
        rhs = np.stack([np.sum(weight * z[index] * d**k, axis=1) for k in range(3)], axis=-1)
        matrix = np.stack([np.stack(powers[i : i + 3], axis=-1) for i in range(3)], axis=-2)
        solution = np.linalg.solve(matrix, rhs[..., None])[..., 0]
        height[block], slope[block] = solution[:, 0], solution[:, 1] / sigma[block]
    return height, slope


def _line(x, z, mask):
    """Least-squares offset and tilt of ``z`` over ``x[mask]``, as a function and a pair."""
    xm = x[mask]
    centre = xm.mean()
    tilt, offset = np.polyfit(xm - centre, z[mask], 1)
    return (lambda at: offset + tilt * (at - centre)), tilt


def _crossing(x, r, start, step, tolerance, reach):
    """Where ``r`` first reaches 0 (to ``tolerance``) from index ``start`` in direction
    ``step``: the wall below it, extended by the straight line through two samples at least
    ``reach`` samples short of the first sample reaching it (beyond the smoothing's reach of
    a kink there), clipped to between the nearer of them and that sample; None if the end
    of the trace comes first."""
    if step < 0:
        found = np.flatnonzero(r[:start] >= -tolerance)
        if found.size == 0:
            return None
        outer = found[-1]
        last = outer + 1
        inner = min(last + reach, start)
        second = min(inner + 1, start)
    else:
        found = np.flatnonzero(r[start:] >= -tolerance)
        if found.size == 0:
            return None
        outer = start + found[0]
        last = outer - 1
        inner = max(last - reach, start - 1)
        second = max(inner - 1, start - 1)
    rise = (r[inner] - r[second]) / (x[inner] - x[second]) if second != inner else 0.0
    if rise * (x[outer] - x[last]) > 0.0:  # the wall climbs towards the line
        edge = x[inner] - r[inner] / rise
    else:
        edge = x[last] + r[last] / (r[last] - r[outer]) * (x[outer] - x[last])
    return float(np.clip(edge, *sorted((x[inner], x[outer]))))


def _shoulders(x, centre, half_width):
    """Samples of the unworn surface (see the module docstring), or None if too few."""
    for factor in _SHOULDER_FACTORS:
        left = x < centre - factor * half_width
        right = x > centre + factor * half_width
        if left.sum() >= _MIN_SHOULDER and right.sum() >= _MIN_SHOULDER:
            return left | right
    return None


def _scar_extent(x, zs, half_width, reach=0):
    """Reference line, centre, half-width and depth of the scar in smoothed heights ``zs``."""
    span = x[-1] - x[0]
    mask = (x < x[0] + span / 5.0) | (x > x[-1] - span / 5.0)
    previous = None
    for _ in range(20):
        line, tilt = _line(x, zs, mask)
        r = zs - line(x)
        shoulder_noise = 1.4826 * np.median(np.abs(r[mask] - np.median(r[mask])))
        deepest = int(np.argmin(r))
        depth = -r[deepest]
        if not depth > max(_NOISE_FACTOR * shoulder_noise, _MIN_RELIEF * (r.max() - r.min())):
            raise ValueError(
                "z: no depression found: the deepest point is "
                f"{depth:.3g} m below the unworn surface (a straight line fitted to the "
                f"trace's ends): not more than {_NOISE_FACTOR:g} times its noise "
                f"({shoulder_noise:.3g} m) and {_MIN_RELIEF:.0%} of the trace's relief. Heights "
                "must increase upwards (the scar is a depression), in metres."
            )
        tolerance = _LINE_TOLERANCE * depth
        left = _crossing(x, r, deepest, -1, tolerance, reach)
        right = _crossing(x, r, deepest + 1, +1, tolerance, reach)
        if left is None or right is None:
            side = "left" if left is None else "right"
            raise ValueError(
                f"x: the scar reaches the {side} end of the trace (no unworn surface beside "
                "it): the trace must extend beyond both edges of the scar"
            )
        centre = 0.5 * (left + right)
        width = 0.5 * (right - left) if half_width is None else half_width
        if half_width is not None and (centre - width < x[0] or centre + width > x[-1]):
            raise ValueError(
                f"half_width = {half_width!r} m does not fit the trace: the scar centre is at "
                f"x = {centre!r} m and the trace spans [{x[0]!r}, {x[-1]!r}] m"
            )
        mask = _shoulders(x, centre, width)
        if mask is None:
            raise ValueError(
                "x: the trace is too short for levelling: it needs at least "
                f"{_MIN_SHOULDER} samples of unworn surface beyond 1.1 half-widths from the "
                f"scar centre on each side (centre {centre!r} m, half-width {width!r} m, "
                f"trace [{x[0]!r}, {x[-1]!r}] m)"
            )
        key = (left, right)
        if key == previous:
            break
        previous = key
    return line, tilt, centre, width, r


def scar_profile(x, z, half_width=None, smoothing=None, level=False) -> ScarProfile:
    r"""A wear-scar profile from a measured trace (arrays in metres).

    Parameters
    ----------
    x : array_like, shape (N,)
        Positions along the fretting direction, strictly increasing. [m]
    z : array_like, shape (N,)
        Heights, increasing upwards (the scar is a depression). [m]
    half_width : float, optional
        The scar's half-width :math:`W`, overriding the detected one (the centre stays the
        detected one). [m]
    smoothing : float, optional
        Standard deviation of the Gaussian weights of the local quadratic fits that give
        the heights and slopes (module docstring); 0 for none. Default:
        :data:`AUTO_SMOOTHING` times the detected half-width. It is raised to the median
        sample spacing if smaller, and must not exceed a fifth of the half-width. [m]
    level : bool
        Subtract the unworn surface's line (tilt and offset fitted on the shoulders) from
        the heights and its tilt from the slopes. Off by default: the arrays are taken as
        the pad feels them, so a genuinely tilted scar stays tilted.

    Returns
    -------
    profile : ScarProfile
        Positions relative to the detected centre, the heights (levelled if asked), the
        smoothed slopes, and the depth, half-width, worn area, centre and reference line.

    Raises
    ------
    ValueError
        Naming the parameter: ``x`` and ``z`` not 1-D arrays of equal length, NaN or
        infinite values, ``x`` not strictly increasing (unsorted or repeated positions), no
        depression deeper than the noise, a scar that reaches an end of the trace or a trace
        too short to level, fewer than :data:`MIN_SCAR_SAMPLES` samples across the scar, a
        ``half_width`` that does not fit the trace, or a bad ``smoothing``.

    Notes
    -----
    The edges, the reference line and the smoothing follow the rules of the module
    docstring. The model maps a pad position :math:`x` to :math:`X = xW/x_o` (eq. 11).

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 11.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.linspace(-100e-6, 100e-6, 401)
    >>> z = np.where(np.abs(x) < 50e-6, 10e-6 * ((x / 50e-6) ** 2 - 1), 0.0)
    >>> p = scar_profile(x, z, smoothing=0)
    >>> round(float(p.half_width) * 1e6, 6), round(float(p.depth) * 1e6, 6)
    (50.0, 10.0)
    """
    x = _array("x", x)
    z = _array("z", z)
    if x.size != z.size:
        raise ValueError(f"x and z must have the same length, got {x.size} and {z.size}")
    if x.size < 2 * MIN_SCAR_SAMPLES:
        raise ValueError(f"x: a trace needs at least {2 * MIN_SCAR_SAMPLES} samples, got {x.size}")
    _check_positions(x)
    if half_width is not None:
        half_width = float(_array("half_width", [half_width])[0])
        if half_width <= 0.0:
            raise ValueError(f"half_width must be > 0, got {half_width!r}")
    if smoothing is not None:
        smoothing = float(_array("smoothing", [smoothing])[0])
        if smoothing < 0.0:
            raise ValueError(f"smoothing must be >= 0 (0: none), got {smoothing!r}")
    spacing = float(np.median(np.diff(x)))
    # The edges are found on lightly smoothed heights (a kink at an edge would move under
    # heavier smoothing); the slopes are smoothed over 2 % of the half-width by default.
    light = 0.0 if smoothing == 0.0 else _EDGE_SMOOTHING * spacing
    zs, _ = local_quadratic(x, z, light)
    reach = int(np.ceil(_REACH * light / spacing))
    line, tilt, centre, width, r = _scar_extent(x, zs, half_width, reach)
    sigma = AUTO_SMOOTHING * width if smoothing is None else smoothing
    sigma = 0.0 if sigma == 0.0 else max(sigma, spacing)
    if sigma > width / 5.0:
        raise ValueError(
            f"smoothing = {sigma!r} m is more than a fifth of the scar's half-width "
            f"({width!r} m): it would flatten the scar; give a smaller smoothing"
        )
    smooth, gs = local_quadratic(x, z, sigma)
    inside = np.abs(x - centre) <= width
    count = int(inside.sum())
    if count < MIN_SCAR_SAMPLES:
        raise ValueError(
            f"x: only {count} samples across the scar (half-width {width!r} m); at least "
            f"{MIN_SCAR_SAMPLES} are needed: sample the trace more densely"
        )
    depth = float(-np.min(smooth[inside] - line(x[inside])))
    edges = (centre - width, centre + width)
    ends = np.interp(edges, x, r)
    area_x = np.concatenate([[edges[0]], x[inside], [edges[1]]])
    area_r = np.concatenate([[ends[0]], r[inside], [ends[1]]])
    worn = float(np.trapezoid(np.maximum(-area_r, 0.0), area_x))
    if level:
        height, slope = z - line(x), gs - tilt
        reference = (0.0, 0.0)
    else:
        height, slope = z, gs
        reference = (float(line(centre)), float(tilt))
    return _profile(x - centre, height, slope, depth, width, worn, centre, *reference)
