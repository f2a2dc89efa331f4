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

*Outliers.* First, spikes and dropouts (a sample far from its neighbours' median; a
Hampel filter, :func:`outlying_samples`: the 8 nearest other samples, 6 scaled MADs) are
replaced by linear interpolation between the nearest samples kept, and listed in a
:class:`ScarProfileWarning` (``remove_outliers=False`` keeps them).

*Reference line (the unworn surface).* A straight line (offset and tilt) fitted by least
squares to the *shoulders*: the samples beyond the disturbed band (below) and farther than
1.5 half-widths from the scar centre (1.25 or 1.1 when the trace is too short to leave 5
samples on each side there), without those farther from the line than the band's
threshold (debris) if 5 are left on each side. It starts from the outer fifths of the
trace and is refitted with the edges it gives until they settle.

*Edges.* From the deepest point below the reference line, the first samples on either side
that reach the line (to within :math:`10^{-9}` of the depth, or on a rough surface to within
3 times the shoulders' noise but at most 5 % of the depth, so that a valley of the
roughness beside the groove does not carry the edge out); the edge is where the wall,
extended by a straight line, reaches it. The straight line runs through two samples of the
wall beyond the reach of the light smoothing from the last sample below the line (the last
two without smoothing): exact for a straight wall cut into a flat surface, second order in
that distance for a curved one. On a rough surface it is the least-squares line through
the wall's samples from there down to 4 times that tolerance below the line, and it may
reach the line beyond the first sample within the tolerance by as far as it takes to climb
the tolerance; the line is fitted down to at least 2 tolerances below that first sample (a
shorter stretch of wall near the line gives a slope that the roughness tilts, and an edge
carried out by micrometres). These are the *groove's* edges.

*Uncertain edges.* Where 3 times the shoulders' noise exceeds 5 % of the depth, a valley of
the roughness beside the groove deeper than the tolerance can still carry an edge out. The
edges are then also read with the tolerance 3 times the noise, and when that moves an edge
by more than :data:`UNCERTAIN_EDGES` of the half-width, a :class:`ScarProfileWarning` says
the edges are uncertain and gives both half-widths (``alternative_half_width`` keeps the
other; ``half_width=`` takes it). On a groove 31 µm in half-width and 3 µm deep, on 100
random surfaces rough by 7 % of the depth (correlated over 2 µm), 92 warn, and none of the
others is off by more than 10 % of the half-width (31 were off by more than 2 µm, up to
22 µm, silently, before); at 2 % roughness none warns and each edge is within 1.5 µm. Over
1500 such surfaces rough by 1 % to 10 % of the depth, correlated over 1 to 10 µm, 2 (7 %
roughness over 3 µm) were off by 11.5 % and 11.8 % without a warning.

*Pile-up ridges and the disturbed band.* The band around the groove is disturbed: its
samples lie farther from the line than 5 times the shoulders' noise and than 2 % of the
depth, with no quiet stretch longer than a quarter of the groove's half-width (and than 10
sample spacings) between them. Pile-up ridges are material that the counterbody pushed out
at the ends of the track; it slides up their inner flanks to where it stops, so the track
lies between the ridges and its edges are their *crests* (the band between the ridges is
measured crest to crest).

Pile-up ridges come in pairs, however quiet the floor between them and the groove. The
highest runs above the threshold on either side of the groove, within 5 of its half-widths
of its centre or a quarter of the trace's span (whichever is farther: a groove that is a
valley of the roughness inside a wide track must not keep the track's ridges out of
reach), are a pair when each is the outstanding feature of its side (all else beyond
the groove there, apart from its own disturbed stretch, lower than half its height) and
either both stand above the threshold over at least a quarter of the groove's half-width
and lie at distances from the centre within a ratio of 1.5, or they are narrow ridges, not
two asperities: each at least 5 samples wide and higher than twice the threshold (10
times the shoulders' noise), the two alike (heights and widths within a ratio of 1.5) and
mirror images about the groove's centre (their crests' distances from it differ by less
than half the sum of their widths). The band then reaches at least to their outer ends. Two
asperities that happen to meet all this are taken for ridges, with the warning below: on
random rough shoulders with one asperity a side, 2 surfaces in 1500 (measured with the
reach of 5 half-widths alone); with 1 to 4 a side, 3 in 1500 (none with that reach alone).

