"""The wear-scar profile the model uses (:class:`ScarProfile`, a JAX pytree), and
:func:`scar_profile`, which builds one from a measured trace: outliers replaced (a Hampel
filter), heights and slopes smoothed (local quadratic fits), the edges found by
:mod:`ecofmaps.model.profile_edges`. The method is explained in ``docs/profiles.md``.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ecofmaps._codes import warn
from ecofmaps._inputs import is_concrete, si_units
from ecofmaps.model.profile_edges import ScarProfileWarning, scar_extent

#: Fewest samples a measured profile must have between the scar's edges.
MIN_SCAR_SAMPLES = 20
#: Outliers: neighbours on each side of a sample whose median and MAD it is judged by.
OUTLIER_NEIGHBOURS = 4
#: Outliers: farther than this many scaled MADs (1.4826 MAD) from the neighbours' median.
OUTLIER_THRESHOLD = 6.0
#: Default smoothing length as a fraction of the scar's half-width. [1]
AUTO_SMOOTHING = 0.02
# Local quadratic fits reach this many standard deviations of their Gaussian weights, which
# are lowered to reach zero there (so a sample's weight never jumps as positions move).
_REACH = 4.0
_EDGE_WEIGHT = float(np.exp(-0.5 * _REACH**2))
# Edges and depth are read on heights smoothed over this many sample spacings (at most).
_EDGE_SMOOTHING = 1.0
# Elements per block of the local fits (bounds their memory).
_CHUNK = 2**21


class ScarProfile(NamedTuple):
    """A wear-scar profile as the model uses it: a JAX pytree of float64 arrays (NumPy's when
    made from numbers, JAX's inside a traced function; a batch has a leading axis on each).

    Attributes
    ----------
    position, height, slope : jax.Array, shape (N,)
        Sample positions :math:`X` relative to the scar centre, strictly increasing [m];
        heights :math:`z` (levelled when asked) [m]; smoothed slopes :math:`g = dz/dX`,
        taken piecewise linear between samples [1].
    depth, half_width : jax.Array, shape ()
        Scar depth :math:`D` below the unworn surface and half-width :math:`W`: the scar is
        ``position`` in ``[-half_width, half_width]``. [m]
    worn_area : jax.Array, shape ()
        Area between the unworn surface and the profile, between the edges. [m²]
    centre : jax.Array, shape ()
        Position of the scar centre in the coordinates of the trace as given. [m]
    reference_height, reference_slope : jax.Array, shape ()
        Height at the centre [m] and tilt [1] of the unworn surface, in the frame of
        ``height`` and ``slope`` (0 when levelled).
    alternative_half_width : jax.Array, shape ()
        The other plausible half-width of ambiguous or uncertain edges, else NaN. [m]
    replaced : jax.Array, shape (N,) or ()
        1 where an outlier's height (:func:`outlying_samples`) was interpolated, else 0; a
        scalar 0 when no sample was tested (the families). [1]
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
    alternative_half_width: jax.Array = float("nan")
    replaced: jax.Array = 0.0

    @property
    def aspect_ratio(self):
        """Depth over half-width :math:`D/W`, the paper's :math:`z_o/x_o` (eq. 11). [1]"""
        return self.depth / self.half_width

    @property
    def edges(self):
        """The scar's edges ``(left, right)`` in the coordinates of the trace as given. [m]"""
        stack = np.stack if is_concrete(self) else jnp.stack  # float64 either way
        return stack([self.centre - self.half_width, self.centre + self.half_width], -1)


def profile_of(*parts) -> ScarProfile:
    """A :class:`ScarProfile` of ``parts`` (its defaults after them) as NumPy float64 arrays."""
    return ScarProfile(*(np.asarray(part, dtype=np.float64) for part in ScarProfile(*parts)))


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


def _trace(x, z):
    """``x`` and ``z`` as float64 arrays of one length, checked."""
    x, z = _array("x", x), _array("z", z)
    if x.size != z.size:
        raise ValueError(f"x and z must have the same length, got {x.size} and {z.size}")
    return x, z


def outlying_samples(x, z, neighbours=OUTLIER_NEIGHBOURS, threshold=OUTLIER_THRESHOLD):
    """Which samples of a trace are outliers (bool, shape (N,)): a Hampel filter (Hampel 1974)
    judging each sample by the median and scaled MAD of ``neighbours`` samples on each side
    (``docs/profiles.md``); a run of up to ``neighbours - 1`` outliers is found."""
    x, z = _trace(x, z)
    if not (isinstance(neighbours, int | np.integer) and 1 <= neighbours < z.size / 2):
        raise ValueError(
            f"neighbours must be an integer >= 1 and less than half the {z.size} samples, "
            f"got {neighbours!r}"
        )
    # The 2 * neighbours samples nearest each (itself left out), shifted inwards at the ends.
    rows, count = np.arange(z.size), int(neighbours)
    start = np.clip(rows - count, 0, z.size - 2 * count - 1)
    window = start[:, None] + np.arange(2 * count + 1)[None, :]
    around = z[np.where(window < rows[:, None], window, window + 1)[:, : 2 * count]]
    median = np.median(around, axis=1)
    spread = 1.4826 * np.median(np.abs(around - median[:, None]), axis=1)
    between = z[:-2] + (z[2:] - z[:-2]) * (x[1:-1] - x[:-2]) / (x[2:] - x[:-2])
    noise = 1.4826 / np.sqrt(1.5) * np.median(np.abs(z[1:-1] - between))
    steps = np.abs(np.diff(z))
    resolution = float(np.min(steps[steps > 0.0])) if steps.any() else 0.0
    off = np.abs(z - median)
    typical = 1.4826 * np.median(off)
    scale = np.maximum(np.maximum(spread, noise), max(resolution, typical))
    return off > threshold * scale


def _outliers_replaced(x, z):
    """Heights with their outliers interpolated, the outliers' mask and the warnings."""
    outlier = outlying_samples(x, z)
    if not outlier.any():
        return z, outlier, []
    kept = ~outlier
    cleaned = z.copy()
    cleaned[outlier] = np.interp(x[outlier], x[kept], z[kept])
    samples = np.flatnonzero(outlier)
    details = [
        f"x = {x[i] * 1e6:.6g} µm, {abs(z[i] - cleaned[i]) * 1e6:.3g} µm "
        f"{'below' if z[i] < cleaned[i] else 'above'} its neighbours"
        for i in samples
    ]
    summary = (
        f"{samples.size} outlier(s) (a spike or dropout: more than {OUTLIER_THRESHOLD:g} "
        f"scaled MADs from the median of its {2 * OUTLIER_NEIGHBOURS} neighbours) replaced by "
        "linear interpolation between the nearest samples kept"
    )
    return cleaned, outlier, [ScarProfileWarning(summary, samples, details)]


def _checked_trace(x, z, half_width, smoothing):
    """The trace and the parameters of :func:`scar_profile` as float64, checked."""
    x, z = _trace(x, z)
    if x.size < 2 * MIN_SCAR_SAMPLES:
        raise ValueError(f"x: a trace needs at least {2 * MIN_SCAR_SAMPLES} samples, got {x.size}")
    steps = np.diff(x)
    if np.any(steps <= 0.0):
        i = int(np.argmax(steps <= 0.0)) + 1
        kind = "repeated" if steps[i - 1] == 0.0 else "decreasing"
        raise ValueError(
            f"x must be strictly increasing; x[{i}] = {x[i]!r} after x[{i - 1}] = {x[i - 1]!r} "
            f"({kind}); sort the trace and drop repeated positions"
        )
    if half_width is not None:
        half_width = float(_array("half_width", [half_width])[0])
        if half_width <= 0.0:
            raise ValueError(f"half_width must be > 0, got {half_width!r}")
    if smoothing is not None:
        smoothing = float(_array("smoothing", [smoothing])[0])
        if smoothing < 0.0:
            raise ValueError(f"smoothing must be >= 0 (0: none), got {smoothing!r}")
    return x, z, half_width, smoothing


def local_quadratic(x: np.ndarray, z: np.ndarray, smoothing: float):
    """Heights [m] and slopes [1] of Gaussian-weighted local quadratic fits at every sample,
    of standard deviation ``smoothing`` [m] (``docs/profiles.md``); 0: ``z`` and
    ``numpy.gradient``."""
    if smoothing == 0.0:
        return z.copy(), np.gradient(z, x, edge_order=2)
    n = x.size
    rows = np.arange(n)
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


def scar_profile_and_findings(
    x, z, half_width=None, smoothing=None, level=False, remove_outliers=True
):
    """:func:`scar_profile` and its warnings, not issued: ``(profile, findings)``."""
    x, z, half_width, smoothing = _checked_trace(x, z, half_width, smoothing)
    findings, replaced = [], np.zeros(x.size, dtype=bool)
    if remove_outliers:
        z, replaced, findings = _outliers_replaced(x, z)
    spacing = float(np.median(np.diff(x)))
    # The edges are found on lightly smoothed heights (heavier smoothing moves a kink).
    light = 0.0 if smoothing == 0.0 else _EDGE_SMOOTHING * spacing
    zs, _ = local_quadratic(x, z, light)
    reach = int(np.ceil(_REACH * light / spacing))
    (line, tilt, centre, width, r), alternative, more = scar_extent(x, zs, half_width, reach)
    findings += more
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
    edges = np.array([centre - width, centre + width])  # the samples inside between them
    area_x, area_r = np.insert(edges, 1, x[inside]), np.insert(np.interp(edges, x, r), 1, r[inside])
    worn = float(np.trapezoid(np.maximum(-area_r, 0.0), area_x))
    if level:
        height, slope, reference = z - line(x), gs - tilt, (0.0, 0.0)
    else:
        height, slope, reference = z, gs, (float(line(centre)), float(tilt))
    parts = (depth, width, worn, centre, *reference, alternative, replaced)
    return profile_of(x - centre, height, slope, *parts), findings


@si_units(x="length", z="length", half_width="length")
def scar_profile(
    x, z, half_width=None, smoothing=None, level=False, remove_outliers=True
) -> ScarProfile:
    r"""A wear-scar profile from a measured trace (arrays in metres): edges, reference line and
    smoothing as ``docs/profiles.md`` explains; the model maps a pad at :math:`x` to :math:`X =
    xW/x_o` (eq. 11).

    Parameters
    ----------
    x, z : array_like, shape (N,)
        Positions along the fretting direction, strictly increasing, and heights, increasing
        upwards (the scar is a depression). [m]
    half_width : float, optional
        The scar's half-width :math:`W`, overriding the detected one (the centre stays the
        detected one). [m]
    smoothing : float, optional
        Standard deviation of the local quadratic fits' Gaussian weights (0: none); default
        :data:`AUTO_SMOOTHING` times the half-width, at least the median sample spacing, at
        most a fifth of the half-width. [m]
    level : bool
        Subtract the unworn surface's line (fitted on the shoulders) from the heights and
        its tilt from the slopes; off by default, so a genuinely tilted scar stays tilted.
    remove_outliers : bool
        Replace outliers (:func:`outlying_samples`) by linear interpolation between the
        nearest samples kept, before anything else (``replaced`` marks them).

    Returns
    -------
    profile : ScarProfile
        Positions relative to the detected centre; heights levelled if asked.

    Warns
    -----
    ScarProfileWarning
        For outliers replaced (count, indices, positions), and for ambiguous or uncertain
        edges: both half-widths, the one returned and the ``half_width=`` taking the other.

    Raises
    ------
    ValueError
        Naming the parameter: ``x``, ``z`` not finite 1-D arrays of equal length or ``x``
        not strictly increasing; no depression deeper than the noise; a scar reaching an end
        of the trace, a trace too short to level, fewer than :data:`MIN_SCAR_SAMPLES`
        samples across the scar, a ``half_width`` off the trace or a bad ``smoothing``.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 11.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.linspace(-100e-6, 100e-6, 401)
    >>> z = np.where(np.abs(x) < 50e-6, 10e-6 * ((x / 50e-6) ** 2 - 1), 0.0)
    >>> p = scar_profile(x, z, smoothing=0)
    >>> round(float(p.half_width) * 1e6, 6), round(float(p.depth) * 1e6, 6)
    (50.0, 10.0)
    """
    profile, findings = scar_profile_and_findings(
        x, z, half_width, smoothing, level, remove_outliers
    )
    for finding in findings:
        warn(finding, ScarProfileWarning)
    return profile
