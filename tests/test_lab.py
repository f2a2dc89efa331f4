"""A lab's numbers (ecofmaps.lab) on loops of the Mindlin oracle through analyze_loops: the
sliding condition, the transition, energy wear; and bad input."""

import functools
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import ecofmaps
from ecofmaps.lab.wear import cycle_sum
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.quality import has_reason
from ecofmaps.measured.synthetic import synthetic_recording
from tests import mindlin
from tests.lab_cases import ALPHA, CYCLES, DELTA_T, HALF_WIDTH, LENGTH, LOAD, MU, recorded_test

RIGS = (15e6, 35e6, 100e6)


def _analysed(amplitudes, stiffness, mu=MU, delta_t=DELTA_T, samples=200, **options):
    """analyze_loops of the oracle driven through one cycle at each amplitude."""
    contact = mindlin.Contact(mu, LOAD, delta_t)
    applied = mindlin.sweep(amplitudes, samples)
    _, force = mindlin.drive(contact, applied, stiffness)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a sphere's stick is curved: flagged, as it should
        return ecofmaps.analyze_loops(applied, force, LOAD, **options)


def _sweep(stiffness, **options):
    """The variable-displacement method: 0.45 to 1.8 Δ_t, each amplitude held two cycles."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    return _analysed(np.repeat(np.linspace(0.45, 1.8, 20) * at, 2), stiffness, **options)


def _campaign(stiffness, factors=(0.5, 0.7, 0.85, 0.95, 1.05, 1.2, 1.5, 1.8)):
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    return [_analysed([f * at] * 3, stiffness) for f in factors]


@pytest.mark.parametrize("stiffness", RIGS)
def test_transition_from_a_campaign(stiffness):
    found = ecofmaps.transition(_campaign(stiffness), rig_stiffness=stiffness)
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    assert float(found.amplitude) == pytest.approx(at, rel=0.05)
    assert abs(float(found.amplitude) - at) < 2 * float(found.amplitude_se)
    assert float(found.mu) == pytest.approx(MU, rel=0.03)
    contact = float(found.amplitude) - float(found.mu) * LOAD / stiffness
    assert float(found.contact_amplitude) == pytest.approx(contact)
    assert found.amplitude.attrs["units"] == "m"


def test_without_the_rig_a_spheres_spring_stands_for_it():
    """Without the rig's stiffness the spring fitted behind a sphere's stick (its mindlin-stick
    cycles) stands for it. Without them, the transition is where Q* reaches the sliding
    friction, between two amplitudes; without a GICoF either, it is read on the applied
    displacement, where A > 0.2 calls gross-slip cycles partial slip and it lands high. The
    contact's is unknown then."""
    stiffness = 35e6
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    tests = _campaign(stiffness)
    found = ecofmaps.transition(tests)
    xr.testing.assert_allclose(found, ecofmaps.transition(tests, rig_stiffness=stiffness))
    by_force = ecofmaps.transition([test.drop_vars("quality") for test in tests])
    # between the campaign's 0.95 and 1.05 Δ_t: the middle, ± the spacing over √12
    assert float(by_force.amplitude) == pytest.approx(at, rel=1e-3)
    assert float(by_force.amplitude_se) == pytest.approx(0.1 * at / np.sqrt(12), rel=1e-3)
    applied = ecofmaps.transition([test.drop_vars(["quality", "gicof"]) for test in tests])
    assert float(applied.amplitude) > 1.1 * at
    for found in (by_force, applied):
        assert np.isnan(float(found.contact_amplitude))


