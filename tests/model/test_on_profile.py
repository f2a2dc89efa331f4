"""The model on a scar profile against brute force, the closed forms, and its regimes."""

import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import ecofmaps
from ecofmaps import Regime
from ecofmaps.model.first_passage import JAMMED_TRACTION
from ecofmaps.model.on_profile import steady_numbers
from ecofmaps.paper import AMPLITUDE, LOAD, MU, STIFFNESS
from ecofmaps.units import DOMAIN
from tests.brute_force import ProfileBruteForce

EXAMPLE_2 = dict(amplitude=AMPLITUDE, load=LOAD, stiffness=STIFFNESS, mu=MU)  # without a groove
D, W = 10e-6, 50e-6  # D/W = 0.2 (Figure 5)

# Families at D/W = 0.2, and the mapping and rigs (amplitude, stiffness) each is checked on.
# The ridged scar is driven beyond its edges (X = x, amplitude 60 um > W = 40 um) onto ridges
# steep enough for the pad to jump over their crests on the stiffer rig.
FAMILIES = {
    "parabolic": (ecofmaps.parabolic_profile(D, W), "scaled"),
    "flat": (ecofmaps.flat_bottomed_profile(D, W, 0.5), "scaled"),
    "w": (ecofmaps.w_shaped_profile(D, W, 0.3), "scaled"),
    "tilted": (ecofmaps.flat_bottomed_profile(D, W, 0.3, tilt=0.12), "scaled"),
    "ridged": (ecofmaps.ridged_profile(8e-6, 40e-6, 4e-6, 30e-6, extent=3.0), "physical"),
}
RIGS = [(50e-6, 35e6), (60e-6, 20e6), (60e-6, 60e6), (50e-6, np.inf)]


def brute_force(profile, mapping, amplitude, stiffness, mu=0.8, load=450.0):
    length = float(profile.half_width) if mapping == "scaled" else amplitude
    return ProfileBruteForce(
        profile.position, profile.slope, amplitude, load, stiffness, mu, length
    ).steady_loop()


@pytest.mark.parametrize("family", list(FAMILIES))
def test_against_brute_force(family):
    """δ*, E_d, μ_E and the loop's ends vs first-passage scan + brentq + quad (1e-9; the
    issue asks 1e-6), on the same piecewise linear slope; the ridged scar with jumps."""
    profile, mapping = FAMILIES[family]
    amplitude = np.array([a for a, _ in RIGS])
    stiffness = np.array([s for _, s in RIGS])
    numbers = steady_numbers(profile, amplitude, 450.0, stiffness, 0.8, mapping=mapping)
    energy = ecofmaps.dissipated_energy(amplitude, 450.0, stiffness, 0.8, profile=profile,
                                        mapping=mapping)  # fmt: skip
    jumps = []
    for i, (a, s) in enumerate(RIGS):
        expected = brute_force(profile, mapping, a, s)
        assert numbers["regime"][i] == Regime.GROSS_SLIP
        slip = a * float(numbers["slip_ratio"][i])
        assert slip == pytest.approx(expected["slip_amplitude"], rel=1e-12)
        assert float(numbers["minus"][i]) == pytest.approx(expected["minus"], rel=1e-12)
        assert float(numbers["plus"][i]) == pytest.approx(expected["plus"], rel=1e-12)
        ecof = 0.8 * float(numbers["ecof_ratio"][i])
        assert ecof == pytest.approx(expected["ecof"], rel=1e-9)
        assert float(energy[i]) == pytest.approx(expected["dissipated_energy"], rel=1e-9)
        jumps.append(expected["jumps"])
    if family == "ridged":
        assert jumps[2]  # the stiff rig: x + Q+/S falls over the ridge's crest
    if family == "tilted":  # the loop is off-centre: x+ != -x-
        assert abs(float(numbers["plus"][0] + numbers["minus"][0])) > 0.05