Going inwards from the band's outer end, the first crest that stands higher than the
threshold above the line is a pile-up ridge. Down its inner flank, whatever its shape
(Gaussian, sin², triangular, asymmetric), its foot is where the flank stops falling: the
lowest point before the profile rises by the threshold again (a floor above the line,
debris, roughness) or, if it first stays level, the first point after which it falls by no
more than the threshold over a quarter of the groove's half-width (a floor at the line or
above it). When that foot lies beyond the groove's edge by more than
:data:`AMBIGUOUS_EDGES` of the groove's half-width, the band's edge is the ridge's crest:
the vertex of the parabola fitted to the samples within the threshold of its top (within
2 µm of the true crest for ridges 1.5 µm high in noise of 0.02 µm, 4 µm in noise of 0.1 µm).
Where the flank falls all the way into the groove, or stops nearer its edge (the groove's
walls run up into the ridges, as in :func:`~ecofmaps.ridged_profile`), the edge is the
groove's. Without a ridge, the band's edge is its outermost sample.

When an edge of the band lies beyond the groove's by more than :data:`AMBIGUOUS_EDGES` of
the groove's half-width, the edges are ambiguous, and a :class:`ScarProfileWarning` gives
both candidates with their half-widths and edges: the groove below the unworn surface's
line, and the band between the ridges' crests (or the disturbed band); it says which one
was returned, and ``half_width=`` (``--profile-half-width`` on the command line) takes the
other, which ``alternative_half_width`` keeps. Which one the model needs is the user's
judgement. The band is returned when both its edges lie beyond the groove's (a shallow
groove inside a wider worn track, or a roughness valley inside a disturbed band), the
groove when only one does (most often debris lying beside the groove).

The half-width is half the distance of the two edges, the centre their midpoint;
``half_width=`` overrides the half-width (the centre stays that of the detected edges,
of the groove or of the band, whichever is nearer in width). The depth is the largest
depth of the smoothed profile below the line between the edges, and the worn area the area
between the line and the profile there. A depression no deeper
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

from ecofmaps._codes import warn
from ecofmaps._inputs import is_concrete, si_units

__all__ = [
    "AMBIGUOUS_EDGES",
    "AUTO_SMOOTHING",
    "MIN_SCAR_SAMPLES",
    "OUTLIER_NEIGHBOURS",
    "OUTLIER_THRESHOLD",
    "UNCERTAIN_EDGES",
    "ScarProfile",
    "ScarProfileWarning",
    "outlying_samples",
    "scar_profile",
    "scar_profile_and_findings",
    "scar_profile_from_parts",
]

#: Default smoothing length as a fraction of the scar's half-width. [1]
AUTO_SMOOTHING = 0.02
#: Fewest samples a measured profile must have between the scar's edges.
MIN_SCAR_SAMPLES = 20
#: Outliers: neighbours on each side of a sample whose median and MAD it is judged by.
OUTLIER_NEIGHBOURS = 4
#: Outliers: farther than this many scaled MADs (1.4826 MAD) from the neighbours' median.
OUTLIER_THRESHOLD = 6.0
#: The edges are ambiguous when an edge of the band between the ridges lies beyond the
#: groove's by more than this fraction of the groove's half-width. [1]
AMBIGUOUS_EDGES = 0.1
#: On a rough surface the groove's edges are uncertain when reading them within 3 times the
#: shoulders' noise of the line, rather than within 5 % of the depth, moves one by more
#: than this fraction of the groove's half-width. [1]
UNCERTAIN_EDGES = 0.05

