"""The figures of measured loops: the loops with Q = SΔ and the friction over the test, drawn
from the Dataset."""

import re
import warnings

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from ecofmaps.figures import cof_evolution, measured_loops, resolved_loops, save_figure
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.quality import add_reason
from ecofmaps.measured.resolve import resolve_analyzed_loops
from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.model.regimes import GROSS_SLIP

LOAD = 450.0


@pytest.fixture(scope="module")
def results():
    """Nine cycles whose groove deepens from flat to z_o/x_o = 0.3."""
    displacement, force = synthetic_recording(
        amplitude=50e-6,
        load=LOAD,
        stiffness=35e6,
        mu=0.8,
        aspect_ratio=np.linspace(0.0, 0.3, 9),
    )
    return analyze_loops(displacement, force, LOAD, keep_loops=True)


def test_measured_loops(results, tmp_path):
    """One panel per cycle: the loop in µm and N, the line Q = SΔ, the two crossings."""
    figure = measured_loops(results)
    panels = [ax for ax in figure.axes if ax.get_visible()]
    assert len(panels) == 6  # six of the nine cycles, the first and the last included
    assert panels[0].get_title().startswith(f"cycle {int(results.cycle[0])}:")
    assert panels[-1].get_title().startswith(f"cycle {int(results.cycle[-1])}:")
    assert "[µm]" in panels[-1].get_xlabel() and "[N]" in panels[0].get_ylabel()
    loop, line, crossings = panels[-1].get_lines()[:3]
    last = results.isel(cycle=-1)
    np.testing.assert_allclose(loop.get_xdata(), last.loop_displacement * 1e6)
    x, q = line.get_xydata().T
    np.testing.assert_allclose(q, float(last.stiffness) * x * 1e-6, rtol=1e-12)  # Q = SΔ
    np.testing.assert_allclose(
        crossings.get_ydata(), [last.gicof_forward * LOAD, -last.gicof_backward * LOAD]
    )
    np.testing.assert_allclose(
        crossings.get_xdata(),
        [last.crossing_displacement_forward * 1e6, last.crossing_displacement_backward * 1e6],
    )
    assert [t.get_text() for t in figure.legends[0].get_texts()] == [
        "measured loop",
        "$Q = S\\Delta$",
        "GICoF crossings",
    ]
    path = save_figure(measured_loops(results, cycles=[2, 3], columns=2), tmp_path / "l.png")
    assert path.read_bytes()[:4] == b"\x89PNG"


def test_cof_evolution(results):
    """Figure 9: ECoF and GICoF against the cycle, and the ECoF's excess in %."""
    figure = cof_evolution(results)
    top, bottom = figure.axes
    ecof, gicof = top.get_lines()
    np.testing.assert_allclose(ecof.get_ydata(), results.ecof)
    np.testing.assert_allclose(gicof.get_ydata(), results.gicof)
    np.testing.assert_array_equal(gicof.get_xdata(), results.cycle)
    excess = bottom.get_lines()[0].get_ydata()
    np.testing.assert_allclose(excess, (results.ecof / results.gicof - 1) * 100)
    assert excess[-1] > 3.0  # z_o/x_o = 0.3 at S = 35 MN/m: μ_E well above μ
    assert bottom.get_xlabel() == "Cycle number [1]" and "[1]" in top.get_ylabel()
    assert figure.get_suptitle().startswith("The ECoF and the GICoF over the cycles\n")


def test_measured_loops_needs_the_loops(results):
    with pytest.raises(ValueError, match="keep_loops=True"):
        measured_loops(results.drop_vars(["loop_displacement", "loop_force"]))


def test_resolved_loops_draws_the_datasets_numbers(results, tmp_path):
    """μ(ξ) and h(ξ) of chosen cycles in µm, h over (position, cycle), μ over the test."""
    resolved = resolve_analyzed_loops(results)
    figure = resolved_loops(resolved, results)
    stroke, felt, image, test = figure.axes[:4]  # then the colour bar and the twin axis
    last = resolved.where(resolved.quality == "ok", drop=True).isel(cycle=-1)
    name = f"cycle {last.cycle.item()}"
    (mu,) = [line for line in stroke.get_lines() if line.get_label() == name]
    np.testing.assert_allclose(mu.get_xdata(), resolved.position * 1e6)
    np.testing.assert_allclose(mu.get_ydata(), last.mu)
    (profile,) = [line for line in felt.get_lines() if line.get_label() == name]
    np.testing.assert_allclose(profile.get_ydata(), last.felt_profile * 1e6)
    assert "[µm]" in stroke.get_xlabel() and "[µm]" in felt.get_ylabel()
    assert image.get_ylabel() == "Cycle number [1]"
    series = {line.get_label(): line for line in test.get_lines()}
    np.testing.assert_allclose(series["GICoF"].get_ydata(), results.gicof)
    np.testing.assert_allclose(series[r"$\mu$ read along the stroke"].get_ydata(),
                               resolved.mu_resolved)  # fmt: skip
    save_figure(figure, tmp_path / "resolved.png")


