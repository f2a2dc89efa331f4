"""An amplitude sweep of the Mindlin oracle (tests/mindlin.py) through analyze_loops: every
cycle found and numbered as driven, the regime on the contact's displacement, and the
GICoF of a sphere's gross-slip loops despite their curved stick."""

import io
import warnings

import numpy as np
import pandas as pd
import pytest

import ecofmaps
from ecofmaps.measured import cycles as cycles_module
from ecofmaps.measured import pipeline
from ecofmaps.measured import samples as passes
from ecofmaps.measured.quality import has_reason
from tests import mindlin
from tests.cli.commands import run_loops
from tests.measured.test_out_of_core import analysed, assert_equal_results, lazily
from tests.recordings import write_csv

MU, LOAD, DELTA_T = 0.8, 450.0, 6e-6
SAMPLES = 200  # per cycle


@pytest.fixture(scope="module", params=[15e6, 35e6, 100e6])
def sweep(request):
    """A sweep from 0.45 to 1.8 Δ_t, each amplitude held two cycles, behind a rig S; the
    amplitude of each complete cycle (the recording's first is a lead-in) and its results."""
    stiffness = request.param
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    amplitudes = np.repeat(np.linspace(0.45, 1.8, 20) * at, 2)
    applied = mindlin.sweep(amplitudes, SAMPLES)
    _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, stiffness)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = ecofmaps.analyze_loops(applied, force, LOAD, rig_stiffness=stiffness)
    # the recording's first and last cycles (a lead-in and a lead-out) are cut short
    return stiffness, at, applied, amplitudes, results


def test_every_cycle_of_a_sweep_is_reported_numbered_as_driven(sweep):
    _, _, applied, driven, results = sweep
    np.testing.assert_array_equal(results.cycle, np.arange(1, driven.size + 1))
    assert results.attrs["incomplete_cycles"] == 2
    found = cycles_module.find_cycles(applied)
    stretches = [applied[s : s + c] for s, c in zip(found.start, found.count, strict=True)]
    # each cycle holds the drive's cycle of its number, at one amplitude: both its
    # reversals, and its ends where the drive's cycles meet (at the centre)
    np.testing.assert_allclose([x.max() for x in stretches], driven, rtol=1e-3)
    np.testing.assert_allclose([-x.min() for x in stretches], driven, rtol=1e-3)
    np.testing.assert_allclose(results.amplitude, driven, rtol=1e-3)
    ends = np.array([[x[0], x[-1]] for x in stretches])
    assert np.abs(ends).max() < 0.02 * driven.max()


def test_a_falling_sweep_reports_each_cycles_own_amplitude():
    """Cut at a bottom reversal, the first cycle after a step down would begin at the old
    amplitude and report the mean of the two."""
    stiffness = 35e6
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    amplitudes = np.repeat(np.linspace(1.8, 0.45, 8) * at, 2)
    applied = mindlin.sweep(amplitudes, SAMPLES)
    _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, stiffness)
    results = analysed(applied, force)
    np.testing.assert_array_equal(results.cycle, np.arange(1, amplitudes.size + 1))
    np.testing.assert_allclose(results.amplitude, amplitudes, rtol=1e-3)


def test_the_regime_is_decided_on_the_contacts_displacement(sweep):
    """At most 5 % of the cycles more than 5 % away from Δ_t in the wrong regime."""
    _, at, _, driven, results = sweep
    far = np.abs(driven / at - 1.0) > 0.05
    gross = results.regime.values == int(ecofmaps.Regime.GROSS_SLIP)
    wrong = gross[far] != (driven[far] > at)
    assert np.count_nonzero(wrong) <= 0.05 * np.count_nonzero(far)
    assert np.isfinite(results.contact_energy_ratio).all()
    contact = results.amplitude - results.max_force / sweep[0]
    np.testing.assert_allclose(results.contact_amplitude, contact)


def test_a_spheres_gross_slip_cycles_keep_their_gicof(sweep):
    """The GICoF read within 2 % of μ on at least 80 % of the gross-slip cycles."""
    _, at, _, driven, results = sweep
    gross = driven > 1.05 * at
    read = np.abs(results.gicof.values[gross] / MU - 1.0) <= 0.02
    assert np.count_nonzero(read) >= 0.8 * np.count_nonzero(gross)


