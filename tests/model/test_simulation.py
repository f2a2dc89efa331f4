"""Fretting loops (ecofmaps.model.simulation): the steady loop and the stick/slip simulation."""

import jax
import numpy as np
import pytest

import ecofmaps
from ecofmaps.paper import AMPLITUDE, EXAMPLE_2

#: Example 2 without its amplitude, the groove's half-width x_o = Δ* = 50 µm given instead.
MATERIAL = {k: v for k, v in EXAMPLE_2.items() if k != "amplitude"} | {
    "groove_half_width": AMPLITUDE
}


def area(displacement, force):
    """∮ Q dΔ of a closed polygon (trapezoids, equal to the shoelace sum)."""
    return float(np.sum((force[1:] + force[:-1]) / 2 * np.diff(displacement)))


def crossings(displacement, force, level):
    """(Δ, Q) where the polygon crosses the line Q = level(Δ), by linear interpolation."""
    above = force - level(displacement) >= 0
    gap = force - level(displacement)
    index = np.nonzero(above[:-1] != above[1:])[0]
    weight = gap[index] / (gap[index] - gap[index + 1])
    at = displacement[index] + weight * (displacement[index + 1] - displacement[index])
    return at, force[index] + weight * (force[index + 1] - force[index])


def triangle(amplitudes, samples_per_quarter):
    """Triangle wave from 0 through +A, -A, ... with every reversal sampled exactly."""
    quarter = np.linspace(0.0, 1.0, samples_per_quarter + 1)[1:]
    pieces = []
    for amplitude in amplitudes:
        pieces += [amplitude * quarter, amplitude * (1 - quarter), -amplitude * quarter]
        pieces += [-amplitude * (1 - quarter)]
    return np.concatenate(pieces)


# --- the steady loop -----------------------------------------------------------------------


def test_steady_loop_shape_and_landmarks():
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**EXAMPLE_2, num=101))
    assert displacement.shape == force.shape == (203,)
    peak = float(ecofmaps.max_force(**EXAMPLE_2))
    # starts at the reversal (-Δ*, -Q*), reaches (Δ*, Q*) halfway, closes on itself
    assert (displacement[0], force[0]) == (-50e-6, pytest.approx(-peak, rel=1e-15))
    assert displacement[101] == pytest.approx(50e-6, rel=1e-15)
    assert force[101] == pytest.approx(peak, rel=1e-15)
    assert displacement[-1] == pytest.approx(displacement[0], rel=1e-14)
    assert force[-1] == pytest.approx(force[0], rel=1e-14)
    # the stick segment after a reversal has the rig's slope S (eq. 10)
    slope = (force[1] - force[0]) / (displacement[1] - displacement[0])
    assert slope == pytest.approx(35e6, rel=1e-9)


def test_loop_half_width_at_zero_force_is_slip_amplitude():
    """Section 1: delta* is the loop's half-width at Q = 0 (while Q_+(-delta*) >= 0)."""
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**EXAMPLE_2))
    at_zero, _ = crossings(displacement, force, lambda d: 0 * d)
    slip = float(ecofmaps.slip_amplitude(**EXAMPLE_2))
    np.testing.assert_allclose(np.sort(at_zero), [-slip, slip], rtol=1e-12)


@pytest.mark.parametrize(("num", "tolerance"), [(100, 3e-5), (101, 1e-15), (2000, 1e-7)])
@pytest.mark.parametrize("aspect_ratio", [0.0, 0.1, 0.2, 0.3])
def test_gicof_of_model_loop_is_mu(aspect_ratio, num, tolerance):
    """Eq. 17-18: the loop crosses Q = S Δ where x = 0, at Q = ±mu P, whatever the groove.
    Linear interpolation between samples errs by O(h^2): 2.1e-5 at 100 points a branch; an odd
    number of points samples x = 0 itself."""
    point = dict(EXAMPLE_2, aspect_ratio=aspect_ratio)
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**point, num=num))
    _, cross = crossings(displacement, force, lambda d: 35e6 * d)
    np.testing.assert_allclose(np.sort(cross) / 450, [-0.8, 0.8], rtol=tolerance)


