"""The long synthetic test: made block by block, written to rig formats, read back."""

import numpy as np
import pytest

import ecofmaps
from ecofmaps.measured.synthetic import LONG_TEST, long_recording, write_long_recording
from ecofmaps.paper import EXAMPLE_2

QUIET = dict(displacement_noise=0.0, force_noise=0.0)


def joined(cycles, samples, **options):
    blocks = list(long_recording(cycles, samples, **options))
    return [np.concatenate(parts) for parts in zip(*blocks, strict=True)]


def test_blocks_continue_each_other():
    """Without noise the loops are the model's (GICoF = μ, Section 5), the drift runs on
    across block edges without a step (the offsets found per cycle lie on one line), and
    the ECoF rises with the groove as it deepens (the paper's Fig. 11)."""
    cycles, samples = 40, 80
    cycle, displacement, force = joined(cycles, samples, block_cycles=7, **QUIET)
    np.testing.assert_array_equal(cycle, np.repeat(np.arange(1, cycles + 1), samples))
    results = ecofmaps.analyze_loops(displacement, force, LONG_TEST["load"], cycle=cycle)
    assert results.cycle.size == cycles
    # 80 samples per cycle: the crossing fit reads μ to about 2e-4 in the deepest groove.
    np.testing.assert_allclose(results.gicof, LONG_TEST["mu"], rtol=5e-4)
    offsets = results.displacement_offset.values
    drift = LONG_TEST["displacement_drift"] / cycles
    steps = np.diff(offsets)
    np.testing.assert_allclose(steps, drift, rtol=1e-6)
    unshifted = joined(cycles, samples, block_cycles=7, force_offset=0.0, **QUIET)[2]
    np.testing.assert_allclose(force - unshifted, LONG_TEST["force_offset"], rtol=1e-12)
    assert np.all(np.diff(results.ecof) > 0)
    final = ecofmaps.energy_cof(**EXAMPLE_2)
    assert abs(float(results.ecof[-1]) / float(final) - 1) < 2e-3


def test_same_seed_same_recording_other_seed_other_noise():
    first = joined(10, 40, block_cycles=4)
    again = joined(10, 40, block_cycles=4)
    other = joined(10, 40, block_cycles=4, seed=1)
    np.testing.assert_array_equal(first[2], again[2])
    assert not np.array_equal(first[2], other[2])
    force_noise = np.std(first[2] - joined(10, 40, block_cycles=4, **QUIET)[2])
    assert abs(force_noise / LONG_TEST["force_noise"] - 1) < 0.1


@pytest.mark.parametrize("suffix", [".tdms", ".h5", ".zarr"])
def test_written_files_read_back_bit_for_bit(tmp_path, suffix):
    path = write_long_recording(
        tmp_path / f"long{suffix}",
        cycles=23,
        samples_per_cycle=40,
        block_cycles=5,
        chunk_samples=300,
        cycle_numbers=True,
    )
    cycle, displacement, force = joined(23, 40, block_cycles=5)
    read = ecofmaps.read_recording(path)
    np.testing.assert_array_equal(read.displacement, displacement)
    np.testing.assert_array_equal(read.force, force)
    np.testing.assert_array_equal(read.cycle, cycle)
    lazy = ecofmaps.read_recording(path, lazy=True, chunks=300)
    np.testing.assert_array_equal(lazy.force.compute(), force)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (dict(cycles=0), "cycles must be an integer >= 1"),
        (dict(cycles=3, block_cycles=1.5), "block_cycles must be an integer >= 1"),
        (dict(cycles=3, samples_per_cycle=4), "samples_per_cycle must be >= 8"),
    ],
)
def test_bad_arguments(arguments, message):
    with pytest.raises(ValueError, match=message):
        next(long_recording(**arguments))


def test_unknown_parameter():
    with pytest.raises(TypeError, match="unknown parameters: noise"):
        next(long_recording(3, noise=1.0))
