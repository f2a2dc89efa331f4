"""Energy wear of a sphere's round scar (ecofmaps.energy_wear, contact='sphere') against a
brute-force integration of the scar over the plane, and α from a round scar grown by an
energy law; its standard error against the scatter over noise."""

import warnings

import numpy as np
import pytest

import ecofmaps
from tests import mindlin
from tests.lab_cases import ALPHA, DELTA_T, LOAD, MU, recorded_test, round_scar

RADIUS = 500e-6  # the round scar's radius a [m]


@pytest.fixture(scope="module")
def recorded():
    """A gross-slip test recorded every 500th cycle, and its closed-form sums."""
    return recorded_test(2.5 * mindlin.transition_amplitude(MU, LOAD, DELTA_T, 35e6), 35e6)


def _trace(volume, noise=0.0, seed=0):
    """The levelled profile of :func:`round_scar`."""
    x, z, _ = round_scar(volume, RADIUS, noise, seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ecofmaps.scar_profile(x, z, level=True)


def test_a_round_scar_volume_is_the_plane_integral_of_its_depth(recorded):
    n = 2001  # midpoints of an n × n grid over the scar
    grid = (np.arange(n) + 0.5) / n * 2 * RADIUS - RADIUS
    depth = round_scar(1.0, RADIUS)[2]
    plane = depth(np.hypot(*np.meshgrid(grid, grid))).sum() * (2 * RADIUS / n) ** 2
    assert plane == pytest.approx(1.0, rel=1e-6)  # the grid against the closed form
    wear = ecofmaps.energy_wear(recorded[0], _trace(1e-12), contact="sphere")
    assert float(wear.wear_volume) == pytest.approx(plane * 1e-12, rel=2e-4)


def test_alpha_from_a_round_scar_grown_by_an_energy_law(recorded):
    results, sums = recorded
    volume = ALPHA * sums["energy"]
    wear = ecofmaps.energy_wear(results, _trace(volume, noise=50e-9), contact="sphere")
    assert float(wear.wear_volume) == pytest.approx(volume, rel=0.03)
    assert float(wear.energy_wear_coefficient) == pytest.approx(ALPHA, rel=0.05)
    assert float(wear.archard_slip) == pytest.approx(volume / sums["slip"], rel=0.03)
    assert 0 < float(wear.wear_volume_se) < 0.01 * volume


def test_the_round_scar_standard_error_is_the_scatter_over_noise(recorded):
    found = [
        ecofmaps.energy_wear(recorded[0], _trace(1e-12, noise=30e-9, seed=seed), contact="sphere")
        for seed in range(60)
    ]
    volume = np.array([float(w.wear_volume) for w in found])
    se = np.array([float(w.wear_volume_se) for w in found])
    assert np.std(volume) / np.mean(se) == pytest.approx(1.0, abs=0.3)
    assert np.mean(np.abs(volume - 1e-12) < 2 * se) > 0.85


def test_the_contact_is_named(recorded):
    results, profile = recorded[0], _trace(1e-12)
    with pytest.raises(ValueError, match="a line contact's length in metres"):
        ecofmaps.energy_wear(results, profile)
    with pytest.raises(ValueError, match="a sphere's round scar has no length"):
        ecofmaps.energy_wear(results, profile, length=5e-3, contact="sphere")
    with pytest.raises(ValueError, match="contact = 'ball': 'line' or 'sphere'"):
        ecofmaps.energy_wear(results, profile, contact="ball")
