"""Plausibility of measured loops: every flag of ``quality``
driven by the input that causes it in a lab, and no implausible number ever reported.

A recording is checked cycle by cycle; a value that cannot be stood behind is NaN and the
cycle's ``quality`` says why (ecofmaps.measured.quality). The model's loops, clean or with
the noise, offsets and drift of a rig, must come out 'ok'.
"""

import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ecofmaps
from ecofmaps.lab.regime import sliding_condition_line
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.measure import _RIG_RATIOS
from ecofmaps.measured.pipeline import LoopOptions
from ecofmaps.measured.quality import (
    ALL,
    REASONS,
    RESOLVED,
    SEPARATOR,
    LoopQualityWarning,
    add_reason,
    has_reason,
    quality_strings,
    quality_summary,
    refused,
)
from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.model.regimes import sliding_condition_of
from ecofmaps.paper import EXAMPLE_2, LOAD
from tests.measured.compare import PER_CYCLE, scope_of
from tests.recordings import mindlin_recording, noisy

AMPLITUDE = EXAMPLE_2["amplitude"]


def quiet(*args, **kwargs):
    """analyze_loops without its LoopQualityWarning (tested on its own below)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LoopQualityWarning)
        return analyze_loops(*args, **kwargs)


@pytest.fixture(scope="module")
def rig():
    """Ten cycles of Example 2 as a rig records them: noise, offsets, drift. [m], [N]"""
    return noisy(EXAMPLE_2, 10, 3)


# --- clean loops are 'ok' --------------------------------------------------------------------


@pytest.mark.parametrize(
    "point",
    [
        EXAMPLE_2,
        dict(EXAMPLE_2, aspect_ratio=0.0),
        dict(EXAMPLE_2, stiffness=20e6, mu=0.5, aspect_ratio=0.3),
        dict(EXAMPLE_2, stiffness=np.inf),  # rigid rig: vertical stick sides
    ],
    ids=["Example 2", "flat groove", "compliant rig", "rigid rig"],
)
def test_model_loops_are_ok(point):
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**point, num=201))
    with warnings.catch_warnings():
        warnings.simplefilter("error", LoopQualityWarning)
        result = analyze_loops(displacement, force, LOAD)
    assert result.quality.values.tolist() == ["ok"]
    assert result.attrs["quality_summary"] == "1 cycle: 1 ok"
    assert result.regime.values.tolist() == [ecofmaps.GROSS_SLIP]
    assert not any(np.isnan(result[name]).any() for name in PER_CYCLE)
    assert float(result.stick_residual[0]) < 1e-12 * AMPLITUDE  # straight stick sides


def test_rig_recording_is_ok_and_stick_residual_is_the_noise(rig):
    """Noise of 0.5 % of Δ* on the displacement: the stick lines are off by about that."""
    result = analyze_loops(*rig, LOAD)
    assert (result.quality == "ok").all()
    residual = result.stick_residual / (0.005 * AMPLITUDE)
    assert float(residual.min()) > 0.7 and float(residual.max()) < 1.6


def test_reversal_dwell_is_ok():
    """A clipped sine drive (the actuator dwells at each reversal) is a valid loop."""
    phase = np.arange(6 * 200 + 1) / 200
    imposed = np.clip(-np.cos(2 * np.pi * phase), -0.9, 0.9) * AMPLITUDE / 0.9
    force = np.asarray(ecofmaps.simulate(imposed, LOAD, 35e6, 0.8, 0.2, AMPLITUDE))
    result = analyze_loops(imposed, force, LOAD)
    assert (result.quality == "ok").all()
    np.testing.assert_allclose(result.gicof, 0.8, rtol=1e-9)


# --- each flag, from the input that causes it -------------------------------------------------


def test_force_recorded_with_the_other_sign(rig):
    """Anticlockwise loops with stick sides sloping down: refused, unless flip_force."""
    displacement, force = rig
    with pytest.raises(
        ValueError, match=r"anticlockwise 10, negative-stiffness 10\).*flip_force=True"
    ):
        quiet(displacement, -force, LOAD)
    flipped = analyze_loops(displacement, -force, LOAD, flip_force=True)
    assert flipped.attrs["flip_force"] == 1
    xr.testing.assert_equal(flipped, analyze_loops(displacement, force, LOAD))


def test_time_reversed(rig):
    """Played backwards the loops run anticlockwise, with stick sides sloping up."""
    displacement, force = rig
    with pytest.raises(ValueError, match=r"anticlockwise 10.*backwards in time"):
        quiet(displacement[::-1], force[::-1], LOAD)


def test_swapped_columns(rig):
    """Force read as displacement: an amplitude of hundreds of metres, anticlockwise."""
    displacement, force = rig
    with pytest.raises(
        ValueError,
        match=r"no plausible cycle.*implausible-amplitude.*anticlockwise.*columns are swapped",
    ):
        analyze_loops(force, displacement, LOAD)


@pytest.mark.parametrize("scale", [1e6, 1e-3, 1e-6])
def test_displacement_in_another_unit_is_refused(rig, scale):
    """Micrometres passed as metres, or metres as millimetres or micrometres: every cycle
    is refused, and the error names the unit and the option."""
    displacement, force = rig
    with pytest.raises(ValueError, match=r"implausible-amplitude.*--displacement-unit"):
        quiet(displacement * scale, force, LOAD)


def test_a_millimetre_stroke_is_reciprocating_sliding(rig):
    """A damper's 12.8 mm stroke: analysed, ok, and called reciprocating sliding."""
    displacement, force = rig
    with warnings.catch_warnings():
        warnings.simplefilter("error", LoopQualityWarning)
        result = analyze_loops(displacement * 256, force, LOAD)
    assert (result.quality == "ok").all()
    assert result.attrs["motion"] == "reciprocating sliding"
    assert analyze_loops(displacement, force, LOAD).attrs["motion"] == "fretting"