# Shoulders for the reference line: farther than these many half-widths from the centre
# (the first that leaves _MIN_SHOULDER samples on each side).
_SHOULDER_FACTORS = (1.5, 1.25, 1.1)
_MIN_SHOULDER = 5
# A depression is a scar only if it is deeper than this many times the shoulders' noise,
# and than this fraction of the relief (highest minus lowest) about the reference line.
_NOISE_FACTOR = 5.0
_MIN_RELIEF = 0.05
# The disturbed band: samples farther from the line than _NOISE_FACTOR times the noise and
# than this fraction of the depth, with no quiet stretch longer than this fraction of the
# groove's half-width and than _BAND_GAP sample spacings between them.
_BAND_FLOOR = 0.02
_BAND_GAP_WIDTH = 0.25
_BAND_GAP = 10
# Pile-up ridges beyond a quiet floor: a pair, the highest crest on each side within this
# many groove half-widths of its centre, at distances from it within this ratio (each
# higher than the band's threshold over at least the band's longest quiet stretch).
_RIDGE_REACH = 5.0
# ... or within this share of the trace's span (a groove that is a valley of the roughness
# inside a wide track would otherwise keep the track's ridges out of reach).
_RIDGE_SPAN = 0.25
_RIDGE_PAIR = 1.5
# Each ridge of a pair is the outstanding feature of its side: all else beyond the groove
# there lower than this fraction of its height.
_RIDGE_PROMINENCE = 0.5
# Narrower ridges (not both as wide as that quiet stretch) are a pair, not asperities, when
# each is this many samples wide or more and higher than this many times the threshold, the
# two alike (heights and widths within this ratio) and mirror images about the groove's
# centre (their crests' distances from it differ by less than this times their widths' sum).
_NARROW_SAMPLES = 5
_NARROW_HEIGHT = 2.0
_NARROW_ALIKE = 1.5
_NARROW_MIRROR = 0.5
# Local quadratic fits reach this many standard deviations of their Gaussian weights, which
# are lowered to reach zero there (so a sample's weight never jumps as positions move).
_REACH = 4.0
_EDGE_WEIGHT = float(np.exp(-0.5 * _REACH**2))
# Edges and depth are read on heights smoothed over this many sample spacings (at most).
_EDGE_SMOOTHING = 1.0
# The profile reaches the reference line when within this fraction of the depth of it, or
# within this many times the shoulders' noise (a rough surface's valleys dip below the
# line), but not more than this share of the depth.
_LINE_TOLERANCE = 1e-9
_LINE_NOISE = 3.0
_LINE_SHARE = 0.05
# Elements per block of the local fits (bounds their memory).
_CHUNK = 2**21


