"""The paper's figures: what each draws, the numbers behind Figure 11, the `figures` command.

Each figure is drawn once per session from the registry's Datasets (paper parameters:
Δ* = x_o = 50 µm, P = 450 N, S = 35 MN/m, μ = 0.8) and its artists are inspected: number
of curves, plotted values in the tribologist's units, contour levels, labels, markers.
"""

import math
import re
import subprocess
import sys

import numpy as np
import pytest
from matplotlib.contour import ContourSet

import ecofmaps
from ecofmaps import figures
from ecofmaps.cli import main
from tests.brute_force import steady_loop

LOAD = 450.0
MU = 0.8


@pytest.fixture(scope="module")
def drawn():
    """Every registered figure of the model, drawn once, with the Dataset it was drawn from
    (the scar shapes' figure is tested in test_profile_figures)."""
    model = ("model_figures", "map_figures")
    names = [name for name, recipe in figures.FIGURES.items() if recipe.module in model]
    datasets = {name: figures.FIGURES[name].dataset() for name in names}
    return {name: (figure, datasets[name]) for name, figure in figures.make_figures(names)}


def _lines(ax):
    """The labelled curves of an axes (not the zero lines, not markers)."""
    return [line for line in _labelled(ax) if line.get_linestyle() != "None"]


def _markers(ax):
    """The labelled markers (points without a line) of an axes."""
    return [line for line in _labelled(ax) if line.get_linestyle() == "None"]


def _labelled(ax):
    return [line for line in ax.lines if not line.get_label().startswith("_")]


def _contour_sets(ax):
    """(filled, line) contour sets of μ_E/μ: the first filled set and the first line set."""
    sets = [c for c in ax.collections if isinstance(c, ContourSet)]
    filled = next(c for c in sets if c.filled)
    lines = next(c for c in sets if not c.filled)
    return filled, lines


def test_registry_names_match_the_issue():
    assert list(figures.FIGURES) == [
        "fig5", "fig6", "fig7a", "fig7b", "fig8", "fig11a", "fig11b", "universal", "shapes",
    ]  # fmt: skip


def test_every_axis_is_labelled_with_units(drawn):
    for name, (figure, _) in drawn.items():
        ax = figure.axes[0]
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            assert re.search(r"\[[^\]]+\]", label), (name, label)
        assert ax.get_title(), name
        assert ax.get_legend() is not None or figure.legends, name


def test_fig5_rigid_and_compliant_loops(drawn):
    figure, loops = drawn["fig5"]
    ax = figure.axes[0]
    curves = _lines(ax)
    assert len(curves) == 2
    assert "µm" in ax.get_xlabel() and "[N]" in ax.get_ylabel()
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert "rigid" in labels[0] and "35 MN/m" in labels[1]
    # Plotted in µm and N, from the Dataset's SI values.
    for curve, stiffness in zip(curves, (math.inf, 35e6), strict=True):
        loop = loops.sel(stiffness=stiffness)
        np.testing.assert_array_equal(curve.get_xdata(), loop.displacement.values * 1e6)
        np.testing.assert_array_equal(curve.get_ydata(), loop.force.values)
    # Both loops span the stroke ±Δ* = ±50 µm; the rigid one slips over all of it.
    for curve in curves:
        assert np.max(np.abs(curve.get_xdata())) == pytest.approx(50.0, rel=1e-12)
    assert float(loops.slip_amplitude.sel(stiffness=math.inf)) == pytest.approx(50e-6, rel=1e-15)
    assert float(loops.slip_amplitude.sel(stiffness=35e6)) < 50e-6
    # A right-hand axis reads the force as Q/P.
    secondary = [child for child in ax.child_axes if "Q/P" in child.get_ylabel()]
    assert len(secondary) == 1


def _shoelace(x, y):
    """Area enclosed by a closed polyline (any orientation)."""
    return abs(0.5 * np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]))


