"""The correction of a reported ECoF read off a map of :func:`ecofmaps.compute_map`, in NumPy
and SciPy: docs/model.md, "Correcting a reported ECoF"."""

from __future__ import annotations

import numpy as np

from ecofmaps._codes import warn_nan
from ecofmaps._inputs import si_units
from ecofmaps.correction.inversion import groove_aspect_ratio
from ecofmaps.correction.outcomes import CorrectionStatus, check_test


def _map_axes(ecof_map):
    """The map's grid axes as ``(name, sorted values, order)`` and its fixed coordinates."""
    axes, fixed = [], {}
    for name in ("stiffness_ratio", "aspect_ratio", "amplitude"):
        if name in ecof_map.dims and ecof_map.sizes[name] > 1:
            values = np.asarray(ecof_map[name], dtype=np.float64)
            if name == "stiffness_ratio":
                values = 1.0 / values  # interpolate in P/S: finite for a rigid rig
            order = np.argsort(values)
            if np.any(np.diff(values[order]) <= 0.0):
                raise ValueError(f"the map's {name} coordinate has repeated values")
            axes.append((name, values[order], order))
        elif name in ecof_map.coords:
            fixed[name] = float(np.asarray(ecof_map[name], dtype=np.float64).reshape(-1)[0])
        else:
            raise ValueError(f"map_dataset has no {name!r} coordinate (from compute_map)")
    return axes, fixed


def _crossing(curves, mu_grid, ecof):
    """Invert each curve ``ecof(mu)`` by linear interpolation; count its crossings."""
    above, finite = curves > ecof[:, None], np.isfinite(curves)
    crossing = finite[:, :-1] & finite[:, 1:] & (above[:, :-1] != above[:, 1:])
    count = crossing.sum(axis=1)
    index = np.argmax(crossing, axis=1)
    c0, c1 = np.take_along_axis(curves, index[:, None] + np.arange(2), axis=1).T
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = (ecof - c0) / (c1 - c0)
    mu = mu_grid[index] + fraction * (mu_grid[index + 1] - mu_grid[index])
    return mu, count


@si_units
def lookup_correction(
    map_dataset,
    ecof,
    amplitude,
    load,
    stiffness,
    aspect_ratio=None,
    scar_depth=None,
    scar_half_width=None,
    *,
    return_status=False,
):
    r"""The contact CoF behind a reported ECoF, read off a map by interpolation: the correction
    of :func:`correct_ecof` up to its error (docs/model.md, "Correcting a reported ECoF").

    Parameters
    ----------
    map_dataset : xarray.Dataset
        A map of :func:`ecofmaps.compute_map` with ``ecof`` over at least two values of
        ``mu``; ``stiffness_ratio``, ``aspect_ratio``, ``amplitude`` as dimensions or scalars.
    ecof, amplitude, load, stiffness, aspect_ratio, scar_depth, scar_half_width, return_status
        As for :func:`correct_ecof` (no interval). [1], [m], [N], [N/m], [1], [m], [m]

    Returns
    -------
    mu : numpy.ndarray of float64
        The contact CoF; NaN where it cannot be read off the map (for an array without
        ``return_status``, with a :class:`~ecofmaps.RegimeWarning`). [1]
    status : numpy.ndarray of int32
        Only with ``return_status=True``: :class:`CorrectionStatus` codes; ``OUTSIDE_MAP`` off
        the map's grid (a scalar coordinate: by more than 1e-9 relative) or :math:`\mu`
        range, ``AMBIGUOUS`` where the interpolated curve crosses the ECoF more than once.

    Raises
    ------
    ValueError
        As for :func:`correct_ecof`, and for a map without the coordinates above.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 13-15, 16.
    """
    from scipy.interpolate import RegularGridInterpolator

    if isinstance(aspect_ratio, tuple):
        raise ValueError("lookup_correction takes no aspect_ratio interval; use correct_ecof")
    check_test(ecof, amplitude, load, stiffness)
    ratio = np.asarray(groove_aspect_ratio(aspect_ratio, scar_depth, scar_half_width))
    ecof, amplitude, load, stiffness, ratio = np.broadcast_arrays(
        *(np.asarray(v, dtype=np.float64) for v in (ecof, amplitude, load, stiffness)), ratio
    )
    if "ecof" not in map_dataset or "mu" not in map_dataset["ecof"].dims:
        raise ValueError("map_dataset must hold the variable 'ecof' over a 'mu' dimension")
    ecof_map = map_dataset["ecof"]
    if ecof_map.sizes["mu"] < 2:
        raise ValueError("map_dataset's 'mu' dimension must have at least 2 values")
    axes, fixed = _map_axes(ecof_map)
    query = {"stiffness_ratio": stiffness / load, "aspect_ratio": ratio, "amplitude": amplitude}
    query = {name: value.ravel() for name, value in query.items()}
    inside = np.ones(ecof.size, dtype=bool)
    for name, value in fixed.items():  # inf (a rigid rig) is close to itself only
        inside &= np.isclose(query[name], value, rtol=1e-9, atol=0.0)
    points = []
    for name, values, _ in axes:
        coordinate = 1.0 / query[name] if name == "stiffness_ratio" else query[name]
        inside &= (coordinate >= values[0]) & (coordinate <= values[-1])
        points.append(np.clip(coordinate, values[0], values[-1]))
    mu_order = np.argsort(np.asarray(ecof_map["mu"], dtype=np.float64))
    ecof_map = ecof_map.isel({name: order for name, _, order in axes} | {"mu": mu_order})
    mu_grid = np.asarray(ecof_map["mu"], dtype=np.float64)
    names = [name for name, _, _ in axes]
    shape = [ecof_map.sizes[n] for n in names] + [mu_grid.size]
    table = ecof_map.transpose(*names, "mu", ...).values.reshape(shape).astype(np.float64)
    if axes:
        curves = RegularGridInterpolator([v for _, v, _ in axes], table)(np.stack(points, axis=-1))
    else:
        curves = np.broadcast_to(table, (ecof.size, mu_grid.size))
    mu, count = _crossing(curves, mu_grid, ecof.ravel())
    lam = load.ravel() / (stiffness.ravel() * amplitude.ravel())
    status = np.select(
        [ecof.ravel() * lam >= 1.0, ~inside | (count == 0), count > 1],
        [CorrectionStatus.NO_GROSS_SLIP, CorrectionStatus.OUTSIDE_MAP, CorrectionStatus.AMBIGUOUS],
        CorrectionStatus.CORRECTED,
    ).astype(np.int32)
    mu = np.where(status == CorrectionStatus.CORRECTED, mu, np.nan)
    mu, status = mu.reshape(ecof.shape), status.reshape(ecof.shape)
    if not return_status:
        if status.ndim == 0 and status != CorrectionStatus.CORRECTED:
            reason = CorrectionStatus(int(status)).reason
            raise ValueError(f"ecof = {float(ecof):.6g} cannot be read off the map: {reason}")
        warn_nan(mu, status, CorrectionStatus, "lookup_correction")
    return (mu, status) if return_status else mu
