r"""Parameter maps: the model over whole grids, as labelled xarray Datasets.

Each function takes one value or one 1-D array per parameter; the arrays become the
Dataset's dimensions (in the order of the arguments), the single values its scalar
coordinates. The grid is evaluated with the dimensionless core of :mod:`ecofmaps.model`
inside one ``jax.jit`` (broadcasting, float64, no Python loop over points), in regular
blocks of at most ``max_chunk`` points so that any grid that fits in memory as a result can
be computed. :func:`compute_map` and :func:`compute_universal_map` keep their results in the
disk cache (:mod:`ecofmaps.maps.cache`).

As in the paper, the groove half-width is the displacement amplitude, :math:`x_o = \Delta^*`,
so the curvature number is :math:`\kappa = 2 z_o/x_o` and the compliance ratio is
:math:`\lambda = P/(S\Delta^*)`.
"""

from __future__ import annotations

import itertools
import math

import jax
import jax.numpy as jnp
import numpy as np
import xarray as xr

from ecofmaps import model
from ecofmaps._inputs import check, float64
from ecofmaps.maps.cache import cached_dataset
from ecofmaps.model.simulation import fretting_loop
from ecofmaps.model.steady_state import dimensionless

__all__ = [
    "MAX_CHUNK",
    "compute_loops",
    "compute_map",
    "compute_profile_map",
    "compute_universal_map",
]

#: Default bound on the number of grid points evaluated in one block (results of about 870 MB).
MAX_CHUNK = 2**24

PAPER = (
    "X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent "
    "coefficient of friction from fretting loops exhibiting non-Coulomb frictional behaviour"
)
MODEL = (
    "compliant wear-scar interaction model: a rigid round-ended pad with Coulomb friction in a "
    "parabolic groove z = z_o (x/x_o)^2, driven through a spring of stiffness S (the rig); "
    "steady loops of displacement amplitude Delta*, groove half-width x_o = Delta*"
)

# Names, units (CF / UDUNITS spelling) and descriptions of every coordinate and variable.
_ATTRS = {
    "stiffness_ratio": ("rig stiffness over normal load S/P", "m-1"),
    "stiffness": ("rig stiffness S", "N m-1"),
    "aspect_ratio": ("groove depth over half-width z_o/x_o", "1"),
    "amplitude": ("displacement amplitude Δ*", "m"),
    "mu": ("contact coefficient of friction μ", "1"),
    "load": ("normal load P", "N"),
    "point": ("point along the loop (from the reversal at -Δ*)", "1"),
    "slip_amplitude": ("slip amplitude δ*", "m"),
    "slip_ratio": ("slip amplitude over displacement amplitude δ*/Δ*", "1"),
    "ecof": ("energy coefficient of friction μ_E", "1"),
    "ecof_ratio": ("energy CoF over contact CoF μ_E/μ", "1"),
    "compliance_ratio": ("compliance ratio λ = P/(S Δ*)", "1"),
    "regime": ("contact regime", "1"),
    "dissipated_energy": ("energy dissipated per cycle E_d", "J"),
    "max_force": ("peak tangential force Q*", "N"),
    "displacement": ("actuator displacement Δ", "m"),
    "force": ("tangential force Q", "N"),
}

_REGIME_ATTRS = {
    "flag_values": np.array([int(code) for code in model.Regime], dtype=np.int32),
    "flag_meanings": " ".join(code.name.lower() for code in model.Regime),
}


def _attrs(name: str) -> dict:
    long_name, units = _ATTRS[name]
    attrs = {"long_name": long_name, "units": units}
    if name == "regime":
        attrs.update(_REGIME_ATTRS)
    return attrs


def _global_attrs(title: str) -> dict:
    from ecofmaps import __version__

    return {
        "title": title,
        "model": MODEL,
        "references": PAPER,
        "source": f"ecofmaps {__version__}",
        "ecofmaps_version": __version__,
    }