@pytest.mark.parametrize("stiffness", RIGS)
def test_without_the_rig_a_force_at_the_sliding_friction_is_gross_slip(stiffness):
    """Without the rig's stiffness or a sphere's spring, a cycle whose Q*/P has reached the
    sliding friction (the GICoF of the cycles A > 0.2 already calls gross slip) is in gross
    slip: the sweep's cycles more than 5 % from Δ_t all in their regime. Without a GICoF,
    A > 0.2 alone calls the first gross-slip cycles partial slip."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    factors = np.repeat(np.linspace(0.45, 1.8, 20), 2)
    results = _analysed(factors * at, stiffness).drop_vars("quality")
    far, gross = np.abs(factors - 1) > 0.05, factors > 1
    called = ecofmaps.sliding_condition(results).gross_slip.values == 1
    np.testing.assert_array_equal(called[far], gross[far])
    applied = ecofmaps.sliding_condition(results.drop_vars("gicof")).gross_slip.values == 1
    assert np.count_nonzero(applied[far] != gross[far]) >= 2
    assert not np.any(applied & ~called)


@pytest.mark.parametrize("stiffness", RIGS)
def test_transition_from_a_sweep(stiffness):
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    results = _sweep(stiffness)
    found = ecofmaps.transition(results, rig_stiffness=stiffness)
    assert float(found.amplitude) == pytest.approx(at, rel=0.05)
    assert float(found.mu) == pytest.approx(MU, rel=0.03)
    condition = ecofmaps.sliding_condition(results, rig_stiffness=stiffness)
    assert condition.attrs["sliding_condition"] == "mixed slip"
    assert condition.attrs["regime_changes_at"].size >= 1


def test_the_rig_stiffness_the_results_were_analysed_with_is_the_default():
    """analyze_loops(..., rig_stiffness=S) keeps S in the attrs; an argument overrides it."""
    stiffness = 35e6
    results = _sweep(stiffness, rig_stiffness=stiffness)
    assert results.attrs["rig_stiffness"] == stiffness
    bare = results.drop_attrs(deep=False)
    for lab in (ecofmaps.sliding_condition, ecofmaps.transition):
        xr.testing.assert_identical(lab(results), lab(bare, stiffness))
        xr.testing.assert_identical(lab(results, 100e6), lab(bare, 100e6))
    found = ecofmaps.transition(results)
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    assert float(found.amplitude) == pytest.approx(at, rel=0.05)
    assert float(found.contact_amplitude) == pytest.approx(DELTA_T, rel=0.1)
    # none given, none recorded, no sphere's spring: on the applied displacement
    bare = bare.drop_vars("quality")
    assert np.isnan(float(ecofmaps.transition(bare).contact_amplitude))
    assert np.isnan(ecofmaps.sliding_condition(bare).contact_energy_ratio).all()


@pytest.mark.parametrize("factor, condition", [(0.7, "partial slip"), (1.5, "gross slip")])
def test_sliding_condition_of_a_test(factor, condition):
    stiffness = 35e6
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    found = ecofmaps.sliding_condition(_analysed([factor * at] * 4, stiffness), stiffness)
    assert found.attrs["sliding_condition"] == condition
    assert found.attrs["regime_changes_at"].size == 0
    assert (found.gross_slip == (factor > 1)).all()
    if factor > 1:  # a Mindlin gross-slip loop on the contact's displacement
        energy, slip = mindlin.gross_slip_loop(factor * at, MU, LOAD, DELTA_T, stiffness)
        contact = factor * at - MU * LOAD / stiffness
        assert float(found.contact_energy_ratio[1]) == pytest.approx(
            energy / (4 * contact * MU * LOAD), rel=1e-3
        )
        assert float(found.contact_opening_ratio[1]) == pytest.approx(slip / contact, rel=1e-2)


def test_a_campaign_that_never_crosses_is_an_error():
    stiffness = 35e6
    tests = _campaign(stiffness, factors=(0.5, 0.7, 0.9))
    with pytest.raises(ValueError, match=r"never cross the transition.*partial slip.*larger"):
        ecofmaps.transition(tests, rig_stiffness=stiffness)


def test_a_regime_that_changes_at_one_amplitude_is_no_transition():
    """A test whose friction runs in at one amplitude: partial slip, then gross slip."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, 35e6)
    tests = [_analysed([1.1 * at] * 3, 35e6, mu=mu) for mu in (1.2, MU)]
    with pytest.raises(ValueError, match=r"every cycle is at one amplitude \(17\.9"):
        ecofmaps.transition(tests, rig_stiffness=35e6)


