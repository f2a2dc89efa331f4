"""analyze_loops: per-cycle quantities of measured loops against the model and brute force.

Noise-free loops are checked to rounding where the method is exact for the model (Δ*, Q*,
S, δ*, GICoF) and to the trapezoidal rule's bound for E_d; noisy recordings (1 % of Q* on
the force, 0.5 % of Δ* on the displacement, offsets, drift) against the issue's accuracy.
"""

import numpy as np
import pytest
import xarray as xr
from hypothesis import assume, given
from hypothesis import strategies as st

import ecofmaps
from ecofmaps.measured import LoopQualityWarning
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.paper import AMPLITUDE, EXAMPLE_2, LOAD
from tests.recordings import SAMPLES, load_steps, mindlin_recording, ploughing_recording

EXACT = 1e-10  # relative tolerance where the method is exact for the model
QUANTITIES = ("amplitude", "slip_amplitude", "max_force", "dissipated_energy", "stiffness")


def model_values(point):
    """The model's steady-loop quantities at ``point`` (SI)."""
    return {
        "slip_amplitude": float(ecofmaps.slip_amplitude(**point)),
        "max_force": float(ecofmaps.max_force(**point)),
        "dissipated_energy": float(ecofmaps.dissipated_energy(**point)),
    }


def shoelace(x, y):
    """Area of the closed polygon through the points (x_i, y_i), clockwise positive."""
    return 0.5 * np.sum(np.roll(x, -1) * y - x * np.roll(y, -1))


def trapezoid_bound(point, spacing):
    """Bound on the trapezoidal rule's error for E_d = 2∫Q+ dx with contact-position steps.

    |error| <= 2 (2δ*) h² max|Q''| / 12, with Q'' = 2Pμk²(1+μ²)/(1-μkx)³ largest at x = δ*.
    """
    slip = float(ecofmaps.slip_amplitude(**point))
    mu, k = point["mu"], 2.0 * point["aspect_ratio"] / point["amplitude"]
    curvature = 2.0 * point["load"] * mu * k**2 * (1 + mu**2) / (1.0 - mu * k * slip) ** 3
    return 2.0 * 2.0 * slip * spacing**2 * curvature / 12.0


def closed_recording(point, cycles, **options):
    """``cycles`` whole cycles of the model, ending on the reversal where they began."""
    displacement, force = synthetic_recording(**point, cycles=cycles + 1, **options)
    samples = options.get("samples_per_cycle", SAMPLES)
    return displacement[: cycles * samples + 1], force[: cycles * samples + 1]


def relative(a, b):
    return np.abs(np.asarray(a) / np.asarray(b) - 1.0)


# --- noise-free: exact where the method is exact -----------------------------------------------


@pytest.mark.parametrize(
    "point",
    [
        EXAMPLE_2,
        dict(EXAMPLE_2, aspect_ratio=0.0),  # flat groove: the loop is a parallelogram
        dict(EXAMPLE_2, stiffness=20e6, mu=0.5, aspect_ratio=0.3),
        dict(EXAMPLE_2, stiffness=80e6, mu=1.1, aspect_ratio=0.1),
    ],
)
def test_model_loop_is_read_exactly(point):
    """One steady loop of the model (Figure 5): every quantity to rounding or its bound."""
    num = 201
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**point, num=num))
    result = analyze_loops(displacement, force, LOAD).isel(cycle=0)
    expected = model_values(point)
    assert result.regime == ecofmaps.GROSS_SLIP
    assert relative(result.amplitude, point["amplitude"]) < EXACT
    assert relative(result.max_force, expected["max_force"]) < EXACT
    assert relative(result.slip_amplitude, expected["slip_amplitude"]) < EXACT
    assert relative(result.stiffness, point["stiffness"]) < EXACT
    # GICoF (eq. 17-18): Q = μP on both branches, at Δ = ±μP/S.
    for name in ("gicof", "gicof_forward", "gicof_backward"):
        assert relative(result[name], point["mu"]) < EXACT
    crossing = point["mu"] * LOAD / point["stiffness"]
    assert relative(result.crossing_displacement_forward, crossing) < EXACT
    assert relative(-result.crossing_displacement_backward, crossing) < EXACT
    # E_d is the polygon's area, and within the trapezoidal bound of eq. 12.
    assert relative(result.dissipated_energy, shoelace(displacement, force)) < 1e-12
    spacing = 2.0 * expected["slip_amplitude"] / (num - 1)
    error = abs(float(result.dissipated_energy) - expected["dissipated_energy"])
    assert error <= trapezoid_bound(point, spacing) + 1e-14 * expected["dissipated_energy"]
    assert (
        relative(result.ecof, result.dissipated_energy / (4 * LOAD * result.slip_amplitude)) < 1e-14
    )
    assert (
        relative(
            result.energy_ratio,
            shoelace(displacement, force) / (4 * float(result.amplitude) * float(result.max_force)),
        )
        < 1e-12
    )


