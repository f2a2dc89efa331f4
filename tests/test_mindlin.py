"""The Mindlin oracle (tests/mindlin.py) against its closed forms, before anything trusts it."""

import numpy as np
import pytest

from tests import mindlin

MU, LOAD, DELTA_T = 0.8, 450.0, 6e-6
SAMPLES = 4000  # per cycle: the loop's area by the trapezoidal rule to better than 1e-5


def _steady_loop(amplitude, stiffness):
    """The contact displacement and force of the second of three cycles at ``amplitude``."""
    contact = mindlin.Contact(MU, LOAD, DELTA_T)
    delta, force = mindlin.drive(contact, mindlin.sweep([amplitude], SAMPLES), stiffness)
    span = slice(SAMPLES, 2 * SAMPLES + 1)
    return delta[span], force[span]


def test_first_loading_is_mindlins():
    delta = np.linspace(0.0, 1.2 * DELTA_T, 2001)
    expected = MU * LOAD * (1 - (1 - np.minimum(delta / DELTA_T, 1)) ** 1.5)
    found = mindlin.Contact(MU, LOAD, DELTA_T).first_loading(delta)
    assert np.max(np.abs(found - expected)) < 1e-5 * MU * LOAD


@pytest.mark.parametrize("psi", [0.3, 0.5, 0.8, 0.95, 0.99, 0.999])
def test_partial_slip_loops_match_the_closed_forms(psi):
    amplitude = mindlin.slip_amplitude_closed(psi, DELTA_T)
    delta, force = _steady_loop(amplitude, np.inf)  # no rig: the contact's own loop
    energy = np.trapezoid(force, delta)
    assert force.max() / (MU * LOAD) == pytest.approx(psi, rel=2e-4)
    assert energy == pytest.approx(mindlin.energy_closed(psi, MU, LOAD, DELTA_T), rel=2e-4)


@pytest.mark.parametrize("stiffness", [15e6, 35e6, 100e6])
def test_ratios_at_the_transition_are_mindlins(stiffness):
    """As ψ → 1, A → 0.2 and B → 2^(1/3) - 1 on the contact's displacement, whatever the rig;
    the rig's compliance adds μP/S to the applied amplitude."""
    psi = 0.99999
    applied = mindlin.slip_amplitude_closed(psi, DELTA_T) + psi * MU * LOAD / stiffness
    delta, force = _steady_loop(applied, stiffness)
    applied_loop = delta + force / stiffness
    assert applied_loop.max() == pytest.approx(applied, rel=1e-9)
    q_star, d_star = force.max(), delta.max()
    energy = np.trapezoid(force, delta)
    assert energy == pytest.approx(np.trapezoid(force, applied_loop), rel=1e-9)  # the rig stores
    assert energy / (4 * d_star * q_star) == pytest.approx(mindlin.A_T, abs=2e-3)
    rising = np.gradient(delta) > 0
    at_zero = [np.interp(0.0, np.sort(force[m]), delta[m][np.argsort(force[m])])
               for m in (rising, ~rising)]  # fmt: skip
    opening = 0.5 * abs(at_zero[1] - at_zero[0])
    assert opening / d_star == pytest.approx(mindlin.B_T, abs=2e-3)
    assert applied == pytest.approx(mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness),
                                    rel=1e-3)  # fmt: skip


def test_gross_slip_loops_match_the_closed_forms():
    stiffness = 35e6
    amplitude = 1.6 * mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    delta, force = _steady_loop(amplitude, stiffness)
    energy, slip = mindlin.gross_slip_loop(amplitude, MU, LOAD, DELTA_T, stiffness)
    assert np.trapezoid(force, delta) == pytest.approx(energy, rel=2e-4)
    rising = np.gradient(delta) > 0
    crossing = delta[~rising][np.argmin(np.abs(force[~rising]))]
    assert abs(crossing) == pytest.approx(slip, rel=2e-3)


def test_a_grown_groove_holds_the_energy_laws_area():
    x, z, area = mindlin.grown_groove(10.0, 2e-14, 5e-3, 100e-6, threshold=2.0)
    assert area == pytest.approx(2e-14 * 8.0 / 5e-3)
    assert -np.trapezoid(np.minimum(z, 0.0), x) == pytest.approx(area, rel=1e-3)