def shoelace(x, y):
    return 0.5 * np.sum(x[:-1] * y[1:] - x[1:] * y[:-1])


def stroke(levels, steps):
    """Actuator positions from -1 to 1 in ``steps`` with ``levels`` (jumps' onsets) and a
    point 1e-12 above each inserted, so that a polyline has the jumps' vertical sides."""
    values = np.linspace(-1.0, 1.0, steps)
    values = np.concatenate([values, levels, np.asarray(levels) + 1e-12])
    return np.unique(values[(values >= -1.0) & (values <= 1.0)])


@pytest.mark.parametrize(("family", "rig"), [("w", 0), ("ridged", 2), ("tilted", 1)])
def test_simulated_loop_area(family, rig):
    """The shoelace area of the loop simulate draws over its last of several cycles is the
    steady E_d (1e-6), jumps included: the actuator history passes the jump levels, which
    the brute force finds on its own grid."""
    profile, mapping = FAMILIES[family]
    amplitude, stiffness = RIGS[rig]
    bf = ProfileBruteForce(
        profile.position, profile.slope, amplitude, 450.0, stiffness, 0.8,
        float(profile.half_width) if mapping == "scaled" else amplitude,
    )  # fmt: skip
    minus, plus = bf.loop()
    grid = bf.grid[(bf.grid > minus) & (bf.grid < plus)]
    running = np.maximum.accumulate(bf.forward_branch(grid))
    up = running[1:][np.diff(running) == 0.0]  # plateaus: the pad jumps at these levels
    falling = np.minimum.accumulate(bf.backward_branch(grid[::-1]))
    down = falling[1:][np.diff(falling) == 0.0]
    rise = stroke(np.unique(up), 4001)
    fall = -stroke(np.unique(-down - 1e-12), 4001)
    history = np.concatenate([np.linspace(0.0, 1.0, 2001)] + [fall[1:], rise[1:]] * 3)
    x_o = {} if mapping == "physical" else {"groove_half_width": amplitude}
    force = np.asarray(ecofmaps.simulate(amplitude * history, 450.0, stiffness, 0.8,
                                         profile=profile, mapping=mapping, **x_o))  # fmt: skip
    cycle = slice(history.size - (fall.size + rise.size - 1), None)
    area = -shoelace(amplitude * history[cycle], force[cycle])
    expected = float(ecofmaps.dissipated_energy(amplitude, 450.0, stiffness, 0.8,
                                                profile=profile, mapping=mapping))  # fmt: skip
    assert area == pytest.approx(expected, rel=1e-6)


@pytest.mark.slow
def test_drawn_loop():
    """fretting_loop on a profile: closed, clockwise, its area the steady E_d; on the
    parabola it is the closed-form loop."""
    profile = FAMILIES["parabolic"][0]
    x, q = ecofmaps.fretting_loop(**EXAMPLE_2, profile=profile, num=51)
    x0, q0 = ecofmaps.fretting_loop(**EXAMPLE_2, aspect_ratio=0.2, num=51)
    np.testing.assert_allclose(x, x0, rtol=0, atol=1e-17)
    np.testing.assert_allclose(q, q0, rtol=1e-12)
    ridged, mapping = FAMILIES["ridged"]
    rig = dict(amplitude=60e-6, load=450.0, stiffness=60e6, mu=0.8, mapping=mapping)
    x, q = (np.asarray(v) for v in ecofmaps.fretting_loop(**rig, profile=ridged, num=4001))
    assert x[0] == x[-1] and q[0] == q[-1] and x.size == 8003
    energy = float(ecofmaps.dissipated_energy(**rig, profile=ridged))
    assert -shoelace(x, q) == pytest.approx(energy, rel=1e-6)


# --- the closed forms ---------------------------------------------------------------------


