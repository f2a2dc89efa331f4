"""The model fit to a measured loop (ecofmaps.measured.fit), on loops simulated with known values.

The measured loops are made by ``ecofmaps.simulate`` (the stick/slip return map driven in
time), which is independent of the closed-form branches the fit evaluates.
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import ecofmaps
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.fit import MIN_SAMPLES, LoopFit, fit_loop
from ecofmaps.measured.synthetic import EXAMPLE, example_recording, synthetic_recording

LOAD = 450.0  # P [N], the paper's Section 3
AMPLITUDE = 50e-6  # Δ* = x_o [m]
# The paper's Example 2 of Section 3 (μ_E is 4 % above μ) and the two loops of Figure 10.
EXAMPLE_2 = dict(mu=0.8, aspect_ratio=0.2, stiffness=35e6)
FIGURE_10 = {
    "Example 1": dict(mu=0.825, aspect_ratio=1.8e-6 / AMPLITUDE, stiffness=45e6),
    "Example 2": dict(mu=0.825, aspect_ratio=8.0e-6 / AMPLITUDE, stiffness=35e6),
}
SAMPLES = 201  # every loop has this many samples, so the fit compiles once


def measured_loop(mu, aspect_ratio, stiffness, phase=None, cycles=2):
    """Samples of the last of ``cycles`` sine cycles driven through ``simulate``.

    ``phase`` (default: uniform, starting at a maximum) are the sampling instants within
    the cycle in units of the period, in [0, 1]; the peaks are always sampled, so the
    measured reversals are the true ones.
    """
    if phase is None:
        phase = np.linspace(0.0, 1.0, SAMPLES)
    time = np.concatenate(
        [np.linspace(0.0, cycles - 1, 100 * (cycles - 1) + 1), cycles - 1 + phase]
    )
    displacement = AMPLITUDE * np.cos(2.0 * np.pi * time)
    force = ecofmaps.simulate(
        displacement, LOAD, stiffness, mu, aspect_ratio, groove_half_width=AMPLITUDE
    )
    count = phase.size
    return displacement[-count:], np.asarray(force)[-count:]


def assert_recovered(fit, mu, aspect_ratio, stiffness, rtol):
    assert fit.success, fit.message
    assert fit.mu == pytest.approx(mu, rel=rtol)
    assert fit.stiffness == pytest.approx(stiffness, rel=rtol)
    # z_o relative to the groove half-width x_o = Δ*, so a flat groove is tested too
    assert fit.groove_depth == pytest.approx(aspect_ratio * AMPLITUDE, abs=rtol * AMPLITUDE)
    assert fit.aspect_ratio == pytest.approx(aspect_ratio, abs=rtol)
    assert fit.amplitude == pytest.approx(AMPLITUDE, rel=rtol)


# --- noise-free loops: the fit returns the parameters that made them -----------------------


@pytest.mark.parametrize(
    "parameters",
    [
        EXAMPLE_2,
        *FIGURE_10.values(),
        dict(mu=0.5, aspect_ratio=0.0, stiffness=20e6),
    ],
    ids=["Example 2 (Section 3)", *FIGURE_10, "flat groove"],
)
def test_recovers_noise_free_loop(parameters):
    displacement, force = measured_loop(**parameters)
    fit = fit_loop(displacement, force, LOAD)
    assert_recovered(fit, rtol=1e-9, **parameters)
    assert fit.displacement_offset == pytest.approx(0.0, abs=1e-9 * AMPLITUDE)
    assert fit.force_offset == pytest.approx(0.0, abs=1e-9 * LOAD)
    # the model passes through every sample; the reported residual is the samples' own
    assert fit.rms_residual < 1e-9 * LOAD
    assert fit.r_squared == pytest.approx(1.0, abs=1e-12)
    assert fit.standard_errors["mu"] < 1e-9 * fit.mu
    # the cycle fitted is the input loop turned round to start at its lowest displacement
    start = np.argmin(displacement)
    np.testing.assert_array_equal(fit.displacement, np.roll(displacement, -start))
    np.testing.assert_array_equal(fit.force, np.roll(force, -start))
    np.testing.assert_allclose(fit.model_force, fit.force, rtol=0, atol=1e-9 * LOAD)
    residual = np.sqrt(np.mean((fit.force - fit.model_force) ** 2))
    assert fit.rms_residual == pytest.approx(residual, rel=1e-12, abs=0)


def test_recovers_offsets_and_any_start_and_sampling():
    """Shifted axes, a loop that starts mid-stroke, non-uniform sampling instants."""
    rng = np.random.default_rng(7)
    inner = np.sort(rng.uniform(0.0, 1.0, SAMPLES - 3))
    phase = np.sort(np.concatenate([inner, [0.0, 0.5, 1.0]]))  # the two peaks sampled
    displacement, force = measured_loop(**EXAMPLE_2, phase=phase)
    start = 37  # one period, starting on the falling branch
    displacement = np.roll(displacement[:-1], -start)
    force = np.roll(force[:-1], -start)
    displacement = np.append(displacement, displacement[0]) + 3e-6
    force = np.append(force, force[0]) - 12.0
    fit = fit_loop(displacement, force, LOAD)
    assert_recovered(fit, rtol=1e-9, **EXAMPLE_2)
    assert fit.displacement_offset == pytest.approx(3e-6, rel=1e-9)
    assert fit.force_offset == pytest.approx(-12.0, rel=1e-9)


@given(
    mu=st.floats(0.1, 1.5),
    aspect_ratio=st.floats(0.0, 0.4),
    mu_lam=st.floats(0.02, 0.9),
)
def test_recovers_any_gross_slip_loop(mu, aspect_ratio, mu_lam):
    """Over the gross-slip domain: μ in [0.1, 1.5], z_o/x_o <= 0.4, μP/(SΔ*) up to 0.9.

    It includes grooves whose slope at the end of the slip exceeds μ, where the stick after
    a reversal ends before the force crosses zero.
    """
    stiffness = LOAD * mu / (mu_lam * AMPLITUDE)
    displacement, force = measured_loop(mu, aspect_ratio, stiffness)
    fit = fit_loop(displacement, force, LOAD)
    assert_recovered(fit, mu, aspect_ratio, stiffness, rtol=1e-8)


# --- noisy loops: stated tolerances ---------------------------------------------------------


def noisy(displacement, force, seed):
    """Noise of 0.5 % of Δ* on displacement and 1 % of Q* on force, and offsets."""
    rng = np.random.default_rng(seed)
    peak = np.max(np.abs(force))
    displacement = displacement + rng.normal(0.0, 0.005 * AMPLITUDE, displacement.size) + 2e-6
    force = force + rng.normal(0.0, 0.01 * peak, force.size) + 8.0
    return displacement, force


@pytest.mark.parametrize("name", list(FIGURE_10))
def test_recovers_noisy_loop(name):
    """Ten noisy copies of each Figure 10 loop: μ within 1 %, S within 5 %, z_o within 10 %."""
    parameters = FIGURE_10[name]
    clean_displacement, clean_force = measured_loop(**parameters)
    depth = parameters["aspect_ratio"] * AMPLITUDE
    peak = np.max(np.abs(clean_force))
    for seed in range(10):
        displacement, force = noisy(clean_displacement, clean_force, seed)
        fit = fit_loop(displacement, force, LOAD)
        assert fit.success, fit.message
        assert fit.mu == pytest.approx(parameters["mu"], rel=0.01)
        assert fit.stiffness == pytest.approx(parameters["stiffness"], rel=0.05)
        assert fit.groove_depth == pytest.approx(depth, rel=0.10)
        assert fit.displacement_offset == pytest.approx(2e-6, abs=0.005 * AMPLITUDE)
        assert fit.force_offset == pytest.approx(8.0, abs=0.01 * peak)
        # the residual is the noise: force noise 1 % of Q*, and on the stick segments the
        # displacement noise times S; it cannot be below the force noise alone by much
        floor = 0.01 * peak
        ceiling = np.hypot(floor, parameters["stiffness"] * 0.005 * AMPLITUDE)
        assert 0.8 * floor < fit.rms_residual < ceiling
        assert fit.r_squared > 0.99


def test_standard_errors_match_the_scatter_of_noisy_fits():
    """Thirty noisy copies of Example 2 of Figure 10: the reported standard errors of μ, S
    and z_o are within a factor 1.5 of the fits' scatter, and the fits are unbiased: their
    mean is within three standard errors of the mean of the truth.

    (Measured 1.37, 0.85 and 1.16: μ's error is conservative, since the stick samples carry
    more noise, S times the displacement noise, than the slip samples that fix μ.)
    """
    parameters = FIGURE_10["Example 2"]
    truth = {"mu": parameters["mu"], "stiffness": parameters["stiffness"]}
    truth["groove_depth"] = parameters["aspect_ratio"] * AMPLITUDE
    clean = measured_loop(**parameters)
    fits = [fit_loop(*noisy(*clean, seed), LOAD) for seed in range(30)]
    for name, true_value in truth.items():
        values = np.array([getattr(fit, name) for fit in fits])
        errors = np.array([fit.standard_errors[name] for fit in fits])
        scatter = values.std(ddof=1)
        assert 1 / 1.5 < errors.mean() / scatter < 1.5, name
        assert abs(values.mean() - true_value) < 3 * scatter / np.sqrt(values.size), name


# --- the fitted μ is the loop's GICoF (eq. 17-18) ------------------------------------------


@pytest.mark.parametrize("name", list(FIGURE_10))
def test_mu_agrees_with_gicof(name):
    """The fit and ecofmaps.analyze_loops' GICoF read the same μ off the same loop.

    Noise-free both are μ (the GICoF to the 1e-4 of its local parabola); with the noise
    above each is within 1 % of μ, so they agree within 1 %.
    """
    parameters = FIGURE_10[name]
    displacement, force = measured_loop(**parameters)
    gicof = float(analyze_loops(displacement, force, LOAD).gicof[0])
    assert fit_loop(displacement, force, LOAD).mu == pytest.approx(gicof, rel=1e-4)
    for seed in range(5):
        noisy_displacement, noisy_force = noisy(displacement, force, seed)
        results = analyze_loops(noisy_displacement, noisy_force, LOAD)
        fit = fit_loop(noisy_displacement, noisy_force, LOAD)
        assert fit.mu == pytest.approx(float(results.gicof[0]), rel=0.01)


# --- recordings of many cycles --------------------------------------------------------------

RATIOS = [0.05, 0.1, 0.15, 0.2]  # one groove per cycle, 50 % apart at least


def test_fits_chosen_cycle_of_labelled_recording():
    """Each recorded cycle is its own groove's steady loop: recovered exactly."""
    displacement, force = synthetic_recording(
        AMPLITUDE, LOAD, EXAMPLE_2["stiffness"], EXAMPLE_2["mu"], RATIOS,
        samples_per_cycle=SAMPLES - 1, displacement_offset=3e-6, force_offset=6.0,
    )  # fmt: skip
    numbers = np.repeat([10, 20, 30, 40], SAMPLES - 1)
    for number, ratio in zip([10, 20, 30, 40], RATIOS, strict=True):
        fit = fit_loop(displacement, force, LOAD, numbers, cycle_number=number)
        assert fit.cycle == number
        assert_recovered(fit, EXAMPLE_2["mu"], ratio, EXAMPLE_2["stiffness"], rtol=1e-9)
        assert fit.displacement_offset == pytest.approx(3e-6, rel=1e-9)
        assert fit.force_offset == pytest.approx(6.0, rel=1e-9)
    assert fit_loop(displacement, force, LOAD, numbers).cycle == 40  # the last by default
    with pytest.raises(ValueError, match=r"cycle_number 25 is not a complete cycle.* 10 to 40"):
        fit_loop(displacement, force, LOAD, numbers, cycle_number=25)


