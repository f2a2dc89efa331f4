"""Synthetic recordings and the shipped example: regenerated, labelled, and true to the model."""

import numpy as np
import pytest

import ecofmaps
from ecofmaps.io.recordings import read_recording
from ecofmaps.measured.synthetic import (
    EXAMPLE,
    example_path,
    example_recording,
    synthetic_recording,
    write_example,
)
from ecofmaps.paper import AMPLITUDE, LOAD, MU, STIFFNESS
from tests.measured.ugly import UGLY_KINDS, UGLY_RIG, ugly_recording

POINT = dict(amplitude=AMPLITUDE, load=LOAD, stiffness=STIFFNESS, mu=MU)


def test_shipped_scar_profile_is_regenerated_byte_for_byte(tmp_path):
    """ecofmaps/data/synthetic_scar_profile.csv is what scar_example_trace() writes."""
    from ecofmaps.measured.synthetic import scar_example_path, write_scar_example

    rewritten = write_scar_example(tmp_path / "scar.csv")
    assert rewritten.read_bytes() == scar_example_path().read_bytes()
    assert scar_example_path().read_text().startswith("# SYNTHETIC DATA, not a measurement")


def test_shipped_example_is_regenerated(tmp_path):
    """The generator reproduces the shipped file to the printed digits (0.1 nm, 1 mN)."""
    shipped = read_recording(example_path())
    cycle, displacement, force = example_recording()
    np.testing.assert_array_equal(shipped.cycle, cycle)
    np.testing.assert_allclose(shipped.displacement, displacement, rtol=0, atol=0.51e-10)
    np.testing.assert_allclose(shipped.force, force, rtol=0, atol=0.51e-3)
    rewritten = write_example(tmp_path / "example.csv")
    assert rewritten.read_text().splitlines()[:12] == example_path().read_text().splitlines()[:12]


def test_shipped_example_is_labelled_synthetic_and_small():
    text = example_path().read_text()
    assert text.startswith("# SYNTHETIC DATA, not a measurement")
    assert example_path().stat().st_size < 2_000_000
    readme = (example_path().parent / "README.md").read_text()
    assert "synthetic" in readme.lower() and example_path().name in readme
    cycles = EXAMPLE["test_cycles"] // EXAMPLE["recorded_every"]
    assert read_recording(example_path()).force.size == cycles * EXAMPLE["samples_per_cycle"]


def test_groove_per_cycle():
    """One aspect ratio per cycle: each cycle's μ_E is the model's for its groove (eq. 15)."""
    ratios = np.array([0.0, 0.1, 0.2, 0.3])
    displacement, force = synthetic_recording(**POINT, aspect_ratio=ratios)
    assert displacement.size == 4 * 200
    closed = slice(0, 4 * 200)  # the recording ends one sample before the 5th reversal
    result = ecofmaps.analyze_loops(displacement[closed], force[closed], 450.0)
    expected = ecofmaps.energy_cof(**POINT, aspect_ratio=ratios[:3])
    # Cycles run between bottom reversals, so cycle k is the k-th groove; the last cycle is
    # one sample short and left out. 200 samples per cycle: trapezoidal error below 3e-4.
    # The sample closing cycle k is the first of cycle k + 1, on the next groove, which
    # moves the GICoF by up to 3e-5.
    np.testing.assert_allclose(result.ecof[:3], expected, rtol=3e-4)
    np.testing.assert_allclose(result.gicof[:3], POINT["mu"], rtol=1e-4)


def test_sensor_effects_are_added():
    """Offsets, drift and noise go on the recorded signals only, reproducibly by seed."""
    clean_d, clean_f = synthetic_recording(**POINT, aspect_ratio=0.2, cycles=3)
    options = dict(
        displacement_noise=1e-7,
        force_noise=2.0,
        displacement_offset=3e-6,
        force_offset=5.0,
        displacement_drift=1e-6,
        seed=7,
    )
    d, f = synthetic_recording(**POINT, aspect_ratio=0.2, cycles=3, **options)
    again_d, again_f = synthetic_recording(**POINT, aspect_ratio=0.2, cycles=3, **options)
    np.testing.assert_array_equal(d, again_d)
    np.testing.assert_array_equal(f, again_f)
    drift = 3e-6 + 1e-6 * np.arange(600) / 200
    residual_d, residual_f = d - clean_d - drift, f - clean_f - 5.0
    assert abs(residual_d.std() / 1e-7 - 1) < 0.1 and abs(residual_d.mean()) < 2e-8
    assert abs(residual_f.std() / 2.0 - 1) < 0.1 and abs(residual_f.mean()) < 0.4


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (dict(samples_per_cycle=4), "samples_per_cycle must be >= 8"),
        (dict(sampling_jitter=0.5), "sampling_jitter must satisfy"),
        (dict(cycles=0), "cycles must be >= 1"),
        (dict(aspect_ratio=np.zeros((2, 2))), "aspect_ratio must be one value or one per cycle"),
        (
            dict(aspect_ratio=np.zeros(3), cycles=4),
            "cycles must be >= 1 and match the 3 aspect ratios",
        ),
    ],
)
def test_bad_arguments(options, message):
    arguments = dict(POINT, aspect_ratio=0.2) | options
    with pytest.raises(ValueError, match=message):
        synthetic_recording(**arguments)