@pytest.mark.slow
def test_parabola_family_reproduces_the_closed_forms():
    """A parabolic profile with aspect_ratio=D/W: every quantity within 1e-10 (eq. 9-16),
    over random rigs (rigid ones included), loads, mu and x_o >= amplitude."""
    rng = np.random.default_rng(11)
    count = 300
    points = dict(
        amplitude=10 ** rng.uniform(-5.5, -4, count),
        load=10 ** rng.uniform(0, 3.5, count),
        mu=10 ** rng.uniform(-1.3, 0.2, count),
    )
    points["groove_half_width"] = points["amplitude"] * 10 ** rng.uniform(0, 0.5, count)
    mu_lam = rng.uniform(0.0, 1.5, count)  # no gross slip above 1
    with np.errstate(divide="ignore"):
        points["stiffness"] = points["load"] * points["mu"] / (mu_lam * points["amplitude"])
    for ratio in (0.02, 0.2, 0.45):
        profile = ecofmaps.parabolic_profile(ratio * 1e-4, 1e-4, samples=1000)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ecofmaps.RegimeWarning)
            for name in ("slip_amplitude", "dissipated_energy", "energy_cof", "max_force"):
                function = getattr(ecofmaps, name)
                got = np.asarray(function(**points, profile=profile))
                expected = np.asarray(function(**points, aspect_ratio=ratio))
                np.testing.assert_allclose(got, expected, rtol=1e-10, atol=0, err_msg=name)
        np.testing.assert_array_equal(
            ecofmaps.slip_regime(**points, profile=profile),
            ecofmaps.slip_regime(**points, aspect_ratio=ratio),
        )


@pytest.mark.slow
@pytest.mark.parametrize("smoothing", [0.0, None])
def test_sampled_parabola_arrays_match_the_closed_forms(smoothing):
    """A parabola given as 4000 samples (edges, slopes and D/W found from the arrays):
    δ*, μ_E and E_d within 1e-5 of the closed forms (Example 2 and softer and stiffer rigs)."""
    x = np.linspace(-1.5 * W, 1.5 * W, 4000)
    z = np.where(np.abs(x) < W, D * ((x / W) ** 2 - 1.0), 0.0)
    profile = ecofmaps.scar_profile(x, z, smoothing=smoothing)
    stiffness = np.array([10e6, 35e6, 100e6])
    for name in ("slip_amplitude", "energy_cof", "dissipated_energy"):
        function = getattr(ecofmaps, name)
        got = np.asarray(function(50e-6, 450.0, stiffness, 0.8, profile=profile))
        expected = np.asarray(function(50e-6, 450.0, stiffness, 0.8, aspect_ratio=0.2))
        np.testing.assert_allclose(got, expected, rtol=1e-5, err_msg=name)


# --- regimes ------------------------------------------------------------------------------


def test_locking():
    """A flank with mu g >= 1 inside the stroke: a rigid rig locks (SELF_LOCKING, NaN, a
    warning that names it); any compliance stops the pad short of it (a finite loop)."""
    steep = ecofmaps.parabolic_profile(0.8 * W, W)  # slope 1.6 at the edges: mu g = 1.28
    rigid = dict(amplitude=50e-6, load=450.0, stiffness=np.inf, mu=0.8, profile=steep)
    assert int(ecofmaps.slip_regime(**rigid)) == Regime.SELF_LOCKING
    with pytest.warns(ecofmaps.RegimeWarning, match="self-locking"):
        assert np.isnan(ecofmaps.energy_cof(**rigid))
    compliant = {**rigid, "stiffness": 1e9}
    assert int(ecofmaps.slip_regime(**compliant)) == Regime.GROSS_SLIP
    slip = float(ecofmaps.slip_amplitude(**compliant))
    assert 0.0 < slip < 50e-6 / 1.28  # short of the locking point, x = W/(mu g'W)
    assert np.isfinite(ecofmaps.energy_cof(**compliant))
    history = 50e-6 * np.sin(np.linspace(0, 2 * np.pi, 400))
    force = np.asarray(ecofmaps.simulate(history, 450.0, np.inf, 0.8, profile=steep,
                                         groove_half_width=50e-6))  # fmt: skip
    assert np.isnan(force[-1]) and np.isfinite(force[10])


