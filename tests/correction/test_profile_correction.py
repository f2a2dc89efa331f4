"""correct_ecof and correction_factor on a scar profile: round trips, statuses, errors."""

import numpy as np
import pytest

import ecofmaps
from ecofmaps import CorrectionStatus, correct_ecof, correction_factor
from ecofmaps.paper import AMPLITUDE, LOAD, STIFFNESS

RIG = dict(amplitude=AMPLITUDE, load=LOAD, stiffness=STIFFNESS)  # the paper's Example 2


def random_rigs(count, seed):
    rng = np.random.default_rng(seed)
    amplitude = rng.uniform(20e-6, 100e-6, count)
    stiffness = rng.uniform(10e6, 100e6, count)
    mu = rng.uniform(0.1, 1.2, count)
    return amplitude, stiffness, np.minimum(mu, 0.9 * stiffness * amplitude / 450.0)


@pytest.mark.parametrize(
    ("profile", "parabola"),
    [
        pytest.param(ecofmaps.parabolic_profile(10e-6, 50e-6), 0.2, marks=pytest.mark.slow),
        pytest.param(
            ecofmaps.flat_bottomed_profile(10e-6, 50e-6, 0.5, tilt=0.05),
            None,
            marks=pytest.mark.slow,
        ),
        pytest.param(ecofmaps.w_shaped_profile(10e-6, 50e-6, 0.3), None, marks=pytest.mark.slow),
    ],
    ids=["parabolic", "flat-tilted", "w"],
)
def test_round_trip(profile, parabola):
    """correct_ecof(energy_cof(μ)) = μ to 1e-10 (here a few ulp) where unique; on the
    parabola, the closed-form inversion with aspect_ratio = D/W (1e-12)."""
    amplitude, stiffness, mu = random_rigs(12, 7)
    ecof = ecofmaps.energy_cof(amplitude, 450.0, stiffness, mu, profile=profile)
    got, status = correct_ecof(ecof, amplitude, 450.0, stiffness, profile=profile,
                               return_status=True)  # fmt: skip
    assert np.all(np.asarray(status) == CorrectionStatus.CORRECTED)
    np.testing.assert_allclose(got, mu, rtol=1e-10)
    factor = correction_factor(ecof, amplitude, 450.0, stiffness, profile=profile)
    np.testing.assert_allclose(factor, np.asarray(got) / np.asarray(ecof), rtol=1e-15)
    assert np.all(np.asarray(factor) <= 1.0)  # mu <= mu_E on every profile
    if parabola is not None:
        closed = correct_ecof(ecof, amplitude, 450.0, stiffness, aspect_ratio=parabola)
        np.testing.assert_allclose(got, closed, rtol=1e-12)


@pytest.mark.slow
def test_shipped_example_corrects_less_than_its_parabola():
    """The shipped trace (D/W = 0.16, flat-bottomed with a hump and ridges): the ECoF of
    Example 2 needs a smaller correction than the D/W shortcut of eq. 11 gives."""
    from ecofmaps.measured.synthetic import scar_example_path

    profile = ecofmaps.read_scar_profile(scar_example_path())
    ecof = 0.85
    on_scar = float(correct_ecof(ecof, **RIG, profile=profile))
    shortcut = float(correct_ecof(ecof, **RIG, aspect_ratio=float(profile.aspect_ratio)))
    assert shortcut < on_scar < ecof


@pytest.mark.slow
def test_ambiguous_and_jumps_are_reported():
    """On a ridged scar the pad jumps and μ_E(μ) falls over part of its range: ECoFs there
    are AMBIGUOUS, never a confident number; every CORRECTED point is the true μ."""
    profile = ecofmaps.ridged_profile(10e-6, 40e-6, 4e-6, 30e-6, extent=3.0)
    amplitude, stiffness, mu = random_rigs(24, 0)
    kw = dict(profile=profile, mapping="physical")
    ecof = np.asarray(ecofmaps.energy_cof(amplitude, 450.0, stiffness, mu, **kw))
    got, status = correct_ecof(ecof, amplitude, 450.0, stiffness, return_status=True, **kw)
    got, status = np.asarray(got), np.asarray(status)
    corrected = status == CorrectionStatus.CORRECTED
    assert np.any(status == CorrectionStatus.AMBIGUOUS) and corrected.sum() > 12
    np.testing.assert_allclose(got[corrected], mu[corrected], rtol=1e-10)
    assert np.all(np.isnan(got[~corrected]))
    with pytest.warns(ecofmaps.RegimeWarning, match="several contact CoFs"):
        correct_ecof(ecof, amplitude, 450.0, stiffness, **kw)


@pytest.mark.slow
def test_no_gross_slip_and_bad_input():
    profile = ecofmaps.w_shaped_profile(10e-6, 50e-6, 0.3)
    limit = 35e6 * 50e-6 / 450.0 * (1.0 + 1e-12)  # S Δ*/P: above every gross-slip μ_E
    with pytest.raises(ValueError, match="cannot be corrected on this profile: it is at or above"):
        correct_ecof(limit, **RIG, profile=profile)
    _, status = correct_ecof([0.8, limit], **RIG, profile=profile, return_status=True)
    assert list(np.asarray(status)) == [CorrectionStatus.CORRECTED, CorrectionStatus.NO_GROSS_SLIP]
    with pytest.raises(ValueError, match="not several"):
        correct_ecof(0.8, **RIG, aspect_ratio=0.2, profile=profile)
    with pytest.raises(ValueError, match="ecof must satisfy 0 < ecof"):
        correct_ecof(-0.8, **RIG, profile=profile)
    with pytest.raises(ValueError, match="mapping applies to a profile only"):
        correct_ecof(0.8, **RIG, aspect_ratio=0.2, mapping="physical")
    import jax

    with pytest.raises(ValueError, match="needs concrete inputs"):
        jax.jit(lambda e: correct_ecof(e, **RIG, profile=profile))(0.8)