def test_rigid_rig():
    """S = ∞ (Figure 5's rigid loop): vertical sides, δ* = Δ*, the crossings at Δ = 0."""
    point = dict(EXAMPLE_2, stiffness=np.inf)
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**point))
    result = analyze_loops(displacement, force, LOAD).isel(cycle=0)
    assert np.isposinf(result.stiffness)
    assert relative(result.slip_amplitude, AMPLITUDE) < EXACT
    assert relative(result.gicof_forward, point["mu"]) < EXACT
    assert relative(result.gicof_backward, point["mu"]) < EXACT
    assert result.crossing_displacement_forward == 0.0
    assert relative(result.ecof, ecofmaps.energy_cof(**point)) < 1e-3  # 201-point loop


@given(
    mu=st.floats(0.1, 1.5),
    aspect_ratio=st.floats(0.0, 0.4),
    slip_ratio=st.floats(0.3, 0.95),
)
def test_gicof_is_mu_for_any_groove(mu, aspect_ratio, slip_ratio):
    """Property: for the model's loop the GICoF is μ, S the rig's and δ* the model's (Sec. 5).

    The stiffness is chosen so that a flat groove would slip over ``slip_ratio`` of the
    amplitude. The half-width at Q = 0 is δ* while the slope at the reversal, kδ*, is < μ,
    and the loop is read as gross slip while its energy ratio is above 0.2.
    """
    stiffness = mu * LOAD / ((1.0 - slip_ratio) * AMPLITUDE)
    point = dict(EXAMPLE_2, stiffness=stiffness, mu=mu, aspect_ratio=aspect_ratio)
    expected = model_values(point)
    slip = expected["slip_amplitude"]
    assume(2.0 * aspect_ratio * slip / AMPLITUDE < 0.95 * mu)
    assume(expected["dissipated_energy"] / (4 * AMPLITUDE * expected["max_force"]) > 0.21)
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**point, num=101))
    result = analyze_loops(displacement, force, LOAD).isel(cycle=0)
    assert relative(result.gicof_forward, mu) < 1e-9
    assert relative(result.gicof_backward, mu) < 1e-9
    assert relative(result.stiffness, stiffness) < 1e-9
    assert relative(result.slip_amplitude, slip) < 1e-9


@pytest.fixture(scope="module")
def noise_free():
    """Six whole cycles of Example 2 sampled 200 times per cycle, and one loop's results."""
    displacement, force = closed_recording(EXAMPLE_2, 6)
    reference = analyze_loops(displacement, force, LOAD)
    return displacement, force, reference


def test_recording_of_cycles(noise_free):
    """Cut at the reversals: every cycle is the steady loop; E_d is each polygon's area."""
    displacement, force, result = noise_free
    expected = model_values(EXAMPLE_2)
    assert result.cycle.values.tolist() == [1, 2, 3, 4, 5, 6]
    assert result.attrs["incomplete_cycles"] == 0
    assert result.attrs["dropped_samples"] == 0
    assert relative(result.amplitude, AMPLITUDE).max() < EXACT  # the reversals are sampled
    assert relative(result.max_force, expected["max_force"]).max() < EXACT
    assert relative(result.slip_amplitude, expected["slip_amplitude"]).max() < EXACT
    assert relative(result.stiffness, EXAMPLE_2["stiffness"]).max() < EXACT
    assert relative(result.gicof, EXAMPLE_2["mu"]).max() < EXACT
    for k in range(6):
        window = slice(k * SAMPLES, (k + 1) * SAMPLES + 1)
        area = shoelace(displacement[window], force[window])
        assert relative(result.dissipated_energy[k], area) < 1e-12
    # Sampled uniformly in time, 200 per cycle: the trapezoidal error is 1.3e-4 of E_d.
    assert relative(result.dissipated_energy, expected["dissipated_energy"]).max() < 3e-4


