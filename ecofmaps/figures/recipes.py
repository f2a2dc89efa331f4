r"""The figures ``ecofmaps figures`` writes: :data:`FIGURES`, for each figure the function that
builds its Dataset with the paper's parameters (:mod:`ecofmaps.paper`), the function that draws
it and what it marks; :func:`make_figure` does both, :func:`make_figures` for several."""

from __future__ import annotations

import hashlib
import importlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

import ecofmaps
from ecofmaps import paper
from ecofmaps._nomenclature import attrs

if TYPE_CHECKING:  # imported when a figure is made: the registry reads without them
    import xarray as xr
    from matplotlib.figure import Figure

#: Groove aspect ratios z_o/x_o of Figures 7, 8, 11 and the universal map. [1]
_ASPECT_RATIOS = np.linspace(0.0, 0.3, 61)
#: λ of the universal map, on a logarithmic scale: near-rigid rigs to well past the end of
#: gross slip at μλ = 1, covering Figure 11 at both amplitudes. [1]
_COMPLIANCE_RATIOS = np.geomspace(0.01, 2.0, 161)
#: Example 2's amplitude, load and μ.
_RIG = dict(amplitude=paper.AMPLITUDE, load=paper.LOAD, mu=paper.MU)


@dataclass(frozen=True)
class FigureRecipe:
    """How to make one figure: its Dataset (the paper's parameters) and its drawing function.

    Attributes
    ----------
    name, description : str
        File stem (``'fig7a'``) and one line saying what the figure shows.
    data : callable
        ``data() -> xarray.Dataset`` through the cache; recipes that share it share the Dataset.
    draw, module : str
        ``draw(dataset, **options) -> Figure`` and its module of :mod:`ecofmaps.figures`, by name.
    selection, options : dict
        Coordinates picked with ``.sel`` before drawing; keyword arguments of ``draw``.
    cost : float
        Rough time from an empty cache, relative to a plain figure (:func:`figure_groups`). [1]
    parts : tuple of callable
        Each caches a part of the Dataset ``data`` reads, in parallel first (:func:`figure_parts`).
    """

    name: str
    description: str
    data: Callable[[], xr.Dataset]
    draw: str
    selection: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)
    module: str = "model_figures"
    cost: float = 1.0
    parts: tuple = ()

    def dataset(self) -> xr.Dataset:
        """The Dataset this figure draws."""
        return self.data().sel(self.selection)

    def figure(self, dataset: xr.Dataset) -> Figure:
        """The figure, drawn from ``dataset`` (the Dataset of :attr:`data`, before selection)."""
        draw = getattr(importlib.import_module(f"ecofmaps.figures.{self.module}"), self.draw)
        return draw(dataset.sel(self.selection), **self.options)


def _loops() -> xr.Dataset:
    """The loops of Figures 5 and 6 (the registry reads without JAX: imports on first use)."""
    from ecofmaps.maps.cache import cached_dataset
    from ecofmaps.maps.grid import compute_loops

    grid = dict(stiffness=np.array([np.inf, paper.STIFFNESS]), aspect_ratio=np.arange(4) / 10)
    inputs = grid | _RIG
    return cached_dataset("compute_loops", inputs, lambda: compute_loops(**inputs))


def _stiffness_curves_data() -> xr.Dataset:
    ratios = np.array(paper.FIGURE_7_STIFFNESSES) / paper.LOAD
    return ecofmaps.compute_map(ratios, _ASPECT_RATIOS, paper.AMPLITUDE, paper.MU, paper.LOAD)


def _ecof_ratio_map(panel: str) -> Callable[[], xr.Dataset]:
    amplitude = paper.FIGURE_11_AMPLITUDES[panel]

    def data() -> xr.Dataset:
        ratios = paper.FIGURE_11_STIFFNESS_RATIOS
        return ecofmaps.compute_map(ratios, _ASPECT_RATIOS, amplitude, paper.MU)

    return data


def _universal_map() -> xr.Dataset:
    return ecofmaps.compute_universal_map(_COMPLIANCE_RATIOS, _ASPECT_RATIOS, paper.MU)


#: The ``shapes`` figure's scar families at Example 2's D/W = 0.2, W = x_o = Δ*: the function
#: and its shape parameters (fractions of D or W). [1]
_SCAR_SHAPES = {
    "parabolic": ("parabolic_profile", {}),
    "flat-bottomed": ("flat_bottomed_profile", {"flat_fraction": 0.5}),
    "W-shaped": ("w_shaped_profile", {"hump": 0.25}),
    "ridged": ("ridged_profile", {"ridge_height": 0.3, "ridge_width": 0.6}),
}
#: The sources beside the model's revision that decide the ``shapes`` Dataset.
_SCAR_SHAPES_SOURCES = ("figures/recipes.py", "correction/*.py")