class ScarProfile(NamedTuple):
    """A wear-scar profile as the model uses it (a JAX pytree of float64 arrays).

    Made from numbers (:func:`scar_profile`, :func:`ecofmaps.read_scar_profile`, the
    families) its arrays are NumPy's, so that arithmetic on them stays float64 outside JAX's
    64-bit mode; made inside a traced function they are JAX's.

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
    alternative_half_width : jax.Array, shape ()
        The other plausible half-width when the edges were ambiguous (the groove's below
        the unworn surface's line, or the band's between the crests of pile-up ridges,
        whichever was not returned) or uncertain on a rough surface (read within 3 times
        the roughness of the line; see the module docstring), NaN when they were neither
        (or the half-width was given). [m]
    replaced : jax.Array, shape (N,) or ()
        1 where the sample was an outlier (a spike or dropout, :func:`outlying_samples`)
        and its height was interpolated from its neighbours', else 0; a scalar 0 when no
        sample was tested (the analytic families). [1]

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


def scar_profile_from_parts(position, height, slope, depth, half_width, worn_area, centre=0.0,
             reference_height=0.0, reference_slope=0.0, alternative_half_width=np.nan,
             replaced=0.0) -> ScarProfile:  # fmt: skip
    values = (position, height, slope, depth, half_width, worn_area, centre,
              reference_height, reference_slope, alternative_half_width, replaced)  # fmt: skip
    if is_concrete(*values):
        # NumPy arrays: a user's own arithmetic on them (``profile.half_width * 1e6``) stays
        # float64, where JAX outside its 64-bit mode would truncate it to float32.
        return ScarProfile(*(np.asarray(v, dtype=np.float64) for v in values))
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


class ScarProfileWarning(UserWarning):
    """What reading a measured profile decided that its user must see.

    Outliers replaced (``samples``: their indices in the trace, ``details``: what each
    shows) or ambiguous or uncertain edges (``alternative``: the other half-width).
    Callers that know where the samples came from (a file's lines) name them with
    :meth:`text`.

    Attributes
    ----------
    summary : str
        The finding, without the samples.
    samples : tuple of int
        Indices of the samples concerned in the trace as given.
    details : tuple of str
        What each sample shows (its position and deviation), in the order of ``samples``.
    alternative : float or None
        For ambiguous edges, the half-width not taken (``half_width=`` takes it). [m]
    alternative_name : str
        What that half-width is: ``'groove'`` or ``'band'``.
    """

    def __init__(self, summary: str, samples=(), details=(), alternative=None,
                 alternative_name=""):  # fmt: skip
        self.summary = summary
        self.samples = tuple(int(i) for i in samples)
        self.details = tuple(details)
        self.alternative = alternative
        self.alternative_name = alternative_name
        hint = "" if alternative is None else (
            f"; half_width={alternative:.6g} (m) takes the {alternative_name}"
        )  # fmt: skip
        super().__init__(self.text([f"sample {i}" for i in self.samples]) + hint)

    def text(self, labels) -> str:
        """The finding with each sample named by ``labels`` (at most 10 listed)."""
        if not self.samples:
            return self.summary
        shown = [f"{label} ({detail})" for label, detail in zip(labels, self.details, strict=True)]
        more = len(shown) - 10
        listed = "; ".join(shown[:10]) + (f"; and {more} more" if more > 0 else "")
        return f"{self.summary}: {listed}"


def _neighbours(n: int, count: int) -> np.ndarray:
    """Indices, shape (n, 2 count), of the ``2 count`` nearest other samples of each sample
    (``count`` each side, shifted inwards at the ends of the trace)."""
    rows = np.arange(n)
    start = np.clip(rows - count, 0, n - 2 * count - 1)
    window = start[:, None] + np.arange(2 * count + 1)[None, :]
    others = np.where(window < rows[:, None], window, window + 1)
    return others[:, : 2 * count]


def outlying_samples(x, z, neighbours=OUTLIER_NEIGHBOURS, threshold=OUTLIER_THRESHOLD):
    r"""Which samples of a trace are outliers (spikes, dropouts): a Hampel filter.

    Parameters
    ----------
    x, z : array_like, shape (N,)
        Positions (strictly increasing) and heights. [m]
    neighbours : int
        Samples on each side that a sample is judged by (shifted inwards at the ends of the
        trace). A run of up to ``neighbours - 1`` outliers is found.
    threshold : float
        How many scaled MADs from the neighbours' median make an outlier. [1]

    Returns
    -------
    outlier : numpy.ndarray of bool, shape (N,)

    Notes
    -----
    A sample is an outlier when it is farther from the median :math:`m` of its
    ``2 neighbours`` nearest neighbours (itself left out) than ``threshold`` times the
    largest of their scaled median absolute deviation :math:`1.4826\,\mathrm{MAD}`, the
    trace's noise (:math:`1.4826/\sqrt{1.5}` times the median distance of a sample from the
    straight line through its two neighbours, the standard deviation of white noise), the
    trace's typical distance of a sample from its neighbours' median (1.4826 times its
    median over the trace, so that on a surface whose roughness is correlated over a few
    samples, the stretches where the neighbours happen to lie close together do not make
    its ordinary samples outliers: 79 of 100 such surfaces had one or more before) and its
    resolution (the smallest step between two samples, so that a quantised trace's
    one-step blips on an otherwise constant stretch, where the MAD is 0, are not taken). A
    spike is far from its neighbours' median; a scar's edge, a kink, a step between
    two samples or the bottom of a V is not (the median of the neighbours on both sides lies
    within about 2 MADs of them). With the defaults (8 neighbours, 6 MADs) no sample of
    white noise was flagged in 2e5.
    """
    x, z = _array("x", x), _array("z", z)
    if x.size != z.size:
        raise ValueError(f"x and z must have the same length, got {x.size} and {z.size}")
    if not (isinstance(neighbours, int | np.integer) and 1 <= neighbours < z.size / 2):
        raise ValueError(
            f"neighbours must be an integer >= 1 and less than half the {z.size} samples, "
            f"got {neighbours!r}"
        )
    around = z[_neighbours(z.size, int(neighbours))]
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


def _without_outliers(x, z):
    """Heights with their outliers replaced by linear interpolation, the mask of those, and
    the warning that lists them (or None)."""
    outlier = outlying_samples(x, z)
    if not outlier.any():
        return z, outlier, None
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
    return cleaned, outlier, ScarProfileWarning(summary, samples, details)


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
    a kink there), clipped to between the nearer of them and where that line, climbing,
    has risen by ``tolerance`` beyond that sample; and the index of that sample. None if the
    end of the trace comes first."""
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
    """Where the wall's least-squares line reaches 0, and its slope, over the wall's samples
    from ``inner`` inwards down to 4 ``tolerance`` below the line (at least the two of the
    two-point line ``edge``, ``rise``, which are kept if the fit's slope does not climb)."""
    deep = r < min(-4.0 * tolerance, r[inner] - 2.0 * tolerance)
    if step > 0:
        below = np.flatnonzero(deep[start : inner + 1])
        first = start + int(below[-1]) if below.size else start
        span = slice(first, inner + 1)
    else:
        below = np.flatnonzero(deep[inner : start + 1])
        last = inner + int(below[0]) if below.size else start
        span = slice(inner, last + 1)
    if span.stop - span.start < 3:
        return edge, rise
    slope, offset = np.polyfit(x[span], r[span], 1)
    if not slope * rise > 0.0:
        return edge, rise
    return -offset / slope, slope