def test_convergence_of_the_loop_area():
    """E_d's error is the trapezoidal rule's: twice the samples, four times smaller."""
    expected = model_values(EXAMPLE_2)["dissipated_energy"]
    errors = []
    for samples in (800, 1600):
        displacement, force = closed_recording(EXAMPLE_2, 1, samples_per_cycle=samples)
        result = analyze_loops(displacement, force, LOAD)
        errors.append(float(relative(result.dissipated_energy[0], expected)))
    assert 3.5 < errors[0] / errors[1] < 4.5
    assert errors[1] < 5e-6


def test_offsets_and_drift_are_removed(noise_free):
    """Offsets of Δ and Q and a linear drift of Δ (1 % of Δ* per cycle) change nothing."""
    _, _, reference = noise_free
    drift = 0.5e-6  # per cycle [m]
    displacement, force = closed_recording(
        EXAMPLE_2, 6, displacement_offset=3e-6, force_offset=9.0, displacement_drift=drift
    )
    result = analyze_loops(displacement, force, LOAD)
    for name in (*QUANTITIES, "ecof"):
        assert relative(result[name], reference[name]).max() < 1e-12, name
    # The drift moves the two crossings by ±1.5e-5 and cancels from their mean.
    assert relative(result.gicof, EXAMPLE_2["mu"]).max() < 1e-9
    # The centres removed: the offsets plus the drift at each cycle's middle, to O(drift²/Δ*).
    centres = 3e-6 + drift * (np.arange(6) + 0.5)
    np.testing.assert_allclose(result.displacement_offset, centres, rtol=0, atol=1e-9)
    np.testing.assert_allclose(result.force_offset, 9.0, rtol=1e-12)


def test_labelled_cycles_turned_to_their_reversal(noise_free):
    """Loops numbered in the file, starting anywhere on the loop, each with its own offset."""
    _, _, reference = noise_free
    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=6, start_phase=0.3)
    labels = np.repeat(np.arange(1000, 7000, 1000), SAMPLES)
    jumps = np.repeat(np.arange(6) * 1e-6, SAMPLES)  # a new offset for each loop
    result = analyze_loops(displacement + jumps, force + 2e3 * jumps, LOAD, cycle=labels)
    assert result.cycle.values.tolist() == [1000, 2000, 3000, 4000, 5000, 6000]
    assert result.attrs["cycles_from"] == "cycle numbers"
    for name in (*QUANTITIES, "gicof", "ecof"):
        assert relative(result[name], reference[name][0]).max() < EXACT, name
    np.testing.assert_allclose(result.force_offset - 2e3 * result.displacement_offset, 0, atol=1e-9)


def test_incomplete_cycles_are_dropped_and_counted(noise_free):
    """A recording that starts and ends part-way through a cycle keeps its whole cycles."""
    _, _, reference = noise_free
    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=6, start_phase=0.3)
    result = analyze_loops(displacement, force, LOAD)
    # The first bottom reversal is at phase 1.0, 140 samples in; the last is 1000 samples on.
    assert result.cycle.size == 5
    assert result.attrs["incomplete_cycles"] == 2
    assert result.attrs["dropped_samples"] == 140 + (6 * SAMPLES - 1 - 1140)
    for name in (*QUANTITIES, "gicof"):
        assert relative(result[name], reference[name][0]).max() < EXACT, name


def test_single_loop_starting_anywhere(noise_free):
    """One closed loop that starts at zero displacement on the rise is read as one cycle."""
    _, _, reference = noise_free
    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=1, start_phase=0.25)
    result = analyze_loops(displacement, force, LOAD)
    assert result.cycle.size == 1
    for name in (*QUANTITIES, "gicof"):
        assert relative(result[name], reference[name][0]).max() < EXACT, name