def source_digest(patterns) -> np.ndarray:
    """SHA-256 of the package's source files matching ``patterns``, as 32 numbers."""
    package = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for pattern in patterns:
        for path in sorted(package.glob(pattern)):
            digest.update(f"{path.relative_to(package).as_posix()}\0".encode())
            digest.update(path.read_bytes())
    return np.frombuffer(digest.digest(), dtype=np.uint8)


def _cached_shapes_part(function: str, compute: Callable[[], xr.Dataset]) -> xr.Dataset:
    from ecofmaps.maps.cache import cached_dataset

    return cached_dataset(function, {"sources": source_digest(_SCAR_SHAPES_SOURCES)}, compute)


def _scar_shape_model() -> xr.Dataset:
    return _cached_shapes_part("scar_shape_model", scar_shape_model_dataset)


def _scar_shape_parabola() -> xr.Dataset:
    return _cached_shapes_part("scar_shape_parabola", scar_shape_parabola_dataset)


def _scar_shapes() -> xr.Dataset:
    return _cached_shapes_part("scar_shapes", scar_shapes_dataset)


def _scar_profiles() -> list:
    """The scar families of :data:`_SCAR_SHAPES`, in order."""
    depth, width = paper.ASPECT_RATIO * paper.AMPLITUDE, paper.AMPLITUDE
    scale = {"ridge_height": depth, "ridge_width": width}
    profiles = []
    for family, shape in _SCAR_SHAPES.values():
        options = {name: value * scale.get(name, 1.0) for name, value in shape.items()}
        profiles.append(getattr(ecofmaps, family)(depth, width, **options))
    return profiles


def _labelled(variables: dict, coords: dict) -> xr.Dataset:
    import xarray as xr

    return xr.Dataset(
        {name: (dims, values, attrs(name)) for name, (dims, values) in variables.items()},
        coords={name: ((name if np.ndim(v) else ()), v, attrs(name)) for name, v in coords.items()},
    )


#: The rig of the ``shapes`` figure's loops: Example 2's.
_SHAPES_RIG = {name: value for name, value in paper.EXAMPLE_2.items() if name != "aspect_ratio"}
#: Figure 11's S/P with Example 2's among them: its steady values come from the same map. [1/m]
_SHAPES_STIFFNESS_RATIOS = np.union1d(
    paper.FIGURE_11_STIFFNESS_RATIOS, [paper.STIFFNESS / paper.LOAD]
)
_AT_EXAMPLE = int(np.searchsorted(_SHAPES_STIFFNESS_RATIOS, paper.STIFFNESS / paper.LOAD))
#: The steady values of a loop, over S/P.
_STEADY = ("slip_amplitude", "dissipated_energy", "ecof", "ecof_ratio")


def scar_shape_model_dataset() -> xr.Dataset:
    """The model on each scar family: steady values over S/P and the loop of Example 2's rig."""
    from ecofmaps.model.on_profile import steady_numbers_and_loops, steady_values

    ratios = _SHAPES_STIFFNESS_RATIOS
    loop = ("displacement", "force")
    values = {name: [] for name in (*_STEADY, *loop)}
    for profile in _scar_profiles():
        steady = steady_numbers_and_loops(profile, **_RIG, stiffness=ratios * paper.LOAD)
        numbers = {name: np.asarray(value) for name, value in steady.items()}
        numbers |= steady_values(numbers, paper.AMPLITUDE, paper.LOAD, paper.MU)  # as maps
        for name in values:
            values[name].append(numbers[name][_AT_EXAMPLE] if name in loop else numbers[name])
    variables = {
        name: (("shape", "point" if name in loop else "stiffness_ratio"), np.array(value))
        for name, value in values.items()
    }
    return _labelled(variables, {"shape": list(_SCAR_SHAPES), "stiffness_ratio": ratios})