def test_beyond_the_trace():
    """A stroke that runs off the trace is BEYOND_PROFILE, NaN, and said so."""
    profile = ecofmaps.parabolic_profile(D, W, extent=1.2)
    rig = dict(amplitude=80e-6, load=450.0, stiffness=1e9, mu=0.8, profile=profile)
    assert int(ecofmaps.slip_regime(**rig, mapping="physical")) == Regime.BEYOND_PROFILE
    with pytest.warns(ecofmaps.RegimeWarning, match="beyond an end of the scar profile"):
        assert np.isnan(ecofmaps.slip_amplitude(**rig, mapping="physical"))
    assert int(ecofmaps.slip_regime(**rig)) == Regime.GROSS_SLIP  # scaled: X = x W/Δ* stays inside


def test_no_gross_slip():
    """μλ >= 1 at a flat groove centre: δ* = 0, E_d = 0, μ_E NaN, Q* = SΔ* (as eq. 16)."""
    profile = FAMILIES["w"][0]
    rig = dict(amplitude=50e-6, load=450.0, stiffness=5e6, mu=0.8, profile=profile)
    assert int(ecofmaps.slip_regime(**rig)) == Regime.NO_GROSS_SLIP
    assert float(ecofmaps.slip_amplitude(**rig)) == 0.0
    assert float(ecofmaps.dissipated_energy(**rig)) == 0.0
    assert float(ecofmaps.max_force(**rig)) == pytest.approx(5e6 * 50e-6, rel=1e-15)
    with pytest.warns(ecofmaps.RegimeWarning, match="no gross slip"):
        assert np.isnan(ecofmaps.energy_cof(**rig))


# --- batches, jit and vmap -------------------------------------------------------------------


@pytest.mark.slow
def test_vmap_over_a_batch_of_profiles():
    """jax.vmap over a stacked batch of profiles equals one call per profile."""
    profiles = [
        ecofmaps.w_shaped_profile(D, W, h, samples=1000, tilt=t)
        for h, t in ((0.1, 0.0), (0.3, 0.05), (0.6, -0.1))
    ]
    batch = jax.tree.map(lambda *leaves: jnp.stack(leaves), *profiles)
    stiffness = np.array([20e6, 35e6, 80e6, 1e9])

    def ecof(profile):
        return ecofmaps.energy_cof(50e-6, 450.0, stiffness, 0.8, profile=profile)

    mapped = np.asarray(jax.vmap(ecof)(batch))
    one_by_one = np.stack([np.asarray(ecof(p)) for p in profiles])
    np.testing.assert_allclose(mapped, one_by_one, rtol=1e-14)


@pytest.mark.slow
def test_jit_and_vmap_over_mu_and_amplitude():
    """Traced μ (each point its own O(N) tables) gives the concrete path's numbers."""
    profile = FAMILIES["w"][0]
    mu = np.array([0.2, 0.5, 0.8, 1.1])
    amplitude = np.array([30e-6, 50e-6, 80e-6, 100e-6])
    concrete = np.asarray(ecofmaps.energy_cof(amplitude, 450.0, 35e6, mu, profile=profile))

    @jax.jit
    def traced(mu, amplitude):
        return ecofmaps.energy_cof(amplitude, 450.0, 35e6, mu, profile=profile)

    np.testing.assert_allclose(traced(mu, amplitude), concrete, rtol=1e-14)
    single = jax.vmap(traced)(mu, amplitude)
    np.testing.assert_allclose(single, concrete, rtol=1e-14)
    assert single.dtype == jnp.float64


# --- properties -----------------------------------------------------------------------------