def test_without_the_rig_the_regime_is_read_on_the_applied_displacement():
    """Without rig_stiffness the results carry no contact ratios and the regime is read on
    the applied displacement, as before."""
    stiffness = 35e6
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    applied = mindlin.sweep([1.1 * at] * 3, SAMPLES)
    _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, stiffness)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bare = ecofmaps.analyze_loops(applied, force, LOAD)
        rig = ecofmaps.analyze_loops(applied, force, LOAD, rig_stiffness=stiffness)
    assert "contact_energy_ratio" not in bare
    assert (bare.regime == int(ecofmaps.Regime.PARTIAL_SLIP)).all()
    assert (rig.regime == int(ecofmaps.Regime.GROSS_SLIP)).all()
    np.testing.assert_array_equal(bare.energy_ratio, rig.energy_ratio)


def test_a_rig_stiffness_that_is_not_positive_is_refused():
    x = np.sin(np.linspace(0, 6 * np.pi, 301)) * 20e-6
    with pytest.raises(ValueError, match="rig_stiffness"):
        ecofmaps.analyze_loops(x, 3e7 * x, LOAD, rig_stiffness=-1.0)


def test_a_sweep_out_of_core_as_in_memory(monkeypatch):
    """The local band's stretches cut across chunks and tasks: the same cycles and numbers."""
    monkeypatch.setattr(passes, "_CHUNK", 1000)
    monkeypatch.setattr(passes, "_SAMPLE", 256)
    monkeypatch.setattr(pipeline, "TASK_SAMPLES", 777)
    stiffness = 35e6
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    applied = mindlin.sweep(np.repeat(np.linspace(0.45, 1.8, 10) * at, 2), SAMPLES)
    _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, stiffness)
    memory = analysed(applied, force)
    assert memory.cycle.size == 20
    lazy = analysed(*lazily(applied, force, chunks=1700), scheduler="threads")
    assert_equal_results(lazy, memory)


# held amplitudes (× Δ_t), three cycles each: steps of ×1.3 and ×1.8 (every cycle crosses
# the whole recording's band), ×3, ×4 (40 µm to 10 µm), ×5 and ×10
STEEP = {
    "x1.3-falling": [1.3, 1.0],
    "x1.8-rising": [0.55, 1.0],
    "x3-rising": [0.5, 1.5, 4.5],
    "x3-falling": [4.5, 1.5, 0.5],
    "x4-down-and-up": [2.46, 0.615, 2.46, 0.615],
    "x5-rising": [0.4, 2.0],
    "x5-falling": [2.0, 0.4],
    "x10-dip": [2.0, 0.2, 2.0],
}


def steep_sweep(steps, noise=0.0, samples=SAMPLES, held=3, stiffness=35e6):
    """The applied displacement and force of a sweep holding each of ``steps`` × Δ_t ``held``
    cycles behind a rig ``stiffness`` (``samples`` a cycle), with white noise of ``noise`` ×
    their largest amplitude and force, and the amplitude of each drive cycle."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    amplitudes = np.repeat(np.asarray(steps) * at, held)
    applied = mindlin.sweep(amplitudes, samples)
    _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, stiffness)
    rng = np.random.default_rng(1)
    applied += noise * amplitudes.max() * rng.standard_normal(applied.size)
    force += noise * MU * LOAD * rng.standard_normal(force.size)
    return applied, force, amplitudes


@pytest.mark.parametrize("noise", [0.0, 0.01])
@pytest.mark.parametrize("steps", STEEP.values(), ids=STEEP.keys())
def test_every_cycle_after_a_steep_step_is_reported_with_values(steps, noise):
    """The local band is set by the least amplitude near each sample: a cycle right after
    (or before) one several times larger crosses it; the lead-in and lead-out, cut short by
    the recording's ends, are not taken for cycles even where noise crosses their band."""
    applied, force, amplitudes = steep_sweep(steps, noise)
    results = analysed(applied, force)
    np.testing.assert_array_equal(results.cycle, np.arange(1, amplitudes.size + 1))
    assert results.attrs["incomplete_cycles"] == 2
    # a cycle whose amplitude the noise's extremes would read too large has no values
    unclear = has_reason(results.quality.values, "noise-amplitude")
    assert np.isfinite(results.dissipated_energy.values[~unclear]).all()
    assert (noise * amplitudes.max() / amplitudes[unclear] > 0.03).all()
    if not noise:
        np.testing.assert_allclose(results.amplitude, amplitudes, rtol=1e-3)