@pytest.mark.parametrize(("load", "scale"), [(1.0, 1.0), (LOAD, 1e-3), (LOAD * 1000, 1.0)])
def test_an_implausible_friction_coefficient_is_not_ok(rig, load, scale):
    """--load 1N on a 450 N test (a CoF of 360), or the force in kN read as N (a CoF of
    0.0008): no cycle is ok, the coefficients are NaN, and a warning names the load."""
    displacement, force = rig
    with (
        pytest.warns(LoopQualityWarning, match=rf"load of {load:g} N: is the load right"),
        pytest.warns(LoopQualityWarning, match="0 ok; implausible-cof 10"),
    ):
        result = analyze_loops(displacement, force * scale, load, resolve=True)
    assert (result.quality == "implausible-cof").all()
    for name in ("ecof", "gicof", "cof_max", "mu_resolved"):
        assert result[name].isnull().all(), name
    assert np.isfinite(result.amplitude).all() and np.isfinite(result.stiffness).all()


def test_dead_force_channel(rig):
    """A channel that dies mid-test: its cycles are refused, the others stand."""
    displacement, force = rig
    dead = force.copy()
    dead[1000:] = 7.25  # the last value the amplifier held
    result = quiet(displacement, dead, LOAD)
    cycle, quality = result.cycle.values, result.quality.values
    assert (quality[cycle <= 5] == "ok").all()
    assert refused(quality[cycle >= 6]).all()  # the 6th holds a live sample or two
    assert all("constant-force" in text for text in quality[cycle >= 7])
    assert result.gicof.sel(cycle=slice(6, None)).isnull().all()
    assert (result.regime.sel(cycle=slice(6, None)) == ecofmaps.INVALID).all()
    with pytest.raises(ValueError, match=r"constant-force 10.*force does not vary"):
        quiet(displacement, np.full_like(force, 7.25), LOAD)


def test_noise_only_is_refused():
    """No oscillation, only noise: the cycles cut at noise crossings are short, have no
    straight stick sides, and branches that do not cross zero force: no loops."""
    rng = np.random.default_rng(0)
    with pytest.raises(
        ValueError,
        match=r"no plausible cycle .*few-samples \d+, .*no-stick \d+, no-zero-crossing \d+",
    ):
        quiet(1e-6 * rng.normal(size=4000), 10.0 * rng.normal(size=4000), LOAD)


