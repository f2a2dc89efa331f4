"""Figures of scar profiles: a read profile as the model sees it, and the scar shapes figure.

The shapes figure's Dataset is checked against the model (the parabolic family on the
parabola's closed form, the D/W shortcut's error against a correction done here), and the
drawn artists against the Dataset.
"""

import warnings

import numpy as np
import pytest
from matplotlib.figure import Figure

import ecofmaps
from ecofmaps import figures, paper
from ecofmaps.cli import main
from ecofmaps.measured.synthetic import scar_example_path


def _labelled(ax):
    return [line for line in ax.lines if not line.get_label().startswith("_")]


def _drawn(function, *args, **kwargs) -> Figure:
    """Draw with every warning an error, and render (layout warnings come at drawing)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        figure = function(*args, **kwargs)
        figure.canvas.draw()
    return figure


# --- a read profile ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def example():
    return ecofmaps.read_scar_profile(scar_example_path())


def test_profile_figure_draws_heights_edges_and_slope(example):
    figure = _drawn(figures.scar_profile_figure, example, name="synthetic_scar_profile.csv")
    top, bottom = figure.axes
    assert top.get_ylabel() == "Height of the scar profile $z$ [µm]"
    assert bottom.get_ylabel() == "Slope of the scar profile $g = dz/dX$ [1]"
    assert bottom.get_xlabel().startswith("Position across the scar $X$ [µm]")
    title = top.get_title()
    assert "synthetic_scar_profile.csv" in title and "$W$ = 500.4 µm" in title
    assert f"$D/W$ = {float(example.aspect_ratio):.3g}" in title
    labels = [line.get_label() for line in _labelled(top)]
    assert labels[:3] == ["profile $z(X)$", "unworn surface (levelling line)",
                          "parabola of the same $D/W$"]  # fmt: skip
    x_um = np.asarray(example.position) * 1e6
    profile_line, slope_line = _labelled(top)[0], _labelled(bottom)[0]
    np.testing.assert_allclose(profile_line.get_xdata(), x_um)
    np.testing.assert_allclose(profile_line.get_ydata(), np.asarray(example.height) * 1e6)
    np.testing.assert_allclose(slope_line.get_ydata(), np.asarray(example.slope))
    for ax in (top, bottom):  # the edges ±W
        edges = [line.get_xdata()[0] for line in ax.lines if line.get_linestyle() == ":"]
        assert edges == pytest.approx([-float(example.half_width) * 1e6,
                                       float(example.half_width) * 1e6])  # fmt: skip
    # The parabola's slope 2DX/W^2 across the scar (up to 2D/W = 0.32 at the edges).
    parabola = _labelled(bottom)[1]
    x, g = parabola.get_xdata() * 1e-6, parabola.get_ydata()
    depth, width = float(example.depth), float(example.half_width)
    np.testing.assert_allclose(g, 2 * depth * x / width**2, rtol=1e-12)
    assert x.min() == pytest.approx(-width, abs=2e-6) and x.max() == pytest.approx(width, abs=2e-6)


def test_profile_figure_of_a_tilted_profile_draws_the_tilted_surface(example):
    tilted = ecofmaps.read_scar_profile(scar_example_path(), level=False)
    figure = _drawn(figures.scar_profile_figure, tilted)
    surface = _labelled(figure.axes[0])[1]
    x, z = surface.get_xdata(), surface.get_ydata()
    assert (z[-1] - z[0]) / (x[-1] - x[0]) == pytest.approx(float(tilted.reference_slope))
    assert float(tilted.reference_slope) == pytest.approx(0.004, rel=0.05)  # the file's tilt
    assert figure.axes[0].get_title().startswith("Wear-scar profile\n")


def test_profile_figure_refuses_a_batch():
    profile = ecofmaps.parabolic_profile(10e-6, 50e-6, samples=101)
    batch = type(profile)(*(np.stack([leaf, leaf]) for leaf in profile))
    with pytest.raises(ValueError, match="one profile, not a batch"):
        figures.scar_profile_figure(batch)


# --- the shapes figure ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def shapes():
    recipe = figures.FIGURES["shapes"]
    dataset = recipe.dataset()
    return _drawn(recipe.figure, dataset), dataset


def test_shapes_dataset_against_the_model(shapes):
    _, dataset = shapes
    assert list(dataset["shape"].values) == ["parabolic", "flat-bottomed", "W-shaped", "ridged"]
    for name in dataset.variables:  # attrs from the nomenclature
        assert {"long_name", "units"} <= set(dataset[name].attrs), name
    assert float(dataset.scar_depth / dataset.scar_half_width) == paper.ASPECT_RATIO
    # The parabolic family is the parabola (analytic family: within 1e-10).
    parabolic = dataset.sel(shape="parabolic")
    np.testing.assert_allclose(parabolic.ecof_ratio.sel(groove="profile"),
                               parabolic.ecof_ratio.sel(groove="parabola"), rtol=1e-10)  # fmt: skip
    np.testing.assert_allclose(parabolic.shortcut_error, 0.0, atol=1e-9)
    # Example 2 on the parabola: μ_E/μ = 1.0385 (Section 4, about 4 %), δ* = 32.73 µm.
    example = parabolic.sel(groove="parabola")
    assert float(example.ecof) / paper.MU == pytest.approx(1.03850, abs=5e-5)
    assert float(example.slip_amplitude) == pytest.approx(32.7302e-6, rel=1e-5)
    # The shortcut's error, recomputed: the profile's μ_E corrected with the parabola.
    flat = dataset.sel(shape="flat-bottomed")
    ecof = paper.MU * flat.ecof_ratio.sel(groove="profile").values
    ratio = dataset.stiffness_ratio.values
    mu = ecofmaps.correct_ecof(ecof, paper.AMPLITUDE, paper.LOAD, ratio * paper.LOAD, 0.2)
    np.testing.assert_allclose(flat.shortcut_error, mu / paper.MU - 1.0, rtol=1e-12)
    # A flat bottom biases μ_E less than the parabola (about half at Example 2).
    at_example = dict(stiffness_ratio=paper.STIFFNESS / paper.LOAD)
    bias = (dataset.ecof_ratio.sel(**at_example) - 1.0).sel(shape="flat-bottomed")
    assert 0.1 < float(bias.sel(groove="profile") / bias.sel(groove="parabola")) < 0.5
    assert float(flat.ecof.sel(groove="profile")) == pytest.approx(
        float(ecofmaps.energy_cof(paper.AMPLITUDE, paper.LOAD, paper.STIFFNESS, paper.MU,
                                  profile=ecofmaps.flat_bottomed_profile(10e-6, 50e-6))),
        rel=1e-12)  # fmt: skip
    # The ridges lie beyond the pad's reach (δ* < Δ* = x_o): the ridged loop is the parabola's.
    ridged = dataset.sel(shape="ridged")
    np.testing.assert_allclose(ridged.force.sel(groove="profile"),
                               ridged.force.sel(groove="parabola"), rtol=1e-9)  # fmt: skip


def test_shapes_figure_draws_every_shape(shapes):
    figure, dataset = shapes
    panels = [ax for ax in figure.axes if not ax.get_ylabel().startswith("$Q/P$")]
    ax_shapes, *loops, ax_ratio, ax_error = panels
    assert len(loops) == 3
    assert [line.get_label() for line in _labelled(ax_shapes)] == list(dataset["shape"].values)
    for ax, shape in zip(loops, ["flat-bottomed", "W-shaped", "ridged"], strict=True):
        assert (
            ax.get_title() == f"{shape} scar"
            and ax.get_xlabel() == "Applied displacement $\\Delta$ [µm]"
        )
        profile_line, parabola_line = _labelled(ax)
        delta = float(dataset.slip_amplitude.sel(shape=shape, groove="profile")) * 1e6
        assert f"= {delta:.1f} µm" in profile_line.get_label()
        assert parabola_line.get_linestyle() == "--"
        np.testing.assert_allclose(profile_line.get_ydata(),
                                   dataset.force.sel(shape=shape, groove="profile"))  # fmt: skip
    assert loops[0].get_ylabel() == "Tangential force $Q$ [N]"
    assert any("beyond the pad's reach" in text.get_text() for text in loops[2].texts)
    assert not any(text.get_text() for text in loops[0].texts)
    assert ax_ratio.get_ylabel() == "$\\mu_E/\\mu$ [1]"
    assert ax_ratio.get_xlabel().startswith("Stiffness over load $S/P$")
    assert "[%]" in ax_error.get_ylabel()
    assert len(_labelled(ax_ratio)) == 1 + 4 + 1  # the parabola, four shapes, Example 2
    errors = {line.get_label(): line for line in _labelled(ax_error)}
    flat = errors["flat-bottomed scar"].get_ydata()
    np.testing.assert_allclose(flat, dataset.shortcut_error.sel(shape="flat-bottomed") * 100)


@pytest.mark.slow
def test_shapes_figure_from_the_command(tmp_path, capsys):
    assert main(["figures", "--out", str(tmp_path), "--only", "shapes"]) == 0
    assert (tmp_path / "shapes.png").stat().st_size > 10_000
    assert "shapes" in capsys.readouterr().err