def _band_end(x, r, outer, step, threshold, gap):
    """Index of the outermost sample of the disturbed band beyond the groove's edge sample
    ``outer`` in direction ``step``: farther than ``threshold`` from the line, with no quiet
    stretch longer than ``gap`` before it; ``outer`` if there is none."""
    if step > 0:
        index = outer + np.flatnonzero(np.abs(r[outer:]) > threshold)
    else:
        index = np.flatnonzero(np.abs(r[: outer + 1]) > threshold)[::-1]
    gaps = np.abs(np.diff(np.concatenate([[x[outer]], x[index]])))
    far = np.flatnonzero(gaps > gap)
    count = int(far[0]) if far.size else index.size
    return int(index[count - 1]) if count else outer


def _forward_minimum(values, count):
    """The minimum of ``values[j : j + count]`` for each ``j`` with a full window (the
    van Herk-Gil-Werman method: linear in the number of values, whatever ``count``)."""
    size = values.size - count + 1
    if size <= 0:
        return np.empty(0)
    padded = np.concatenate([values, np.full(-values.size % count, np.inf)]).reshape(-1, count)
    prefix = np.minimum.accumulate(padded, axis=1).ravel()
    suffix = np.minimum.accumulate(padded[:, ::-1], axis=1)[:, ::-1].ravel()
    return np.minimum(suffix[:size], prefix[count - 1 : count - 1 + size])


def _crest(x, r, index, drop):
    """Position of the crest of a ridge whose highest sample is ``index``: the vertex of the
    least-squares parabola through the samples around it within ``drop`` of its height (the
    cap, the stretch where the noise could hide the top), clipped to the cap; the sample
    itself when the cap has fewer than 3 samples. [m]"""
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
    """The inner foot of the band's pile-up ridge on one side and the index of its crest.

    Inwards from the band's outermost sample ``end``: the first crest higher than
    ``threshold`` above the line is a pile-up ridge; down its inner flank, its foot is where
    the flank stops falling: the lowest sample before it first rises by ``threshold`` again
    (debris, roughness), unless it stays level first: then the first sample after which it
    falls by no more than ``threshold`` over ``level`` samples (a floor, at the line or
    above it, whatever the ridge's shape). The foot is None where the groove's wall runs up
    into the ridge: its flank falls, to within ``threshold``, all the way to the groove's
    edge sample ``outer``. Without a ridge: the position of ``end`` (None if it is
    ``outer``) and no crest (None)."""
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
    """The :class:`_Ridge` around the highest sample above ``threshold`` beyond the groove's
    edge sample ``outer`` in direction ``step`` and within ``reach`` of ``centre``, or None.
    The ridge itself is left out of ``rest``: its disturbed stretch, running on while the
    samples above ``threshold`` are less than ``gap`` apart (its flanks, broken by noise),
    and its flanks beyond, down to the line."""
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