def test_non_uniform_sampling():
    """A jittered clock: the loop's corners are missed by up to a sample, nothing more."""
    displacement, force = closed_recording(EXAMPLE_2, 6, sampling_jitter=0.45, seed=5)
    result = analyze_loops(displacement, force, LOAD)
    expected = model_values(EXAMPLE_2)
    assert result.cycle.size == 6
    # The reversal peaks fall between samples: Δ* and Q* to (π/200)²/2 ~ 1.2e-4; and the
    # jitter reads as noise round them, which the parabolas fitted there average (to 1e-3).
    assert relative(result.amplitude, AMPLITUDE).max() < 1e-3
    assert relative(result.max_force, expected["max_force"]).max() < 1e-3
    # Cycle centres read from uneven samples make a spurious drift of ~1e-10 m.
    assert relative(result.stiffness, EXAMPLE_2["stiffness"]).max() < 1e-4
    assert relative(result.slip_amplitude, expected["slip_amplitude"]).max() < 2e-4
    assert relative(result.gicof, EXAMPLE_2["mu"]).max() < 2e-4
    assert relative(result.dissipated_energy, expected["dissipated_energy"]).max() < 5e-4


def test_sparse_sampling_falls_back_to_interpolation():
    """16 samples per cycle on a flat groove: too few to fit, exact by interpolation."""
    point = dict(EXAMPLE_2, aspect_ratio=0.0)
    displacement, force = closed_recording(point, 3, samples_per_cycle=16)
    result = analyze_loops(displacement, force, LOAD)
    assert result.cycle.size == 3
    assert relative(result.gicof, point["mu"]).max() < EXACT
    assert relative(result.stiffness, point["stiffness"]).max() < EXACT


# --- noisy recordings: the accuracy ---------------------------------------------------


@pytest.mark.parametrize(
    ("point", "jitter"),
    [
        (dict(EXAMPLE_2, aspect_ratio=0.1), 0.0),
        (EXAMPLE_2, 0.0),
        (dict(EXAMPLE_2, stiffness=50e6, mu=0.6, aspect_ratio=0.15), 0.4),
    ],
)
def test_accuracy_with_noise_offsets_and_drift(point, jitter):
    """GICoF within 1 % of μ (median cycle) and 2.5 % (worst), S within 5 %, δ* and E_d 2 %."""
    expected = model_values(point)
    displacement, force = synthetic_recording(
        **point,
        cycles=40,
        displacement_noise=0.005 * AMPLITUDE,
        force_noise=0.01 * expected["max_force"],
        displacement_offset=4e-6,
        force_offset=7.0,
        displacement_drift=0.05e-6,
        sampling_jitter=jitter,
        seed=11,
    )
    result = analyze_loops(displacement, force, LOAD)
    assert result.cycle.size >= 38  # the first and last may be dropped as incomplete
    assert (result.regime == ecofmaps.GROSS_SLIP).all()
    gicof = relative(result.gicof, point["mu"])
    assert float(np.median(gicof)) < 0.01
    assert float(gicof.max()) < 0.025
    assert float(relative(result.stiffness, point["stiffness"]).max()) < 0.05
    for name in ("slip_amplitude", "dissipated_energy"):
        assert float(relative(result[name], expected[name]).max()) < 0.02, name


@pytest.mark.filterwarnings("ignore:cycles flagged:ecofmaps.measured.LoopQualityWarning")
def test_noise_makes_no_false_reversal():
    """Displacement noise of 5 % of Δ* (10 times the issue's) still gives one cycle per cycle
    (some flagged noise-amplitude: the noise lifts their peaks by about 16 % of Δ*)."""
    displacement, force = closed_recording(
        EXAMPLE_2, 6, displacement_noise=0.05 * AMPLITUDE, force_noise=6.0, seed=3
    )
    result = analyze_loops(displacement, force, LOAD)
    # A noisy sample beside the first or last reversal may leave a fragment of a few samples.
    assert result.cycle.size == 6
    assert result.attrs["dropped_samples"] < 20