def test_resolved_loops_marks_cycles_without_a_value(results):
    partial = results.copy()
    third = np.arange(partial.cycle.size) == 2
    partial["quality"] = partial["quality"].copy(
        data=add_reason(partial["quality"].values, third, "partial-slip")
    )
    resolved = resolve_analyzed_loops(partial)
    test = resolved_loops(resolved).axes[3]
    (marks,) = [line for line in test.get_lines() if "no resolved value" in line.get_label()]
    assert "partial-slip" in marks.get_label()
    assert 3 in marks.get_xdata()  # the third cycle's number


# --- ugly recordings: microslip, a single cycle, every cycle flagged ------------------------


def quiet_analysis(displacement, force, load):
    """analyze_loops with its quality warnings silenced (the figures are under test)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyze_loops(displacement, force, load, keep_loops=True)


@pytest.fixture(scope="module")
def microslip():
    """Six cycles of 5 µm: no gross slip, some flagged three times over."""
    displacement, force = synthetic_recording(amplitude=5e-6, load=LOAD, stiffness=35e6, mu=0.8,
        aspect_ratio=0.0, cycles=6, force_noise=3.0, displacement_noise=0.05e-6)  # fmt: skip
    results = quiet_analysis(displacement, force, LOAD)
    assert (results.quality != "ok").all() and (results.regime != GROSS_SLIP).all()
    assert "negative-area+negative-slip+partial-slip" in results.quality.values
    return results


@pytest.fixture(scope="module")
def single():
    """One gross-slip cycle."""
    displacement, force = synthetic_recording(
        amplitude=50e-6, load=LOAD, stiffness=35e6, mu=0.8, aspect_ratio=0.15, cycles=1
    )
    results = quiet_analysis(displacement, force, LOAD)
    assert results.cycle.size == 1 and results.quality.item() == "ok"
    return results


@pytest.fixture(scope="module")
def flagged():
    """Four cycles read with a load 450 times too small: every one implausible."""
    displacement, force = synthetic_recording(
        amplitude=50e-6, load=LOAD, stiffness=35e6, mu=0.8, aspect_ratio=0.15, cycles=4
    )
    results = quiet_analysis(displacement, force, 1.0)
    assert (results.quality == "implausible-cof").all()
    return results


def rendered(figure):
    """``figure`` drawn, and its renderer."""
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    return canvas.get_renderer()


def drawn_labels(ax) -> list[str]:
    """The labels of the artists drawn in ``ax`` that a legend would list."""
    return ax.get_legend_handles_labels()[1]


def integer_ticks(axis) -> np.ndarray:
    """The tick positions of ``axis`` within its view limits."""
    low, high = sorted(axis.get_view_interval())
    ticks = np.asarray(axis.get_majorticklocs())
    return ticks[(ticks >= low - 1e-9) & (ticks <= high + 1e-9)]


@pytest.mark.filterwarnings("error")
def test_loop_titles_fit_side_by_side_with_flags_on_their_own_line(microslip):
    """Three flags on one cycle: every panel title inside the figure, none overlapping."""
    figure = measured_loops(microslip)
    renderer = rendered(figure)
    panels = [ax for ax in figure.axes if ax.get_visible()]
    boxes = [ax.title.get_window_extent(renderer) for ax in panels]
    inside = figure.bbox
    for box in boxes:
        assert inside.x0 - 0.5 <= box.x0 and box.x1 <= inside.x1 + 0.5
        assert inside.y0 - 0.5 <= box.y0 and box.y1 <= inside.y1 + 0.5
    for index, box in enumerate(boxes):
        assert not any(box.overlaps(other) for other in boxes[index + 1 :])
    titles = [ax.get_title() for ax in panels]
    assert any("flagged: negative-area, negative-slip, partial-slip" in t for t in titles)


@pytest.mark.filterwarnings("error")
def test_loop_legend_lists_only_what_is_drawn(microslip, results):
    """No GICoF without gross slip: no crossings drawn, and none in the legend."""
    figure = measured_loops(microslip)
    rendered(figure)
    legend = [t.get_text() for t in figure.legends[0].get_texts()]
    assert legend == ["measured loop", r"$Q = S\Delta$"]
    drawn = {label for ax in figure.axes for label in drawn_labels(ax)}
    assert set(legend) == drawn
    gross = measured_loops(results)
    assert "GICoF crossings" in [t.get_text() for t in gross.legends[0].get_texts()]


@pytest.mark.filterwarnings("error")
def test_loops_above_a_hidden_panel_keep_their_displacement_scale(flagged):
    """Four cycles in rows of three: the panels of cycles 2 and 3 have none below them, and
    show their displacement ticks and label; cycle 1's panel, above cycle 4's, does not."""
    figure = measured_loops(flagged)
    rendered(figure)
    panels = [ax for ax in figure.axes if ax.get_visible()]
    assert len(panels) == 4
    for panel, lowest in zip(panels, [False, True, True, True], strict=True):
        labels = [label.get_text() for label in panel.get_xticklabels() if label.get_visible()]
        assert bool(labels) == lowest and bool(panel.get_xlabel()) == lowest, panel.get_title()
        if lowest:
            assert "[µm]" in panel.get_xlabel()


def test_flags_of_a_title_are_shortened_when_long(microslip):
    """More flags than fit beside each other: the first and how many more."""
    many = microslip.copy()
    threefold = many.quality.values == "negative-area+negative-slip+partial-slip"
    many["quality"] = many["quality"].copy(
        data=add_reason(many["quality"].values, threefold, "implausible-cof")
    )
    label = int(many.cycle[threefold][0])
    (panel,) = measured_loops(many, cycles=[label]).axes
    assert panel.get_title().endswith("\nflagged: negative-area and 3 more")


@pytest.mark.filterwarnings("error")
def test_single_cycle_figures_show_the_cycle(single):
    """One cycle: integer cycle ticks, (c) a band of h over the positions, (d) μ ± 2 se."""
    evolution = cof_evolution(single)
    rendered(evolution)
    ticks = integer_ticks(evolution.axes[1].xaxis)
    assert ticks.size >= 1 and np.all(ticks == np.round(ticks))
    assert int(single.cycle[0]) in ticks
    resolved = resolve_analyzed_loops(single)
    figure = resolved_loops(resolved, single)
    rendered(figure)
    image, test = figure.axes[2], figure.axes[3]
    (mesh,) = image.collections
    rows = mesh.get_coordinates()[:, 0, 1]
    assert rows.max() - rows.min() == pytest.approx(1.0)  # one cycle, one row of height 1
    assert np.isfinite(mesh.get_array()).any()
    ticks = integer_ticks(test.xaxis)
    assert ticks.size >= 1 and np.all(ticks == np.round(ticks))
    (errorbar,) = test.containers
    low, high = errorbar.lines[2][0].get_segments()[0][:, 1]
    assert high - low == pytest.approx(4 * resolved.mu_resolved_se.item())
    (mu,) = [line for line in test.get_lines() if "along the stroke" in line.get_label()]
    assert mu.get_marker() == "o"


@pytest.mark.filterwarnings("error")
def test_every_cycle_flagged_is_said_in_the_panels(flagged):
    """Nothing to draw: each empty panel says why, and the cycle axis still spans the test."""
    evolution = cof_evolution(flagged)
    rendered(evolution)
    top, bottom = evolution.axes
    assert top.get_lines() == [] and top.get_legend() is None
    (note,) = top.texts
    assert "every cycle flagged" in note.get_text() and "implausible-cof 4" in note.get_text()
    assert bottom.get_xlim()[0] <= 1 and bottom.get_xlim()[1] >= 4
    assert list(integer_ticks(bottom.xaxis)) == [1, 2, 3, 4]
    figure = resolved_loops(resolve_analyzed_loops(flagged), flagged)
    rendered(figure)
    stroke, felt, image, test = figure.axes[:4]
    for panel in (stroke, felt, image, test):
        assert panel.texts, panel.get_title()
    assert "implausible-cof 4" in image.texts[0].get_text()
    # No value at all: the marks of the cycles without one stand on no scale of friction.
    assert list(test.get_yticks()) == []
    assert drawn_labels(test) == ["no resolved value: implausible-cof"]
    assert [t.get_text() for t in test.get_legend().get_texts()] == drawn_labels(test)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("name", ["flagged", "microslip"])
def test_empty_panels_have_no_ticks_on_their_value_axes(name, request):
    """An axis on which nothing was drawn has no ticks (no 0 to 1 scale in µm, % or of
    cycles); the cycle axes keep integer ticks over the test's cycles."""
    recording = request.getfixturevalue(name)
    cycles = list(recording.cycle.values)
    evolution = cof_evolution(recording)
    rendered(evolution)
    top, bottom = evolution.axes
    assert list(top.get_yticks()) == [] and list(bottom.get_yticks()) == []
    assert bottom.get_lines() == []  # no line of 0 % with no value beside it
    assert list(integer_ticks(bottom.xaxis)) == cycles
    figure = resolved_loops(resolve_analyzed_loops(recording), recording)
    rendered(figure)
    stroke, felt, image = figure.axes[:3]
    for panel in (stroke, felt):
        assert list(panel.get_xticks()) == [] and list(panel.get_yticks()) == []
        assert "[µm]" in panel.get_xlabel()  # the labels say what the panel would show
    assert list(image.get_xticks()) == []
    low, high = image.get_ylim()  # one row per cycle, as when there are profiles
    assert (low, high) == (-0.5, len(cycles) - 0.5)
    labels = [int(tick.get_text()) for tick in image.get_yticklabels()]
    assert labels[0] == cycles[0] and labels[-1] == cycles[-1]