def _narrow_pair(ridges, heights, threshold) -> bool:
    """Whether two outstanding runs, not both as wide as the band's longest quiet stretch,
    are a pair of narrow pile-up ridges rather than two asperities: each
    :data:`_NARROW_SAMPLES` samples wide or more and higher than :data:`_NARROW_HEIGHT`
    times ``threshold``, the two alike (heights and widths within a ratio of
    :data:`_NARROW_ALIKE`) and mirror images about the groove's centre (their crests'
    distances from it differ by less than :data:`_NARROW_MIRROR` times their widths' sum).
    """
    widths = [ridge.width for ridge in ridges]
    distances = [ridge.distance for ridge in ridges]
    return (
        all(ridge.run[1] - ridge.run[0] + 1 >= _NARROW_SAMPLES for ridge in ridges)
        and min(heights) > _NARROW_HEIGHT * threshold
        and max(heights) < _NARROW_ALIKE * min(heights)
        and max(widths) < _NARROW_ALIKE * min(widths)
        and abs(distances[1] - distances[0]) < _NARROW_MIRROR * (widths[0] + widths[1])
    )


def _paired_ridges(x, r, sides, centre, threshold, gap):
    """The outer ends (indices) of the disturbed runs around the highest samples above the
    line beyond the groove's edge samples ``sides`` (left, right) and within
    :data:`_RIDGE_REACH` groove half-widths of its ``centre``, if they are a pair of
    pile-up ridges, however quiet the floor between them and the groove; None if not.

    Each must be the outstanding feature of its side of the trace: all else beyond the
    groove there lower than :data:`_RIDGE_PROMINENCE` times its height. Then either both
    stand higher than ``threshold`` over at least ``gap`` and lie at distances from the
    centre within a ratio of :data:`_RIDGE_PAIR`, or they are a pair of narrow ridges
    (:func:`_narrow_pair`)."""
    reach = max(_RIDGE_REACH * 0.5 * (x[sides[1]] - x[sides[0]]), _RIDGE_SPAN * (x[-1] - x[0]))
    ridges = [_highest_run(x, r, outer, step, centre, reach, threshold, gap)
              for outer, step in zip(sides, (-1, +1), strict=True)]  # fmt: skip
    if None in ridges:
        return None
    heights = [float(r[ridge.crest]) for ridge in ridges]
    if any(ridge.rest >= _RIDGE_PROMINENCE * h for ridge, h in zip(ridges, heights, strict=True)):
        return None
    distances = [ridge.distance for ridge in ridges]
    if all(ridge.width >= gap for ridge in ridges):
        paired = max(distances) <= _RIDGE_PAIR * min(distances)
    else:
        paired = _narrow_pair(ridges, heights, threshold)
    if not paired:
        return None
    return [_band_end(x, r, ridge.crest, step, threshold, gap)
            for ridge, step in zip(ridges, (-1, +1), strict=True)]  # fmt: skip


def _shoulders(x, centre, half_width, band, quiet):
    """Samples of the unworn surface (see the module docstring), or None if too few.

    Beyond ``band`` (the disturbed band's outer ends) and the half-widths of
    :data:`_SHOULDER_FACTORS`, without the ``quiet=False`` samples (debris) if enough stay.
    """
    for outside in (band, (np.inf, -np.inf)):
        for factor in _SHOULDER_FACTORS:
            left = x < min(centre - factor * half_width, outside[0])
            right = x > max(centre + factor * half_width, outside[1])
            for keep in (quiet, True):
                if (left & keep).sum() >= _MIN_SHOULDER and (right & keep).sum() >= _MIN_SHOULDER:
                    return (left | right) & keep
    return None


class _Extent(NamedTuple):
    """What :func:`_scar_extent` found (see there)."""

    line: object
    tilt: float
    centre: float
    width: float
    residual: np.ndarray
    groove: tuple
    band: tuple
    wide: bool
    ridges: tuple
    rough_groove: tuple | None