def _axis(name: str, value, rule: str, unit: str) -> np.ndarray:
    """``value`` checked (``ValueError`` naming ``name``) as a float64 scalar or 1-D array."""
    check(name, value, rule, unit)
    array = np.asarray(value, dtype=np.float64)
    if array.ndim > 1:
        raise ValueError(f"{name} must be a single value or a 1-D array, got shape {array.shape}")
    if array.size == 0:
        raise ValueError(f"{name} must hold at least one value, got an empty array")
    return array


# ---------------------------------------------------------------------------------------
# Grid evaluation in regular blocks
# ---------------------------------------------------------------------------------------


def _mesh(*axes):
    """The 1-D ``axes`` reshaped to broadcast against each other, axis ``i`` along dim ``i``."""
    count = len(axes)
    return [
        jnp.reshape(axis, tuple(-1 if j == i else 1 for j in range(count)))
        for i, axis in enumerate(axes)
    ]


def _blocks(shape: tuple[int, ...], max_chunk: int):
    """Tile ``shape`` with blocks of at most ``max_chunk`` points, all of one block shape.

    The split axis ``k`` is the first one whose trailing axes hold at most ``max_chunk``
    points together; each block takes one index along the axes before ``k``, ``rows``
    consecutive indices along ``k`` and all of the axes after it.

    Yields
    ------
    starts : tuple of int
        The block's first index along each axis before and at ``k``.
    stops : tuple of int
        One past its last index along those axes (the last block along ``k`` is short).
    rows : int
        The block's length along ``k`` (the short last block is padded up to it).
    """
    k = next(i for i in range(len(shape)) if math.prod(shape[i + 1 :]) <= max_chunk)
    rows = min(shape[k], max(1, max_chunk // math.prod(shape[k + 1 :])))
    for outer in itertools.product(*(range(n) for n in shape[:k])):
        for start in range(0, shape[k], rows):
            stop = min(start + rows, shape[k])
            yield (*outer, start), (*(i + 1 for i in outer), stop), rows


def _evaluate_grid(kernel, axes, extra, max_chunk: int) -> dict[str, np.ndarray]:
    """Evaluate ``kernel(*block_axes, *extra)`` over the grid spanned by 1-D ``axes``.

    ``kernel`` is jit-compiled and returns a dict of arrays of the block's full shape. A
    grid of at most ``max_chunk`` points is one block, and its arrays are XLA's own buffers,
    read-only, without a copy (XLA spreads the work over the cores; a copy would not be).
    Otherwise all blocks have one shape (the last one along the split axis is padded by
    repeating its last value, and the padding is dropped), so the kernel compiles once, and
    they are copied into the result arrays.
    """
    if not (isinstance(max_chunk, int) and max_chunk >= 1):
        raise ValueError(f"max_chunk must be an integer >= 1, got {max_chunk!r}")
    shape = tuple(axis.size for axis in axes)
    if math.prod(shape) <= max_chunk:
        return jax.device_get(kernel(*axes, *extra))
    results: dict[str, np.ndarray] = {}
    for starts, stops, rows in _blocks(shape, max_chunk):
        k = len(starts) - 1
        block_axes = [a[start:stop] for a, start, stop in zip(axes, starts, stops, strict=False)]
        block_axes[k] = np.pad(block_axes[k], (0, rows - block_axes[k].size), mode="edge")
        block_axes += list(axes[k + 1 :])
        values = jax.device_get(kernel(*block_axes, *extra))
        index = tuple(slice(start, stop) for start, stop in zip(starts, stops, strict=True))
        for name, value in values.items():
            if name not in results:
                results[name] = np.empty(shape, dtype=value.dtype)
            results[name][index] = value[(slice(None),) * k + (slice(0, stops[k] - starts[k]),)]
    return results


def _dataset(axes: dict, values: dict, title: str, extra=None) -> xr.Dataset:
    """A Dataset of grid ``values`` over ``axes`` (scalars become scalar coordinates).

    A value is an array over the whole grid (with a length-1 axis for each scalar
    coordinate), or a ``(dims, array)`` pair for one that depends on fewer parameters.
    ``extra`` coordinates are not grid axes: 0-d ones are scalar coordinates, 1-D ones
    trailing dimensions of the values that have more axes than the grid.
    """
    dims = [name for name, axis in axes.items() if axis.ndim == 1]
    squeeze = tuple(i for i, axis in enumerate(axes.values()) if axis.ndim == 0)
    extra = extra or {}
    trailing = [name for name, coordinate in extra.items() if coordinate.ndim == 1]
    coords = {
        name: ((name,) if axis.ndim == 1 else (), axis, _attrs(name))
        for name, axis in {**axes, **extra}.items()
    }
    data_vars = {}
    for name in sorted(values, key=list(_ATTRS).index):
        if isinstance(values[name], tuple):
            data_vars[name] = (*values[name], _attrs(name))
            continue
        value = np.squeeze(values[name], axis=squeeze)
        data_vars[name] = (dims + trailing[: value.ndim - len(dims)], value, _attrs(name))
    return xr.Dataset(data_vars, coords=coords, attrs=_global_attrs(title))


# ---------------------------------------------------------------------------------------
# Kernels
# ---------------------------------------------------------------------------------------


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


def _broadcast(values: dict, shape) -> dict:
    return {name: jnp.broadcast_to(value, shape) for name, value in values.items()}


@jax.jit
def _map_kernel(stiffness_ratio, aspect_ratio, amplitude, mu, load):
    stiffness_ratio, aspect_ratio, amplitude, mu = _mesh(
        stiffness_ratio, aspect_ratio, amplitude, mu
    )
    kappa = model.curvature_number(1.0, aspect_ratio, 1.0)  # x_o = Δ*: κ = 2 z_o/x_o
    lam = model.compliance_ratio(amplitude, 1.0, stiffness_ratio)  # 1/((S/P) Δ*)
    values = _steady_state(mu, kappa, lam, amplitude, load)
    shape = jnp.broadcast_shapes(stiffness_ratio.shape, aspect_ratio.shape, amplitude.shape)
    return _broadcast(values, jnp.broadcast_shapes(shape, mu.shape))


@jax.jit
def _universal_kernel(compliance_ratio, aspect_ratio, mu):
    lam, aspect_ratio, mu = _mesh(compliance_ratio, aspect_ratio, mu)
    kappa = model.curvature_number(1.0, aspect_ratio, 1.0)
    values = _steady_state(mu, kappa, lam)
    return _broadcast(values, (lam.size, aspect_ratio.size, mu.size))


# ---------------------------------------------------------------------------------------
# Public functions
# ---------------------------------------------------------------------------------------


@float64
def compute_map(
    stiffness_ratio,
    aspect_ratio=None,
    amplitude=None,
    mu=None,
    load=None,
    *,
    profile=None,
    mapping="scaled",
    cache=True,
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
        Normal load :math:`P`; when given, the map also holds ``dissipated_energy`` and
        ``max_force`` and a scalar coordinate ``load``. [N]
    profile : ScarProfile, optional
        A wear-scar profile of any shape instead of ``aspect_ratio``: see
        :func:`compute_profile_map`.
    mapping : {'scaled', 'physical'}
        With a profile: :math:`X = xW/\Delta^*` (eq. 11) or :math:`X = x`.
    cache : bool
        Read the result from the disk cache, and store it there after computing it.
    cache_dir : str or os.PathLike, optional
        Cache directory; default ``$ECOFMAPS_CACHE`` or the per-user cache directory.
    max_chunk : int
        Largest number of grid points evaluated in one block; a bigger grid is evaluated
        block by block and copied into place. [1]

    Returns
    -------
    map : xarray.Dataset
        Dimensions ``stiffness_ratio``, ``aspect_ratio``, ``amplitude``, ``mu`` (in this
        order; only those given as arrays, the others are scalar coordinates). Variables:
        ``slip_amplitude`` [m], ``slip_ratio`` [1], ``ecof`` [1], ``ecof_ratio`` [1],
        ``regime`` (:class:`ecofmaps.Regime` codes, int32), ``compliance_ratio`` [1] (over
        ``stiffness_ratio`` and ``amplitude`` only) and, with a load, ``dissipated_energy``
        [J] and ``max_force`` [N]. Every variable and coordinate has ``long_name`` and
        ``units``. ECoF values are NaN where there is no gross slip; every value but the
        regime is NaN when self-locking (rigid rig, :math:`\mu\kappa \ge 1`). Freshly
        computed arrays of a grid of at most ``max_chunk`` points are read-only (they are
        the computation's buffers, not copies): ``.copy()`` the Dataset to write into them.

    Raises
    ------
    ValueError
        If a parameter is not a scalar or a non-empty 1-D array, or is out of range:
        stiffness_ratio > 0 (inf allowed); aspect_ratio >= 0; amplitude, mu, load > 0;
        all finite except stiffness_ratio, none NaN.

    Warns
    -----
    ecofmaps.maps.cache.CacheWarning
        When a cache file is unusable (it is removed and the map recomputed).

    Notes
    -----
    The map depends on :math:`S`, :math:`P` and :math:`\Delta^*` only through
    :math:`\lambda = P/(S\Delta^*)` (eq. 16): the Figure 11 maps at :math:`\Delta^* = 25` and
    50 µm are one surface read on two scales of :math:`S/P`. Values come from the closed
    forms of eq. 16 (slip amplitude), the corrected eq. 13-15 (:math:`\mu_E`), eq. 12
    (:math:`E_d = 4P\delta^*\mu_E`) and eq. 9 (:math:`Q^*`).

    Examples
    --------
    >>> import numpy as np
    >>> m = compute_map(np.geomspace(2e4, 2e5, 5), np.linspace(0, 0.3, 4), 50e-6, 0.8)
    >>> m.ecof_ratio.dims
    ('stiffness_ratio', 'aspect_ratio')
    """
    if profile is not None or aspect_ratio is None:
        if aspect_ratio is not None:
            raise ValueError("give aspect_ratio or profile, not both")
        return compute_profile_map(
            stiffness_ratio, amplitude, mu, load, profile=profile, mapping=mapping, cache=cache,
            cache_dir=cache_dir, max_chunk=max_chunk,
        )  # fmt: skip
    if mapping != "scaled":
        raise ValueError("mapping applies to a profile only (profile=...)")
    if amplitude is None or mu is None:
        raise ValueError("compute_map needs amplitude and mu")
    axes = {
        "stiffness_ratio": _axis("stiffness_ratio", stiffness_ratio, "positive_or_inf", "1/m"),
        "aspect_ratio": _axis("aspect_ratio", aspect_ratio, "non_negative", "1"),
        "amplitude": _axis("amplitude", amplitude, "positive", "m"),
        "mu": _axis("mu", mu, "positive", "1"),
    }
    if load is not None:
        load = _axis("load", load, "positive", "N")
        if load.ndim:
            raise ValueError(f"load must be a single value, got shape {load.shape}")

    def compute() -> xr.Dataset:
        values = _evaluate_grid(
            _map_kernel, [np.atleast_1d(a) for a in axes.values()], (load,), max_chunk
        )
        # λ depends on S/P and Δ* only: a variable over those two (eq. 16).
        stiffness, amplitude = axes["stiffness_ratio"], axes["amplitude"]
        lam = model.compliance_ratio(
            np.atleast_1d(amplitude), 1.0, np.atleast_1d(stiffness)[:, None]
        )
        scalars = tuple(i for i, axis in enumerate((stiffness, amplitude)) if axis.ndim == 0)
        dims = tuple(n for n in ("stiffness_ratio", "amplitude") if axes[n].ndim == 1)
        values["compliance_ratio"] = (dims, np.squeeze(lam, axis=scalars))
        extra = {} if load is None else {"load": load}
        return _dataset(axes, values, "ECoF map of the compliant wear-scar model", extra)

    if not cache:
        return compute()
    return cached_dataset("compute_map", {**axes, "load": load}, compute, cache_dir)


@float64
def compute_universal_map(
    compliance_ratio,
    aspect_ratio,
    mu,
    *,
    cache=True,
    cache_dir=None,
    max_chunk=MAX_CHUNK,
) -> xr.Dataset:
    r"""The dimensionless map: :math:`\mu_E/\mu` and :math:`\delta^*/\Delta^*` over :math:`\lambda`.

    Parameters
    ----------
    compliance_ratio : float or 1-D array_like
        :math:`\lambda = P/(S\Delta^*)`, the rig's deflection at :math:`Q = P` over the
        displacement amplitude, >= 0 (0 for a rigid rig). [1]
    aspect_ratio : float or 1-D array_like
        Groove depth over half-width :math:`z_o/x_o` with :math:`x_o = \Delta^*`, >= 0. [1]
    mu : float or 1-D array_like
        Contact coefficient of friction, > 0. [1]
    cache, cache_dir, max_chunk
        As for :func:`compute_map`.

    Returns
    -------
    map : xarray.Dataset
        Dimensions ``compliance_ratio``, ``aspect_ratio``, ``mu`` (those given as arrays).
        Variables ``ecof_ratio`` [1], ``slip_ratio`` [1], ``regime``.

    Raises
    ------
    ValueError
        If a parameter is not a scalar or a non-empty 1-D array, or out of range.

    Notes
    -----
    With :math:`x_o = \Delta^*` the curvature number is :math:`\kappa = 2 z_o/x_o`, and
    :math:`\mu_E/\mu` depends on :math:`(\mu, z_o/x_o, \lambda)` only (eq. 13-16): this one
    chart holds both panels of Figure 11, whose axes :math:`S/P` map onto
    :math:`\lambda = 1/((S/P)\Delta^*)`.
    """
    axes = {
        "compliance_ratio": _axis("compliance_ratio", compliance_ratio, "non_negative", "1"),
        "aspect_ratio": _axis("aspect_ratio", aspect_ratio, "non_negative", "1"),
        "mu": _axis("mu", mu, "positive", "1"),
    }

    def compute() -> xr.Dataset:
        values = _evaluate_grid(
            _universal_kernel, [np.atleast_1d(a) for a in axes.values()], (), max_chunk
        )
        return _dataset(axes, values, "Universal ECoF map of the compliant wear-scar model")

    if not cache:
        return compute()
    return cached_dataset("compute_universal_map", axes, compute, cache_dir)


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
    aspect_ratio : float or 1-D array_like
        Groove depth over half-width :math:`z_o/x_o`. [1]
    amplitude : float or 1-D array_like
        Displacement amplitude :math:`\Delta^*` (also the groove half-width). [m]
    load : float or 1-D array_like
        Normal load :math:`P`. [N]
    mu : float or 1-D array_like
        Contact coefficient of friction. [1]
    num : int
        Points on each slip branch (>= 2); each loop has ``2 * num + 1`` points. [1]

    Returns
    -------
    loops : xarray.Dataset
        Dimensions: those of the parameters given as arrays (in the order of the
        arguments), then ``point``. Variables ``displacement`` [m] and ``force`` [N] around
        each loop (see :func:`ecofmaps.fretting_loop`: it starts and ends at the reversal
        :math:`(-\Delta^*, -Q^*)` and runs clockwise), and per loop ``slip_amplitude`` [m],
        ``max_force`` [N], ``dissipated_energy`` [J] (the loop's area) and ``regime``.
        Self-locking loops are NaN.

    Raises
    ------
    ValueError
        If a parameter is not a scalar or a non-empty 1-D array, or out of range (see
        :func:`ecofmaps.slip_amplitude`), or ``num < 2``.

    Notes
    -----
    Slip branches from eq. 9 with eq. 10, stick segments of slope :math:`S`; the per-loop
    quantities from eq. 16 (:math:`\delta^*`), eq. 9 (:math:`Q^*`) and eq. 12 (:math:`E_d`).
    """
    axes = {
        "stiffness": _axis("stiffness", stiffness, "positive_or_inf", "N/m"),
        "aspect_ratio": _axis("aspect_ratio", aspect_ratio, "non_negative", "1"),
        "amplitude": _axis("amplitude", amplitude, "positive", "m"),
        "load": _axis("load", load, "positive", "N"),
        "mu": _axis("mu", mu, "positive", "1"),
    }
    grid = jnp.broadcast_arrays(*_mesh(*(np.atleast_1d(a) for a in axes.values())))
    displacement, force = fretting_loop(
        amplitude=grid[2], load=grid[3], stiffness=grid[0], mu=grid[4], aspect_ratio=grid[1],
        num=num,
    )  # fmt: skip
    values = jax.device_get(_loop_kernel(*grid))
    values["displacement"] = displacement
    values["force"] = force
    values = {name: np.asarray(value) for name, value in values.items()}
    point = np.arange(2 * num + 1)
    return _dataset(axes, values, "Steady fretting loops", extra={"point": point})


# ---------------------------------------------------------------------------------------
# Maps on a scar profile
# ---------------------------------------------------------------------------------------

# Global attributes of a map on a profile: name -> description.  # -> _nomenclature
_PROFILE_ATTRS = {
    "scar_depth": "scar depth D [m]",
    "scar_half_width": "scar half-width W [m]",
    "scar_aspect_ratio": "scar depth over half-width D/W [1]",
    "scar_samples": "samples of the scar profile [1]",
    "mapping": "pad position x to profile position X: scaled, X = x W/Delta* (eq. 11); "
    "physical, X = x",
}

MODEL_ON_PROFILE = (
    "compliant wear-scar interaction model on a measured or modelled scar profile: a rigid "
    "round-ended pad with Coulomb friction feels the profile's slope g(X) (eq. 9 pointwise), "
    "driven through a spring of stiffness S (the rig); steady loops of displacement amplitude "
    "Delta* by first passage of the quasi-static return map"
)


@float64
def compute_profile_map(stiffness_ratio, amplitude, mu, load=None, *, profile, mapping="scaled",
                        cache=True, cache_dir=None, max_chunk=MAX_CHUNK) -> xr.Dataset:  # fmt: skip
    r"""The steady-loop quantities on a scar profile over a grid of test conditions.

    Parameters
    ----------
    stiffness_ratio : float or 1-D array_like
        Rig stiffness over normal load :math:`S/P`; ``numpy.inf`` for a rigid rig. [1/m]
    amplitude : float or 1-D array_like
        Displacement amplitude :math:`\Delta^*`. [m]
    mu : float or 1-D array_like
        Contact coefficient of friction :math:`\mu`. [1]
    load : float, optional
        Normal load :math:`P`, for ``dissipated_energy`` and ``max_force``. [N]
    profile : ScarProfile
        The scar (:func:`ecofmaps.scar_profile`, :func:`ecofmaps.read_scar_profile`, a
        profile family).
    mapping : {'scaled', 'physical'}
        :math:`X = xW/x_o` with :math:`x_o = \Delta^*` (eq. 11), or :math:`X = x`.
    cache, cache_dir, max_chunk
        As for :func:`compute_map`; the cache key holds every array of the profile.

    Returns
    -------
    map : xarray.Dataset
        Dimensions ``stiffness_ratio``, ``amplitude``, ``mu`` (those given as arrays), the
        variables of :func:`compute_map`, and the profile's depth, half-width, aspect ratio,
        sample count and the mapping as global attributes. Points where the pad slips off
        the trace have the regime ``BEYOND_PROFILE`` and NaN values.

    Raises
    ------
    ValueError
        As for :func:`compute_map`, and for a missing or bad profile or mapping.

    Notes
    -----
    With the scaled mapping the map depends on :math:`S/P` and :math:`\Delta^*` only through
    :math:`\lambda = P/(S\Delta^*)`, as in eq. 16; the steady loop comes from
    :func:`ecofmaps.model.on_profile.steady_numbers` (one set of tables per :math:`\mu`).

    Examples
    --------
    >>> import numpy as np, ecofmaps
    >>> p = ecofmaps.flat_bottomed_profile(10e-6, 50e-6)
    >>> m = compute_map(np.geomspace(2e4, 2e5, 5), amplitude=50e-6, mu=0.8, profile=p)
    >>> m.ecof_ratio.dims
    ('stiffness_ratio',)
    """
    from ecofmaps.model.on_profile import as_profile, check_mapping, steady_numbers

    if profile is None:
        raise ValueError("compute_map needs aspect_ratio or profile")
    if amplitude is None or mu is None:
        raise ValueError("compute_map needs amplitude and mu")
    physical = check_mapping(mapping, None)
    profile = as_profile(profile)
    axes = {
        "stiffness_ratio": _axis("stiffness_ratio", stiffness_ratio, "positive_or_inf", "1/m"),
        "amplitude": _axis("amplitude", amplitude, "positive", "m"),
        "mu": _axis("mu", mu, "positive", "1"),
    }
    if load is not None:
        load = _axis("load", load, "positive", "N")
        if load.ndim:
            raise ValueError(f"load must be a single value, got shape {load.shape}")
    if not (isinstance(max_chunk, int) and max_chunk >= 1):
        raise ValueError(f"max_chunk must be an integer >= 1, got {max_chunk!r}")

    def compute() -> xr.Dataset:
        grid = [np.atleast_1d(a) for a in axes.values()]
        shape = tuple(a.size for a in grid)
        size = math.prod(shape)
        names = ("slip_ratio", "ecof_ratio", "regime", "normalized_energy", "normalized_max_force")
        flat = {name: np.empty(size, dtype=np.int32 if name == "regime" else np.float64)
                for name in names}  # fmt: skip
        for start in range(0, size, max_chunk):
            index = np.unravel_index(np.arange(start, min(start + max_chunk, size)), shape)
            stiffness, amplitude, mu = (axis[i] for axis, i in zip(grid, index, strict=True))
            # λ = P/(S Δ*) = 1/((S/P) Δ*): a unit load and the stiffness ratio.
            numbers = steady_numbers(profile, amplitude, 1.0, stiffness, mu, mapping=mapping)
            for name in names:
                flat[name][start : start + index[0].size] = np.asarray(numbers[name])
        values = {name: flat[name].reshape(shape) for name in names}
        amplitude = grid[1][None, :, None]
        values["slip_amplitude"] = amplitude * values["slip_ratio"]
        values["ecof"] = grid[2][None, None, :] * values["ecof_ratio"]
        if load is not None:
            values["dissipated_energy"] = load * amplitude * values["normalized_energy"]
            values["max_force"] = load * values["normalized_max_force"]
        del values["normalized_energy"], values["normalized_max_force"]
        stiffness, amplitude = axes["stiffness_ratio"], axes["amplitude"]
        lam = model.compliance_ratio(
            np.atleast_1d(amplitude), 1.0, np.atleast_1d(stiffness)[:, None]
        )
        scalars = tuple(i for i, axis in enumerate((stiffness, amplitude)) if axis.ndim == 0)
        dims = tuple(n for n in ("stiffness_ratio", "amplitude") if axes[n].ndim == 1)
        values["compliance_ratio"] = (dims, np.squeeze(lam, axis=scalars))
        extra = {} if load is None else {"load": load}
        dataset = _dataset(axes, values, "ECoF map of the compliant wear-scar model on a scar "
                           "profile", extra)  # fmt: skip
        dataset.attrs["model"] = MODEL_ON_PROFILE
        dataset.attrs.update(
            scar_depth=float(profile.depth),
            scar_half_width=float(profile.half_width),
            scar_aspect_ratio=float(profile.aspect_ratio),
            scar_samples=int(profile.position.shape[-1]),
            mapping=mapping,
        )
        return dataset

    if not cache:
        return compute()
    inputs = {**axes, "load": load, "mapping": float(physical)}
    inputs.update({f"profile_{name}": value for name, value in profile._asdict().items()})
    return cached_dataset("compute_profile_map", inputs, compute, cache_dir)