def test_fits_chosen_cycle_of_continuous_recording():
    """Cut at the reversals: cycle k is the k-th loop, the last complete one by default.

    A reversal found one sample off takes one sample of the neighbouring groove into the
    loop, so the groove is recovered within 2 % (the grooves differ by 25 % or more).
    """
    displacement, force = synthetic_recording(
        AMPLITUDE, LOAD, EXAMPLE_2["stiffness"], EXAMPLE_2["mu"], RATIOS,
        samples_per_cycle=SAMPLES - 1,
    )  # fmt: skip
    numbers = analyze_loops(displacement, force, LOAD).cycle.values
    for number in numbers:
        fit = fit_loop(displacement, force, LOAD, cycle_number=number)
        assert fit.cycle == number
        assert fit.aspect_ratio == pytest.approx(RATIOS[number - 1], rel=0.02)
    assert fit_loop(displacement, force, LOAD).cycle == numbers[-1]


def test_fits_last_loop_of_example_recording():
    """The shipped synthetic test (noise, offsets, drift): its last loop's parameters."""
    cycle, displacement, force = example_recording()
    fit = fit_loop(displacement, force, EXAMPLE["load"], cycle)
    assert fit.cycle == EXAMPLE["test_cycles"]
    assert fit.success, fit.message
    assert fit.mu == pytest.approx(EXAMPLE["mu"], rel=0.01)
    assert fit.stiffness == pytest.approx(EXAMPLE["stiffness"], rel=0.05)
    assert fit.aspect_ratio == pytest.approx(EXAMPLE["final_aspect_ratio"], rel=0.10)


