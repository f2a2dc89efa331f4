r"""Analytic families of wear-scar profiles, for studies of the groove's shape: each a
:class:`~ecofmaps.model.profiles.ScarProfile` of the exact heights and slopes of its shape,
sampled with every breakpoint among the samples, with an optional tilt.
"""

from __future__ import annotations

import numpy as np

from ecofmaps._inputs import si_units
from ecofmaps.model.profiles import MIN_SCAR_SAMPLES, ScarProfile, profile_of


def _above(name: str, value, bound=0.0, unit="") -> float:
    """``value`` as a float; ``ValueError`` unless it is finite and > ``bound``."""
    value = float(value)
    if not (np.isfinite(value) and value > bound):
        raise ValueError(f"{name} must be finite and > {bound:g}{unit}, got {value!r}")
    return value


def _fraction(name: str, value) -> float:
    value = float(value)
    if not (np.isfinite(value) and 0.0 <= value < 1.0):
        raise ValueError(f"{name} must satisfy 0.0 <= {name} < 1.0, got {value!r}")
    return value


def _grid(breakpoints, half_width, extent, samples: int, reach=1.0) -> np.ndarray:
    """``samples`` positions over ``extent`` half-widths (> ``reach``) about evenly spread, with
    0, the edges, each breakpoint and their mirrors."""
    extent = _above("extent", extent, reach, " (half-widths)")
    if not (isinstance(samples, int | np.integer) and samples >= 2 * MIN_SCAR_SAMPLES):
        raise ValueError(f"samples must be an integer >= {2 * MIN_SCAR_SAMPLES}, got {samples!r}")
    breakpoints = np.asarray([*breakpoints, half_width, extent * half_width], dtype=np.float64)
    breakpoints = np.unique(np.concatenate([-breakpoints, [0.0], breakpoints]))
    # Breakpoints closer than 1e-9 of the span (a flat bottom of nearly zero width) merge.
    tolerance = 1e-9 * (breakpoints[-1] - breakpoints[0])
    kept = [breakpoints[0]]
    for point in breakpoints[1:-1]:
        if point - kept[-1] > tolerance and breakpoints[-1] - point > tolerance:
            kept.append(point)
    breakpoints = np.array([*kept, breakpoints[-1]])
    lengths = np.diff(breakpoints)
    # Intervals per piece: at least 2 each, the rest by largest remainders of the share.
    share = 2 + (samples - 1 - 2 * lengths.size) * lengths / lengths.sum()
    counts = np.floor(share).astype(int)
    counts[np.argsort(counts - share)[: samples - 1 - counts.sum()]] += 1
    ends = zip(breakpoints[:-1], breakpoints[1:], counts, strict=True)
    pieces = [np.linspace(left, right, count + 1)[1:] for left, right, count in ends]
    return np.concatenate([breakpoints[:1], *pieces])


def _family(position, height, slope, depth, half_width, tilt):
    """A profile from the exact heights and slopes of a shape symmetric about X = 0."""
    tilt = float(tilt)
    if not np.isfinite(tilt):
        raise ValueError(f"tilt must be finite, got {tilt!r}")
    inside = np.abs(position) <= half_width
    worn = np.trapezoid(np.where(inside, -np.minimum(height, 0.0), 0.0), position)
    return profile_of(
        position, height + tilt * position, slope + tilt, depth, half_width, worn, 0.0, 0.0, tilt
    )


@si_units(depth="length", half_width="length")
def parabolic_profile(depth, half_width, *, tilt=0.0, samples=2001, extent=2.0) -> ScarProfile:
    r"""A parabolic scar, the paper's groove: :math:`z = -D(1 - (X/W)^2)` for :math:`|X| \le W`.

    Parameters
    ----------
    depth, half_width : float
        Scar depth :math:`D` and half-width :math:`W`. [m]
    tilt : float
        Slope added to the whole trace, :math:`z + tX` (a tilted specimen). [1]
    samples : int
        Number of samples, about evenly spaced, with samples at the edges. [1]
    extent : float
        The trace spans :math:`\pm\text{extent}\,W`, unworn outside the scar. [1]

    Returns
    -------
    profile : ScarProfile
        Slopes :math:`g = 2DX/W^2` (eq. 7, 11): on it the model reproduces the closed forms
        with ``aspect_ratio=D/W`` to rounding.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 7, 11.

    Examples
    --------
    >>> p = parabolic_profile(10e-6, 50e-6)
    >>> float(p.aspect_ratio)
    0.2
    """
    depth, half_width = _above("depth", depth), _above("half_width", half_width)
    x = _grid([], half_width, extent, samples)
    inside = np.abs(x) <= half_width
    u = x / half_width
    z = np.where(inside, -depth * (1.0 - u * u), 0.0)
    g = np.where(inside, 2.0 * depth * u / half_width, 0.0)
    return _family(x, z, g, depth, half_width, tilt)