def test_ploughing_peaks_leave_the_gicof():
    """Peaks of 0.3 μP at the stroke ends (Fig. 1b): GICoF within 2.5 %, noise-free 1e-5."""
    mu = EXAMPLE_2["mu"]
    displacement, force = ploughing_recording(0.3 * mu * LOAD, 3, noise=False)
    clean = analyze_loops(displacement, force, LOAD)
    assert float(relative(clean.gicof, mu).max()) < 1e-5
    assert float(relative(clean.stiffness, EXAMPLE_2["stiffness"]).max()) < EXACT
    assert float(clean.cof_max.max()) > 1.4  # the peak is well above μ
    displacement, force = ploughing_recording(0.3 * mu * LOAD, 40, noise=True)
    noisy = analyze_loops(displacement, force, LOAD)
    assert float(relative(noisy.gicof, mu).max()) < 0.025
    assert float(np.median(relative(noisy.gicof, mu))) < 0.01


def test_partial_slip_is_labelled():
    """Mindlin's partial-slip loop is labelled partial slip, and so is the model's full stick
    (μλ >= 1, its regime NO_GROSS_SLIP): a measured loop without slip has A = 0."""
    displacement, force = mindlin_recording(0.9)
    with pytest.warns(LoopQualityWarning, match="0 ok; curved-stick 4, partial-slip 4"):
        result = analyze_loops(displacement, force, LOAD)
    assert (result.regime == ecofmaps.PARTIAL_SLIP).all()
    assert result.regime.attrs["flag_meanings"].split()[ecofmaps.PARTIAL_SLIP] == "partial_slip"
    assert (result.cof_max < 0.8).all()  # Q*/P, kept: a lower bound of μ
    assert (result.energy_ratio < 0.2).all()
    assert result.gicof.isnull().all() and result.ecof.isnull().all()
    assert result.dissipated_energy.notnull().all()
    # The model's rig takes the whole amplitude: the loop is the line Q = SΔ, with noise.
    point = dict(EXAMPLE_2, stiffness=5e6)  # μλ = 0.8 * 450 / (5e6 * 50e-6) = 1.44
    assert ecofmaps.slip_regime(**point) == ecofmaps.NO_GROSS_SLIP
    displacement, force = synthetic_recording(
        **point, cycles=6, displacement_noise=0.25e-6, force_noise=2.5, seed=2
    )
    with pytest.warns(LoopQualityWarning, match="partial-slip 6"):
        result = analyze_loops(displacement, force, LOAD)
    assert (result.regime == ecofmaps.PARTIAL_SLIP).all()
    assert float(relative(result.stiffness, point["stiffness"]).max()) < 0.02
    assert float(np.abs(result.energy_ratio).max()) < 0.02


def test_gross_slip_threshold():
    """The criterion is A > threshold: a loop with A ≈ 0.4 changes label at 0.5."""
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**EXAMPLE_2))
    default = analyze_loops(displacement, force, LOAD)
    strict = analyze_loops(displacement, force, LOAD, gross_slip_threshold=0.5)
    assert 0.4 < float(default.energy_ratio[0]) < 0.41
    assert default.regime.values.tolist() == [ecofmaps.GROSS_SLIP]
    assert strict.regime.values.tolist() == [ecofmaps.PARTIAL_SLIP]
    assert np.isnan(strict.gicof[0]) and np.isnan(strict.ecof[0])


# --- the Dataset ----------------------------------------------------------------------------------


