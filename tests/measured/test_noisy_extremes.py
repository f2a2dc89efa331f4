"""Δ* and Q* of noisy loops: each extreme read from a parabola fitted round it
(kernels.fitted_extremes), checked by Monte Carlo on drives of known shape with white noise;
noise-free loops keep their samples' extremes, bit for bit."""

import numpy as np
import pytest

from ecofmaps.measured import kernels

SAMPLES, LOOPS = 200, 2000
SHAPES = {  # a cycle's shape over its phase [cycles], peak 1
    "sine": lambda phase: np.cos(2 * np.pi * phase),
    "clipped": lambda phase: np.clip(np.cos(2 * np.pi * phase) / 0.8, -1.0, 1.0),
    "triangle": lambda phase: 1.0 - 4.0 * np.abs(phase % 1.0 - 0.5),
}


def _half_ranges(shape, noise, seed=0):
    """Half the range read by fitted_extremes and by the samples, over LOOPS cycles of
    ``shape`` at random phases with white noise of ``noise``, and noise-free."""
    rng = np.random.default_rng(seed)
    clean = SHAPES[shape](np.arange(SAMPLES) / SAMPLES + rng.uniform(0, 1, (LOOPS, 1)))
    noisy = clean + noise * rng.standard_normal(clean.shape)
    offset, count = np.arange(LOOPS) * SAMPLES, np.full(LOOPS, SAMPLES)
    *_, high, low = kernels.fitted_extremes(noisy.ravel(), offset, count, 64)
    samples = [0.5 * (v.max(axis=1) - v.min(axis=1)) for v in (noisy, clean)]
    return 0.5 * (high - low), *samples


@pytest.mark.parametrize("noise", [0.003, 0.01, 0.03])
@pytest.mark.parametrize(("shape", "within"), [("sine", 0.2), ("clipped", 0.35), ("triangle", 0.6)])
def test_half_the_range_is_read_through_the_noise(shape, within, noise):
    """The mean over 2000 cycles lies within ``within`` noise sd of the noise-free samples'
    half range (the Monte Carlo's own standard error is 0.01 sd); the samples' half range is
    lifted by more than 0.8 sd on a sine and 2 on a clipped sine. A triangle's kink, which a
    parabola rounds, reads within 0.6 sd, where the samples read up to 0.7 sd high."""
    fitted, samples, clean = _half_ranges(shape, noise)
    bias, lift = ((np.mean(v - clean)) / noise for v in (fitted, samples))
    print(f"{shape} with noise {noise}: fitted {bias:+.2f} sd, samples {lift:+.2f} sd")
    assert abs(bias) < within
    if shape != "triangle":
        assert lift > (0.8 if shape == "sine" else 2.0)


def test_noise_free_loops_keep_their_samples_extremes():
    """Noise-free (a sine, and a Mindlin-like loop's force with its kinks), the extremes are
    the samples' own, to the bit; so with noise below 1e-6 of the range."""
    phase = np.arange(SAMPLES) / SAMPLES + np.linspace(0, 1, 7)[:, None]
    x = 50e-6 * np.cos(2 * np.pi * phase)
    q = 360.0 * np.clip(1.0 - 2.0 * (1.0 - np.cos(2 * np.pi * phase)) ** 1.5, -1.0, 1.0)
    tiny = 1e-8 * np.random.default_rng(1).standard_normal(x.shape)
    offset, count = np.arange(7) * SAMPLES, np.full(7, SAMPLES)
    for values in (x, q, x * (1.0 + tiny), q + 360.0 * tiny):
        *_, high, low = kernels.fitted_extremes(values.ravel(), offset, count, 64)
        np.testing.assert_array_equal(high, values.max(axis=1))
        np.testing.assert_array_equal(low, values.min(axis=1))