# --- bad input ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def loop():
    return measured_loop(**EXAMPLE_2)


@pytest.mark.parametrize("load", [0.0, -450.0, np.nan, np.inf])
def test_rejects_bad_load(loop, load):
    with pytest.raises(ValueError, match=r"load must satisfy 0 < load < inf \[N\]"):
        fit_loop(*loop, load)


def test_rejects_load_array(loop):
    with pytest.raises(ValueError, match="load must be a single number"):
        fit_loop(*loop, [450.0, 450.0])


def test_rejects_too_few_samples(loop):
    displacement, force = loop
    step = displacement.size // (MIN_SAMPLES - 2)
    with pytest.raises(ValueError, match=f"at least {MIN_SAMPLES} samples"):
        fit_loop(displacement[::step], force[::step], LOAD)


@pytest.mark.parametrize("name", ["displacement", "force"])
@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_rejects_non_finite_samples(loop, name, value):
    samples = dict(zip(("displacement", "force"), (np.array(a) for a in loop), strict=True))
    samples[name][17] = value
    with pytest.raises(ValueError, match=rf"{name} must satisfy .* at index \(17,\)"):
        fit_loop(samples["displacement"], samples["force"], LOAD)


def test_rejects_mismatched_or_multidimensional_arrays(loop):
    displacement, force = loop
    with pytest.raises(ValueError, match="same length"):
        fit_loop(displacement, force[:-1], LOAD)
    with pytest.raises(ValueError, match="displacement must be one-dimensional"):
        fit_loop(displacement.reshape(3, -1), force.reshape(3, -1), LOAD)
    with pytest.raises(ValueError, match="does not vary"):
        fit_loop(np.zeros_like(displacement), force, LOAD)


