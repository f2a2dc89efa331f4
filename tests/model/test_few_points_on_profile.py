"""A few points on a scar profile: each builds its own tables, with the shared tables' values."""

import numpy as np
import pytest

import ecofmaps
from ecofmaps.model import on_profile

D, W = 10e-6, 50e-6  # D/W = 0.2 (the paper's Example 2)
NAMES = ("slip_ratio", "ecof_ratio", "normalized_energy", "normalized_max_force", "minus", "plus")


@pytest.mark.parametrize(
    "profile",
    [
        pytest.param(
            ecofmaps.flat_bottomed_profile(D, W, 0.5, samples=401), marks=pytest.mark.slow
        ),
        pytest.param(  # the pad jumps: jumps' areas
            ecofmaps.w_shaped_profile(D, W, 0.25, samples=401), marks=pytest.mark.slow
        ),
    ],
    ids=["flat-bottomed", "W-shaped"],
)
def test_few_points_have_the_shared_tables_values(profile, monkeypatch):
    """92 rigs (Figure 11's S/P and Example 2's) build no shared tables, and every number
    agrees within 1e-12 with the same rigs among 400 more, which share their tables."""
    ratios = np.geomspace(2e4, 2e6, 92)
    more = np.concatenate([ratios, np.geomspace(1.5e4, 3e6, 400)])
    shared = on_profile.steady_numbers(profile, W, 1.0, more, 0.8)
    assert more.size > on_profile._FEW_POINTS >= ratios.size

    def refused(*args, **kwargs):
        raise AssertionError("a few points built shared tables")

    monkeypatch.setattr(on_profile, "_shared", refused)
    own = on_profile.steady_numbers(profile, W, 1.0, ratios, 0.8)
    np.testing.assert_array_equal(own["regime"], shared["regime"][: ratios.size])
    assert np.any(np.isfinite(own["ecof_ratio"]))
    for name in NAMES:
        expected = np.asarray(shared[name])[: ratios.size]
        np.testing.assert_allclose(own[name], expected, rtol=1e-12, atol=0, err_msg=name)


@pytest.mark.slow
def test_numbers_and_loops_by_one_kernel():
    """The steady numbers of steady_numbers and the loops of fretting_loop, at once: on a
    W-shaped scar (jumps) over rigs, a rigid one among them, and amplitudes."""
    profile = ecofmaps.w_shaped_profile(D, W, 0.25, samples=401)
    amplitude = np.array([[40e-6], [50e-6]])
    stiffness = np.array([10e6, 35e6, 120e6, np.inf])
    both = on_profile.steady_numbers_and_loops(profile, amplitude, 450.0, stiffness, 0.8, num=51)
    assert both["displacement"].shape == both["force"].shape == (2, 4, 103)
    numbers = on_profile.steady_numbers(profile, amplitude, 450.0, stiffness, 0.8)
    for name in NAMES:
        np.testing.assert_allclose(both[name], numbers[name], rtol=1e-12, atol=0, err_msg=name)
    np.testing.assert_array_equal(both["regime"], numbers["regime"])
    loop = np.asarray(
        ecofmaps.fretting_loop(amplitude, 450.0, stiffness, 0.8, num=51, profile=profile)
    )
    assert np.all(np.isfinite(loop))
    np.testing.assert_allclose(both["displacement"], loop[0], rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(both["force"], loop[1], rtol=1e-12, atol=1e-9)
