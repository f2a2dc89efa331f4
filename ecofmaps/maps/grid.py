r"""The model over whole grids, as labelled xarray Datasets: one value or one 1-D array per
parameter (a scalar coordinate or a dimension), :math:`x_o = \Delta^*` as in the paper. The
method: docs/model.md; tiles, blocks and the cache: docs/performance.md."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import xarray as xr

from ecofmaps import model
from ecofmaps._inputs import float64
from ecofmaps.maps.cache import cached_dataset
from ecofmaps.maps.dataset import checked_axes, checked_load, grid_dataset, map_dataset
from ecofmaps.maps.tiles import MAX_CHUNK, check_max_chunk, grid_values
from ecofmaps.model.on_profile import as_profile, check_mapping, steady_numbers, steady_values
from ecofmaps.model.simulation import fretting_loop
from ecofmaps.model.steady_state import dimensionless

_MODEL_ON_PROFILE = (
    "compliant wear-scar interaction model on a measured or modelled scar profile: a rigid "
    "round-ended pad with Coulomb friction feels the profile's slope g(X) (eq. 9 pointwise), "
    "driven through a spring of stiffness S (the rig); steady loops of displacement amplitude "
    "Delta* by first passage of the quasi-static return map"
)


def _steady_state(mu, kappa, lam, amplitude=None, load=None) -> dict:
    """The steady-loop quantities of the core numbers, by variable name (eq. 1, 9, 12, 16)."""
    values = {
        "slip_ratio": model.slip_ratio(mu, kappa, lam),
        "ecof_ratio": model.ecof_ratio(mu, kappa, lam),
        "regime": model.regime_code(mu, kappa, lam),
    }
    if amplitude is not None:
        values["slip_amplitude"] = amplitude * values["slip_ratio"]
        values["ecof"] = mu * values["ecof_ratio"]
    if load is not None:
        values["dissipated_energy"] = load * amplitude * model.normalized_energy(mu, kappa, lam)
        values["max_force"] = load * model.normalized_max_force(mu, kappa, lam)
    return values


def _broadcast(values: dict, axes) -> dict:
    shape = jnp.broadcast_shapes(*(axis.shape for axis in axes))
    return {name: jnp.broadcast_to(value, shape) for name, value in values.items()}


@jax.jit
def _map_kernel(stiffness_ratio, aspect_ratio, amplitude, mu, load):
    axes = jnp.ix_(stiffness_ratio, aspect_ratio, amplitude, mu)
    stiffness_ratio, aspect_ratio, amplitude, mu = axes
    kappa = model.curvature_number(1.0, aspect_ratio, 1.0)  # x_o = Δ*: κ = 2 z_o/x_o
    lam = model.compliance_ratio(amplitude, 1.0, stiffness_ratio)  # 1/((S/P) Δ*)
    return _broadcast(_steady_state(mu, kappa, lam, amplitude, load), axes)


@jax.jit
def _universal_kernel(compliance_ratio, aspect_ratio, mu):
    axes = jnp.ix_(compliance_ratio, aspect_ratio, mu)
    lam, aspect_ratio, mu = axes
    kappa = model.curvature_number(1.0, aspect_ratio, 1.0)
    return _broadcast(_steady_state(mu, kappa, lam), axes)


def _cached(function: str, inputs: dict, compute, cache, chunks, cache_dir) -> xr.Dataset:
    """``compute()``, through the disk cache if ``cache`` (refused for a chunked map)."""
    if cache not in (None, True, False):
        raise ValueError(f"cache must be True, False or None, got {cache!r}")
    if cache and chunks is not None:
        raise ValueError(
            "cache=True with chunks: a chunked map is not cached (it is evaluated block by "
            "block where it is written); leave cache out"
        )
    return cached_dataset(function, inputs, compute, cache_dir) if cache else compute()


@float64
def compute_map(
    stiffness_ratio,
    aspect_ratio=None,
    amplitude=None,
    mu=None,
    load=None,
    *,
    chunks=None,
    profile=None,
    mapping="scaled",
    cache=None,
    cache_dir=None,
    max_chunk=MAX_CHUNK,
) -> xr.Dataset:
    r"""The steady-loop quantities of the model over a grid of test conditions.

    Parameters
    ----------
    stiffness_ratio : float or 1-D array_like
        Rig stiffness over normal load :math:`S/P`; ``numpy.inf`` for a rigid rig. [1/m]
    aspect_ratio : float or 1-D array_like
        Groove depth over half-width :math:`z_o/x_o`, >= 0. [1]
    amplitude : float or 1-D array_like
        Displacement amplitude :math:`\Delta^*` (also the groove half-width :math:`x_o`). [m]
    mu : float or 1-D array_like
        Contact coefficient of friction :math:`\mu`. [1]
    load : float, optional
        Normal load :math:`P`: adds ``dissipated_energy``, ``max_force`` and a coordinate. [N]
    chunks : 'auto', int or dict, optional
        Return a chunked map of dask arrays, evaluated block by block when computed or
        written (:func:`ecofmaps.maps.write_map`): an int is the most grid points in a
        block, ``'auto'`` :data:`ecofmaps.maps.tiles.BLOCK_POINTS`, a dict the block
        length by dimension name (-1 or None, or not named: whole). Default: in memory.
    profile : ScarProfile, optional
        A scar profile instead of ``aspect_ratio``: see :func:`compute_profile_map`.
    mapping : {'scaled', 'physical'}
        With a profile: :math:`X = xW/\Delta^*` (eq. 11) or :math:`X = x`.
    cache : bool, optional
        Use the disk cache (default: only on a profile; never chunked); an unusable file is
        removed with a :class:`~ecofmaps.maps.cache.CacheWarning` and the map recomputed.
    cache_dir : str or os.PathLike, optional
        Cache directory; default ``$ECOFMAPS_CACHE`` or the per-user cache directory.
    max_chunk : int
        Most grid points in one call of the compiled kernel (a tile, one core each). [1]

    Returns
    -------
    map : xarray.Dataset
        Dimensions ``stiffness_ratio``, ``aspect_ratio``, ``amplitude``, ``mu`` (those given
        as arrays, in order); variables with ``long_name`` and ``units``: ``slip_amplitude``
        [m] (eq. 16), ``slip_ratio`` [1], ``ecof`` [1] (eq. 13-15), ``ecof_ratio`` [1],
        ``regime`` (:class:`ecofmaps.Regime`), ``compliance_ratio`` [1] (over S/P and
        amplitude), with a load ``dissipated_energy`` [J] (eq. 12) and ``max_force`` [N]
        (eq. 9). ECoFs are NaN without gross slip, all but the regime when self-locking.
        Computed, a chunked map equals the map in memory; a single tile's arrays are read-only.

    Raises
    ------
    ValueError
        For a parameter not a scalar or non-empty 1-D array, or out of range (stiffness_ratio
        > 0, inf allowed; aspect_ratio >= 0; amplitude, mu, load > 0; within
        :data:`ecofmaps.units.DOMAIN`); a bad ``chunks``; ``cache=True`` with ``chunks``; a
        map in memory that would not fit in the memory available.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 1, 9, 11, 12, 13-15, 16.

    Examples
    --------
    >>> import numpy as np
    >>> m = compute_map(np.geomspace(2e4, 2e5, 5), np.linspace(0, 0.3, 4), 50e-6, 0.8,
    ...                 chunks={"stiffness_ratio": 2})
    >>> m.ecof_ratio.chunks
    ((2, 2, 1), (4,))
    """
    if profile is not None or aspect_ratio is None:
        if aspect_ratio is not None:
            raise ValueError("give aspect_ratio or profile, not both")
        if chunks is not None:
            raise ValueError(
                "chunks is for maps of the parabolic groove; a map on a profile "
                "is computed in memory"
            )
        options = dict(mapping=mapping, cache=cache is not False, cache_dir=cache_dir)
        return compute_profile_map(
            stiffness_ratio, amplitude, mu, load, profile=profile, max_chunk=max_chunk, **options
        )
    if mapping != "scaled":
        raise ValueError("mapping applies to a profile only (profile=...)")
    if amplitude is None or mu is None:
        raise ValueError("compute_map needs amplitude and mu")
    axes = checked_axes(
        stiffness_ratio=stiffness_ratio, aspect_ratio=aspect_ratio, amplitude=amplitude, mu=mu
    )
    load = checked_load(load)

    def compute() -> xr.Dataset:
        values = grid_values(_map_kernel, axes, (load,), max_chunk, chunks)
        return map_dataset(axes, values, load, "ECoF map of the compliant wear-scar model")

    return _cached("compute_map", {**axes, "load": load}, compute, cache, chunks, cache_dir)


@float64
def compute_universal_map(
    compliance_ratio,
    aspect_ratio,
    mu,
    *,
    chunks=None,
    cache=None,
    cache_dir=None,
    max_chunk=MAX_CHUNK,
) -> xr.Dataset:
    r"""The dimensionless map: :math:`\mu_E/\mu` and :math:`\delta^*/\Delta^*` over :math:`\lambda`,
    which holds both panels of Figure 11 (docs/model.md, "The dimensionless core").

    Parameters
    ----------
    compliance_ratio : float or 1-D array_like
        :math:`\lambda = P/(S\Delta^*)`, >= 0 (0 for a rigid rig). [1]
    aspect_ratio, mu, chunks, cache, cache_dir, max_chunk
        As for :func:`compute_map`.

    Returns
    -------
    map : xarray.Dataset
        Dimensions ``compliance_ratio``, ``aspect_ratio``, ``mu`` (those given as arrays).
        Variables ``ecof_ratio`` [1], ``slip_ratio`` [1], ``regime``.

    Raises
    ------
    ValueError
        As for :func:`compute_map`.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 13-16.
    """
    axes = checked_axes(compliance_ratio=compliance_ratio, aspect_ratio=aspect_ratio, mu=mu)

    def compute() -> xr.Dataset:
        values = grid_values(_universal_kernel, axes, (), max_chunk, chunks)
        return grid_dataset(axes, values, "Universal ECoF map of the compliant wear-scar model")

    return _cached("compute_universal_map", axes, compute, cache, chunks, cache_dir)


@jax.jit
def _loop_kernel(stiffness, aspect_ratio, amplitude, load, mu):
    mu, kappa, lam, code = dimensionless(amplitude, load, stiffness, mu, aspect_ratio, amplitude)
    values = _steady_state(mu, kappa, lam, amplitude, load)
    values = {n: values[n] for n in ("slip_amplitude", "max_force", "dissipated_energy")}
    values["regime"] = code
    return values


@float64
def compute_loops(stiffness, aspect_ratio, amplitude, load, mu, num=201) -> xr.Dataset:
    r"""Steady fretting loops over a grid of test conditions (Figures 5 and 6).

    Parameters
    ----------
    stiffness : float or 1-D array_like
        Rig stiffness :math:`S`; ``numpy.inf`` for a rigid rig. [N/m]
    aspect_ratio, amplitude, mu
        As for :func:`compute_map`. [1], [m], [1]
    load : float or 1-D array_like
        Normal load :math:`P`. [N]
    num : int
        Points on each slip branch (>= 2); each loop has ``2 * num + 1`` points. [1]

    Returns
    -------
    loops : xarray.Dataset
        Dimensions: the parameters given as arrays (in order), then ``point``. Variables
        ``displacement`` [m] and ``force`` [N] around each loop (as
        :func:`ecofmaps.fretting_loop`: eq. 9-10), and per loop ``slip_amplitude`` [m]
        (eq. 16), ``max_force`` [N], ``dissipated_energy`` [J] (eq. 12) and ``regime``.
        Self-locking loops are NaN.

    Raises
    ------
    ValueError
        As for :func:`compute_map` (stiffness > 0, inf allowed), or ``num < 2``.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 10, 12, 16.
    """
    axes = checked_axes(
        stiffness=stiffness, aspect_ratio=aspect_ratio, amplitude=amplitude, load=load, mu=mu
    )
    grid = jnp.broadcast_arrays(*jnp.ix_(*(np.atleast_1d(a) for a in axes.values())))
    values = jax.device_get(_loop_kernel(*grid))
    values["displacement"], values["force"] = fretting_loop(
        grid[2], grid[3], grid[0], grid[4], grid[1], num=num
    )
    values = {name: np.asarray(value) for name, value in values.items()}
    return grid_dataset(axes, values, "Steady fretting loops", {"point": np.arange(2 * num + 1)})


@float64
def compute_profile_map(
    stiffness_ratio,
    amplitude,
    mu,
    load=None,
    *,
    profile,
    mapping="scaled",
    cache=True,
    cache_dir=None,
    max_chunk=MAX_CHUNK,
) -> xr.Dataset:
    r"""The steady-loop quantities on a scar profile over a grid of test conditions.

    Parameters
    ----------
    stiffness_ratio, amplitude, mu, load
        As for :func:`compute_map`. [1/m], [m], [1], [N]
    profile : ScarProfile
        The scar (:func:`ecofmaps.scar_profile`, :func:`ecofmaps.read_scar_profile`, ...).
    mapping, cache, cache_dir, max_chunk
        As for :func:`compute_map` (the cache key holds every array of the profile).

    Returns
    -------
    map : xarray.Dataset
        As :func:`compute_map` (no ``aspect_ratio``), with the profile's depth, half-width,
        aspect ratio, sample count and the mapping as global attributes. Points where the
        pad slips off the trace have the regime ``BEYOND_PROFILE`` and NaN values.

    Raises
    ------
    ValueError
        As for :func:`compute_map`, and for a missing or bad profile or mapping.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 11, 16.

    Examples
    --------
    >>> import numpy as np, ecofmaps
    >>> p = ecofmaps.flat_bottomed_profile(10e-6, 50e-6)
    >>> m = ecofmaps.compute_map(np.geomspace(2e4, 2e5, 5), amplitude=50e-6, mu=0.8, profile=p)
    >>> m.ecof_ratio.dims
    ('stiffness_ratio',)
    """
    if profile is None:
        raise ValueError("compute_map needs aspect_ratio or profile")
    if amplitude is None or mu is None:
        raise ValueError("compute_map needs amplitude and mu")
    physical = check_mapping(mapping, None)
    profile = as_profile(profile)
    axes = checked_axes(stiffness_ratio=stiffness_ratio, amplitude=amplitude, mu=mu)
    load = checked_load(load)
    check_max_chunk(max_chunk)

    def compute() -> xr.Dataset:
        grid = [np.atleast_1d(a) for a in axes.values()]
        points = [axis.ravel() for axis in np.meshgrid(*grid, indexing="ij")]
        # λ = P/(S Δ*) = 1/((S/P) Δ*): a unit load and the stiffness ratio
        bounds = range(max_chunk, points[0].size, max_chunk)
        pieces = zip(*(np.split(p, bounds) for p in points), strict=True)
        tiles = [steady_numbers(profile, a, 1.0, s, m, mapping=mapping) for s, a, m in pieces]
        shape = tuple(axis.size for axis in grid)
        names = ("slip_ratio", "ecof_ratio", "regime", "normalized_energy", "normalized_max_force")
        values = {n: np.concatenate([t[n] for t in tiles]).reshape(shape) for n in names}
        values.update(steady_values(values, grid[1][None, :, None], load, grid[2][None, None, :]))
        del values["normalized_energy"], values["normalized_max_force"]
        title = "ECoF map of the compliant wear-scar model on a scar profile"
        return map_dataset(axes, values, load, title).assign_attrs(
            model=_MODEL_ON_PROFILE,
            scar_depth=float(profile.depth),
            scar_half_width=float(profile.half_width),
            scar_aspect_ratio=float(profile.aspect_ratio),
            scar_samples=int(profile.position.shape[-1]),
            mapping=mapping,
        )

    inputs = {**axes, "load": load, "mapping": float(physical)}
    inputs.update({f"profile_{name}": value for name, value in profile._asdict().items()})
    return _cached("compute_profile_map", inputs, compute, cache, None, cache_dir)
