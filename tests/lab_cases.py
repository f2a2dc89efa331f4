"""The cases of the lab's tests (tests/test_lab.py, tests/cli/test_wear.py): the Mindlin
contact they share, and a gross-slip test recorded every 500th cycle while its friction runs
in, with the constants of the groove an energy law grows from it."""

import warnings

import numpy as np

import ecofmaps
from tests import mindlin

MU, LOAD, DELTA_T = 0.8, 450.0, 6e-6
CYCLES = np.concatenate([[1], np.arange(500, 10001, 500)])  # recorded every 500th cycle
ALPHA, LENGTH, HALF_WIDTH = 2.5e-14, 5e-3, 150e-6  # m³/J, m, m


def running_in_mu(cycle):
    """Friction rising through the test (the running-in), and the contact's δ_t with it."""
    return 0.5 + 0.3 * (1.0 - np.exp(-cycle / 3000.0))


def recorded_cycles(amplitude, stiffness, cycles=CYCLES):
    """The applied displacement [m], force [N] and cycle number of each sample of the recorded
    cycles of a gross-slip test: one steady loop each, numbered as driven."""
    samples = 200
    pieces = []
    for n in cycles:
        mu = running_in_mu(n)
        contact = mindlin.Contact(mu, LOAD, DELTA_T * mu / MU)
        applied = mindlin.sweep([amplitude], samples)
        _, force = mindlin.drive(contact, applied, stiffness)
        span = slice(samples, 2 * samples)
        pieces.append((applied[span], force[span], np.full(samples, n)))
    return tuple(np.concatenate(p) for p in zip(*pieces, strict=True))


def recorded_test(amplitude, stiffness, cycles=CYCLES):
    """analyze_loops of :func:`recorded_cycles` and the closed-form sums over every cycle
    driven."""
    applied, force, cycle = recorded_cycles(amplitude, stiffness, cycles)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = ecofmaps.analyze_loops(applied, force, LOAD, cycle=cycle)
    every = np.arange(1, cycles[-1] + 1)
    mu = running_in_mu(every)
    energy, slip = mindlin.gross_slip_loop(amplitude, mu, LOAD, DELTA_T * mu / MU, stiffness)
    sums = {"energy": energy.sum(), "slip": (4 * LOAD * slip).sum(),
            "nominal": 4 * LOAD * amplitude * every.size}  # fmt: skip
    return results, sums


def round_scar(volume, radius, noise=0.0, seed=0):
    """A profilometer trace (x, z) [m] through the centre of a sphere's round scar of
    ``volume`` [m³], W-shaped (shallower at its centre), off the trace's zero and tilted,
    with a pile-up rim (not worn) and white noise; and the scar's depth at radius r."""

    def depth(r):  # ∫ 2πr d dr = π a² D ∫(1 - u)(1/2 + 2u) du = π a² D 7/12
        u = (r / radius) ** 2
        return np.where(u < 1, volume / (np.pi * radius**2 * 7 / 12) * (1 - u) * (0.5 + 2 * u), 0)

    x = np.linspace(-4 * radius, 4 * radius, 1601)
    r = np.abs(x - 37e-6)
    rim = 0.05 * depth(0.0) * np.exp(-50 * (r / radius - 1.3) ** 2)
    noise = noise * np.random.default_rng(seed).standard_normal(x.size)
    return x, -depth(r) + rim + 2e-4 * x + 1e-6 + noise, depth