def test_a_spheres_gross_slip_cycles_read_their_gicof():
    """A gross-slip loop whose stick follows Mindlin's law (mindlin-stick) reads its GICoF as
    Q/P on its sliding part, and the spring behind the law as its stiffness; only the first
    loop after a step up, which starts on the old amplitude's branch, does not."""
    stiffness = 35e6
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    results = _analysed([1.1 * at] * 3, stiffness, rig_stiffness=stiffness)
    assert (results.quality == "mindlin-stick").all()
    np.testing.assert_allclose(results.gicof, MU, rtol=1e-4)
    np.testing.assert_allclose(results.stiffness, stiffness, rtol=1e-3)
    assert results.crossing_displacement_forward.isnull().all()
    gross = _sweep(stiffness, rig_stiffness=stiffness).where(
        lambda r: r.regime == ecofmaps.GROSS_SLIP, drop=True
    )
    assert float((abs(gross.gicof / MU - 1) < 0.02).mean()) >= 0.8


def test_mu_t_without_a_gicof_has_no_standard_error():
    """From Q*/P alone (a table without GICoF), μ_t is a peak that the force's noise biases
    up: its standard error is NaN, and says why."""
    stiffness = 35e6
    tests = [test[["amplitude", "max_force", "dissipated_energy"]] for test in _campaign(stiffness)]
    found = ecofmaps.transition(tests, rig_stiffness=stiffness)
    assert float(found.mu) == pytest.approx(MU, rel=1e-3)
    assert np.isnan(float(found.mu_se)) and "noise" in found.mu_se.attrs["comment"]
    assert np.isnan(float(found.contact_amplitude_se))
    with_gicof = ecofmaps.transition(_campaign(stiffness), rig_stiffness=stiffness)
    assert "comment" not in with_gicof.mu_se.attrs


# --- the numbers on the oracle, measured (slow) -------------------------------------

SWEEP = np.repeat(np.linspace(0.45, 1.8, 20), 2)  # × Δ_t, each amplitude held two cycles
NOISE = 0.01  # × the largest amplitude on the displacement, × μP on the force