def test_rigid_loop_has_vertical_sides():
    displacement, force = (
        np.asarray(a) for a in ecofmaps.fretting_loop(**dict(EXAMPLE_2, stiffness=np.inf))
    )
    assert displacement[0] == displacement[1] == -50e-6
    assert force[1] > force[0]
    assert np.abs(displacement).max() == pytest.approx(50e-6, rel=1e-15)


def test_no_gross_slip_loop_is_the_stick_line():
    point = dict(EXAMPLE_2, stiffness=5e6)
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**point, num=11))
    np.testing.assert_allclose(force, 5e6 * displacement, rtol=1e-14, atol=1e-12)
    assert displacement.min() == -50e-6 and displacement.max() == 50e-6
    assert area(displacement, force) == pytest.approx(0.0, abs=1e-15)


def test_self_locking_loop_is_nan():
    point = dict(EXAMPLE_2, stiffness=np.inf, aspect_ratio=0.7)
    displacement, force = ecofmaps.fretting_loop(**point, num=5)
    assert np.isnan(displacement).all() and np.isnan(force).all()


def test_loop_broadcasts_and_vmaps():
    aspect = np.array([0.0, 0.1, 0.2])
    displacement, force = ecofmaps.fretting_loop(**dict(EXAMPLE_2, aspect_ratio=aspect), num=21)
    assert displacement.shape == force.shape == (3, 43)
    mapped = jax.vmap(lambda r: ecofmaps.fretting_loop(**dict(EXAMPLE_2, aspect_ratio=r), num=21))
    np.testing.assert_allclose(np.asarray(mapped(aspect)[1]), np.asarray(force), rtol=1e-15)
    energy = [area(d, q) for d, q in zip(np.asarray(displacement), np.asarray(force), strict=True)]
    expected = np.asarray(ecofmaps.dissipated_energy(**dict(EXAMPLE_2, aspect_ratio=aspect)))
    np.testing.assert_allclose(energy, expected, rtol=2e-4)  # 21 points a branch


@pytest.mark.parametrize("num", [1, 0, 2.5, "many"])
def test_loop_rejects_bad_num(num):
    with pytest.raises(ValueError, match="num must be an integer >= 2"):
        ecofmaps.fretting_loop(**EXAMPLE_2, num=num)


def test_loop_rejects_bad_parameters():
    with pytest.raises(ValueError, match="0 < load < inf"):
        ecofmaps.fretting_loop(**dict(EXAMPLE_2, load=-1.0))


# --- the time simulation -------------------------------------------------------------------


def test_simulated_peaks_are_the_closed_form_exactly():
    """The return map solves eq. 16 exactly: every peak after the first is Q*, to 1e-12."""
    displacement = triangle([50e-6] * 3, 50)
    force = np.asarray(ecofmaps.simulate(displacement, **MATERIAL))
    peak = float(ecofmaps.max_force(**EXAMPLE_2))
    tops = force[np.isclose(displacement, 50e-6, rtol=0, atol=1e-18)]
    bottoms = force[np.isclose(displacement, -50e-6, rtol=0, atol=1e-18)]
    np.testing.assert_allclose(tops, peak, rtol=1e-12)
    np.testing.assert_allclose(bottoms, -peak, rtol=1e-12)


def test_simulation_has_no_time_step_error():
    """Forces at shared instants are identical whether Δ(t) is sampled coarsely or 20x finer
    (the map is rate-independent and exact on each monotone stretch)."""
    coarse = triangle([50e-6, 30e-6, 60e-6], 10)
    fine = triangle([50e-6, 30e-6, 60e-6], 200)
    force_coarse = np.asarray(ecofmaps.simulate(coarse, **MATERIAL))
    force_fine = np.asarray(ecofmaps.simulate(fine, **MATERIAL))
    np.testing.assert_allclose(force_fine[19::20], force_coarse, rtol=1e-12, atol=1e-9)