def scar_shape_parabola_dataset() -> xr.Dataset:
    """The parabola of Example 2's D/W (values over S/P, loop) and the scar families' heights."""
    ratios = _SHAPES_STIFFNESS_RATIOS
    position = np.linspace(-1.6, 1.6, 321) * paper.AMPLITUDE
    heights = [np.interp(position, p.position, p.height) for p in _scar_profiles()]
    # Not cached on its own: the figure's part is cached whole (_scar_shape_parabola).
    parabola = ecofmaps.compute_map(ratios, paper.ASPECT_RATIO, **_RIG, cache=False)
    loop = np.asarray(ecofmaps.fretting_loop(**_SHAPES_RIG, aspect_ratio=paper.ASPECT_RATIO))
    variables = {
        "scar_height": (("shape", "scar_position"), np.array(heights)),
        **{name: ("stiffness_ratio", parabola[name].values) for name in _STEADY},
        "displacement": ("point", loop[0]),
        "force": ("point", loop[1]),
    }
    coords = {"shape": list(_SCAR_SHAPES), "scar_position": position, "stiffness_ratio": ratios}
    return _labelled(variables, coords)


def scar_shapes_dataset() -> xr.Dataset:
    """The four scar families at Example 2's D/W: profiles, loops, μ_E/μ over S/P (Fig. 11's)."""
    model, parabola = _scar_shape_model(), _scar_shape_parabola()
    ratios = _SHAPES_STIFFNESS_RATIOS
    # μ from each profile's μ_E corrected with the parabola of the same D/W (eq. 11)
    rig = (paper.AMPLITUDE, paper.LOAD, ratios * paper.LOAD, paper.ASPECT_RATIO)
    corrected = [
        ecofmaps.correct_ecof(paper.MU * ratio, *rig) for ratio in model["ecof_ratio"].values
    ]
    errors = [np.asarray(mu) / paper.MU - 1.0 for mu in corrected]

    def by_groove(name, index=...):  # the profile's values and the parabola's
        on_profile = model[name].values[:, index]
        same = np.broadcast_to(parabola[name].values[index], on_profile.shape)
        return np.stack([on_profile, same], axis=1)

    groove = ("shape", "groove")
    variables = {
        "scar_height": (("shape", "scar_position"), parabola["scar_height"].values),
        "displacement": ((*groove, "point"), by_groove("displacement")),
        "force": ((*groove, "point"), by_groove("force")),
        **{name: (groove, by_groove(name, _AT_EXAMPLE)) for name in _STEADY[:3]},
        "ecof_ratio": ((*groove, "stiffness_ratio"), by_groove("ecof_ratio")),
        "shortcut_error": (("shape", "stiffness_ratio"), np.array(errors)),
    }
    coords = {
        "shape": list(_SCAR_SHAPES),
        "groove": ["profile", "parabola"],
        "scar_position": parabola["scar_position"].values,
        "stiffness_ratio": ratios,
        **_SHAPES_RIG,
        "scar_depth": paper.ASPECT_RATIO * paper.AMPLITUDE,
        "scar_half_width": paper.AMPLITUDE,
    }
    dataset = _labelled(variables, coords)
    dataset.attrs["title"] = (
        "Scar shapes at equal D/W: the model on each profile against the parabola of the same "
        "D/W (the paper's eq. 11 shortcut)"
    )
    return dataset


_EXAMPLE_2 = {"Example 2": paper.EXAMPLE_2}

