"""Loop-scar closure (ecofmaps.loop_scar_closure) on a closed truth: a recording generated on
a known parabolic groove closes on that groove's profile, and not on a wrong one; bad input."""

import warnings

import numpy as np
import pytest
import xarray as xr

import ecofmaps

AMPLITUDE, LOAD, STIFFNESS, MU, ASPECT = 50e-6, 450.0, 35e6, 0.8, 0.2
HALF_WIDTH = 60e-6  # the groove's x_o, wider than the stroke


@pytest.fixture(scope="module")
def loops():
    """analyze_loops (with the loops kept) and resolve_loops of 4 noisy cycles on the groove
    z = z_o (x/x_o)² with z_o/x_o = 0.2."""
    displacement, force = ecofmaps.synthetic_recording(
        AMPLITUDE, LOAD, STIFFNESS, MU, ASPECT, HALF_WIDTH, cycles=4, samples_per_cycle=400,
        force_noise=0.5, displacement_noise=5e-9, seed=1,
    )  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = ecofmaps.analyze_loops(displacement, force, LOAD, keep_loops=True)
        resolved = ecofmaps.resolve_loops(displacement, force, LOAD, STIFFNESS)
    return results, resolved


def _profile(depth=ASPECT * HALF_WIDTH, half_width=HALF_WIDTH):
    return ecofmaps.parabolic_profile(depth, half_width)  # one sample count: one compilation


def test_the_true_groove_closes(loops):
    closure = ecofmaps.loop_scar_closure(*loops, _profile(), rig_stiffness=STIFFNESS)
    assert int(closure.cycle) == 4  # the last loop
    assert float(closure.mu) == pytest.approx(MU, rel=2e-3)
    assert float(closure.loop_residual) < 5e-3  # the force noise is 0.5 N of Q* = 580 N
    assert float(closure.scar_relative_residual) < 0.01
    assert float(closure.scar_residual) == pytest.approx(
        float(closure.scar_relative_residual) * ASPECT * HALF_WIDTH
    )
    # the implied scar spans the slip and follows the groove's parabola
    position = closure.position.values
    assert position.max() > 0.9 * float(loops[0].slip_amplitude[-1])
    curvature = np.polyfit(position, closure.implied_scar.values, 2)[0]
    assert curvature == pytest.approx(ASPECT / HALF_WIDTH, rel=0.02)
    assert closure.loop_force.attrs["units"] == "N"
    assert closure.implied_scar.attrs["units"] == "m"


def test_the_measured_stick_slope_closes_too(loops):
    """Without rig_stiffness the reading's stiffness (here the one given to it) is used."""
    closure = ecofmaps.loop_scar_closure(*loops, _profile())
    assert float(closure.stiffness) == STIFFNESS
    assert float(closure.loop_residual) < 5e-3


def test_the_rig_stiffness_the_results_were_analysed_with_is_the_default(loops):
    results, resolved = loops
    analysed = results.assign_attrs(rig_stiffness=2 * STIFFNESS)
    wrong = ecofmaps.loop_scar_closure(results, resolved, _profile(), rig_stiffness=2 * STIFFNESS)
    xr.testing.assert_identical(ecofmaps.loop_scar_closure(analysed, resolved, _profile()), wrong)
    given = ecofmaps.loop_scar_closure(analysed, resolved, _profile(), rig_stiffness=STIFFNESS)
    assert float(given.stiffness) == STIFFNESS and float(given.loop_residual) < 5e-3


@pytest.mark.parametrize(
    "profile",
    [
        pytest.param({"depth": ASPECT * HALF_WIDTH / 2}, id="half as deep"),
        pytest.param({"half_width": 1.5 * HALF_WIDTH}, id="wider"),
    ],
)
def test_a_wrong_groove_does_not_close(loops, profile):
    closure = ecofmaps.loop_scar_closure(*loops, _profile(**profile), rig_stiffness=STIFFNESS)
    assert float(closure.loop_residual) > 0.05
    assert float(closure.scar_relative_residual) > 0.03  # the true groove: < 0.01


def test_a_wrong_rig_does_not_close(loops):
    closure = ecofmaps.loop_scar_closure(*loops, _profile(), rig_stiffness=2 * STIFFNESS)
    assert float(closure.loop_residual) > 0.05


def test_bad_input(loops):
    results, resolved = loops
    with pytest.raises(ValueError, match=r"results: .*keep_loops=True"):
        ecofmaps.loop_scar_closure(results.drop_vars("loop_displacement"), resolved, _profile())
    summary = results.drop_vars(["loop_displacement", "loop_force"])
    with pytest.raises(ValueError, match=r"resolved: .*resolve_loops"):
        ecofmaps.loop_scar_closure(results, summary, _profile())
    flat = _profile()._replace(depth=np.float64(0.0), worn_area=np.float64(0.0))
    with pytest.raises(ValueError, match=r"profile: no scar"):
        ecofmaps.loop_scar_closure(results, resolved, flat)
    with pytest.raises(TypeError, match=r"profile must be a ScarProfile"):
        ecofmaps.loop_scar_closure(results, resolved, np.zeros(5))
    with pytest.raises(ValueError, match=r"profile: .*in metres"):  # a trace in µm
        ecofmaps.loop_scar_closure(results, resolved, _profile(12.0, 60.0))
    with pytest.raises(ValueError, match=r"rig_stiffness = 35 N/m .*in N/m"):  # in MN/m
        ecofmaps.loop_scar_closure(results, resolved, _profile(), rig_stiffness=35.0)
    unread = resolved.copy()
    unread["felt_profile"] = unread.felt_profile * np.nan
    with pytest.raises(ValueError, match=r"results, resolved: no cycle"):
        ecofmaps.loop_scar_closure(results, unread, _profile())


def test_the_figure_draws_both_comparisons(loops):
    pytest.importorskip("matplotlib")
    from ecofmaps.figures import loop_scar_closure_figure

    closure = ecofmaps.loop_scar_closure(*loops, _profile(), rig_stiffness=STIFFNESS)
    loop, scar = loop_scar_closure_figure(closure).axes
    assert loop.get_xlabel().endswith("[µm]") and loop.get_ylabel().endswith("[N]")
    assert scar.get_xlabel().endswith("[µm]") and scar.get_ylabel().endswith("[µm]")
    for ax in (loop, scar):
        assert len(ax.get_legend().get_texts()) == len(ax.get_lines()) == 2
    model = loop.get_lines()[1]
    np.testing.assert_allclose(model.get_ydata(), closure.model_force)
    np.testing.assert_allclose(scar.get_lines()[1].get_ydata(), closure.implied_scar * 1e6)