@settings(max_examples=25)
@given(
    hump=st.floats(0.0, 0.9),
    ratio=st.floats(0.01, 0.4),
    tilt=st.floats(-0.1, 0.1),
    mu=st.floats(0.05, 1.5),
    mu_lam=st.floats(0.0, 0.99),
)
# a rig so stiff (S = 4e22 N/m) that the pad stops where Q/P = 8e14: the area was rounding
@example(hump=0.625, ratio=0.3828125, tilt=0.0, mu=1.0, mu_lam=2.220446049250313e-16)
# a subnormal mu_lam: mu_lam * 50e-6 underflows to 0, a rigid rig (the test divided by it)
@example(hump=0.0, ratio=0.25, tilt=0.0, mu=1.0, mu_lam=5e-324)
# a rig stiffer than the model's domain (S = 2.5e293 N/m): taken as rigid, which it all but is
@example(hump=0.0, ratio=0.25, tilt=0.0, mu=1.0, mu_lam=3.560893861611701e-287)
def test_properties_on_random_w_shapes(hump, ratio, tilt, mu, mu_lam):
    """On any scar: μ_E >= μ (e >= 0, jumps add), 0 < δ* <= Δ*, E_d = 4Pδ*μ_E > 0."""
    profile = ecofmaps.w_shaped_profile(ratio * W, W, hump, tilt=tilt, samples=1000)
    compliance = mu_lam * 50e-6 / (450.0 * mu)  # 1/S [m/N]
    stiffest = DOMAIN["stiffness"][1]
    stiffness = 1.0 / compliance if compliance * stiffest > 1.0 else np.inf
    rig = dict(amplitude=50e-6, load=450.0, stiffness=stiffness, mu=mu, profile=profile)
    if int(ecofmaps.slip_regime(**rig)) != Regime.GROSS_SLIP:
        return  # a rigid rig may lock on the steepest flanks
    ecof = float(ecofmaps.energy_cof(**rig))
    slip = float(ecofmaps.slip_amplitude(**rig))
    assert ecof >= mu * (1.0 - 1e-15)
    assert 0.0 < slip <= 50e-6 * (1.0 + 1e-15)
    energy = float(ecofmaps.dissipated_energy(**rig))
    assert energy == pytest.approx(4 * 450.0 * slip * ecof, rel=1e-14)


def test_symmetric_profile_gives_a_centred_loop():
    numbers = steady_numbers(FAMILIES["flat"][0], 50e-6, 450.0, np.array([20e6, 60e6]), 0.8)
    np.testing.assert_allclose(numbers["minus"], -numbers["plus"], rtol=1e-14)


def test_flat_bottomed_scars_bias_the_ecof_less_than_the_parabola():
    """The issue's finding, at the D/W of Example 2 (0.2): a flat-bottomed scar biases the
    ECoF less than the parabola of eq. 11, the less the wider its flat bottom (the pad
    slides mostly on the flat); flat_fraction = 0 is the parabola itself."""
    bias = [
        float(ecofmaps.energy_cof(**EXAMPLE_2, profile=ecofmaps.flat_bottomed_profile(D, W, f)))
        / 0.8
        - 1.0
        for f in (0.0, 0.25, 0.5, 0.75)
    ]
    parabola = float(ecofmaps.energy_cof(**EXAMPLE_2, aspect_ratio=0.2)) / 0.8 - 1.0
    assert bias[0] == pytest.approx(parabola, rel=1e-10)
    assert parabola > bias[1] > bias[2] > bias[3] > 0.0


