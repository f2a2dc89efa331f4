"""Every figure is clean: its words inside the canvas, no warning while drawn, numbers readable.

Each figure function is drawn (and rendered) with every warning an error, so a legend
asked for with no labelled artist fails the test; then every title, axis label, legend
text and annotation must lie inside the figure (tick labels outside the view limits are
never drawn, so they are left out).
"""

import warnings

import numpy as np
import pytest
from matplotlib.axis import Axis
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.text import Text

import ecofmaps
from ecofmaps import figures, paper
from ecofmaps.figures import (
    cof_evolution,
    measured_and_fitted_loops,
    measured_loops,
    resolved_loops,
    scar_profile_figure,
)
from ecofmaps.figures.style import number_text, stiffness_label
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.fit import fit_loop
from ecofmaps.measured.quality import add_reason
from ecofmaps.measured.resolve import resolve_analyzed_loops
from ecofmaps.measured.synthetic import synthetic_recording

LOAD = 450.0


def texts_outside(figure) -> list[str]:
    """The drawn words of ``figure`` (not tick labels) that reach beyond its canvas."""
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    renderer = canvas.get_renderer()
    ticks = {
        id(label) for axis in figure.findobj(Axis) for label in axis.get_ticklabels(which="both")
    }
    box = figure.bbox
    outside = []
    for text in figure.findobj(Text):
        if id(text) in ticks or not text.get_visible() or not text.get_text():
            continue
        extent = text.get_window_extent(renderer)
        if (
            extent.x0 < box.x0 - 0.5
            or extent.y0 < box.y0 - 0.5
            or extent.x1 > box.x1 + 0.5
            or extent.y1 > box.y1 + 0.5
        ):
            outside.append(text.get_text())
    return outside


def drawn_cleanly(make):
    """The figure ``make()`` returns, drawn and rendered with every warning an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        figure = make()
        assert texts_outside(figure) == []
    return figure


@pytest.fixture(scope="module")
def results():
    """Nine cycles whose groove deepens from flat to z_o/x_o = 0.3."""
    displacement, force = synthetic_recording(
        amplitude=50e-6, load=LOAD, stiffness=35e6, mu=0.8, aspect_ratio=np.linspace(0, 0.3, 9)
    )
    return analyze_loops(displacement, force, LOAD, keep_loops=True)


def test_the_helper_finds_a_clipped_title():
    """The check itself: a title wider than its figure is found, one that fits is not."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(3.0, 2.0), layout="constrained")
    figure.add_subplot().set_title("a title far too long for a figure three inches wide " * 2)
    assert len(texts_outside(figure)) == 1
    figure.axes[0].set_title("short")
    assert texts_outside(figure) == []


@pytest.mark.slow
@pytest.mark.parametrize("name", list(figures.FIGURES))
def test_registered_figures_are_clean(name):
    recipe = figures.FIGURES[name]
    dataset = recipe.data()  # from the session's cache after the first test that needs it
    drawn_cleanly(lambda: recipe.figure(dataset))


def test_a_single_cycle_keeps_its_titles_inside(results):
    first = int(results.cycle[0])
    figure = drawn_cleanly(lambda: measured_loops(results, cycles=[first]))
    assert figure.get_suptitle().startswith("Measured loops")
    drawn_cleanly(lambda: measured_loops(results))


def test_measured_figures_are_clean(results):
    drawn_cleanly(lambda: cof_evolution(results))
    resolved = resolve_analyzed_loops(results)
    drawn_cleanly(lambda: resolved_loops(resolved, results))
    profile = ecofmaps.parabolic_profile(10e-6, 50e-6)
    drawn_cleanly(lambda: scar_profile_figure(profile, "a parabola"))


def test_fitted_loops_are_clean():
    loops = {}
    for name, parameters in paper.FIGURE_10_FITS.items():
        displacement, force = ecofmaps.fretting_loop(**parameters)
        loops[name] = fit_loop(np.asarray(displacement), np.asarray(force), parameters["load"])
    figure = drawn_cleanly(lambda: measured_and_fitted_loops(loops))
    assert len([ax for ax in figure.axes if ax.get_legend()]) == len(loops)


def test_resolved_loops_without_a_read_cycle_draws_no_empty_legend(results):
    """No cycle of quality 'ok': panel (a) says so instead of an empty legend (a warning)."""
    unread = results.copy()
    everywhere = np.ones(unread.cycle.size, dtype=bool)
    unread["quality"] = unread["quality"].copy(
        data=add_reason(unread["quality"].values, everywhere, "partial-slip")
    )
    figure = drawn_cleanly(lambda: resolved_loops(resolve_analyzed_loops(unread)))
    stroke = figure.axes[0]
    assert stroke.get_legend() is None
    assert any("no cycle was read" in text.get_text() for text in stroke.texts)


@pytest.mark.parametrize(
    ("stiffness", "text"),
    [(35e6, "$S$ = 35 MN/m"), (0.02e6, "$S$ = 0.02 MN/m"), (35.04e6, "$S$ = 35 MN/m"),
     (123.456e6, "$S$ = 123 MN/m"), (np.inf, r"rigid ($S = \infty$)"), (2500e6, "$S$ = 2500 MN/m")],
)  # fmt: skip
def test_stiffness_label_has_sensible_digits(stiffness, text):
    assert stiffness_label(stiffness) == text


def test_number_text():
    assert [number_text(v) for v in (0.0123456, 9.996, -1.5, 1e-7)] == [
        "0.0123", "10", "-1.5", "0.0000001",
    ]  # fmt: skip
    assert number_text(3.14159, digits=2) == "3.1"
    assert number_text(np.nan) == "–" and number_text(-np.inf) == "−∞"


def test_a_soft_rig_is_labelled_in_its_own_digits(results):
    """A measured stiffness of 0.02 MN/m read "S = 0.0 MN/m" before; S is italic."""
    soft = results.copy()
    soft["stiffness"] = soft["stiffness"] * 0.0 + 0.02e6
    figure = measured_loops(soft, cycles=[int(soft.cycle[0])])
    assert "$S$ = 0.02 MN/m" in figure.axes[0].get_title()
    assert stiffness_label(np.inf) == r"rigid ($S = \infty$)"


def test_figures_label_stiffness_with_the_shared_helper():
    """Figure 5's legend and Figure 6's title: 35 MN/m with S italic, the rigid rig by name."""
    recipe = figures.FIGURES["fig6"]
    figure = recipe.figure(recipe.data())
    assert "$S$ = 35 MN/m" in figure.axes[0].get_title()
    recipe = figures.FIGURES["fig5"]
    labels = [t.get_text() for t in recipe.figure(recipe.data()).axes[0].get_legend().get_texts()]
    assert labels[0].startswith("rigid") and labels[1].startswith("$S$ = 35 MN/m:")