FIGURES: dict[str, FigureRecipe] = {
    recipe.name: recipe
    for recipe in (
        FigureRecipe(
            "fig5",
            "loop of a rigid rig against S = 35 MN/m, z_o/x_o = 0.2",
            _loops,
            "rigid_and_compliant_loops",
            {"aspect_ratio": paper.ASPECT_RATIO},
            cost=2.0,
        ),
        FigureRecipe(
            "fig6",
            "loops for z_o/x_o = 0, 0.1, 0.2, 0.3 at S = 35 MN/m, with Q = SΔ",
            _loops,
            "loops_by_aspect_ratio",
            {"stiffness": paper.STIFFNESS},
        ),
        FigureRecipe(
            "fig7a",
            "slip amplitude against z_o/x_o for S = 20, 35, 50, 100 MN/m and rigid",
            _stiffness_curves_data,
            "slip_amplitude_curves",
        ),
        FigureRecipe(
            "fig7b",
            "dissipated energy against z_o/x_o for S = 20, 35, 50, 100 MN/m and rigid",
            _stiffness_curves_data,
            "dissipated_energy_curves",
        ),
        FigureRecipe(
            "fig8",
            "μ_E/μ against z_o/x_o for S = 20, 35, 50, 100 MN/m and rigid, Example 2 marked",
            _stiffness_curves_data,
            "ecof_ratio_curves",
            options={"markers": _EXAMPLE_2},
        ),
        FigureRecipe(
            "fig11a",
            "contours of μ_E/μ over S/P and z_o/x_o at Δ* = 25 µm",
            _ecof_ratio_map("11a"),
            "ecof_ratio_contours",
            options={"number": "11a"},
            module="map_figures",
        ),
        FigureRecipe(
            "fig11b",
            "contours of μ_E/μ over S/P and z_o/x_o at Δ* = 50 µm, Example 2 marked",
            _ecof_ratio_map("11b"),
            "ecof_ratio_contours",
            options={"number": "11b", "markers": _EXAMPLE_2},
            module="map_figures",
        ),
        FigureRecipe(
            "universal",
            "μ_E/μ over λ = P/(SΔ*) and z_o/x_o: Fig. 11a and 11b in one chart",
            _universal_map,
            "universal_ecof_ratio_map",
            module="map_figures",
            options={
                "markers": paper.FIGURE_10_FITS,
                "windows": {
                    panel: (amplitude, paper.FIGURE_11_STIFFNESS_RATIOS)
                    for panel, amplitude in paper.FIGURE_11_AMPLITUDES.items()
                },
            },
        ),
        FigureRecipe(
            "shapes",
            "four scar shapes at Example 2's D/W: loops, μ_E/μ over S/P, the D/W shortcut's error",
            _scar_shapes,
            "scar_shape_comparison",
            module="profile_figures",
            cost=8.0,
            parts=(_scar_shape_model, _scar_shape_parabola),
        ),
    )
}


def _recipe(name: str) -> FigureRecipe:
    if name not in FIGURES:
        raise ValueError(f"unknown figure {name!r}; valid names: {', '.join(FIGURES)}")
    return FIGURES[name]


def make_figure(name: str) -> Figure:
    """Build the Dataset of figure ``name`` (from the cache when there) and draw it.

    Parameters
    ----------
    name : str
        A key of :data:`FIGURES`.

    Returns
    -------
    figure : matplotlib.figure.Figure

    Raises
    ------
    ValueError
        If ``name`` is not a key of :data:`FIGURES`.
    """
    recipe = _recipe(name)
    return recipe.figure(recipe.data())


def make_figures(names=None) -> Iterator[tuple[str, Figure]]:
    """Draw several figures, building each Dataset only once.

    Parameters
    ----------
    names : iterable of str, optional
        Keys of :data:`FIGURES`; default all of them, in order.

    Yields
    ------
    name : str
    figure : matplotlib.figure.Figure
        Drawn lazily: a caller can time each one.

    Raises
    ------
    ValueError
        As :func:`make_figure`, before anything is computed.
    """
    recipes = [_recipe(name) for name in (FIGURES if names is None else names)]
    datasets: dict = {}
    for recipe in recipes:
        if recipe.data not in datasets:
            datasets[recipe.data] = recipe.data()
        yield recipe.name, recipe.figure(datasets[recipe.data])


def figure_groups(names=None) -> list[list[str]]:
    """The figures by the Dataset they share, the costliest group (:attr:`FigureRecipe.cost`)
    first: one process draws each group (``ecofmaps figures --jobs``), building its Dataset once.

    Parameters
    ----------
    names : iterable of str, optional
        Keys of :data:`FIGURES`; default all of them.

    Returns
    -------
    groups : list of list of str
        Each name once; within a group in the order given.

    Raises
    ------
    ValueError
        As :func:`make_figure`.

    Examples
    --------
    >>> figure_groups(["fig7a", "fig5", "fig8", "fig6", "shapes"])
    [['shapes'], ['fig5', 'fig6'], ['fig7a', 'fig8']]
    """
    groups: dict = {}
    for name in dict.fromkeys(FIGURES if names is None else names):
        recipe = _recipe(name)
        groups.setdefault(recipe.data, []).append(recipe)
    ordered = sorted(groups.values(), key=lambda group: -sum(recipe.cost for recipe in group))
    return [[recipe.name for recipe in group] for group in ordered]


def figure_parts(names=None) -> list[list[Callable[[], xr.Dataset]]]:
    """The parts of each group's Dataset (:attr:`FigureRecipe.parts`), for parallel work.

    Parameters
    ----------
    names : iterable of str, optional
        As for :func:`figure_groups`.

    Returns
    -------
    parts : list of list of callable
        Per group of :func:`figure_groups` (empty for most), each computing a part into the cache.

    Raises
    ------
    ValueError
        As :func:`make_figure`.
    """
    return [list(_recipe(group[0]).parts) for group in figure_groups(names)]