def test_dataset_attributes_and_round_trip(noise_free, tmp_path):
    """Every variable and coordinate has long_name and units; netCDF round trip is identical."""
    displacement, force, _ = noise_free
    result = analyze_loops(displacement, force, LOAD, keep_loops=True)
    for name in [*result.data_vars, *result.coords]:
        assert result[name].attrs["long_name"], name
        assert "units" in result[name].attrs, name
    assert result.loop_displacement.dims == ("cycle", "point")
    assert result.stiffness.dtype == np.float64
    path = tmp_path / "loops.nc"
    result.to_netcdf(path, engine="h5netcdf")
    with xr.open_dataset(path, engine="h5netcdf") as back:
        xr.testing.assert_identical(back.load(), result)
    table = analyze_loops(displacement, force, LOAD).to_dataframe()
    assert table.index.name == "cycle" and len(table) == 6


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (dict(load=0.0), "load must satisfy"),
        (dict(load=np.array([450.0, 450.0])), "load must have one value per sample: 2 values"),
        (dict(force=np.zeros(5)), "force must have one value per sample"),
        (dict(displacement=np.zeros((2, 600))), "displacement must be one-dimensional"),
        (dict(cycle=np.zeros(3)), "cycle must have one value per sample"),
        (dict(hysteresis=1.0), "hysteresis must satisfy"),
        (dict(stick_window=(0.5, 0.4)), "stick_window must satisfy"),
        (dict(crossing_window=0.0), "crossing_window must satisfy"),
        (dict(gross_slip_threshold=1.5), "gross_slip_threshold must satisfy"),
    ],
)
def test_bad_input(change, message):
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**EXAMPLE_2))
    arguments = dict(displacement=displacement, force=force, load=LOAD) | change
    with pytest.raises(ValueError, match=message):
        analyze_loops(**arguments)


def test_bad_recordings():
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**EXAMPLE_2))
    bad = displacement.copy()
    bad[7] = np.nan
    with pytest.raises(ValueError, match="sample 7 is missing"):
        analyze_loops(bad, force, LOAD, nan_policy="raise")
    with pytest.raises(ValueError, match="Every cycle holds a missing sample"):
        analyze_loops(bad, force, LOAD)  # the one loop is skipped
    with pytest.raises(ValueError, match="too few samples for one cycle: 5"):
        analyze_loops(displacement[:5], force[:5], LOAD)
    with pytest.raises(ValueError, match="does not oscillate"):
        analyze_loops(np.ones(50), np.ones(50), LOAD)
    with pytest.raises(ValueError, match="too few samples for one cycle: no complete cycle"):
        analyze_loops(displacement[:250], force[:250], LOAD)  # half a loop


# --- a normal load recorded sample by sample ------------------------------------------------


# The cycles across each step of the stepping load swing by more than LOAD_SWING.
STEPS_SWING = "load-swing 2"


def test_a_recorded_load_gives_each_cycle_at_its_own_load():
    """The load stepping 300 -> 450 -> 600 N: the cycle in the middle of each step (its
    neighbours at the same load) has the forces, energy and stiffness of the same loops
    analysed at that load as one value to 1e-5 (a reversal may be cut a sample apart), the
    rig's 35 MN/m to 1e-6, its normal_load, and the load's own coefficients. Before, they
    were all at the mean load (Q* 363 N at 300 N, and a stiffness of 52 MN/m)."""
    displacement, force, load = load_steps()
    with pytest.warns(LoopQualityWarning, match=STEPS_SWING):
        results = analyze_loops(displacement, force, load, resolve=True, keep_loops=True)
    assert float(results["load"]) == pytest.approx(load.mean())
    names = ("max_force", "dissipated_energy", "stiffness", "gicof", "ecof", "mu_resolved")
    for step, level in enumerate((300.0, 450.0, 600.0)):
        middle = 4 * step + 1  # the step's second cycle of four
        alone = analyze_loops(
            *load_steps((level,), cycles=4)[:2], level, resolve=True, keep_loops=True
        )
        assert float(results.normal_load[middle]) == pytest.approx(level, rel=1e-12)
        assert float(results.stiffness[middle]) == pytest.approx(35e6, rel=1e-6)
        for name in names:
            expected = float(alone[name][1])
            assert float(results[name][middle]) == pytest.approx(expected, rel=1e-5), name
        peak = np.nanmax(alone.loop_force[1])
        assert np.nanmax(results.loop_force[middle]) == pytest.approx(peak, rel=1e-5)


def test_resolve_loops_takes_a_recorded_load():
    """resolve_loops with the stepping load: its stiffness and the forces read along the
    stroke at each cycle's own load, as for the load given as one value (1e-5)."""
    displacement, force, load = load_steps()
    grid = np.arange(-25, 26) * 1e-6  # inside every cycle's resolved range, with 0
    with pytest.warns(LoopQualityWarning, match=STEPS_SWING):
        resolved = ecofmaps.resolve_loops(displacement, force, load, positions=grid)
    for step, level in enumerate((300.0, 450.0, 600.0)):
        middle = 4 * step + 1
        recording = load_steps((level,), cycles=4)[:2]
        alone = ecofmaps.resolve_loops(*recording, level, positions=grid)
        assert float(resolved.stiffness[middle]) == pytest.approx(35e6, rel=1e-6)
        for name in ("force_forward", "force_backward", "mu"):
            np.testing.assert_allclose(
                resolved[name][middle], alone[name][1], rtol=1e-5, err_msg=name
            )


