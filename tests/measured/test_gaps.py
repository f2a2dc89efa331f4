"""The drive's cycles after a gap: a NaN run of any length at any place
leaves a hole in the numbering only where samples are missing.

The trigger restarts where the samples resume after a long gap, so a complete cycle just
after the gap is found whatever the phase at which the gap ends; the same cycles come out
in memory and out of core, where the gap's ends fall across the chunks of every pass.
"""

import warnings

import dask.array as da
import numpy as np
import pytest

import ecofmaps
from ecofmaps._parallel import Runner
from ecofmaps.measured import cycles, pipeline
from ecofmaps.measured import samples as passes
from ecofmaps.paper import EXAMPLE_2

PERIOD = 200
CYCLES = 12

#: Samples either side of a reversal where the displacement stays within 1 % of the stroke
#: of it (6 of 200, and one more): a gap there may hide the reversal, which is then not
#: taken for one.
NEAR = 7

#: (first missing sample, missing samples): gaps from a sixth of a period to two and a
#: half periods, starting at every phase of the cycle in steps of 10 samples.
GAPS = [
    (start, length)
    for length in (34, 75, 130, 190, 260, 340, 500)
    for start in range(905 + length % 7, 1105 + length % 7, 10)
]


@pytest.fixture(scope="module")
def recording():
    """Twelve cycles of 200 samples with offsets and drift, starting on a bottom reversal."""
    return ecofmaps.synthetic_recording(
        amplitude=50e-6,
        load=450.0,
        stiffness=35e6,
        mu=0.8,
        aspect_ratio=0.2,
        cycles=CYCLES,
        samples_per_cycle=PERIOD,
        displacement_offset=2e-6,
        force_offset=4.0,
        displacement_drift=0.5e-6,
    )


def with_gap(array, start, length):
    gapped = array.copy()
    gapped[start : start + length] = np.nan
    return gapped


def drive_cycles(displacement):
    """The drive's cycles of the recording without its gap: ``{label: (start, count)}``."""
    clean = cycles.find_cycles(displacement)
    assert clean.label.tolist() == list(range(1, CYCLES + 1))
    return dict(zip(clean.label.tolist(), zip(clean.start, clean.count, strict=True), strict=True))


def table(found):
    return {
        int(label): (int(start), int(count), bool(missing))
        for label, start, count, missing in zip(
            found.label, found.start, found.count, found.whole == 0, strict=True
        )
    }


def assert_the_drive_numbers(found, drive, start, length):
    """Each drive cycle that no missing sample touches (its stretch and ``NEAR`` samples
    either side of it) is found with its number; every other row holds the gap and is
    marked."""
    rows = table(found)
    assert list(rows) == sorted(rows)
    gap = np.arange(start, start + length)
    for label, (first, count) in drive.items():
        touched = np.any((gap >= first - NEAR) & (gap < first + count + NEAR))
        if not touched:
            assert rows.get(label) == (first, count, False), (label, rows)
    for label, (first, count, missing) in rows.items():
        holds_gap = np.any((gap >= first) & (gap < first + count))
        assert missing == holds_gap, (label, rows)
        if not missing:
            assert drive[label] == (first, count), (label, rows)


@pytest.mark.parametrize("length", sorted({length for _, length in GAPS}))
def test_every_complete_cycle_after_a_gap_keeps_its_number(recording, length):
    displacement, force = recording
    drive = drive_cycles(displacement)
    for start, size in GAPS:
        if size != length:
            continue
        found = cycles.find_cycles(with_gap(displacement, start, size), force=force)
        assert_the_drive_numbers(found, drive, start, size)


def test_the_cycle_right_after_a_gap_is_found(recording):
    """The gap ends 20 samples before a bottom reversal that begins a complete cycle (drive
    cycle 8, samples 1400 to 1600): before the trigger restarted, the low run went on over
    the gap and the reversals either side of it were one, merging cycles 6 to 8."""
    displacement, force = recording
    found = cycles.find_cycles(with_gap(displacement, 1040, 340), force=force)
    rows = table(found)
    assert rows[8] == (1400, 201, False)
    assert rows[6][2] and 7 not in rows
    assert sorted(rows) == [1, 2, 3, 4, 5, 6, 8, 9, 10, 11, 12]


@pytest.fixture
def tiny_chunks(monkeypatch):
    """Every pass reads 64 samples at a time, the tasks 320 samples each."""
    monkeypatch.setattr(passes, "_CHUNK", 64)
    monkeypatch.setattr(pipeline, "TASK_SAMPLES", 320)


@pytest.mark.slow
def test_out_of_core_finds_the_same_cycles(recording, tiny_chunks):
    displacement, force = recording
    with Runner(2) as runner:
        for start, length in GAPS[::3]:
            x, q = with_gap(displacement, start, length), force
            memory = table(cycles.find_cycles(x, force=q))
            lazy = cycles.find_cycles(
                da.from_array(x, chunks=320), force=da.from_array(q, chunks=320), runner=runner
            )
            assert table(lazy) == memory, (start, length)


@pytest.mark.parametrize("start, length", [(1040, 340), (1113, 75), (930, 500)])
def test_the_analysis_numbers_the_same_in_memory_and_out_of_core(
    recording, tiny_chunks, start, length
):
    displacement, force = recording
    x = with_gap(displacement, start, length)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        memory = ecofmaps.analyze_loops(x, force, 450.0)
        lazy = ecofmaps.analyze_loops(
            da.from_array(x, chunks=320), da.from_array(force, chunks=320), 450.0,
            scheduler="threads",
        )  # fmt: skip
    assert lazy.cycle.values.tolist() == memory.cycle.values.tolist()
    assert lazy.quality.values.tolist() == memory.quality.values.tolist()
    drive = drive_cycles(displacement)
    gap = np.arange(start, start + length)
    untouched = [
        label
        for label, (first, count) in drive.items()
        if not np.any((gap >= first - NEAR) & (gap < first + count + NEAR))
    ]
    assert set(untouched) <= set(memory.cycle.values.tolist())
    assert (memory.quality.sel(cycle=untouched) == "ok").all()


def test_a_gap_in_the_first_cycles_shifts_no_number():
    """A noisy recording that starts on a bottom reversal, with a gap over the second one:
    the first reversal is still one (it is compared with a reversal the gap does not hide),
    so the cycles after the gap keep their numbers."""
    displacement, force = ecofmaps.synthetic_recording(
        **EXAMPLE_2, cycles=CYCLES, samples_per_cycle=PERIOD, displacement_noise=0.2e-6, seed=0,
    )  # fmt: skip
    drive = drive_cycles(displacement)
    for start, length in [(170, 140), (155, 74), (184, 341), (150, 300)]:
        found = cycles.find_cycles(with_gap(displacement, start, length), force=force)
        assert_the_drive_numbers(found, drive, start, length)