# ---------------------------------------------------------------------------------------
# Ugly recordings with a known truth
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", list(UGLY_KINDS))
def test_ugly_recording_shapes_and_seed(kind):
    """Every kind: one sample per entry, cycles numbered from 1, the same for the same seed."""
    recording = ugly_recording(kind, cycles=3, seed=5)
    n = recording.displacement.size // 3
    assert n in (200, 32)
    assert recording.force.shape == recording.cycle.shape == (3 * n,)
    np.testing.assert_array_equal(recording.cycle, np.repeat([1, 2, 3], n))
    assert recording.mu.shape == recording.gicof.shape == (3,)
    assert recording.load == UGLY_RIG["load"]
    again = ugly_recording(kind, cycles=3, seed=5)
    np.testing.assert_array_equal(again.force, recording.force)


def test_ugly_clean_is_the_model():
    """The sample-by-sample slide is ecofmaps.simulate's loop (eq. 9, 10, 16) plus the noise."""
    recording = ugly_recording("clean", cycles=4, seed=2)
    rig = UGLY_RIG
    t = np.arange(5 * 200) / 200
    imposed = -rig["amplitude"] * np.cos(2.0 * np.pi * t)
    model = np.asarray(
        ecofmaps.simulate(
            imposed,
            rig["load"],
            rig["stiffness"],
            rig["mu"],
            rig["aspect_ratio"],
            rig["groove_half_width"],
        )
    )[200:]
    residual = recording.force - model
    assert abs(residual.std() / 0.5 - 1.0) < 0.1 and abs(residual.mean()) < 0.05
    assert abs((recording.displacement - imposed[200:]).std() / 0.05e-6 - 1.0) < 0.1
    np.testing.assert_allclose(recording.mu, rig["mu"], rtol=1e-14)


def test_ugly_chatter_truth_is_the_mean_friction_slid():
    """The truth of a chattering cycle is within ±30 % of μ, differs from cycle to cycle
    (the chatter is not locked to the drive) and from seed to seed (its phase)."""
    truth = ugly_recording("chatter", cycles=20, seed=1).mu
    assert np.all(np.abs(truth / UGLY_RIG["mu"] - 1.0) < 0.3)
    assert truth.std() > 1e-3
    other = ugly_recording("chatter", cycles=20, seed=2).mu
    assert np.max(np.abs(other - truth)) > 1e-3
    np.testing.assert_array_equal(ugly_recording("chatter", cycles=20, seed=1).gicof, truth)


def test_ugly_backlash_holds_the_force_at_the_reversal():
    """Through the dead band (±1.5 µm) after the top reversal the force stands still; without
    it, the rig's spring would change it by S times the displacement."""
    for kind, moves in (("backlash", False), ("clean", True)):
        recording = ugly_recording(kind, cycles=1, seed=3)
        top = np.argmax(recording.displacement)
        back = recording.displacement[top] - recording.displacement
        band = (np.arange(back.size) > top) & (back > 0.3e-6) & (back < 2.7e-6)
        change = np.abs(recording.force[band] - recording.force[top])
        assert band.any()
        assert (change.max() > 10.0) == moves, kind


def test_ugly_sweep_sparse_ploughing_microslip():
    """The sweep's amplitude grows, the sparse loop is digitised, ploughing pushes the force up
    at the ends, and microslip stays below the friction limit with no μ to read."""
    sweep = ugly_recording("sweep", cycles=10, seed=4)
    half = np.ptp(sweep.displacement.reshape(10, 200), axis=1) / 2
    assert 30e-6 < half[0] < 36e-6 and 64e-6 < half[-1] < 70e-6 and np.all(np.diff(half) > 0)
    sparse = ugly_recording("sparse", cycles=2, seed=4)
    assert sparse.displacement.size == 64
    np.testing.assert_allclose(sparse.displacement / 0.5e-6, np.round(sparse.displacement / 0.5e-6))
    np.testing.assert_allclose(sparse.force / 2.0, np.round(sparse.force / 2.0))
    clean = ugly_recording("clean", cycles=2, seed=4)
    ploughing = ugly_recording("ploughing", cycles=2, seed=4)
    assert ploughing.force.max() > clean.force.max() + 10.0
    np.testing.assert_allclose(ploughing.mu, UGLY_RIG["mu"], rtol=1e-14)
    microslip = ugly_recording("microslip", cycles=2, seed=4)
    assert np.all(np.isnan(microslip.mu)) and np.all(np.isnan(microslip.gicof))
    assert np.abs(microslip.force).max() < 0.8 * UGLY_RIG["mu"] * UGLY_RIG["load"]


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (dict(kind="chatte"), "did you mean 'chatter'"),
        (dict(kind="wobble"), "kind must be one of clean, noise"),
        (dict(kind="clean", cycles=0), "cycles must be >= 1"),
    ],
)
def test_ugly_bad_arguments(arguments, message):
    with pytest.raises(ValueError, match=message):
        ugly_recording(**arguments)