def test_a_recorded_load_out_of_core_is_the_same():
    """The recorded load through dask, a chunk of cycles at a time: the same table."""
    import dask.array as da

    displacement, force, load = load_steps()
    with pytest.warns(LoopQualityWarning, match=STEPS_SWING):
        memory = analyze_loops(displacement, force, load)
    with pytest.warns(LoopQualityWarning, match=STEPS_SWING):
        lazy = analyze_loops(*(da.from_array(a, chunks=1500) for a in (displacement, force, load)))
    for name in ("normal_load", "max_force", "stiffness", "dissipated_energy", "ecof"):
        np.testing.assert_allclose(lazy[name], memory[name], rtol=1e-12, err_msg=name)


def _bad_loads():
    """The stepping load with a zero sample in cycle 5, a negative one in cycle 10, and a
    load swinging ±200 N about 450 N over cycle 6 (12 cycles of 200 samples)."""
    displacement, force, load = load_steps()
    load[5 * 200 + 100], load[10 * 200 + 50] = 0.0, -3.0
    load[6 * 200 : 7 * 200] = 450.0 + 200.0 * np.sin(np.arange(200) / 200 * 2 * np.pi)
    force[6 * 200 : 7 * 200] *= load[6 * 200 : 7 * 200] / 450.0  # the force follows the load
    return displacement, force, load


@pytest.mark.filterwarnings("ignore::ecofmaps.measured.LoopQualityWarning")
@pytest.mark.parametrize("chunks", [None, 1500, 700])
def test_a_recorded_load_is_judged_cycle_by_cycle(chunks):
    """A load not positive at one sample refuses its cycle alone; one swinging by more than
    LOAD_SWING of its mean empties the values at its load and keeps the coefficients; the
    cycles across a step of the load swing too. The same in memory and out of core."""
    import dask.array as da

    from ecofmaps.measured.quality import LOAD_SCALED, LOAD_SWING

    assert LOAD_SWING == 0.2
    arrays = _bad_loads()
    if chunks is not None:
        arrays = [da.from_array(a, chunks=chunks) for a in arrays]
    results = analyze_loops(*arrays)
    memory = analyze_loops(*_bad_loads())
    quality = results.quality.values
    assert list(quality[[5, 10]]) == ["load-not-positive"] * 2
    assert np.isnan(results.max_force[[5, 10]]).all() and np.isnan(results.ecof[[5, 10]]).all()
    assert list(np.flatnonzero(quality == "load-swing")) == [3, 6, 7]  # a step: 300 -> 450 N
    for name in LOAD_SCALED:
        assert np.isnan(results[name][[3, 6, 7]]).all(), name
    assert np.isfinite(results.ecof[[3, 6, 7]]).all()
    assert (quality[[0, 1, 2, 4, 8, 9, 11]] == "ok").all()
    assert results.attrs["quality_summary"] == "12 cycles: 7 ok; load-not-positive 2, load-swing 3"
    np.testing.assert_array_equal(quality, memory.quality.values)
    for name in ("normal_load", "max_force", "stiffness", "dissipated_energy", "ecof", "gicof"):
        np.testing.assert_allclose(results[name], memory[name], rtol=1e-12, err_msg=name)
    displacement, force, load = _bad_loads()  # as if the load were missing at those samples
    missing = analyze_loops(displacement, force, np.where(load > 0.0, load, np.nan))
    assert list(missing.quality[[5, 10]]) == ["missing-samples"] * 2
    recorded = ["quality", "normal_load"]  # a refused cycle's mean load: as recorded
    xr.testing.assert_equal(memory.drop_vars(recorded), missing.drop_vars(recorded))


