"""The figures of measured loops: the loops with Q = SΔ and Figure 9, drawn from the Dataset."""

import numpy as np
import pytest

from ecofmaps.figures import cof_evolution, measured_loops, resolved_loops, save_figure
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.quality import add_reason
from ecofmaps.measured.resolved import resolve_analyzed_loops
from ecofmaps.measured.synthetic import synthetic_recording

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
    assert [t.get_text() for t in panels[0].get_legend().get_texts()] == [
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
    assert bottom.get_xlabel() == "Cycle" and "[1]" in top.get_ylabel()
    assert "Fig. 9" in figure.get_suptitle()


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
    assert image.get_ylabel() == "Cycle"
    series = {line.get_label(): line for line in test.get_lines()}
    np.testing.assert_allclose(series["GICoF"].get_ydata(), results.gicof)
    np.testing.assert_allclose(series[r"$\mu$ read along the stroke"].get_ydata(),
                               resolved.mu_resolved)  # fmt: skip
    save_figure(figure, tmp_path / "resolved.png")


def test_resolved_loops_marks_cycles_without_a_value(results):
    partial = results.copy()
    third = np.arange(partial.cycle.size) == 2
    partial["quality"] = partial["quality"].copy(
        data=add_reason(partial["quality"].values, third, "not-gross-slip")
    )
    resolved = resolve_analyzed_loops(partial)
    test = resolved_loops(resolved).axes[3]
    (marks,) = [line for line in test.get_lines() if "no resolved value" in line.get_label()]
    assert "not-gross-slip" in marks.get_label()
    assert 3 in marks.get_xdata()  # the third cycle's number