@pytest.mark.parametrize("samples", [20, SAMPLES])
def test_cycles_under_the_bands_floor_are_rows_of_their_own(samples):
    """Cycles ×30 smaller than their neighbours: analysed when clean, at 20 samples a cycle
    too (a sine's own second differences are not noise); with 1 % noise (a third of their
    amplitude) each is a row still, NaN and flagged no-reversal where no reversal stands
    above the noise; every number as driven."""
    applied, force, amplitudes = steep_sweep([3.0, 0.1, 3.0], samples=samples)
    results = analysed(applied, force)
    np.testing.assert_array_equal(results.cycle, np.arange(1, 10))
    np.testing.assert_allclose(results.amplitude, amplitudes, rtol=1e-3 if samples > 20 else 0.02)
    noisy = analysed(*steep_sweep([3.0, 0.1, 3.0], noise=0.01, samples=samples)[:2])
    np.testing.assert_array_equal(noisy.cycle, np.arange(1, 10))
    hidden = noisy.quality.values == "no-reversal"
    assert hidden.any() and not hidden[[0, 1, 2, 6, 7, 8]].any()
    assert noisy.amplitude.values[hidden].size and np.isnan(noisy.amplitude.values[hidden]).all()
    assert np.isfinite(noisy.dissipated_energy.values[[0, 1, 2, 6, 7, 8]]).all()


# amplitudes (× Δ_t) of one cycle each: alternating ×5, log-spaced ×20, ramps
SINGLE = {
    "x5-alternating": [0.4, 2.0] * 4,
    "log-spaced": np.geomspace(0.2, 4.0, 12),
    "ramp-up": np.linspace(0.45, 1.8, 20),
    "ramp-down": np.linspace(1.8, 0.45, 20),
}


def one_cycle_sweep(steps, noise=0.0, stiffness=35e6):
    """As :func:`steep_sweep`, each amplitude held one cycle (behind a rig ``stiffness``)."""
    return steep_sweep(steps, noise, held=1, stiffness=stiffness)


@pytest.mark.parametrize("noise", [0.0, 0.01])
@pytest.mark.parametrize("steps", SINGLE.values(), ids=SINGLE.keys())
def test_a_new_amplitude_every_cycle_reports_every_cycle(steps, noise):
    applied, force, amplitudes = one_cycle_sweep(steps, noise)
    results = analysed(applied, force)
    np.testing.assert_array_equal(results.cycle, np.arange(1, amplitudes.size + 1))
    assert results.attrs["incomplete_cycles"] == 2
    if not noise:
        np.testing.assert_allclose(results.amplitude, amplitudes, rtol=1e-3)


@pytest.mark.parametrize("noise", [0.0, 0.01])
@pytest.mark.parametrize("steps", [[0.1, 3.0], [3.0, 0.1]], ids=["up", "down"])
def test_a_x30_jump_at_either_end_reports_every_cycle(steps, noise):
    """The small cycles before the first large one, or after the last, are rows too."""
    applied, force, amplitudes = steep_sweep(steps, noise)
    results = analysed(applied, force)
    np.testing.assert_array_equal(results.cycle, np.arange(1, 7))
    big = amplitudes > amplitudes.min()
    np.testing.assert_allclose(results.amplitude.values[big], amplitudes[big], rtol=2e-2)
    small = results.amplitude.values[~big]
    if not noise:
        np.testing.assert_allclose(small, amplitudes[~big], rtol=1e-3)
    else:  # NaN where not found: never a value from noise alone
        assert np.isnan(small[results.quality.values[~big] == "no-reversal"]).all()


