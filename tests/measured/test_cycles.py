"""Cycles found a chunk at a time and loops centred a block at a time, against the reference.

The reference is the frozen padded implementation (tests/measured/reference). Chunks and
blocks are made small here, so that runs, cycles and percentile brackets straddle their
edges; the results must not move.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ecofmaps.measured import cycles
from ecofmaps.measured import measure as centring
from ecofmaps.measured import samples as passes
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.samples import Samples
from ecofmaps.measured.synthetic import synthetic_recording
from tests.measured.reference import cycles as reference
from tests.measured.reference.analysis import analyze_loops as reference_analysis
from tests.measured.test_equivalence import EXAMPLE_2, LOAD, assert_same, noisy


def signal(kind: int, size: int, seed: int):
    """Noise, a random walk, a clipped noisy sine, rounded noise (ties) or a drifting sine."""
    rng = np.random.default_rng(seed)
    period = rng.integers(8, 400)
    sine = np.sin(2 * np.pi * np.arange(size) / period)
    return [
        rng.normal(size=size),
        np.cumsum(rng.normal(size=size)),
        np.clip(sine, -0.7, 0.7) + 0.01 * rng.normal(size=size),
        np.round(rng.normal(size=size), 1),
        sine + 3.0 * np.arange(size) / size + 0.02 * rng.normal(size=size),
    ][kind]


def percentiles(values):
    """The reversal detector's percentiles of ``values`` (taken as detrended already)."""
    samples = Samples(values, None, chunk=passes._CHUNK)
    sample_at = np.sort(np.random.default_rng(0).integers(0, values.size, passes._SAMPLE))
    line = (0.0, 0.0, 0.0, 0.5 * (values.size - 1))
    gaps = np.zeros((0, 2), np.int64)
    return passes.displacement_percentiles(
        samples, gaps, line, sample_at, values[sample_at], values.size
    )


@pytest.fixture
def small_chunks(monkeypatch):
    """Chunks of 1000 samples, percentile samples of 256 and blocks of 700 samples."""
    monkeypatch.setattr(passes, "_CHUNK", 1000)
    monkeypatch.setattr(passes, "_SAMPLE", 256)
    monkeypatch.setattr(centring, "_BLOCK", 700)


@settings(max_examples=60, deadline=None)
@given(kind=st.integers(0, 4), size=st.integers(1, 12_000), seed=st.integers(0, 2**16))
def test_percentiles_are_numpys_to_the_bit(kind, size, seed):
    """The bracketed percentiles of a long recording equal np.percentile exactly."""
    values = signal(kind, size, seed)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(passes, "_CHUNK", 1000)
        patch.setattr(passes, "_SAMPLE", 256)
        result = percentiles(values)
    np.testing.assert_array_equal(result, np.percentile(values, [1.0, 99.0]))


@settings(max_examples=60, deadline=None)
@given(kind=st.integers(0, 4), size=st.integers(8, 12_000), seed=st.integers(0, 2**16))
def test_split_cycles_as_the_reference(kind, size, seed):
    """Reversals, cycles and what is dropped: as the padded implementation, chunk by chunk."""
    x = signal(kind, size, seed)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(passes, "_CHUNK", 1000)
        patch.setattr(passes, "_SAMPLE", 256)
        try:
            found = cycles.split_cycles(x)
        except ValueError as error:
            with pytest.raises(ValueError, match=str(error)):
                reference.split_cycles(x)
            return
    expected = reference.split_cycles(x)
    assert found.label.size == expected.label.size
    assert found.incomplete_cycles == expected.incomplete_cycles
    assert found.dropped_samples == expected.dropped_samples
    if found.label.size:
        samples, points = found.indices(width=expected.samples.shape[1])
        np.testing.assert_array_equal(samples[expected.valid], expected.samples[expected.valid])
        np.testing.assert_array_equal(points, np.count_nonzero(expected.valid, axis=1))
        np.testing.assert_array_equal(found.label, expected.label)


@settings(max_examples=40, deadline=None)
@given(
    kind=st.integers(0, 4),
    size=st.integers(8, 8000),
    length=st.integers(5, 300),
    seed=st.integers(0, 2**16),
)
def test_labelled_cycles_as_the_reference(kind, size, length, seed):
    """Labelled cycles turned to their lowest sample: as the padded implementation."""
    x = signal(kind, size, seed)
    label = np.arange(size) // length * 10
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(passes, "_CHUNK", 1000)
        found = cycles.labelled_cycles(x, label)
    expected = reference.labelled_cycles(x, label)
    assert found.label.size == expected.label.size
    assert found.incomplete_cycles == expected.incomplete_cycles
    assert found.dropped_samples == expected.dropped_samples
    if found.label.size:
        samples, _ = found.indices(width=expected.samples.shape[1])
        np.testing.assert_array_equal(samples[expected.valid], expected.samples[expected.valid])
        np.testing.assert_array_equal(found.label, expected.label)