@pytest.mark.filterwarnings("error")
def test_marks_without_any_value_sit_halfway_up_above_the_note(flagged):
    """Panel (d) with no value: the crosses halfway up the panel whatever its friction
    limits, the note below them and the legend clear of both."""
    figure = resolved_loops(resolve_analyzed_loops(flagged), flagged)
    test = figure.axes[3]
    test.set_ylim(0.2, 3.0)  # the crosses do not hang on a friction scale
    renderer = rendered(figure)
    (marks,) = test.get_lines()
    heights = marks.get_transform().transform(marks.get_xydata())[:, 1]
    box = test.get_window_extent(renderer)
    np.testing.assert_allclose(heights, 0.5 * (box.y0 + box.y1))
    (note,) = test.texts
    text = note.get_window_extent(renderer)
    assert text.y1 < heights.min() - 3  # pixels: below the crosses, readable
    legend = test.get_legend().get_window_extent(renderer)
    assert not legend.overlaps(text) and legend.y0 > heights.max() + 3


@pytest.mark.filterwarnings("error")
def test_no_aspect_ratio_axis_without_an_aspect_ratio(flagged, results):
    """The right-hand axis of (d) shows an aspect ratio only where one is drawn, and the legend
    of (d) lists its line as drawn (dashed, with its markers)."""
    resolved = resolve_analyzed_loops(flagged)
    assert not np.isfinite(resolved.aspect_ratio).any()
    figure = resolved_loops(resolved, flagged)
    rendered(figure)
    assert not [ax for ax in figure.axes if "aspect ratio" in ax.get_ylabel()]
    normal = resolved_loops(resolve_analyzed_loops(results), results)
    rendered(normal)
    (ratio,) = [ax for ax in normal.axes if "aspect ratio" in ax.get_ylabel()]
    assert "dashed" not in ratio.get_ylabel()
    (line,) = ratio.get_lines()
    assert line.get_linestyle() == "--" and np.isfinite(line.get_ydata()).all()
    legend = normal.axes[3].get_legend()
    (entry,) = [
        handle
        for handle, text in zip(legend.legend_handles, legend.get_texts(), strict=True)
        if text.get_text() == line.get_label()
    ]
    assert entry.get_linestyle() == "--" and entry.get_marker() == line.get_marker()