def test_fig6_loops_meet_the_line_q_equals_s_delta_at_mu_p(drawn):
    figure, loops = drawn["fig6"]
    ax = figure.axes[0]
    curves = _lines(ax)
    # four loops (z_o/x_o = 0, 0.1, 0.2, 0.3) and the line Q = SΔ
    assert len(curves) == 5
    np.testing.assert_array_equal(loops.aspect_ratio.values, [0.0, 0.1, 0.2, 0.3])
    line = curves[-1]
    slope = np.diff(line.get_ydata()) / np.diff(line.get_xdata() * 1e-6)
    assert slope[0] == pytest.approx(35e6, rel=1e-12)
    # the two common points, marked at Q = ±μP on the line (eq. 17-18)
    (points,) = _markers(ax)
    np.testing.assert_allclose(points.get_ydata(), [-MU * LOAD, MU * LOAD], rtol=1e-15)
    np.testing.assert_allclose(points.get_xdata() * 1e-6 * 35e6, points.get_ydata(), rtol=1e-12)
    # Every drawn loop crosses Q = SΔ exactly where Q = ±μP: find the crossings on the
    # polyline itself (linear interpolation between samples).
    for curve in curves[:-1]:
        displacement, force = curve.get_xdata() * 1e-6, curve.get_ydata()
        gap = force - 35e6 * displacement
        crossings = []
        for i in np.flatnonzero(np.sign(gap[:-1]) != np.sign(gap[1:])):
            t = gap[i] / (gap[i] - gap[i + 1])
            crossings.append(force[i] + t * (force[i + 1] - force[i]))
        crossings = np.unique(np.round(crossings, 9))
        np.testing.assert_allclose(crossings, [-MU * LOAD, MU * LOAD], rtol=1e-12)
    # Each loop's area is its dissipated energy (eq. 12); the polyline's shoelace area
    # differs from the exact one by the chords' sagitta, below 1e-5 relative at 201 points.
    for curve, ratio in zip(curves[:-1], loops.aspect_ratio.values, strict=True):
        area = _shoelace(curve.get_xdata() * 1e-6, curve.get_ydata())
        energy = float(loops.dissipated_energy.sel(aspect_ratio=ratio))
        assert area == pytest.approx(energy, rel=1e-5)


def _stiffness_legend(ax):
    return [text.get_text() for text in ax.get_legend().get_texts()]


@pytest.mark.parametrize(
    ("name", "variable", "scale", "unit"),
    [
        ("fig7a", "slip_amplitude", 1e6, "[µm]"),
        ("fig7b", "dissipated_energy", 1e3, "[mJ]"),
        ("fig8", "ecof_ratio", 1.0, "[1]"),
    ],
)
def test_fig7_fig8_one_curve_per_rig(drawn, name, variable, scale, unit):
    figure, dataset = drawn[name]
    ax = figure.axes[0]
    curves = _lines(ax)
    assert len(curves) == 5
    assert ax.get_ylabel().endswith(unit) and "z_o/x_o" in ax.get_xlabel()
    stiffnesses = dataset.stiffness_ratio.values * dataset["load"].values
    np.testing.assert_allclose(stiffnesses, [20e6, 35e6, 50e6, 100e6, math.inf], rtol=1e-15)
    for curve, index in zip(curves, range(5), strict=True):
        expected = dataset[variable].isel(stiffness_ratio=index).values * scale
        np.testing.assert_array_equal(curve.get_ydata(), expected)
    legend = _stiffness_legend(ax)
    rigs = ["$S$ = 100 MN/m", "$S$ = 50 MN/m", "$S$ = 35 MN/m", "$S$ = 20 MN/m"]
    assert legend[:5] == [r"rigid ($S = \infty$)", *rigs]


def test_fig7_statements_of_the_paper(drawn):
    # Fig. 7a: the rigid rig slips over the whole stroke, δ* = Δ* = 50 µm at every z_o/x_o;
    # compliant rigs slip less as z_o/x_o grows.
    _, dataset = drawn["fig7a"]
    slip = dataset.slip_amplitude.values
    np.testing.assert_allclose(slip[-1], 50e-6, rtol=1e-15)
    assert np.all(np.diff(slip[:-1], axis=1) < 0)
    # Fig. 7b: a stiffer rig always dissipates more; E_d grows with z_o/x_o for the rigid
    # rig and falls for S = 20 MN/m.
    energy = dataset.dissipated_energy.values
    assert np.all(np.diff(energy, axis=0) > 0)
    assert np.all(np.diff(energy[-1]) > 0)
    assert np.all(np.diff(energy[0]) < 0)