@pytest.mark.filterwarnings("ignore::ecofmaps.measured.LoopQualityWarning")
@pytest.mark.parametrize("chunks", [None, 700])
def test_a_load_not_positive_is_named_with_nan_policy_raise(chunks):
    """Not 'sample 1100 is missing': the recorded load there, its cycle as the table numbers
    it, and for a negative load the hint of compression, in memory and out of core."""
    import dask.array as da

    from ecofmaps.measured.quality import COMPRESSION
    from ecofmaps.measured.samples import MissingSampleError

    labels = analyze_loops(*_bad_loads()).cycle.values
    displacement, force, load = _bad_loads()
    for sample, value, row in ((1100, "0", 5), (2050, "-3", 10)):
        arrays = (displacement, force, load)
        if chunks is not None:
            arrays = [da.from_array(a, chunks=chunks) for a in arrays]
        with pytest.raises(MissingSampleError) as raised:
            analyze_loops(*arrays, nan_policy="raise")
        assert raised.value.sample == sample
        assert str(raised.value) == (
            f"the recorded normal load at sample {sample} (cycle {labels[row]}) is {value} N, "
            "not positive, and the force is scaled by it; nan_policy='skip' flags its cycle "
            "load-not-positive and analyses the others"
            + (f": {COMPRESSION}" if value != "0" else "")
        )
        load[sample] = 450.0  # the next one


@pytest.mark.filterwarnings("ignore::ecofmaps.measured.LoopQualityWarning")
@pytest.mark.parametrize("chunks", [None, 700])
def test_cycles_cut_by_their_numbers_keep_those_with_missing_samples(chunks):
    """Cut by cycle numbers, a cycle whose load is not positive, or with a long gap in its
    displacement, is flagged as when cut at the reversals, not dropped as incomplete."""
    import dask.array as da

    displacement, force, load = _bad_loads()
    load[5 * 200 : 6 * 200] = 0.0  # all of cycle 6
    displacement[9 * 200 : 9 * 200 + 120] = np.nan  # most of cycle 10
    arrays = [displacement, force, load, np.repeat(np.arange(1, 13), 200)]
    if chunks is not None:
        arrays = [da.from_array(a, chunks=chunks) for a in arrays]
    results = analyze_loops(*arrays[:3], cycle=arrays[3])
    assert list(results.cycle.values) == list(range(1, 13))
    refused, gapped = "load-not-positive", "missing-samples"
    assert list(results.quality.values[[5, 9, 10]]) == [refused, gapped, refused]


@pytest.mark.parametrize("lazy", [False, True])
def test_a_recorded_load_nowhere_positive_says_why(lazy):
    """A load recorded negative (compression) asks for the other sign; one without a value
    names the load; one swinging in every cycle refused says so; in memory and out of core."""
    import dask.array as da

    displacement, force, load = load_steps()
    wrap = (lambda a: da.from_array(a, chunks=1500)) if lazy else np.asarray
    with pytest.raises(ValueError, match=r"nowhere positive \(from -600 N to -300 N\): is it "):
        analyze_loops(wrap(displacement), wrap(force), wrap(-load))
    with pytest.raises(ValueError, match=r"compression\? Give it with the other sign \(-Fz\)"):
        analyze_loops(wrap(displacement), wrap(force), wrap(-load))
    with pytest.raises(ValueError, match=r"\(from 0 N to 0 N\): is it the normal load\?"):
        analyze_loops(wrap(displacement), wrap(force), wrap(0.0 * load))
    with pytest.raises(ValueError, match="the recorded normal load holds no value"):
        analyze_loops(wrap(displacement), wrap(force), wrap(np.full(load.size, np.nan)))
    spiked = np.where(np.arange(load.size) % 50 == 7, -load, load)  # in every cycle
    with pytest.raises(ValueError, match=r"load-not-positive 12\). The recorded normal load is"):
        analyze_loops(wrap(displacement), wrap(force), wrap(spiked))
    swinging = np.where(np.arange(load.size) % 200 < 100, 2.0, 600.0)  # every cycle refused
    with pytest.raises(ValueError, match=r"\). The recorded normal load swings by more than 20%"):
        analyze_loops(wrap(displacement), wrap(force), wrap(swinging))