# --- bad input ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (dict(aspect_ratio=0.2, profile=FAMILIES["flat"][0]), "exactly one way.*not both"),
        ({}, "exactly one way.*got neither"),
        (dict(profile=FAMILIES["flat"][0], mapping="warped"), "mapping must be one of"),
        (dict(aspect_ratio=0.2, mapping="physical"), "mapping applies to a profile only"),
        (
            dict(profile=FAMILIES["flat"][0], mapping="physical", groove_half_width=1e-4),
            "mapping='physical' .* takes none",
        ),
        (dict(profile=(1, 2, 3)), "profile must be a ScarProfile"),
        (
            dict(profile=FAMILIES["flat"][0]._replace(position=FAMILIES["flat"][0].position[::-1])),
            "profile.position must be finite and strictly increasing",
        ),
        (dict(profile=FAMILIES["flat"][0], mu=-0.8), "mu must satisfy 0 < mu"),
    ],
)
def test_bad_input(arguments, message):
    rig = {**EXAMPLE_2, **arguments}
    with pytest.raises(ValueError, match=message):
        ecofmaps.energy_cof(**rig)


def test_simulate_bad_input():
    profile = FAMILIES["flat"][0]
    with pytest.raises(ValueError, match="needs groove_half_width"):
        ecofmaps.simulate(np.zeros(3), 450.0, 35e6, 0.8, profile=profile)
    with pytest.raises(ValueError, match="simulate with aspect_ratio needs groove_half_width"):
        ecofmaps.simulate(np.zeros(3), 450.0, 35e6, 0.8, 0.2)


def test_a_rig_too_stiff_for_float64_is_self_locking():
    """On a flank where mu g > 1, a stiffer rig pushes the pad closer to the locking point:
    the force and mu_E grow (mu_E by about 0.35 a decade of S here), until the force exceeds
    JAMMED_TRACTION times the load, where the loop's area is rounding (at S = 4e22 N/m it
    came out as -8.9e8): there the regime is SELF_LOCKING and the numbers NaN, with a reason."""
    profile = ecofmaps.w_shaped_profile(0.3828125e-3, 1e-3, 0.625, samples=1000)
    rig = dict(amplitude=50e-6, load=450.0, mu=1.0, profile=profile)
    lams = np.array([1e-3, 1e-6, 1e-8])
    stiffness = 450.0 / (lams * 50e-6)
    ecof = ecofmaps.energy_cof(**rig, stiffness=stiffness)
    peak = ecofmaps.max_force(**rig, stiffness=stiffness) / 450.0
    assert np.all(np.diff(ecof) > 0.3) and np.all(peak < JAMMED_TRACTION)
    for lam in (1e-10, 2.220446049250313e-16):
        point = dict(rig, stiffness=450.0 / (lam * 50e-6))
        assert int(ecofmaps.slip_regime(**point)) == Regime.SELF_LOCKING
        with pytest.warns(ecofmaps.RegimeWarning, match="self-locking"):
            assert np.isnan(ecofmaps.energy_cof(**point))


@pytest.mark.slow
@pytest.mark.parametrize("stiffness", [np.inf, STIFFNESS])
@pytest.mark.parametrize("name", ["energy_cof", "dissipated_energy", "slip_amplitude"])
def test_grad_on_a_profile_matches_central_differences(name, stiffness):
    """jax.grad of the model on a W-shaped scar, with respect to the amplitude and μ, is the
    central difference (relative step 1e-5: truncation and rounding below 1e-8 of the
    value), on a rigid rig as on a compliant one: finite where the rig takes no deflection."""
    profile, _ = FAMILIES["w"]
    function = getattr(ecofmaps, name)

    def value(amplitude, mu):
        return function(amplitude, LOAD, stiffness, mu, profile=profile)

    gradient = jax.grad(value, argnums=(0, 1))(AMPLITUDE, MU)
    for index, point in enumerate((AMPLITUDE, MU)):
        step = 1e-5 * point
        up, down = [AMPLITUDE, MU], [AMPLITUDE, MU]
        up[index] += step
        down[index] -= step
        expected = (float(value(*up)) - float(value(*down))) / (2.0 * step)
        scale = abs(float(value(AMPLITUDE, MU))) / point
        assert float(gradient[index]) == pytest.approx(expected, rel=1e-5, abs=1e-9 * scale)