@settings(max_examples=60, deadline=None)
@given(count=st.integers(1, 30), seed=st.integers(0, 2**16), scale=st.integers(-9, 3))
def test_drift_is_the_reference_interpolation_to_the_bit(count, seed, scale):
    """The drift on a block's samples is the reference's np.interp plus extrapolation."""
    rng = np.random.default_rng(seed)
    starts = np.cumsum(rng.integers(5, 300, count + 1))
    start, size = starts[:-1], np.diff(starts) + 1
    middle = ((size * (2 * start + size - 1)) // 2 + start) / (size + 1)
    centre = rng.normal(size=count) * 10.0**scale
    first = int(rng.integers(0, count))
    stop = int(rng.integers(first, count)) + 1
    low, high = int(start[first]), int(start[stop - 1] + size[stop - 1])
    drift = centring._drift(low, high, middle, centre, slice(max(first - 1, 0), stop + 1))
    expected = reference._interpolate(np.arange(low, high, dtype=float), middle, centre)
    np.testing.assert_array_equal(drift, expected)


@pytest.mark.parametrize("labelled", [False, True])
def test_chunks_and_blocks_change_nothing(small_chunks, labelled):
    """Tiny chunks and blocks (a few cycles each) give the reference's numbers."""
    displacement, force = noisy(EXAMPLE_2, 12, 9, sampling_jitter=0.3, start_phase=0.2)
    label = np.repeat(np.arange(12), 200) if labelled else None
    assert_same(
        analyze_loops(displacement, force, LOAD, label),
        reference_analysis(displacement, force, LOAD, label),
    )


def test_a_long_loop_gets_a_block_of_its_own():
    """Blocks hold about _BLOCK samples; one long loop among short ones is not padded."""
    points = np.full(1000, 201)
    points[500] = 3 * centring._BLOCK // 2
    blocks = list(centring._blocks(points, 0))
    assert [b.stop - b.start for b in blocks if b.start <= 500 < b.stop] == [1]
    assert sum(b.stop - b.start for b in blocks) == points.size
    for block in blocks:
        if block.stop - block.start > 1:
            assert (block.stop - block.start) * points[block].max() <= 2 * centring._BLOCK


def test_one_cycle_of_a_long_recording():
    """Measuring one cycle uses its neighbours' centres: as in the whole analysis."""
    from ecofmaps.measured.measure import measure_cycles
    from ecofmaps.measured.pipeline import LoopOptions

    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=8, displacement_drift=1e-6)
    found = cycles.find_cycles(displacement)
    whole, _, _ = measure_cycles(found, displacement, force, LoopOptions(LOAD))
    for row in (0, 3, found.label.size - 1):
        one, _, _ = measure_cycles(
            found, displacement, force, LoopOptions(LOAD), rows=slice(row, row + 1)
        )
        for name, value in one.items():
            np.testing.assert_allclose(value, whole[name][row : row + 1], rtol=1e-12, err_msg=name)


@pytest.mark.parametrize("lazy", [False, True])
def test_a_gap_leaves_a_hole_in_the_drive_numbering(lazy):
    """A NaN run of 1.7 cycles in a 12-cycle recording: the cycle that holds it is skipped
    and the cycles after it keep the drive's numbers (issue 23, item 5), in memory and out
    of core alike."""
    import warnings

    import dask.array as da

    import ecofmaps

    displacement, force = ecofmaps.synthetic_recording(
        amplitude=50e-6, load=450.0, stiffness=35e6, mu=0.8, aspect_ratio=0.2, cycles=12
    )
    displacement[1000:1340] = np.nan  # from the 6th bottom reversal, 1.7 periods of 200
    if lazy:
        displacement, force = (da.from_array(a, chunks=700) for a in (displacement, force))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = ecofmaps.analyze_loops(displacement, force, 450.0, scheduler="threads")
    np.testing.assert_array_equal(results.cycle, [1, 2, 3, 4, 5, 8, 9, 10, 11, 12])
    assert results.quality.values.tolist() == ["ok"] * 4 + ["missing-samples"] + ["ok"] * 5