def test_rejects_loop_without_gross_slip():
    """A rig too compliant for the contact to slip: the loop closes onto Q = SΔ."""
    displacement, force = measured_loop(mu=0.8, aspect_ratio=0.2, stiffness=5e6)
    assert ecofmaps.slip_regime(AMPLITUDE, LOAD, 5e6, 0.8, 0.2) == ecofmaps.NO_GROSS_SLIP
    with pytest.raises(ValueError, match="no gross slip"):
        fit_loop(displacement, force, LOAD)


def test_rejects_rigid_loop():
    """Vertical stick segments: the rig's stiffness is infinite and cannot be fitted."""
    displacement, force = ecofmaps.fretting_loop(AMPLITUDE, LOAD, np.inf, 0.8, 0.2, num=100)
    with pytest.raises(ValueError, match="rigid rig"):
        fit_loop(displacement, force, LOAD)


def test_rejects_anticlockwise_loop(loop):
    displacement, force = loop
    with pytest.raises(ValueError, match="anticlockwise"):
        fit_loop(displacement, -force, LOAD)


# --- the result -----------------------------------------------------------------------------


def test_result_is_float64_and_model_loop_matches_fretting_loop(loop):
    fit = fit_loop(*loop, LOAD)
    assert isinstance(fit, LoopFit)
    assert ecofmaps.LoopFit is LoopFit and ecofmaps.fit_loop is fit_loop
    for name in ("mu", "stiffness", "groove_depth", "aspect_ratio", "amplitude", "rms_residual"):
        assert type(getattr(fit, name)) is float
    assert fit.model_force.dtype == np.float64
    displacement, force = fit.model_loop(num=51)
    expected = ecofmaps.fretting_loop(AMPLITUDE, LOAD, num=51, **EXAMPLE_2)
    np.testing.assert_allclose(displacement, expected[0], rtol=0, atol=1e-12 * AMPLITUDE)
    np.testing.assert_allclose(force, expected[1], rtol=0, atol=1e-9 * LOAD)
    with pytest.raises(AttributeError):
        fit.mu = 1.0


