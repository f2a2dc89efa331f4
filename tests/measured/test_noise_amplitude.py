"""A cycle whose amplitude does not stand clear of the noise is flagged noise-amplitude,
never a number read too large from the noise's extremes."""

import warnings

import numpy as np
import pytest

import ecofmaps
from ecofmaps.measured.quality import NOISE_SHARE, LoopQualityWarning, has_reason
from tests import mindlin
from tests.measured.test_out_of_core import analysed
from tests.measured.test_sweep import DELTA_T, LOAD, MU, steep_sweep
from tests.measured.ugly import UGLY_KINDS, ugly_recording


@pytest.mark.parametrize("noise", [0.005, 0.01, 0.02])
def test_the_small_cycles_of_a_noisy_x30_dip_read_right_or_not_at_all(noise):
    """Cycles ×30 smaller than their neighbours, with white noise of ``noise`` × the large
    amplitude (and μP): every small cycle's amplitude within 10 % of its truth or NaN and
    flagged; the large cycles read as without the flag (within the noise's own bias)."""
    applied, force, amplitudes = steep_sweep([3.0, 0.1, 3.0], noise=noise)
    results = analysed(applied, force)
    small = amplitudes < amplitudes.max()
    read = results.amplitude.values
    flagged = has_reason(results.quality.values, "noise-amplitude") | (
        results.quality.values == "no-reversal"
    )
    near = np.abs(read / amplitudes - 1.0) <= 0.1
    assert (near | (flagged & np.isnan(read)))[small].all()
    assert not flagged[~small].any()
    # the large cycles' extremes are lifted by at most the rule's bound
    bias = noise * amplitudes.max() * np.sqrt(2.0 * np.log(200))
    assert (np.abs(read[~small] - amplitudes[~small]) <= bias).all()
    assert bias <= NOISE_SHARE * amplitudes.max()


def test_a_noise_amplitude_cycle_keeps_its_row_and_no_value():
    applied, force, amplitudes = steep_sweep([3.0, 0.1, 3.0], noise=0.005)
    results = analysed(applied, force)
    flagged = has_reason(results.quality.values, "noise-amplitude")
    np.testing.assert_array_equal(results.cycle, np.arange(1, amplitudes.size + 1))
    np.testing.assert_array_equal(flagged, amplitudes < amplitudes.max())
    for name in ("amplitude", "max_force", "dissipated_energy", "slip_amplitude"):
        assert np.isnan(results[name].values[flagged]).all()
    assert (results.regime.values[flagged] == int(ecofmaps.Regime.INVALID)).all()


@pytest.mark.parametrize("samples", [32, 200])
def test_a_clean_dip_is_not_flagged(samples):
    """Without noise the sine's and the sliding force's own second differences are no noise,
    at the fewest samples a cycle judged too."""
    applied, force, _ = steep_sweep([3.0, 0.1, 3.0], samples=samples)
    assert not has_reason(analysed(applied, force).quality.values, "noise-amplitude").any()


@pytest.mark.parametrize("kind", UGLY_KINDS)
def test_the_ugly_recordings_are_not_flagged(kind):
    """Noise, drift, chatter, backlash, a digitised loop: their amplitudes stand clear."""
    recording = ugly_recording(kind, cycles=12, seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LoopQualityWarning)
        results = ecofmaps.analyze_loops(
            recording.displacement, recording.force, recording.load, resolve=False
        )
    assert not has_reason(results.quality.values, "noise-amplitude").any()


@pytest.mark.parametrize("share", [0.5, 2.0])
def test_constant_cycles_are_flagged_beyond_the_rule(share):
    """Mindlin's loops at one amplitude a (200 samples a cycle) with white displacement noise
    σ at ``share`` × the rule's edge σ√(2 ln n) = NOISE_SHARE·a: within it none is flagged
    and each reads a within 10 %; at twice it every cycle is flagged, and a recording of
    nothing else is refused with the hint."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, 35e6)
    applied = mindlin.sweep([1.5 * at] * 10)
    _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, 35e6)
    sigma = share * NOISE_SHARE * 1.5 * at / np.sqrt(2.0 * np.log(201))
    applied += sigma * np.random.default_rng(4).standard_normal(applied.size)
    if share > 1.0:
        with pytest.raises(ValueError, match=r"noise-amplitude 10\)\. The amplitudes do not"):
            analysed(applied, force)
        return
    results = analysed(applied, force)
    assert not has_reason(results.quality.values, "noise-amplitude").any()
    np.testing.assert_allclose(results.amplitude, 1.5 * at, rtol=0.1)