@pytest.mark.parametrize("seed", range(4))
def test_random_walks_are_no_loops(seed):
    """A wandering displacement and force: refused, or every cycle flagged."""
    rng = np.random.default_rng(seed)
    displacement = 1e-7 * np.cumsum(rng.normal(size=4000))
    try:
        result = quiet(displacement, np.cumsum(rng.normal(size=4000)), LOAD)
    except ValueError as error:  # no closed cycle, or none plausible
        assert "cycle" in str(error)
    else:
        assert (result.quality != "ok").all()


def test_unrelated_clipped_sines_are_refused():
    """Two clipped sines that are no friction loop (the force neither sticks nor slips).

    The displacement carries a rig's noise: held exactly flat where it is clipped, the
    force ramps at a constant displacement, a rigid rig's vertical stick side whose slope is
    rounding, and whether a cycle was refused depended on the last bit of its sums.
    """
    phase = np.linspace(0.0, 6.0, 1201)
    displacement = 60e-6 * np.clip(-np.cos(2 * np.pi * phase), -0.8, 0.8)
    displacement += 6e-9 * np.random.default_rng(0).normal(size=phase.size)
    force = 300.0 * np.clip(np.sin(2 * np.pi * phase + 0.3), -0.7, 0.7)
    with pytest.raises(ValueError, match=r"no plausible cycle .*no-stick"):
        quiet(displacement, force, LOAD)


def test_several_loops_under_one_cycle_number(rig):
    """Two cycles under one number: that one is refused, the others stand."""
    displacement, force = rig
    label = np.repeat(np.arange(10), 200)
    label[400:800] = 2
    result = quiet(displacement, force, LOAD, label)
    assert result.quality.sel(cycle=2).item() == "several-loops"
    assert result.sel(cycle=2).gicof.isnull() and result.sel(cycle=2).amplitude.isnull()
    assert (result.quality.drop_sel(cycle=2) == "ok").all()


def test_loop_area_above_its_bounding_box():
    """Two nearly rectangular loops under one number: their area exceeds 4Δ*Q*."""
    point = dict(EXAMPLE_2, stiffness=200e6, aspect_ratio=0.0)  # A = 0.96 per loop
    displacement, force = synthetic_recording(**point, cycles=4, force_noise=1.0, seed=4)
    label = np.repeat([1, 1, 2, 3], 200)
    result = quiet(displacement, force, LOAD, label)
    assert result.quality.sel(cycle=1).item() == "several-loops+energy-ratio-above-1"
    assert (result.quality.sel(cycle=[2, 3]) == "ok").all()


def test_too_few_samples_per_cycle():
    """A rig logging 6 samples per cycle: no loop can be read."""
    dense = np.asarray(ecofmaps.fretting_loop(**EXAMPLE_2, num=401))
    at = np.arange(6 * 8 + 1) / 6 * (dense.shape[1] - 1)
    displacement, force = (
        np.interp(at % (dense.shape[1] - 1), np.arange(dense.shape[1]), v) for v in dense
    )
    with pytest.raises(ValueError, match=r"few-samples 8\)"):
        quiet(displacement, force, LOAD)


def test_rounded_polymer_loop():
    """An elliptical (viscoelastic) loop has no straight stick sides: no S, no GICoF."""
    phase = np.linspace(0.0, 6.0, 1201)
    displacement = -AMPLITUDE * np.cos(2 * np.pi * phase)
    force = -300.0 * np.cos(2 * np.pi * phase + 0.6)
    result = quiet(displacement, force, LOAD)
    assert (result.quality == "curved-stick").all()
    assert result.stiffness.isnull().all() and result.gicof.isnull().all()
    # The area and the ECoF do not need the stick sides: pi/4 sin(0.6) of the box.
    np.testing.assert_allclose(result.energy_ratio, np.pi / 4 * np.sin(0.6), rtol=1e-3)
    assert result.ecof.notnull().all() and (result.stick_residual > 0).all()


def test_micro_slip_is_curved():
    """Mindlin's partial slip loop: curved stick sides and no gross slip, E_d stands."""
    result = quiet(*mindlin_recording(0.9), LOAD)
    assert (result.quality == "curved-stick+partial-slip").all()
    assert (result.regime == ecofmaps.PARTIAL_SLIP).all()
    assert result.stiffness.isnull().all() and result.dissipated_energy.notnull().all()


