"""Cycles found a chunk at a time and loops centred a block at a time, against the outputs of
the padded implementation (tests/measured/golden).

Chunks and blocks are made small here, so that runs, cycles and percentile brackets straddle
their edges; the results must not move.
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
from ecofmaps.paper import EXAMPLE_2, LOAD
from tests.measured import golden
from tests.measured.compare import assert_same
from tests.measured.golden import signal


def percentiles(values):
    """The reversal detector's percentiles of ``values`` (taken as detrended already)."""
    samples = Samples(values, None)
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


def assert_found(found, expected):
    """Cycles found as the padded implementation found them (``golden.found_cycles``)."""
    assert found.label.size == expected["label"].size
    assert found.incomplete_cycles == expected["incomplete_cycles"]
    assert found.dropped_samples == expected["dropped_samples"]
    if found.label.size:
        samples, points = found.indices()
        valid = np.arange(samples.shape[1]) < expected["points"][:, None]
        np.testing.assert_array_equal(samples[valid], expected["samples"])
        np.testing.assert_array_equal(points, expected["points"])
        np.testing.assert_array_equal(found.label, expected["label"])


@pytest.mark.parametrize("number", range(len(golden.SPLIT_CASES)))
def test_split_cycles_as_the_padded_implementation(number):
    """Reversals, cycles and what is dropped: as the padded implementation, chunk by chunk."""
    x = signal(*golden.SPLIT_CASES[number])
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(passes, "_CHUNK", 1000)
        patch.setattr(passes, "_SAMPLE", 256)
        found = cycles.find_cycles(x)
    assert_found(found, golden.found_cycles("split", number))


@pytest.mark.parametrize("number", range(len(golden.LABELLED_CASES)))
def test_labelled_cycles_as_the_padded_implementation(number):
    """Labelled cycles turned to their lowest sample: as the padded implementation."""
    x, label = golden.labelled_input(*golden.LABELLED_CASES[number])
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(passes, "_CHUNK", 1000)
        found = cycles.find_cycles(x, label)
    assert_found(found, golden.found_cycles("labelled", number))


@pytest.mark.parametrize("number", range(len(golden.DRIFT_CASES)))
def test_drift_is_the_padded_interpolation_to_the_bit(number):
    """The drift on a block's samples is the padded implementation's np.interp plus
    extrapolation."""
    low, high, middle, centre, rows = golden.drift_inputs(*golden.DRIFT_CASES[number])
    drift = centring._drift(low, high, middle, centre, rows)
    np.testing.assert_array_equal(drift, golden.drift(number))


@pytest.mark.parametrize("name", golden.CHUNKED)
def test_chunks_and_blocks_change_nothing(small_chunks, name):
    """Tiny chunks and blocks (a few cycles each) give the padded implementation's numbers."""
    make, options = golden.CHUNKED[name]
    displacement, force, label = make()
    new = analyze_loops(displacement, force, LOAD, label, **options)
    assert_same(new, golden.analysis(name, displacement, force))


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
    and the cycles after it keep the drive's numbers, in memory and out
    of core alike."""
    import warnings

    import dask.array as da

    import ecofmaps

    displacement, force = ecofmaps.synthetic_recording(**EXAMPLE_2, cycles=12)
    displacement[1000:1340] = np.nan  # from the 6th bottom reversal, 1.7 periods of 200
    if lazy:
        displacement, force = (da.from_array(a, chunks=700) for a in (displacement, force))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = ecofmaps.analyze_loops(displacement, force, 450.0, scheduler="threads")
    np.testing.assert_array_equal(results.cycle, [1, 2, 3, 4, 5, 8, 9, 10, 11, 12])
    assert results.quality.values.tolist() == ["ok"] * 4 + ["missing-samples"] + ["ok"] * 5