def _edges(x, r, deepest, depth, noise, reach):
    """The groove's edges, the band's edges (the groove's where it has none beyond, else the
    crest of its pile-up ridge, else its outermost sample), the ridges' crests (indices or
    None), the band's outer ends (positions), the band's threshold, and on a rough surface
    the groove's edges read within 3 times the noise of the line (else None) (module
    docstring); ValueError if the groove reaches an end of the trace."""
    tolerance = max(_LINE_TOLERANCE * depth, min(_LINE_NOISE * noise, _LINE_SHARE * depth))
    left = _crossing(x, r, deepest, -1, tolerance, reach)
    right = _crossing(x, r, deepest + 1, +1, tolerance, reach)
    rough = None
    if _LINE_NOISE * noise > tolerance:  # the roughness dips below the tolerance
        rough = [_crossing(x, r, deepest + (step > 0), step, _LINE_NOISE * noise, reach)
                 for step in (-1, +1)]  # fmt: skip
        rough = None if None in rough else (rough[0][0], rough[1][0])
    if left is None or right is None:
        side = "left" if left is None else "right"
        raise ValueError(
            f"x: the scar reaches the {side} end of the trace (no unworn surface beside "
            "it): the trace must extend beyond both edges of the scar"
        )
    threshold = max(_NOISE_FACTOR * noise, _BAND_FLOOR * depth)
    gap = max(_BAND_GAP_WIDTH * 0.5 * (right[0] - left[0]), _BAND_GAP * np.median(np.diff(x)))
    ends = [_band_end(x, r, side[1], step, threshold, gap)
            for side, step in ((left, -1), (right, +1))]  # fmt: skip
    paired = _paired_ridges(x, r, (left[1], right[1]), 0.5 * (left[0] + right[0]), threshold,
                            gap)  # fmt: skip
    if paired is not None:  # the ridges beyond a quiet floor, unless the band reaches farther
        ends = [min(ends[0], paired[0]), max(ends[1], paired[1])]
    level = max(int(np.ceil(gap / np.median(np.diff(x)))), 1)
    found = [_band_edge(x, r, side[1], end, step, threshold, level)
             for side, end, step in ((left, ends[0], -1), (right, ends[1], +1))]  # fmt: skip
    groove = (left[0], right[0])
    near = AMBIGUOUS_EDGES * 0.5 * (groove[1] - groove[0])
    # The track lies between the ridges: the band reaches their crests, where the counterbody
    # sliding up their inner flanks stopped; the groove's edge where the ridge's foot is not
    # beyond it (its wall runs up into the ridge).
    band = tuple(
        groove[i] if foot is None or abs(foot - groove[i]) <= near
        else (foot if crest is None else _crest(x, r, crest, threshold))
        for i, (foot, crest) in enumerate(found)
    )  # fmt: skip
    outer = (min(float(x[ends[0]]), band[0]), max(float(x[ends[1]]), band[1]))
    return groove, band, tuple(crest for _, crest in found), outer, threshold, rough


def _micrometres(length) -> str:
    """``length`` [m] for people: in µm, to 4 significant digits.

    >>> _micrometres(0.00022683321311402322)
    '226.8 µm'
    """
    return f"{float(length) * 1e6 + 0.0:.4g} µm"  # + 0.0: no "-0 µm"


def _too_short_message(x, centre, width, given: bool) -> str:
    """Why the trace ``x`` [m] leaves too little unworn surface beside a scar at ``centre``
    [m] of half-width ``width`` [m] (``given`` by the caller, or detected), and the remedies."""
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


def _scar_extent(x, zs, half_width, reach=0) -> _Extent:
    """Reference line, centre, half-width, residual, groove and band edges and ridges of
    the scar in smoothed heights ``zs``."""
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
    band = band if any(apart) else groove
    return _Extent(line, tilt, centre, width, r, groove, band, wide, ridges, rough)


def _ambiguity(x, extent: _Extent, given: bool):
    """The warning of ambiguous edges (None if the band is the groove or a width was given),
    and the half-width not taken. [m]"""
    if extent.band == extent.groove or given:
        return None, np.nan
    r = extent.residual
    apart = [b != g for b, g in zip(extent.band, extent.groove, strict=True)]
    ridged = [crest is not None and far for crest, far in zip(extent.ridges, apart, strict=True)]
    what = "the band between its pile-up ridges' crests" if all(ridged) else "the disturbed band"
    if not all(apart):
        what = f"the groove and the disturbed band on its {'right' if apart[1] else 'left'}"
    marks = [f" (a crest {r[crest] * 1e6:.3g} µm high)" if ridge else ""
             for crest, ridge in zip(extent.ridges, ridged, strict=True)]  # fmt: skip

    def candidate(edges, words, taken, notes=("", "")):
        width = 0.5 * (edges[1] - edges[0])
        where = (
            f"edges at x = {edges[0] * 1e6:.6g} µm{notes[0]} and {edges[1] * 1e6:.6g} µm{notes[1]}"
        )
        return width, f"{width * 1e6:.6g} µm for {words} ({'returned; ' if taken else ''}{where})"

    band = candidate(extent.band, what, extent.wide, marks)
    groove = candidate(extent.groove, "the groove below the unworn surface's line",
                       not extent.wide)  # fmt: skip
    first, second = (band, groove) if extent.wide else (groove, band)
    summary = (
        f"ambiguous scar edges: half-width {first[1]} or {second[1]}: which the model needs "
        "is a judgement"
    )
    name = "groove" if extent.wide else "band"
    finding = ScarProfileWarning(summary, alternative=second[0], alternative_name=name)
    return finding, second[0]


