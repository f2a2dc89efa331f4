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

POINT = dict(amplitude=50e-6, load=450.0, stiffness=35e6, mu=0.8)


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