def test_loop_without_area_or_slip():
    """A rig too compliant to slip (Q = SΔ plus noise): no area, δ* about zero, S stands."""
    point = dict(EXAMPLE_2, stiffness=5e6)
    displacement, force = synthetic_recording(
        **point, cycles=6, displacement_noise=0.25e-6, force_noise=2.5, seed=2
    )
    result = quiet(displacement, force, LOAD)
    negative_area = has_reason(result.quality, "negative-area")
    negative_slip = has_reason(result.quality, "negative-slip")
    assert negative_area.any() and negative_slip.any()
    assert result.energy_ratio[negative_area].isnull().all()
    assert result.slip_amplitude[negative_slip].isnull().all()
    assert (result.energy_ratio[~negative_area] >= 0).all()
    np.testing.assert_allclose(result.stiffness, 5e6, rtol=0.02)  # every cycle
    assert has_reason(result.quality, "partial-slip").all()


def sparse_digitised_loop(cycles=6, seed=3):
    """Example 2's loop digitised from a figure: the reversals, the stick corners, and the
    slip branches only ahead of their crossing with Q = SΔ (|ξ| > 0.15 δ*), with noise."""
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**EXAMPLE_2, num=401))
    slip = float(ecofmaps.slip_amplitude(**EXAMPLE_2))
    position = displacement - force / EXAMPLE_2["stiffness"]  # eq. 10
    top = int(np.argmax(displacement))
    rising = np.arange(displacement.size) <= top
    keep = np.zeros(displacement.size, dtype=bool)
    keep[[0, top]] = True
    for branch, corner in ((rising, -slip), (~rising, slip)):
        keep[np.flatnonzero(branch & (np.abs(position - corner) < 1e-12))[-1]] = True
    ahead = np.flatnonzero(
        (rising & (position > 0.15 * slip)) | (~rising & (position < -0.15 * slip))
    )
    keep[ahead[:: ahead.size // 14]] = True
    keep[-1] = False  # the loop's last point is its first
    rng = np.random.default_rng(seed)
    samples = [np.append(np.tile(v[keep], cycles), v[0]) for v in (displacement, force)]
    return samples[0] + 0.2e-6 * rng.normal(size=samples[0].size), samples[1] + 3.0 * rng.normal(
        size=samples[1].size
    )


def test_crossing_not_on_the_digitised_loop():
    """No sample near ξ = 0: the GICoF would be extrapolated off the loop, so it is NaN.

    The padded implementation reported GICoFs from 0.57 to 0.96 for μ = 0.8 here; the
    ECoF, which needs no crossing, stands.
    """
    displacement, force = sparse_digitised_loop()
    result = quiet(displacement, force, LOAD)
    assert (result.quality == "no-crossing").all()
    assert result.gicof.isnull().all() and result.crossing_displacement_forward.isnull().all()
    assert result.ecof.notnull().all()


def test_sparse_loops_read_crossings_on_the_loop():
    """Rounded loops digitised with 8 to 12 uneven points per cycle: every GICoF crossing
    reported lies within its loop's forces (the padded implementation put some at up to
    160 times the largest measured force)."""
    rng = np.random.default_rng(1)
    for _ in range(10):
        count = int(rng.integers(8, 13))
        inner = np.sort(rng.uniform(0.0, 1.0, count))
        inner[0] = 0.0
        phase = np.concatenate([inner + k for k in range(4)] + [[4.0]])
        displacement = -AMPLITUDE * np.cos(2 * np.pi * phase)
        force = -300.0 * np.cos(2 * np.pi * phase + 0.6) + 3.0 * rng.normal(size=phase.size)
        assert_plausible(quiet(displacement, force, LOAD, keep_loops=True))


# --- the report --------------------------------------------------------------------------------


def test_one_warning_with_the_summary(rig):
    displacement, force = rig
    label = np.repeat(np.arange(10), 200)
    label[400:800] = 2
    with pytest.warns(LoopQualityWarning) as caught:
        result = analyze_loops(displacement, force, LOAD, label)
    assert len(caught) == 1
    assert str(caught[0].message) == "cycles flagged: 9 cycles: 8 ok; several-loops 1"
    assert result.attrs["quality_summary"] == "9 cycles: 8 ok; several-loops 1"


def test_partial_slip_alone_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error", LoopQualityWarning)
        result = analyze_loops(*mindlin_recording(0.5), LOAD)  # straight enough, no slip
    assert (result.quality == "partial-slip").all()


def test_sliding_condition_of_cycles():
    """Partial, gross or mixed slip, with the first cycle of each new regime; a cycle
    without a regime (NaN) is left out, and a test without any is an error."""
    cycle = np.arange(1, 7)
    assert sliding_condition_of(cycle, [0, 0, 0, 0, 0, 0])[0] == "partial slip"
    condition, changes = sliding_condition_of(cycle, [1, 1, np.nan, 1, 1, 1])
    assert condition == "gross slip" and changes.size == 0
    condition, changes = sliding_condition_of(cycle, [0, np.nan, 1, 1, 0, 0])
    assert condition == "mixed slip" and changes.tolist() == [3, 5]
    with pytest.raises(ValueError, match="no cycle with a regime"):
        sliding_condition_of(cycle, [np.nan] * 6)


def test_results_say_their_sliding_condition():
    """A test whose contact sticks for four cycles and then slides (a stiffer rig) is in
    mixed slip, its regime changing at cycle 5; in the attributes and in words."""
    point = dict(amplitude=AMPLITUDE, load=LOAD, mu=0.8, aspect_ratio=0.2, cycles=4, seed=1)
    parts = [synthetic_recording(**point, stiffness=stiffness) for stiffness in (5e6, 35e6)]
    displacement, force = (np.concatenate(arrays) for arrays in zip(*parts, strict=True))
    results = quiet(displacement, force, LOAD)
    assert results.regime.values.tolist() == [ecofmaps.PARTIAL_SLIP] * 4 + [ecofmaps.GROSS_SLIP] * 4
    assert results.attrs["sliding_condition"] == "mixed slip"
    assert results.attrs["regime_changes_at"].tolist() == [5]
    assert sliding_condition_line(results) == "mixed slip (the regime changes at cycle 5)"
    gross = quiet(*parts[1], LOAD)
    assert gross.attrs["sliding_condition"] == sliding_condition_line(gross) == "gross slip"
    assert gross.attrs["regime_changes_at"].size == 0
    assert quiet(*parts[0], LOAD).attrs["sliding_condition"] == "partial slip"


def test_bad_flip_force(rig):
    with pytest.raises(ValueError, match="flip_force must be True or False"):
        analyze_loops(*rig, LOAD, flip_force="yes")


def test_the_field_s_words():
    """In fretting "stick-slip" names the partial-slip regime (Vingsbo & Söderberg 1988):
    friction that oscillates while sliding is chatter, a measured loop's partial slip has its
    own reason and regime code, apart from the model's full stick (NO_GROSS_SLIP), and the
    docs say how the GICoF is computed (over the central crossing_window of the slip)."""
    assert "partial-slip" in REASONS and "not-gross-slip" not in REASONS
    assert "lower bound" in REASONS["partial-slip"][0]
    assert "chatter" in REASONS["gicof-varies"][0]
    assert not any("stick-slip" in meaning for meaning, _ in REASONS.values())
    assert ecofmaps.PARTIAL_SLIP != ecofmaps.NO_GROSS_SLIP
    assert ecofmaps.PARTIAL_SLIP.label == "partial slip"
    assert "partial" not in ecofmaps.NO_GROSS_SLIP.label
    docs = Path(__file__).parents[2] / "docs"
    rows = (docs / "loops.md").read_text(encoding="utf-8").splitlines()
    (gicof,) = [row for row in rows if row.startswith("| `gicof` |")]
    window = LoopOptions.crossing_window
    assert f"central {window * 100:g} % of the slip" in gicof and f"{window:g} δ*" in gicof
    (partial,) = [row for row in rows if row.startswith("| `partial-slip` |")]
    assert "lower bound of μ" in partial and "ecofmaps.transition" in partial
    assert "no friction coefficient" not in "\n".join(rows)


def test_vocabulary():
    """Reasons are lower-case words joined by hyphens; joined by '+', split back alike."""
    for reason, (meaning, scope) in REASONS.items():
        assert re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", reason), reason
        known = {*PER_CYCLE, *_RIG_RATIOS, *RESOLVED}
        assert meaning and (scope == ALL or set(scope) <= known), reason
    flags = {
        "negative-slip": np.array([True, False, False, True]),
        "curved-stick": np.array([True, False, True, False]),
        "no-crossing": np.array([False, False, True, True]),  # covered by curved-stick
        "partial-slip": np.array([False, False, False, True]),  # covers no-crossing
        "anticlockwise": np.array([False, True, False, False]),
    }
    quality = quality_strings(flags, 4)
    assert quality.tolist() == [
        "negative-slip+curved-stick",
        "anticlockwise",
        "curved-stick",
        "negative-slip+partial-slip",
    ]
    assert refused(quality).tolist() == [False, True, False, False]
    assert has_reason(quality, "negative-slip").tolist() == [True, False, False, True]
    assert quality_summary(quality) == (
        "4 cycles: 0 ok; anticlockwise 1, negative-slip 2, curved-stick 2, partial-slip 1"
    )
    added = add_reason(np.array(["ok", "partial-slip"]), [True, True], "few-slip-samples")
    assert added.tolist() == ["few-slip-samples", "partial-slip+few-slip-samples"]
    assert all(SEPARATOR not in reason for reason in REASONS)
    with pytest.raises(ValueError, match="unknown quality reason 'bad'"):
        add_reason(quality, True, "bad")


# --- no implausible number, whatever the input -------------------------

DENSE = np.asarray(ecofmaps.fretting_loop(**EXAMPLE_2, num=401))
REFUSALS = (
    r"the displacement does not oscillate: no reversal can be found$"
    r"|too few samples for one cycle: no complete cycle in \d+ samples \(.+\)$"
    r"|no plausible cycle in the recording \(\d+ cycles?: 0 ok; .+\)\. .+$"
)


def assert_plausible(result):
    """Every value reported obeys the rules of ecofmaps.measured.quality; every NaN has
    its reason."""
    quality = result.quality.values
    refusal = refused(quality)
    assert (result.regime.values[refusal] == ecofmaps.INVALID).all()
    assert not np.isin(result.regime.values[~refusal], [ecofmaps.INVALID]).any()
    scopes = [scope_of(text) for text in quality]
    for name in PER_CYCLE:
        value = result[name].values
        reached = np.array([name in scope for scope in scopes])
        assert np.isnan(value[reached]).all(), name
        assert not np.isnan(value[~reached]).any(), (name, quality[np.isnan(value) & ~reached])

    def reported(name):
        value = result[name].values
        return value[~np.isnan(value)]

    ratio = reported("energy_ratio")
    assert np.all((ratio >= 0.0) & (ratio <= 1.0 + 1e-9))
    assert np.all(reported("dissipated_energy") >= 0.0)
    slip, amplitude = result.slip_amplitude.values, result.amplitude.values
    has_slip = ~np.isnan(slip)
    assert np.all(slip[has_slip] > 0.0)
    assert np.all(slip[has_slip] <= amplitude[has_slip] * (1.0 + 1e-8))
    assert np.all(reported("stiffness") > 0.0)
    assert np.all(reported("ecof") > 0.0)
    assert np.all(result.regime.values[result.ecof.notnull().values] == ecofmaps.GROSS_SLIP)
    # The GICoF crossings lie within the measured (centred) loop.
    for branch, sign in (("forward", 1.0), ("backward", -1.0)):
        force = sign * result[f"gicof_{branch}"].values * LOAD
        at = result[f"crossing_displacement_{branch}"].values
        read = ~np.isnan(force)
        loops_q = result.loop_force.values[read]
        loops_x = result.loop_displacement.values[read]
        rounding = 1e-9 * np.nanmax(np.abs(loops_q), axis=1)
        assert np.all(force[read] >= np.nanmin(loops_q, axis=1) - rounding)
        assert np.all(force[read] <= np.nanmax(loops_q, axis=1) + rounding)
        assert np.all(at[read] >= np.nanmin(loops_x, axis=1) - 1e-9 * amplitude[read])
        assert np.all(at[read] <= np.nanmax(loops_x, axis=1) + 1e-9 * amplitude[read])


def test_slip_beyond_amplitude():
    """A slip amplitude beyond the amplitude, impossible on a loop, is never reported: a noisy
    cycle (a model loop's columns swapped, 96 samples) whose crossings at Q = 0 lie outside its
    extremes as read through the noise."""
    recording = np.load(Path(__file__).with_name("slip_beyond_amplitude.npz"))
    result = quiet(
        recording["displacement"], recording["force"], LOAD, keep_loops=True, rig_stiffness=1e9
    )
    assert result.quality.values.tolist() == ["slip-beyond-amplitude"]
    for name in ("slip_amplitude", "ecof", "opening_ratio", "contact_opening_ratio"):
        assert np.isnan(result[name]).all(), name
    assert_plausible(result)


@pytest.mark.parametrize("stiffness", [1e12, np.inf])
def test_near_rigid_gross_slip_is_ok(stiffness):
    """On a noise-free loop of a (near-)rigid rig the crossings at Q = 0 are (almost) at the
    extremes: δ* = Δ* - μP/S, not flagged however close."""
    loop = ecofmaps.fretting_loop(50e-6, LOAD, stiffness, 0.8, 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", LoopQualityWarning)
        result = analyze_loops(*(np.asarray(a) for a in loop), LOAD)
    assert result.quality.values.tolist() == ["ok"]
    slip, amplitude = float(result.slip_amplitude[0]), float(result.amplitude[0])
    np.testing.assert_allclose(amplitude - slip, 0.8 * LOAD / stiffness, rtol=1e-6, atol=1e-18)


@st.composite
def odd_recordings(draw):
    """Random (Δ, Q) recordings: model loops as a rig records them, noise, random walks,
    clipped sines; then perhaps the columns swapped, signs flipped, time reversed."""
    kind = draw(st.sampled_from(["model", "noise", "random walk", "clipped sines"]))
    size = draw(st.integers(8, 2500))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    if kind == "model":
        per_cycle = draw(st.integers(6, 300))
        phase = (np.arange(size) + rng.uniform(-0.3, 0.3, size)) / per_cycle + rng.uniform()
        at = phase % 1.0 * (DENSE.shape[1] - 1)
        displacement, force = (np.interp(at, np.arange(DENSE.shape[1]), v) for v in DENSE)
        noise = draw(st.sampled_from([0.0, 0.005, 0.05, 0.3]))
        displacement = displacement + noise * AMPLITUDE * rng.normal(size=size) + 1e-6 * phase
        force = force + noise * 400.0 * rng.normal(size=size) + draw(st.floats(-50, 50))
    elif kind == "noise":
        displacement, force = 1e-6 * rng.normal(size=size), 10.0 * rng.normal(size=size)
    elif kind == "random walk":
        displacement = 1e-7 * np.cumsum(rng.normal(size=size))
        force = np.cumsum(rng.normal(size=size))
    else:
        phase = np.arange(size) / draw(st.integers(6, 400))
        clip = draw(st.floats(0.1, 1.0))
        displacement = AMPLITUDE * np.clip(np.sin(2 * np.pi * phase), -clip, clip)
        lag = draw(st.floats(-np.pi, np.pi))
        force = 400.0 * np.clip(np.sin(2 * np.pi * phase + lag), -clip, clip)
    if draw(st.booleans()):
        displacement, force = force * 1e-7, displacement * 1e7  # swapped, in plausible units
    if draw(st.booleans()):
        force = -force
    if draw(st.booleans()):
        displacement = -displacement
    if draw(st.booleans()):
        displacement, force = displacement[::-1], force[::-1]
    return kind, displacement, force


@pytest.mark.slow
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(recording=odd_recordings())
def test_nothing_implausible_is_reported(recording):
    """Any recording: a ValueError with a message, or only plausible numbers."""
    _, displacement, force = recording
    try:
        result = quiet(displacement, force, LOAD, keep_loops=True)
    except ValueError as error:  # one of the documented refusals, with its message
        assert re.match(REFUSALS, str(error)), str(error)
        return
    assert_plausible(result)