def test_fig8_marks_example_2_about_4_percent(drawn):
    figure, _ = drawn["fig8"]
    ax = figure.axes[0]
    (marker,) = _markers(ax)
    assert marker.get_xdata()[0] == 0.2
    value = marker.get_ydata()[0]
    exact = float(ecofmaps.energy_cof(50e-6, LOAD, 35e6, MU, 0.2)) / MU
    assert value == pytest.approx(exact, rel=1e-9)  # read off the map's grid at 0.2
    assert 1.03 < value < 1.05  # Section 4: "μ_E is only around 4 % higher than μ"
    assert any("Example 2" in text and "+3.8 %" in text for text in _stiffness_legend(ax))


@pytest.mark.parametrize(
    ("name", "amplitude", "levels"),
    [
        ("fig11a", 25e-6, (1.01, 1.02, 1.03, 1.04, 1.05, 1.06, 1.08)),
        ("fig11b", 50e-6, (1.01, 1.02, 1.03, 1.04, 1.05, 1.06, 1.08, 1.10, 1.12)),
    ],
)
def test_fig11_labelled_contours(drawn, name, amplitude, levels):
    figure, dataset = drawn[name]
    ax = figure.axes[0]
    assert float(dataset.amplitude) == amplitude and float(dataset.mu) == MU
    filled, lines = _contour_sets(ax)
    np.testing.assert_allclose(lines.levels, levels)
    labels = {text.get_text() for text in lines.labelTexts}
    assert {f"{level:.2f}" for level in levels} <= labels
    assert "S/P" in ax.get_xlabel() and "1/mm" in ax.get_xlabel()
    # x in (MN/m)/kN = 1/mm: 20 to 200
    x = dataset.stiffness_ratio.values * 1e-3
    assert ax.get_xlim() == pytest.approx((x[0], x[-1]))
    assert (x[0], x[-1]) == pytest.approx((20.0, 200.0), rel=1e-15)
    # the filled levels bracket the data
    top = float(dataset.ecof_ratio.max())
    assert filled.levels[0] == 1.0 and filled.levels[-1] >= top


def test_fig11_ranges_show_the_papers_statements(drawn):
    # Section 6: "variations of up to 13 % are seen in the most extreme cases"
    _, map_50 = drawn["fig11b"]
    assert 1.12 < float(map_50.ecof_ratio.max()) < 1.14
    _, map_25 = drawn["fig11a"]
    assert float(map_25.ecof_ratio.max()) < float(map_50.ecof_ratio.max())
    # ... "the majority of tests reside in the region where the difference is below 5 %":
    # Example 2 (S = 35 MN/m, P = 450 N, z_o/x_o = 0.2, a particularly deep scar) is inside.
    example = map_50.ecof_ratio.interp(stiffness_ratio=35e6 / LOAD, aspect_ratio=0.2)
    assert float(example) < 1.05
    # Δ* = 25 µm has no gross slip below S/P = μ/Δ* = 32 /mm; the map hatches it.
    stuck = map_25.regime == ecofmaps.NO_GROSS_SLIP
    assert bool(stuck.any())
    assert float(map_25.stiffness_ratio.where(stuck.any("aspect_ratio")).max()) <= MU / 25e-6
    figure, _ = drawn["fig11a"]
    labels = [text.get_text() for text in figure.axes[0].get_legend().get_texts()]
    assert any("no gross slip" in label for label in labels)


# Sample points of Figure 11's grids: corners, the middle, Example 2 (index along S/P,
# index along z_o/x_o). Brute force: brentq on eq. 16 and quad of eq. 12.
_SAMPLES = [(0, 0), (0, 60), (90, 60), (90, 1), (45, 30), (29, 40), (7, 13)]