@functools.cache
def _driven(stiffness):
    """The oracle's applied displacement and force over :data:`SWEEP`, noise-free."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    applied = mindlin.sweep(SWEEP * at, 200)
    _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, stiffness)
    return applied, force


def _noisy_sweep(stiffness, noise, seed, rig_stiffness):
    """analyze_loops of the sweep with white ``noise``, and each cycle's driven amplitude / Δ_t."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    applied, force = _driven(stiffness)
    rng = np.random.default_rng(seed)
    applied = applied + noise * SWEEP.max() * at * rng.standard_normal(applied.size)
    force = force + noise * MU * LOAD * rng.standard_normal(force.size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = ecofmaps.analyze_loops(applied, force, LOAD, rig_stiffness=rig_stiffness)
    return results, SWEEP[results.cycle.values - 1]


@pytest.mark.slow
@pytest.mark.parametrize("noise", [0.0, NOISE])
@pytest.mark.parametrize("stiffness", RIGS)
def test_the_lab_numbers_on_a_spheres_sweep(stiffness, noise, record_property):
    """The sweep 0.45 to 1.8 Δ_t behind each rig, noise-free and with 1 % noise, the rig's
    stiffness known: the GICoF on >= 80 % of the gross-slip cycles within 2 % of μ; <= 5 % of
    the cycles more than 5 % from Δ_t in the wrong regime, with the rig's stiffness and
    without it; Δ_t within 5 %, μ_t within 3 %; without the rig's stiffness or the quality
    column (where the force decides), Δ_t within 5 % and ±2 se."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    results, factor = _noisy_sweep(stiffness, noise, 1, stiffness)
    assert results.cycle.size == SWEEP.size
    gross, far = factor > 1, abs(factor - 1) > 0.05
    read = float((abs(results.gicof.values[gross] / MU - 1) < 0.02).mean())
    found = ecofmaps.transition(results)
    wrong = {}
    for known, rig in (("known", stiffness), ("unknown", None)):
        bare = results.drop_attrs(deep=False)
        called = ecofmaps.sliding_condition(bare, rig).gross_slip.values == 1
        wrong[known] = float(((called != gross) & far).sum() / far.sum())
    by_force = ecofmaps.transition(results.drop_attrs(deep=False).drop_vars("quality"))
    numbers = {"gicof": read, "wrong": wrong, "amplitude": float(found.amplitude) / at - 1,
               "mu": float(found.mu) / MU - 1,
               "by_force": float(by_force.amplitude) / at - 1}  # fmt: skip
    record_property("numbers", numbers)
    print(f"S = {stiffness / 1e6:g} MN/m, noise {noise:.0%}: GICoF on {read:.0%} of the "
          f"gross-slip cycles; wrong regime {wrong['known']:.1%} (S known), "
          f"{wrong['unknown']:.1%} (S unknown); Δ_t {numbers['amplitude']:+.2%}, "
          f"μ_t {numbers['mu']:+.3%}; Δ_t by the force {numbers['by_force']:+.2%}")  # fmt: skip
    assert read >= 0.8
    assert wrong["known"] <= 0.05 and wrong["unknown"] <= 0.05
    assert float(found.amplitude) == pytest.approx(at, rel=0.05)
    assert float(found.mu) == pytest.approx(MU, rel=0.03)
    assert float(by_force.amplitude) == pytest.approx(at, rel=0.05)
    assert abs(float(by_force.amplitude) - at) <= 2 * float(by_force.amplitude_se)


@pytest.mark.slow
@pytest.mark.parametrize("stiffness", RIGS)
def test_the_transitions_standard_errors_cover_the_truth(stiffness, record_property):
    """Over 100 sweeps with 1 % noise (seeded), ±2 se of Δ_t covers the truth on >= 95 % of
    them, and of μ_t on >= 85 % (aim 95 %), and Δ_t lies within 4 % on each."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    error = {"amplitude": [], "mu": []}
    for seed in range(100):
        found = ecofmaps.transition(_noisy_sweep(stiffness, NOISE, 1000 + seed, stiffness)[0])
        for name, truth in (("amplitude", at), ("mu", MU)):
            error[name].append((float(found[name]) - truth, float(found[f"{name}_se"]), truth))
    covered = {}
    for name, rows in error.items():
        off, se, truth = np.array(rows).T
        covered[name] = float(np.mean(np.abs(off) <= 2 * se))
        print(f"S = {stiffness / 1e6:g} MN/m {name}: bias {np.mean(off / truth):+.2%}, sd "
              f"{np.std(off / truth):.2%}, mean se {np.mean(se / truth):.2%}, largest "
              f"{np.max(np.abs(off / truth)):.2%}, ±2 se covers {covered[name]:.0%}")  # fmt: skip
        assert np.all(se > 0) and np.all(np.isfinite(se))
    record_property("coverage", covered)
    assert covered["amplitude"] >= 0.95 and covered["mu"] >= 0.85
    off, _, truth = np.array(error["amplitude"]).T
    assert np.all(np.abs(off / truth) < 0.04)


# --- energy wear ---------------------------------------------------------------------------


def _profile(energy, threshold=0.0, noise=0.0, seed=0):
    x, z, area = mindlin.grown_groove(energy, ALPHA, LENGTH, HALF_WIDTH, threshold, noise, seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ecofmaps.scar_profile(x, z, level=True), area


def test_energy_wear_of_a_test_recorded_every_500th_cycle():
    stiffness = 35e6
    amplitude = 2.5 * mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    results, sums = recorded_test(amplitude, stiffness)
    assert results.cycle.values.tolist() == CYCLES.tolist()
    profile, area = _profile(sums["energy"], noise=20e-9)
    wear = ecofmaps.energy_wear(results, profile, length=LENGTH)
    volume = area * LENGTH
    assert float(wear.cumulated_energy) == pytest.approx(sums["energy"], rel=0.03)
    assert float(wear.wear_volume) == pytest.approx(volume, rel=0.03)
    assert float(wear.energy_wear_coefficient) == pytest.approx(volume / sums["energy"], rel=0.03)
    assert float(wear.energy_wear_coefficient) == pytest.approx(ALPHA, rel=0.05)  # the grown α
    assert float(wear.archard_slip) == pytest.approx(volume / sums["slip"], rel=0.03)
    assert float(wear.archard_nominal) == pytest.approx(volume / sums["nominal"], rel=0.03)
    for name in [name for name in wear.data_vars if not name.endswith("_se")]:  # all five
        assert 0 < float(wear[f"{name}_se"]) < 0.03 * float(wear[name]), name
    assert wear.energy_wear_coefficient.attrs["units"] == "m3 J-1"


def test_the_cycle_sum_is_exact_for_energies_linear_in_the_cycle():
    energy = 1e-3 * (1 + CYCLES / 1e4)
    results = xr.Dataset(
        {"amplitude": ("cycle", np.full(CYCLES.size, 50e-6)),
         "slip_amplitude": ("cycle", np.full(CYCLES.size, 40e-6)),
         "dissipated_energy": ("cycle", energy)},
        coords={"cycle": CYCLES, "load": LOAD},
    )  # fmt: skip
    profile, _ = _profile(10.0)
    wear = ecofmaps.energy_wear(results, profile, length=LENGTH)
    every = np.arange(1, CYCLES[-1] + 1)
    assert float(wear.cumulated_energy) == pytest.approx((1e-3 * (1 + every / 1e4)).sum())
    assert float(wear.cumulated_energy_se) < 1e-9


def test_a_sum_over_no_cycle_with_a_value_says_so():
    """Every cycle NaN (all flagged): a ValueError saying why, not a bare NaN."""
    with pytest.raises(ValueError, match="no cycle has a value to sum: every one is NaN"):
        cycle_sum(CYCLES.astype(float), np.full(CYCLES.size, np.nan))


def test_energy_wear_over_a_campaign_finds_alpha_and_the_threshold():
    """Grooves grown by V = α(ΣE_d - E_th) at four amplitudes, each test recorded every
    500th cycle; the fit over the campaign gives α and E_th."""
    stiffness, threshold = 35e6, 5.0
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    tests, profiles = [], []
    for seed, factor in enumerate((1.5, 2.0, 3.0, 4.0)):
        results, sums = recorded_test(factor * at, stiffness, CYCLES[:9])
        tests.append(results)
        profiles.append(_profile(sums["energy"], threshold, noise=10e-9, seed=seed)[0])
    wear = ecofmaps.energy_wear(tests, profiles, length=LENGTH)
    assert wear.sizes["test"] == 4
    assert float(wear.campaign_energy_wear_coefficient) == pytest.approx(ALPHA, rel=0.05)
    assert float(wear.threshold_energy) == pytest.approx(threshold, abs=0.1 * threshold)
    assert float(wear.threshold_energy_se) > 0


# --- bad input -----------------------------------------------------------------------------


def _table(**drop):
    data = {"amplitude": ("cycle", [50e-6, 50e-6]), "slip_amplitude": ("cycle", [4e-5, 4e-5]),
            "dissipated_energy": ("cycle", [0.06, 0.06])}  # fmt: skip
    data = {k: v for k, v in data.items() if k not in drop}
    return xr.Dataset(data, coords={"cycle": [1, 2], "load": LOAD})


def test_bad_input_is_named():
    profile, _ = _profile(10.0)
    with pytest.raises(ValueError, match="dissipated_energy"):
        ecofmaps.energy_wear(_table(dissipated_energy=1), profile, length=LENGTH)
    with pytest.raises(ValueError, match="no cycle numbers"):
        ecofmaps.energy_wear(_table().drop_vars("cycle"), profile, length=LENGTH)
    with pytest.raises(ValueError, match="length = 5 m"):
        ecofmaps.energy_wear(_table(), profile, length=5.0)
    with pytest.raises(ValueError, match="profile: no scar"):
        ecofmaps.energy_wear(_table(), profile._replace(worn_area=np.float64(0.0)), length=LENGTH)
    with pytest.raises(TypeError, match="profile must be a ScarProfile"):
        ecofmaps.energy_wear(_table(), "scar.csv", length=LENGTH)
    with pytest.raises(ValueError, match="one profile and one length per test"):
        ecofmaps.energy_wear([_table(), _table()], [profile], length=LENGTH)
    with pytest.raises(ValueError, match="no depression found"):  # the profile's own reader
        ecofmaps.scar_profile(np.linspace(0, 1e-3, 200), np.zeros(200))


def test_running_condition_map_marks_each_test_and_the_transition():
    from ecofmaps.figures import running_condition_map

    stiffness = 35e6
    tests = _campaign(stiffness, factors=(0.6, 0.95, 1.05, 1.5))
    found = ecofmaps.transition(tests, rig_stiffness=stiffness)
    figure = running_condition_map(tests, found, stiffness)
    (ax,) = figure.axes
    assert ax.get_xlabel().endswith("[µm]") and ax.get_ylabel() == "Normal load $P$ [N]"
    labels = ax.get_legend_handles_labels()[1]
    assert labels[:2] == ["partial slip", "gross slip"] and "transition" in labels[2]
    line = ax.get_lines()[-1]
    at = np.interp(LOAD, line.get_ydata(), line.get_xdata()) * 1e-6
    assert at == pytest.approx(float(found.amplitude), rel=1e-6)


def test_the_worked_examples_in_the_docs_run_and_print_what_they_say(capsys):
    text = (Path(__file__).parents[1] / "docs" / "lab.md").read_text()
    examples = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(examples) == 2  # transition and energy wear; loop-scar closure
    for code in examples:
        exec(compile(code, "docs/lab.md", "exec"), {})
        printed = capsys.readouterr().out
        assert printed.strip() and printed in re.sub(r"\n    ", "\n", text)


def test_a_bad_rig_stiffness_is_named():
    with pytest.raises(ValueError, match="rig_stiffness"):
        ecofmaps.sliding_condition(_table().assign(max_force=("cycle", [300.0] * 2)), -35e6)


@pytest.mark.filterwarnings("ignore::ecofmaps.measured.LoopQualityWarning")
@pytest.mark.parametrize(("sample", "value"), [(1100, 1e9), (1050, 1e6)])
def test_a_force_sample_gone_wild_is_not_summed(sample, value):
    """One force sample gone wild: its cycle is implausible-cof, its row keeps what was
    measured, and ΣE_d passes over it: within 0.1 % of the clean recording's (it was 14 times
    it). A wrong load (every cycle implausible-cof) keeps every energy in the sum."""
    from ecofmaps.lab.wear import cumulated_energy
    from ecofmaps.paper import EXAMPLE_2, LOAD

    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=10, force_noise=1.0)
    clean = analyze_loops(displacement, force, load=LOAD)
    truth, _ = cumulated_energy(clean)
    wrong_load = analyze_loops(displacement, force, load=LOAD / 100.0)
    assert (wrong_load.quality == "implausible-cof").all()
    assert cumulated_energy(wrong_load)[0] == truth
    force = force.copy()
    force[sample] = value
    spiked = analyze_loops(displacement, force, load=LOAD)
    wild = has_reason(spiked.quality.values, "implausible-cof")
    assert wild.sum() == 1 and np.isfinite(spiked.dissipated_energy.values[wild]).all()
    total, _ = cumulated_energy(spiked)
    assert abs(total / truth - 1.0) < 1e-3