def test_a_rest_between_blocks_makes_no_cycle_of_noise():
    """The rig at rest (1 % noise) for five periods between two blocks of three cycles:
    no value from the rest, its periods NaN rows flagged no-reversal, the blocks' cycles
    analysed."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, 35e6)
    block = mindlin.sweep([at] * 3, SAMPLES)[:-1]
    applied = np.concatenate([block[: 4 * SAMPLES], np.zeros(5 * SAMPLES), block[SAMPLES:], [0]])
    _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, 35e6)
    rng = np.random.default_rng(2)
    applied += 0.01 * at * rng.standard_normal(applied.size)
    results = analysed(applied, force)
    hidden = results.quality.values == "no-reversal"
    assert np.isnan(results.amplitude.values[hidden]).all()
    np.testing.assert_allclose(results.amplitude.values[~hidden], at, rtol=0.05)
    assert np.count_nonzero(~hidden) == 6


OUT_OF_CORE = {
    "x4-down-and-up": lambda: steep_sweep(STEEP["x4-down-and-up"]),
    "x30-dip-noisy": lambda: steep_sweep([3.0, 0.1, 3.0], noise=0.01),
    "x30-jump-up-noisy": lambda: steep_sweep([0.1, 3.0], noise=0.01),
    "x5-alternating": lambda: one_cycle_sweep(SINGLE["x5-alternating"]),
}


@pytest.mark.parametrize("make", OUT_OF_CORE.values(), ids=OUT_OF_CORE.keys())
def test_a_steep_sweep_out_of_core_as_in_memory(monkeypatch, make):
    """Rows without a reversal too: the same rows, numbers and flags however it is held."""
    monkeypatch.setattr(passes, "_CHUNK", 1000)
    monkeypatch.setattr(passes, "_SAMPLE", 256)
    monkeypatch.setattr(pipeline, "TASK_SAMPLES", 777)
    applied, force, amplitudes = make()
    memory = analysed(applied, force)
    np.testing.assert_array_equal(memory.cycle, np.arange(1, amplitudes.size + 1))
    lazy = analysed(*lazily(applied, force, chunks=1700), scheduler="threads")
    assert_equal_results(lazy, memory)


@pytest.mark.parametrize("gap", [(200, 300), (1000, 1340), (1100, 1500), (990, 1700), (4000, 4401)])
def test_a_gap_in_a_sweep_leaves_each_cycle_its_row(monkeypatch, gap):
    """Missing samples (NaN) in a sweep of 20 cycles, at its start, over one to three
    cycles, and to its end: every cycle a row numbered as driven, those with a missing
    sample flagged, the others measured; out of core as in memory."""
    monkeypatch.setattr(passes, "_CHUNK", 1000)
    monkeypatch.setattr(pipeline, "TASK_SAMPLES", 777)
    applied, force, amplitudes = one_cycle_sweep(np.repeat(np.linspace(0.45, 1.8, 10), 2))
    applied[slice(*gap)] = np.nan
    memory = analysed(applied, force)
    np.testing.assert_array_equal(memory.cycle, np.arange(1, 21))
    skipped = np.char.startswith(memory.quality.values.astype(str), "missing-samples")
    driven = np.arange(1, 21) * SAMPLES  # where each drive cycle begins
    holds = (driven + SAMPLES >= gap[0]) & (driven <= gap[1])  # a sample of the gap, or beside
    assert skipped.any() and not (skipped & ~holds).any()
    np.testing.assert_allclose(memory.amplitude[~skipped], amplitudes[~skipped], rtol=1e-3)
    lazy = analysed(*lazily(applied, force, chunks=1700), scheduler="threads")
    assert_equal_results(lazy, memory)


@pytest.mark.parametrize("stiffness", [15e6, 35e6, 100e6])
@pytest.mark.parametrize("noise", [0.0, 0.01])
def test_every_cycle_of_a_sweep_with_noise_out_of_core(monkeypatch, noise, stiffness):
    """The sweep of 40 cycles from 0.45 to 1.8 Δ_t (each amplitude held two cycles) with
    and without 1 % noise, in memory and out of core: every cycle, numbered as driven."""
    monkeypatch.setattr(passes, "_CHUNK", 1000)
    monkeypatch.setattr(pipeline, "TASK_SAMPLES", 777)
    steps = np.repeat(np.linspace(0.45, 1.8, 20), 2)
    applied, force, amplitudes = one_cycle_sweep(steps, noise, stiffness)
    memory = analysed(applied, force)
    np.testing.assert_array_equal(memory.cycle, np.arange(1, 41))
    assert np.isfinite(memory.dissipated_energy).all()
    np.testing.assert_allclose(memory.amplitude, amplitudes, rtol=0.1 if noise else 1e-3)
    lazy = analysed(*lazily(applied, force, chunks=1700), scheduler="threads")
    assert_equal_results(lazy, memory)


def test_ecofmaps_loops_reports_every_cycle_of_a_csv(tmp_path, capsys):
    """The ×30 dip with 1 % noise through the command line: a row for each driven cycle,
    those without a reversal flagged no-reversal with empty values."""
    applied, force, _ = steep_sweep([3.0, 0.1, 3.0], noise=0.01)
    path = write_csv(tmp_path / "dip.csv", applied, force)
    status, out, err = run_loops(capsys, path, "--load", "450N", "--no-resolve")
    assert status == 0, err
    table = pd.read_csv(io.StringIO(out))
    assert table.cycle.tolist() == list(range(1, 10))
    hidden = table.quality == "no-reversal"
    assert hidden.any() and table.amplitude_um[hidden].isna().all()