@si_units(depth="length", half_width="length")
def flat_bottomed_profile(
    depth, half_width, flat_fraction=0.5, *, tilt=0.0, samples=2001, extent=2.0
) -> ScarProfile:
    r"""A flat-bottomed (U-shaped) scar: a flat bottom with parabolic walls.

    :math:`z = -D` for :math:`|X| \le a` and :math:`z = -D(1 - s^2)`,
    :math:`s = (|X| - a)/(W - a)`, for :math:`a < |X| \le W`, with :math:`a = fW`: the walls
    meet the bottom tangentially (continuous slope) and the unworn surface at the edges.

    Parameters
    ----------
    depth, half_width, tilt, samples, extent
        As for :func:`parabolic_profile`: :math:`D`, :math:`W` [m].
    flat_fraction : float
        :math:`f = a/W` in ``[0, 1)``: the flat bottom's half-width over the scar's
        (0 gives the parabola). [1]

    Returns
    -------
    profile : ScarProfile
    """
    depth, half_width = _above("depth", depth), _above("half_width", half_width)
    flat = _fraction("flat_fraction", flat_fraction) * half_width
    x = _grid([flat], half_width, extent, samples)
    s = np.clip((np.abs(x) - flat) / (half_width - flat), 0.0, None)
    inside = np.abs(x) <= half_width
    z = np.where(inside, -depth * (1.0 - s * s), 0.0)
    g = np.where(inside, 2.0 * depth * s * np.sign(x) / (half_width - flat), 0.0)
    return _family(x, z, g, depth, half_width, tilt)


@si_units(depth="length", half_width="length")
def w_shaped_profile(
    depth, half_width, hump=0.25, *, tilt=0.0, samples=2001, extent=2.0
) -> ScarProfile:
    r"""A W-shaped scar: two troughs with a hump between them (the less worn centre).

    The quartic :math:`z = D\left[(u^2 - m^2)^2/(1 - m^2)^2 - 1\right]`, :math:`u = X/W`,
    for :math:`|u| \le 1`: depth :math:`D` at the troughs :math:`u = \pm m`, zero at the
    edges, and the hump :math:`hD` above the troughs at the centre, with
    :math:`m^2 = \sqrt h/(1 + \sqrt h)`.

    Parameters
    ----------
    depth, half_width, tilt, samples, extent
        As for :func:`parabolic_profile`: :math:`D`, :math:`W` [m].
    hump : float
        :math:`h` in ``[0, 1)``: the hump's height above the troughs over the depth. [1]

    Returns
    -------
    profile : ScarProfile
    """
    depth, half_width = _above("depth", depth), _above("half_width", half_width)
    hump = _fraction("hump", hump)
    m2 = np.sqrt(hump) / (1.0 + np.sqrt(hump))
    trough = np.sqrt(m2) * half_width
    x = _grid([trough], half_width, extent, samples)
    u = x / half_width
    inside = np.abs(u) <= 1.0
    scale = depth / (1.0 - m2) ** 2
    z = np.where(inside, scale * (u * u - m2) ** 2 - depth, 0.0)
    g = np.where(inside, 4.0 * scale * u * (u * u - m2) / half_width, 0.0)
    return _family(x, z, g, depth, half_width, tilt)


@si_units(depth="length", half_width="length", ridge_height="length", ridge_width="length")
def ridged_profile(
    depth, half_width, ridge_height, ridge_width, *, tilt=0.0, samples=2001, extent=2.0
) -> ScarProfile:
    r"""A parabolic scar with ploughing ridges piled up beside its edges (Figure 1b).

    Inside the edges the parabola of :func:`parabolic_profile`; outside them a ridge
    :math:`z = H\sin^2(\pi v)`, :math:`v = (|X| - W)/w`, for :math:`0 \le v \le 1`, then the
    flat unworn surface. Where :math:`(1 + \mu^2) (P/S)` times the crest's slope rate
    :math:`2\pi^2 H/w^2` exceeds 1, the pad jumps across the crest (``docs/model.md``).

    Parameters
    ----------
    depth, half_width, tilt, samples, extent
        As for :func:`parabolic_profile`: :math:`D`, :math:`W` [m].
    ridge_height : float
        :math:`H` > 0. [m]
    ridge_width : float
        :math:`w` > 0, the ridge's width at its foot; :math:`W + w` must lie inside the
        trace (``extent``). [m]

    Returns
    -------
    profile : ScarProfile
    """
    depth, half_width = _above("depth", depth), _above("half_width", half_width)
    height = _above("ridge_height", ridge_height)
    width = _above("ridge_width", ridge_width)
    ridge = [half_width + 0.5 * width, half_width + width]
    x = _grid(ridge, half_width, extent, samples, 1.0 + width / half_width)
    u = x / half_width
    v = (np.abs(x) - half_width) / width
    inside = np.abs(u) <= 1.0
    ridge = (v > 0.0) & (v <= 1.0)
    z = np.where(
        inside, -depth * (1.0 - u * u), np.where(ridge, height * np.sin(np.pi * v) ** 2, 0.0)
    )
    ridge_slope = np.pi * height / width * np.sin(2.0 * np.pi * v) * np.sign(x)
    g = np.where(inside, 2.0 * depth * u / half_width, np.where(ridge, ridge_slope, 0.0))
    return _family(x, z, g, depth, half_width, tilt)