# --- titles, legends and symbols of a user's recording ---------------------------------------


def all_figures(results, source=None):
    """Every figure of a recording's plots, drawn."""
    resolved = resolve_analyzed_loops(results)
    figures = [
        measured_loops(results, resolved=resolved, source=source),
        cof_evolution(results, source=source),
        resolved_loops(resolved, results, source=source),
    ]
    for figure in figures:
        rendered(figure)
    return figures


def test_figures_are_titled_by_the_recording_not_the_paper(results):
    """The title begins with the recording's file and says what the figure shows."""
    for figure in all_figures(results, source="rig_0042.csv"):
        title = figure.get_suptitle()
        assert title.startswith("rig_0042.csv: ") and "Fig." not in title
    for figure in all_figures(results):
        assert "Fig." not in figure.get_suptitle() and figure.get_suptitle()[0].isupper()


def texts_of(figure) -> list[str]:
    """Every title, label and legend entry of ``figure``."""
    texts = [figure.get_suptitle()]
    legends = list(figure.legends)
    for ax in figure.axes:
        texts += [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
        legends.append(ax.get_legend())
    return texts + [t.get_text() for legend in legends if legend for t in legend.get_texts()]


@pytest.mark.parametrize("name", ["results", "flagged", "microslip"])
def test_quantities_s_and_p_are_italic(name, request):
    """S and P are written in mathtext ($S$, $P$) wherever a figure names them."""
    for figure in all_figures(request.getfixturevalue(name), source="t.csv"):
        for text in texts_of(figure):
            plain = re.sub(r"\$[^$]*\$", "", text)  # outside mathtext
            assert not re.search(r"\b[SPQ]\b", plain), text


def covered(ax, box) -> list[str]:
    """What of ``ax`` is drawn inside the display box ``box``: the points of every line (its
    segments cut into 50 each) and every filled area's outline."""
    hits = []
    for line in ax.get_lines():
        points = line.get_transform().transform(line.get_xydata())
        points = points[np.isfinite(points).all(axis=1)]
        if line.get_linestyle() not in ("None", "", " ") and len(points) > 1:
            steps = np.linspace(0.0, 1.0, 50)[:, None, None]
            points = (points[:-1] + steps * (points[1:] - points[:-1])).reshape(-1, 2)
        if box.count_contains(points):
            hits.append(line.get_label())
    for collection in ax.collections:
        for path in collection.get_paths():
            outline = collection.get_transform().transform(path.vertices)
            if (
                box.count_contains(outline)
                or path.transformed(collection.get_transform())
                .contains_points([[box.x0, box.y0], [box.x1, box.y1]])
                .any()
            ):
                hits.append(collection.get_label())
    return hits


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("name", ["results", "flagged", "microslip", "single"])
def test_legends_never_cover_data(name, request):
    """Every legend inside a panel leaves the panel's lines, markers and areas uncovered, its
    twin's too; the legend of the loops sits outside every panel."""
    for figure in all_figures(request.getfixturevalue(name)):
        for ax in figure.axes:
            legend = ax.get_legend()
            if legend is None:
                continue
            box = legend.get_window_extent()
            twins = [
                other
                for other in figure.axes
                if other is not ax and other.bbox.bounds == ax.bbox.bounds
            ]
            for panel in (ax, *twins):
                assert not covered(panel, box), (figure.get_suptitle(), ax.get_title())
        for legend in figure.legends:
            box = legend.get_window_extent()
            assert not any(box.overlaps(ax.bbox) for ax in figure.axes if ax.get_visible())


def test_a_legend_with_no_free_corner_gets_room_above_the_data():
    """Lines through every corner: the value axis is stretched and the legend goes above them."""
    from matplotlib.figure import Figure

    from ecofmaps.figures.style import legend_clear_of_data

    figure = Figure(figsize=(5.0, 3.5), layout="constrained")
    ax = figure.subplots()
    x = np.linspace(0.0, 1.0, 101)
    ax.plot(x, np.where(np.arange(x.size) % 2, 0.0, 1.0), label="zigzag")
    ax.plot(x, 0.5 + 0.0 * x, label="level")
    legend = legend_clear_of_data(ax)
    rendered(figure)
    assert not covered(ax, legend.get_window_extent())
    assert ax.get_ylim()[1] > 1.2


def test_recording_plots_and_the_papers_are_written_at_300_dpi(results, tmp_path):
    """save_figure's default is the paper figures' resolution; a recording's plots ask theirs."""
    from ecofmaps.figures.style import PAPER_DPI, RECORDING_DPI

    figure = cof_evolution(results)
    paper = save_figure(figure, tmp_path / "paper.png")
    recording = save_figure(figure, tmp_path / "recording.png", dpi=RECORDING_DPI)
    width = {path: int.from_bytes(path.read_bytes()[16:20], "big") for path in (paper, recording)}
    inches = figure.get_size_inches()[0]
    assert (PAPER_DPI, RECORDING_DPI) == (300, 300)
    assert width[paper] == width[recording] == round(inches * 300)
