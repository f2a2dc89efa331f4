"""Recordings the tests make of loops: the model behind a rig's noise, offsets and drift, a
sphere's partial slip (Mindlin), ploughing peaks at the stroke ends, load steps; and a
recording written as a text file.

Displacements in m, forces in N, 200 samples per cycle unless told.
"""

import numpy as np

import ecofmaps
from ecofmaps.model import traction_ratio
from ecofmaps.paper import AMPLITUDE, EXAMPLE_2, LOAD

SAMPLES = 200  # per cycle


def noisy(point, cycles, seed, **options):
    """A recording of the model at ``point`` with the noise, offsets and drift of a rig."""
    max_force = float(ecofmaps.max_force(**point))
    return ecofmaps.synthetic_recording(
        **point,
        cycles=cycles,
        displacement_noise=0.005 * point["amplitude"],
        force_noise=0.01 * max_force,
        displacement_offset=4e-6,
        force_offset=7.0,
        displacement_drift=0.05e-6,
        seed=seed,
        **options,
    )


def ploughing_recording(height, cycles, noise, seed=3):
    """Whole loops with a ploughing peak at each end of the slip (Figure 1b), sampled in time.

    The slip traction is eq. 9 plus a Gaussian bump of ``height`` [N] and width 0.1 δ*
    centred on the end of the slip, Δ = x + Q/S (eq. 10); the stick sides have slope S.
    The slip amplitude is set to 32 µm, so the amplitude follows.
    """
    point = EXAMPLE_2
    slip = 32e-6
    x = np.linspace(-slip, slip, 20001)
    kappa = 2.0 * point["aspect_ratio"]
    traction = LOAD * np.asarray(traction_ratio(x / AMPLITUDE, point["mu"], kappa))
    rising_force = traction + height * np.exp(-(((x - slip) / (0.1 * slip)) ** 2))
    rising_displacement = x + rising_force / point["stiffness"]
    amplitude, peak = rising_displacement[-1], rising_force[-1]
    branch_x = np.concatenate([[-amplitude], rising_displacement])
    branch_q = np.concatenate([[-peak], rising_force])
    assert np.all(np.diff(branch_x) > 0)  # the rising branch is a function of Δ
    phase = np.arange(cycles * SAMPLES + 1) / SAMPLES
    displacement = -amplitude * np.cos(2 * np.pi * phase)
    rising = phase % 1 < 0.5
    force = np.where(
        rising,
        np.interp(displacement, branch_x, branch_q),
        -np.interp(-displacement, branch_x, branch_q),  # the loop is symmetric about 0
    )
    if noise:
        rng = np.random.default_rng(seed)
        displacement = displacement + 0.005 * amplitude * rng.normal(size=phase.size) + 3e-6
        force = force + 0.01 * peak * rng.normal(size=phase.size) + 5.0
    return displacement, force


def mindlin_recording(force_ratio, mu=0.8, cycles=4, compliance=10e-6, stiffness=50e6):
    """Partial slip: the Cattaneo-Mindlin loop of a sphere (Masing rule) behind a rig spring.

    Contact displacement on the rising branch from (-δ*, -Q*):
    δ = -δ* + 2c[1 - (1 - (Q + Q*)/(2μP))^(2/3)], with c the displacement at full slip.
    """
    peak = force_ratio * mu * LOAD
    q = np.linspace(-peak, peak, 4001)
    slip = compliance * (1 - (1 - peak / (mu * LOAD)) ** (2 / 3))
    contact = -slip + 2 * compliance * (1 - (1 - (q + peak) / (2 * mu * LOAD)) ** (2 / 3))
    branch = contact + q / stiffness
    phase = np.arange(cycles * SAMPLES) / SAMPLES
    displacement = -branch[-1] * np.cos(2 * np.pi * phase)
    force = np.where(
        phase % 1 < 0.5,
        np.interp(displacement, branch, q),
        -np.interp(-displacement, branch, q),
    )
    return displacement, force


def load_steps(levels=(300.0, 450.0, 600.0), cycles=4):
    """Loops at each load of ``levels`` in turn (``cycles`` each), and the load channel."""
    point = dict(EXAMPLE_2, aspect_ratio=0.15)
    del point["load"]
    parts = [ecofmaps.synthetic_recording(load=level, cycles=cycles, **point) for level in levels]
    displacement = np.concatenate([d for d, _ in parts])
    force = np.concatenate([q for _, q in parts])
    load = np.concatenate(
        [np.full(d.size, level) for (d, _), level in zip(parts, levels, strict=True)]
    )
    return displacement, force, load


def write_csv(path, displacement, force, separator=",", header=("displacement", "force")):
    """A recording file: displacement in µm, force in N, with a comment line."""
    lines = [f"# a test recording written by {__name__}", separator.join(header)]
    lines += [f"{d * 1e6:.9f}{separator}{f:.9f}" for d, f in zip(displacement, force, strict=True)]
    path.write_text("\n".join(lines) + "\n")
    return path