def _uncertainty(extent: _Extent, given: bool):
    """The warning of uncertain groove edges on a rough surface (None if they are certain,
    the band was returned or a width was given), and the other half-width. [m]"""
    groove, other = extent.groove, extent.rough_groove
    if given or extent.wide or other is None:
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


def _checked(x, z, half_width, smoothing):
    """The trace and parameters as float64, checked (see :func:`scar_profile`)."""
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
    return x, z, half_width, smoothing


def scar_profile_and_findings(x, z, half_width=None, smoothing=None, level=False,
                              remove_outliers=True):  # fmt: skip
    """:func:`scar_profile` and its warnings, not issued: ``(profile, findings)``.

    Parameters and Raises are those of :func:`scar_profile`.

    Returns
    -------
    profile : ScarProfile
    findings : list of ScarProfileWarning
        Outliers replaced (with their sample indices), ambiguous or uncertain edges.
    """
    x, z, half_width, smoothing = _checked(x, z, half_width, smoothing)
    findings = []
    replaced = np.zeros(x.size, dtype=bool)
    if remove_outliers:
        z, replaced, finding = _without_outliers(x, z)
        findings += [finding] if finding is not None else []
    spacing = float(np.median(np.diff(x)))
    # The edges are found on lightly smoothed heights (a kink at an edge would move under
    # heavier smoothing); the slopes are smoothed over 2 % of the half-width by default.
    light = 0.0 if smoothing == 0.0 else _EDGE_SMOOTHING * spacing
    zs, _ = local_quadratic(x, z, light)
    reach = int(np.ceil(_REACH * light / spacing))
    extent = _scar_extent(x, zs, half_width, reach)
    line, tilt, centre, width, r = extent[:5]
    finding, alternative = _ambiguity(x, extent, half_width is not None)
    if finding is None:
        finding, alternative = _uncertainty(extent, half_width is not None)
    findings += [finding] if finding is not None else []
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
    profile = scar_profile_from_parts(
        x - centre, height, slope, depth, width, worn, centre, *reference, alternative,
        replaced.astype(np.float64),
    )  # fmt: skip
    return profile, findings


@si_units(x="length", z="length", half_width="length")
def scar_profile(x, z, half_width=None, smoothing=None, level=False,
                 remove_outliers=True) -> ScarProfile:  # fmt: skip
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
    remove_outliers : bool
        Replace outliers (spikes, dropouts: :func:`outlying_samples`) by linear
        interpolation between the nearest samples kept, before anything else (on by
        default; ``replaced`` marks them).

    Returns
    -------
    profile : ScarProfile
        Positions relative to the detected centre, the heights (levelled if asked), the
        smoothed slopes, and the depth, half-width, worn area, centre and reference line;
        the other plausible half-width if the edges were ambiguous, and the samples
        replaced.

    Warns
    -----
    ScarProfileWarning
        For outliers replaced (their count, sample indices and positions), and for
        ambiguous edges: a band between the crests of pile-up ridges (or a disturbed band)
        wider than the groove below the unworn surface's line by more than
        :data:`AMBIGUOUS_EDGES` on a side; the band is returned if on both sides, else the
        groove, and the message gives both half-widths, which one was returned and the
        ``half_width=`` that takes the other.

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
    profile, findings = scar_profile_and_findings(
        x, z, half_width=half_width, smoothing=smoothing, level=level,
        remove_outliers=remove_outliers,
    )  # fmt: skip
    for finding in findings:
        warn(finding, ScarProfileWarning)
    return profile