# --- the figure (the paper's Figure 10) -----------------------------------------------------


def test_figure_overlays_measured_and_fitted_loops():
    from ecofmaps.figures import measured_and_fitted_loops

    fits = {}
    for seed, (name, parameters) in enumerate(FIGURE_10.items()):
        fits[name] = fit_loop(*noisy(*measured_loop(**parameters), seed), LOAD)
    figure = measured_and_fitted_loops(fits)
    panels = [ax for ax in figure.axes if ax.get_xlabel()]
    assert len(panels) == 2
    for ax, letter, (name, fit) in zip(panels, "ab", fits.items(), strict=True):
        assert ax.get_xlabel() == "Applied displacement $\\Delta$ [µm]"
        assert ax.get_ylabel() == "Tangential force $Q$ [N]"
        assert ax.get_title().startswith(f"({letter}) {name}: $P$ = 450 N")
        assert f"$\\mu$ = {fit.mu:.3f}" in ax.get_title()
        assert [text.get_text() for text in ax.get_legend().get_texts()] == [
            "measured",
            "fitted model",
        ]
        labelled = {line.get_label(): line for line in ax.get_lines()}
        measured, model = labelled["measured"], labelled["fitted model"]
        np.testing.assert_array_equal(measured.get_xdata(), fit.displacement * 1e6)
        np.testing.assert_array_equal(measured.get_ydata(), fit.force)
        assert measured.get_linestyle() == "None"
        loop_displacement, loop_force = fit.model_loop()
        np.testing.assert_allclose(model.get_xdata(), loop_displacement * 1e6, rtol=1e-15)
        np.testing.assert_allclose(model.get_ydata(), loop_force, rtol=1e-15)
    single = measured_and_fitted_loops(fits["Example 2"])
    assert len([ax for ax in single.axes if ax.get_xlabel()]) == 1


def test_rejects_a_cycle_the_analysis_refuses():
    """A dead force channel: the analysis refuses the cycle, and so does the fit."""
    displacement, force = measured_loop(**EXAMPLE_2)
    with pytest.raises(ValueError, match=r"no fretting loop .* constant-force"):
        fit_loop(displacement, np.full_like(force, 12.5), LOAD)
