"""The labelled xarray Dataset of a map: checked grid axes, variables and attributes (names
and units from :mod:`ecofmaps._nomenclature`, the paper's model and citation)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr
from xarray.core.indexes import PandasIndex

from ecofmaps import _nomenclature as nomenclature
from ecofmaps import model, paper
from ecofmaps._inputs import check
from ecofmaps._version import __version__

# The order of the variables in a Dataset (xarray orders the dimensions as they first appear).
_VARIABLES = (
    "displacement",
    "force",
    "slip_amplitude",
    "slip_ratio",
    "ecof",
    "ecof_ratio",
    "compliance_ratio",
    "regime",
    "dissipated_energy",
    "max_force",
)
# The range rule and unit of each grid axis.
_AXES = {
    "stiffness_ratio": ("positive_or_inf", "1/m"),
    "stiffness": ("positive_or_inf", "N/m"),
    "compliance_ratio": ("non_negative", "1"),
    "aspect_ratio": ("non_negative", "1"),
    "amplitude": ("positive", "m"),
    "load": ("positive", "N"),
    "mu": ("positive", "1"),
}


def _attrs(name: str) -> dict:
    return nomenclature.attrs(name) | (model.Regime.flag_attrs() if name == "regime" else {})


def checked_axes(**values) -> dict:
    """Each of ``values`` checked by :func:`checked_axis`, by name."""
    return {name: checked_axis(name, value) for name, value in values.items()}


def checked_axis(name: str, value) -> np.ndarray:
    """``value`` checked (``ValueError`` naming ``name``) as a float64 scalar or 1-D array."""
    check(name, value, *_AXES[name])
    array = np.asarray(value, dtype=np.float64)
    if array.ndim > 1:
        raise ValueError(f"{name} must be a single value or a 1-D array, got shape {array.shape}")
    if array.size == 0:
        raise ValueError(f"{name} must hold at least one value, got an empty array")
    unique, counts = np.unique(array, return_counts=True)
    if np.any(counts > 1):
        repeated = unique[counts > 1][0]
        raise ValueError(
            f"{name} repeats the value {repeated!r} (at indices "
            f"{np.flatnonzero(array == repeated).tolist()}): a grid axis takes each value once"
        )
    return array


def checked_load(load) -> np.ndarray | None:
    """The map's normal load (None, or one value) checked, as :func:`checked_axis` does. [N]"""
    if load is None:
        return None
    load = checked_axis("load", load)
    if load.ndim:
        raise ValueError(f"load must be a single value, got shape {load.shape}")
    return load


def grid_dataset(axes: dict, values: dict, title: str, extra=None) -> xr.Dataset:
    """A Dataset of grid ``values`` over ``axes`` (scalars become scalar coordinates), with
    the coordinates ``extra``; a value ``(dims, array)`` is taken as it is."""
    extra = extra or {}
    dims = [name for name, axis in axes.items() if axis.ndim == 1]
    squeeze = tuple(i for i, axis in enumerate(axes.values()) if axis.ndim == 0)
    trailing = [name for name, coordinate in extra.items() if coordinate.ndim == 1]
    variables, indexes = {}, {}
    for name, value in {**axes, **extra}.items():
        variable = xr.Variable((name,) * value.ndim, value, _attrs(name))
        if value.ndim:  # a dimension coordinate, indexed as xarray.Dataset would index it
            indexes[name] = PandasIndex(pd.Index(value), name)
            variables.update(indexes[name].create_variables({name: variable}))
        else:
            variables[name] = variable
    coords = set(variables)
    for name in sorted(values, key=_VARIABLES.index):
        value = values[name]
        if not isinstance(value, tuple):  # over the grid, but its scalar axes
            value = np.squeeze(value, axis=squeeze)
            value = dims + trailing[: value.ndim - len(dims)], value
        variables[name] = xr.Variable(*value, _attrs(name))
    attrs = {"title": title, "model": paper.MODEL, "references": paper.CITATION}
    attrs.update(source=f"ecofmaps {__version__}", ecofmaps_version=__version__)
    # xarray.Dataset(data_vars, coords, attrs) without aligning variables consistent by design.
    return xr.Dataset._construct_direct(variables, coords, attrs=attrs, indexes=indexes)


def map_dataset(axes: dict, values: dict, load, title: str) -> xr.Dataset:
    """The Dataset of a map of :func:`compute_map`: ``values``, the load as a coordinate, and
    λ = P/(SΔ*) = 1/((S/P)Δ*) over the axes ``stiffness_ratio`` and ``amplitude`` (eq. 16)."""
    stiffness, amplitude = axes["stiffness_ratio"], axes["amplitude"]
    column = stiffness[..., None] if amplitude.ndim else stiffness
    lam = model.compliance_ratio(amplitude, 1.0, column)
    dims = tuple(name for name in ("stiffness_ratio", "amplitude") if axes[name].ndim)
    values = {**values, "compliance_ratio": (dims, lam)}
    return grid_dataset(axes, values, title, {} if load is None else {"load": load})