def test_simulated_loop_lies_on_the_model():
    """Every sample either sticks (Q = S(Δ - x) with x unchanged) or slips on eq. 9 at
    x = Δ - Q/S (eq. 10): checked to 1e-9 relative."""
    displacement = triangle([50e-6] * 2, 40)
    force = np.asarray(ecofmaps.simulate(displacement, **MATERIAL))
    x = displacement - force / 35e6
    k = 2 * 0.2 / 50e-6
    forward = 450 * (0.8 + k * x) / (1 - 0.8 * k * x)
    backward = 450 * (-0.8 + k * x) / (1 + 0.8 * k * x)
    stuck = np.isclose(np.diff(x, prepend=0.0), 0.0, rtol=0, atol=1e-15)
    on_branch = np.isclose(force, forward, rtol=1e-9) | np.isclose(force, backward, rtol=1e-9)
    assert np.all(stuck | on_branch)
    assert np.count_nonzero(~stuck) > len(force) // 3


def test_simulated_cycle_area_is_dissipated_energy():
    """A sampled sinusoid cuts the stick-to-slip corners: O(1/n^2), 2e-5 at 4000 samples a
    cycle. The cycle after the first peak is already steady (slip depends on Δ only)."""
    samples = 4000
    t = np.arange(3 * samples + 1) / samples
    displacement = 50e-6 * np.sin(2 * np.pi * t)
    force = np.asarray(ecofmaps.simulate(displacement, **MATERIAL))
    cycle = slice(samples, 2 * samples + 1)
    energy = float(ecofmaps.dissipated_energy(**EXAMPLE_2))
    assert area(displacement[cycle], force[cycle]) == pytest.approx(energy, rel=2e-5)


def test_simulation_starts_at_rest_in_the_centre():
    displacement = np.linspace(0.0, 5e-6, 6)  # S Δ stays below mu P: the contact sticks
    force = np.asarray(ecofmaps.simulate(displacement, **MATERIAL))
    np.testing.assert_allclose(force, 35e6 * displacement, rtol=1e-15)


def test_rigid_simulation_follows_the_traction_curve():
    displacement = triangle([40e-6], 20)
    point = dict(MATERIAL, stiffness=np.inf)
    force = np.asarray(ecofmaps.simulate(displacement, **point))
    k = 2 * 0.2 / 50e-6
    rising = np.r_[True, np.diff(displacement) > 0]
    expected = np.where(
        rising,
        450 * (0.8 + k * displacement) / (1 - 0.8 * k * displacement),
        450 * (-0.8 + k * displacement) / (1 + 0.8 * k * displacement),
    )
    np.testing.assert_allclose(force, expected, rtol=1e-13)
    # standing still keeps the force
    held = np.asarray(ecofmaps.simulate(np.array([10e-6, 10e-6]), **point))
    assert held[0] == held[1]


def test_amplitude_changes_reach_the_new_steady_loop():
    """Peaks of each block of cycles equal Q* of that block's amplitude (after its first)."""
    amplitudes = [20e-6, 20e-6, 60e-6, 60e-6, 35e-6, 35e-6]
    displacement = triangle(amplitudes, 25)
    force = np.asarray(ecofmaps.simulate(displacement, **MATERIAL))
    tops = force[24::100]
    # the groove (x_o = 50 µm) stays while the amplitude changes
    expected = [float(ecofmaps.max_force(a, **MATERIAL)) for a in amplitudes]
    np.testing.assert_allclose(tops[[1, 2, 3, 5]], np.array(expected)[[1, 2, 3, 5]], rtol=1e-12)


def test_self_locking_simulation_gives_nan():
    point = dict(MATERIAL, stiffness=np.inf, aspect_ratio=0.7)
    force = np.asarray(ecofmaps.simulate(np.linspace(0, 60e-6, 7), **point))
    assert np.isfinite(force[:2]).all() and np.isnan(force[-1])