@pytest.mark.parametrize("name", ["fig11a", "fig11b"])
def test_fig11_data_against_brute_force(drawn, name):
    _, dataset = drawn[name]
    amplitude = float(dataset.amplitude)
    checked = 0
    for i, j in _SAMPLES:
        point = dataset.isel(stiffness_ratio=i, aspect_ratio=j)
        # S/P is what the map holds; any load gives the same ratios (take P = 450 N).
        stiffness = float(point.stiffness_ratio) * LOAD
        reference = steady_loop(amplitude, LOAD, stiffness, MU, float(point.aspect_ratio))
        if reference["slip_amplitude"] == 0.0:  # no gross slip: μ_E undefined
            assert int(point.regime) == ecofmaps.NO_GROSS_SLIP
            assert math.isnan(float(point.ecof_ratio))
            continue
        assert float(point.slip_amplitude) == pytest.approx(reference["slip_amplitude"], rel=1e-12)
        assert float(point.ecof_ratio) == pytest.approx(reference["ecof"] / MU, rel=1e-10)
        checked += 1
    assert checked >= 5


def test_fig11_panels_are_one_surface(drawn):
    # μ_E/μ depends on S/P and Δ* only through λ = P/(SΔ*): Δ* = 25 µm at S/P equals
    # Δ* = 50 µm at S/P/2 (grids of step 2 /mm: 40, 44, ... at 25 µm are 20, 22, ... at 50 µm).
    _, map_25 = drawn["fig11a"]
    _, map_50 = drawn["fig11b"]
    high = map_25.ecof_ratio.sel(stiffness_ratio=slice(40e3, 200e3)).values[::2]
    low = map_50.ecof_ratio.sel(stiffness_ratio=slice(20e3, 100e3)).values
    np.testing.assert_allclose(high, low, rtol=1e-12)


def test_universal_map(drawn):
    figure, dataset = drawn["universal"]
    ax = figure.axes[0]
    assert ax.get_xscale() == "log"
    assert "λ" in ax.get_xlabel() or "lambda" in ax.get_xlabel()
    _, lines = _contour_sets(ax)
    assert 1.05 in lines.levels and len(lines.levels) >= 10
    # Examples 1 and 2 (Figure 10: S = 45 and 35 MN/m, z_o = 1.8 and 8.0 µm, μ = 0.825)
    # and Example 2 as in Section 3 (z_o/x_o = 0.2, μ = 0.8), at λ = P/(SΔ*).
    markers = sorted((m.get_xdata()[0], m.get_ydata()[0]) for m in _markers(ax))
    expected = sorted(
        [(450 / (45e6 * 50e-6), 0.036), (450 / (35e6 * 50e-6), 0.16), (450 / (35e6 * 50e-6), 0.2)]
    )
    np.testing.assert_allclose(markers, expected, rtol=1e-12)
    legend = [text.get_text() for text in figure.legends[0].get_texts()]
    assert sum("Example" in text for text in legend) == 3
    # The Example 2 (Section 3) point on the map agrees with its own μ_E/μ.
    value = dataset.ecof_ratio.interp(compliance_ratio=expected[1][0], aspect_ratio=0.2)
    assert float(value) == pytest.approx(1.0385, abs=2e-4)
    # The title says why one chart holds both panels of Figure 11.
    assert "same" in ax.get_title() and "11a" in ax.get_title()


def test_universal_map_matches_fig11(drawn):
    # The same λ gives the same μ_E/μ: read the universal map at λ = 1/((S/P) Δ*) of
    # Figure 11b's grid (interpolation along log-spaced λ, so to 1e-3).
    _, universal = drawn["universal"]
    _, map_50 = drawn["fig11b"]
    lam = 1.0 / (map_50.stiffness_ratio.values * 50e-6)
    read = universal.ecof_ratio.interp(compliance_ratio=lam, aspect_ratio=map_50.aspect_ratio)
    np.testing.assert_allclose(read.values, map_50.ecof_ratio.values, rtol=1e-3)


