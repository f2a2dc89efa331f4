r"""Maps on a scar profile: the steady-loop quantities of a groove of any shape over a grid.

The pad feels the profile's local slope (eq. 9 pointwise): docs/model.md, "The model on a
scar profile".
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ecofmaps._inputs import float64
from ecofmaps.maps.cache import cached_dataset
from ecofmaps.maps.dataset import checked_axes, checked_load, map_dataset
from ecofmaps.maps.tiles import MAX_CHUNK, check_max_chunk
from ecofmaps.model.on_profile import as_profile, check_mapping, steady_numbers, steady_values

__all__ = ["MODEL_ON_PROFILE", "compute_profile_map"]


MODEL_ON_PROFILE = (
    "compliant wear-scar interaction model on a measured or modelled scar profile: a rigid "
    "round-ended pad with Coulomb friction feels the profile's slope g(X) (eq. 9 pointwise), "
    "driven through a spring of stiffness S (the rig); steady loops of displacement amplitude "
    "Delta* by first passage of the quasi-static return map"
)


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
        shape = tuple(a.size for a in grid)
        size = math.prod(shape)
        names = ("slip_ratio", "ecof_ratio", "regime", "normalized_energy", "normalized_max_force")
        flat = {
            name: np.empty(size, dtype=np.int32 if name == "regime" else np.float64)
            for name in names
        }
        for start in range(0, size, max_chunk):
            index = np.unravel_index(np.arange(start, min(start + max_chunk, size)), shape)
            stiffness, amplitude, mu = (axis[i] for axis, i in zip(grid, index, strict=True))
            # λ = P/(S Δ*) = 1/((S/P) Δ*): a unit load and the stiffness ratio
            numbers = steady_numbers(profile, amplitude, 1.0, stiffness, mu, mapping=mapping)
            for name in names:
                flat[name][start : start + index[0].size] = np.asarray(numbers[name])
        values = {name: flat[name].reshape(shape) for name in names}
        values.update(steady_values(values, grid[1][None, :, None], load, grid[2][None, None, :]))
        del values["normalized_energy"], values["normalized_max_force"]
        title = "ECoF map of the compliant wear-scar model on a scar profile"
        dataset = map_dataset(axes, values, load, title)
        dataset.attrs.update(
            model=MODEL_ON_PROFILE,
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