def test_simulation_broadcasts_parameters_and_jits():
    displacement = triangle([50e-6], 10)
    mu = np.array([0.4, 0.8, 1.2])
    force = np.asarray(ecofmaps.simulate(displacement, **dict(MATERIAL, mu=mu)))
    assert force.shape == (3, displacement.size)
    single = np.asarray(ecofmaps.simulate(displacement, **dict(MATERIAL, mu=1.2)))
    np.testing.assert_allclose(force[2], single, rtol=1e-15)
    jitted = jax.jit(ecofmaps.simulate)(displacement, *MATERIAL.values())
    np.testing.assert_allclose(np.asarray(jitted), force[1], rtol=1e-15)


def test_simulation_invalid_inside_jit_is_nan():
    jitted = jax.jit(ecofmaps.simulate)(triangle([50e-6], 4), 450.0, 35e6, -0.8, 0.2, 50e-6)
    assert np.isnan(np.asarray(jitted)).all()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (dict(displacement=np.array([0.0, np.nan])), "-inf < displacement < inf"),
        (dict(displacement=1e-6), "displacement must have a time axis"),
        (dict(groove_half_width=0.0), "0 < groove_half_width < inf"),
        (dict(mu=np.nan), "0 < mu < inf"),
        (dict(stiffness=-1.0), "0 < stiffness <= inf"),
    ],
)
def test_simulation_rejects_bad_input(change, message):
    arguments = dict(MATERIAL, displacement=np.zeros(3))
    arguments.update(change)
    with pytest.raises(ValueError, match=message):
        ecofmaps.simulate(**arguments)


@pytest.mark.slow
def test_loop_and_simulation_areas_at_random_points():
    """E_d (closed form) against the area of the steady loop and of a simulated sinusoidal
    cycle at ~600 random points over the tribologically meaningful domain, all in one call.
    Sampling errors, measured: steady loop at 401 points a branch 1.2e-5 here (4.7e-4 at the
    worst grid point, near locking), tolerance 1e-3; the simulation cuts the stick-to-slip
    corners, O(1/n^2), 5.8e-6 at 2000 samples a cycle, tolerance 2e-5."""
    rng = np.random.default_rng(17)
    count = 660
    amplitude = 10 ** rng.uniform(-6, -3.5, count)
    load = 10 ** rng.uniform(0, 4, count)
    mu = rng.uniform(0.05, 2.0, count)
    aspect_ratio = rng.uniform(0.0, 1.0, count)
    width = amplitude * rng.uniform(0.5, 10.0, count)
    mu_lam = np.where(rng.random(count) < 0.1, 0.0, rng.uniform(1e-9, 0.99, count))
    with np.errstate(divide="ignore"):
        stiffness = load * mu / (mu_lam * amplitude)
    rigid_locked = (mu_lam == 0) & (mu * 2 * aspect_ratio * amplitude / width >= 0.99)
    keep = ~rigid_locked
    args = [a[keep] for a in (amplitude, load, stiffness, mu, aspect_ratio, width)]
    assert keep.sum() >= 500
    energy = np.asarray(ecofmaps.dissipated_energy(*args))

    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(*args, num=401))
    loop_area = np.sum((force[:, 1:] + force[:, :-1]) / 2 * np.diff(displacement), axis=1)
    np.testing.assert_allclose(loop_area, energy, rtol=1e-3)

    samples = 2000
    t = np.arange(3 * samples + 1) / samples
    displacement = args[0][:, None] * np.sin(2 * np.pi * t)
    force = np.asarray(ecofmaps.simulate(displacement, *args[1:]))
    cycle = slice(samples, 2 * samples + 1)  # the second cycle: steady after the first peak
    d, q = displacement[:, cycle], force[:, cycle]
    simulated_area = np.sum((q[:, 1:] + q[:, :-1]) / 2 * np.diff(d), axis=1)
    np.testing.assert_allclose(simulated_area, energy, rtol=2e-5)