def test_figures_draw_what_they_are_given_and_nothing_else(drawn):
    """Pure functions of their Dataset and arguments: no marker guessed from the data."""
    _, dataset = drawn["fig11b"]
    ax = figures.ecof_ratio_contours(dataset).axes[0]
    assert _markers(ax) == [] and ax.get_title().startswith("Fig. 11 ")
    rig = {"a 60 MN/m rig": dict(stiffness=60e6, load=500.0, aspect_ratio=0.1)}
    ax = figures.ecof_ratio_contours(dataset, number="11x", markers=rig).axes[0]
    (marker,) = _markers(ax)
    assert (marker.get_xdata()[0], marker.get_ydata()[0]) == (60e6 / 500.0 * 1e-3, 0.1)
    assert "a 60 MN/m rig" in marker.get_label() and ax.get_title().startswith("Fig. 11x ")
    _, dataset = drawn["fig8"]
    assert _markers(figures.ecof_ratio_curves(dataset).axes[0]) == []
    _, dataset = drawn["universal"]
    figure = figures.universal_ecof_ratio_map(dataset)
    assert _markers(figure.axes[0]) == []
    # The map does not depend on the load: its title does not print one.
    assert "P =" not in figure.axes[0].get_title() and "windows" not in figure.axes[0].get_title()


def test_make_figures_rejects_unknown_names():
    with pytest.raises(ValueError, match=r"unknown figure 'fig9'; valid names: fig5, fig6"):
        list(figures.make_figures(["fig8", "fig9"]))


def test_save_figure_is_atomic(tmp_path, drawn):
    figure, _ = drawn["fig8"]
    path = figures.save_figure(figure, tmp_path / "fig8.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # A failing write leaves the existing file as it was and no temporary file behind.
    target = tmp_path / "fig8.xyz"
    target.write_text("old")
    with pytest.raises(ValueError, match="xyz"):
        figures.save_figure(figure, target)
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig8.png", "fig8.xyz"]


# --- the command -----------------------------------------------------------------------------


@pytest.mark.slow
def test_command_writes_the_figures(tmp_path, capsys):
    out = tmp_path / "new" / "figures"
    status = main(["figures", "--out", str(out), "--only", "fig8", "fig11b", "--format", "png,svg"])
    assert status == 0
    # the manifest lists what ecofmaps wrote there
    assert sorted(p.name for p in out.iterdir()) == [
        ".ecofmaps-manifest.json", "fig11b.png", "fig11b.svg", "fig8.png", "fig8.svg",
    ]  # fmt: skip
    assert (out / "fig8.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "<svg" in (out / "fig11b.svg").read_text()
    captured = capsys.readouterr()
    assert captured.out == ""
    progress = captured.err.splitlines()
    # Drawn by two processes (one per core, one per Dataset): in the order they finish.
    assert sorted(line.split()[1] for line in progress[1:3]) == ["fig11b", "fig8"]
    assert all(" s " in line for line in progress[1:3])


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--only", "fig9"], "invalid choice: 'fig9' (choose from 'fig5', 'fig6', 'fig7a'"),
        (["--format", "png,jpg"], "unknown figure format 'jpg'"),
        (["--format", ""], "give one or more of png, pdf, svg"),
    ],
)
def test_command_rejects_bad_options(tmp_path, capsys, arguments, message):
    assert main(["figures", "--out", str(tmp_path), *arguments]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and err.startswith("ecofmaps: error: ")
    assert list(tmp_path.iterdir()) == []


def test_command_reports_an_unusable_directory(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["figures", "--out", str(blocker), "--only", "fig8"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ecofmaps: error:") and len(err.strip().splitlines()) == 1


def test_figures_are_loaded_on_first_use_only():
    # `import ecofmaps` pays for neither JAX nor matplotlib; the registry of figures reads
    # without them (so `ecofmaps --help` is quick); drawing loads them.
    code = (
        "import sys, ecofmaps\n"
        "assert 'matplotlib' not in sys.modules, 'import ecofmaps pulled in matplotlib'\n"
        "assert 'fig11b' in ecofmaps.figures.FIGURES\n"
        "assert 'matplotlib' not in sys.modules and 'jax' not in sys.modules\n"
        "assert callable(ecofmaps.figures.save_figure) and 'matplotlib' in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
