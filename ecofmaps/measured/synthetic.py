r"""Synthetic fretting recordings made with the model: :func:`synthetic_recording`, the examples
shipped in the package (:func:`example_path`, :func:`scar_example_path`), and a long test made
and written block by block (:func:`long_recording`, :func:`write_long_recording`)."""

from __future__ import annotations

import importlib.resources
from pathlib import Path

import numpy as np

from ecofmaps._inputs import si_units
from ecofmaps.io.files import write_text
from ecofmaps.io.writers import RecordingWriter
from ecofmaps.measured.cycles import MIN_SAMPLES
from ecofmaps.model.simulation import simulate

__all__ = [
    "EXAMPLE",
    "LONG_TEST",
    "SCAR_EXAMPLE",
    "example_path",
    "example_recording",
    "long_recording",
    "scar_example_path",
    "scar_example_trace",
    "synthetic_recording",
    "write_example",
    "write_long_recording",
    "write_scar_example",
]


@si_units
def synthetic_recording(
    amplitude,
    load,
    stiffness,
    mu,
    aspect_ratio,
    groove_half_width=None,
    *,
    cycles=None,
    samples_per_cycle=200,
    start_phase=0.0,
    displacement_noise=0.0,
    force_noise=0.0,
    displacement_offset=0.0,
    force_offset=0.0,
    displacement_drift=0.0,
    sampling_jitter=0.0,
    seed=0,
):
    r"""A recording of consecutive fretting cycles under the displacement
    :math:`\Delta(t) = -\Delta^*\cos 2\pi t`, the force :func:`ecofmaps.simulate`'s (eq. 9, 10),
    with noise, offsets and drift added to the recorded signals only, as a sensor would.

    Parameters
    ----------
    amplitude : float
        Displacement amplitude :math:`\Delta^*`. [m]
    load, stiffness, mu : float
        Normal load :math:`P` [N], rig stiffness :math:`S` [N/m], contact CoF [1].
    aspect_ratio : float or array_like
        Groove depth over half-width :math:`z_o/x_o`, one value or one per cycle. [1]
    groove_half_width : float, optional
        Groove half-width :math:`x_o`; defaults to ``amplitude`` (the paper's choice). [m]
    cycles : int, optional
        Number of cycles; by default one per value of ``aspect_ratio``. [1]
    samples_per_cycle : int
        Samples in each cycle (>= 8). [1]
    start_phase : float
        Phase of the first sample: 0 at the lowest displacement, 0.25 at zero on the rise. [1]
    displacement_noise, force_noise : float
        Standard deviations of the Gaussian noise on the displacement [m] and force [N].
    displacement_offset, force_offset : float
        Constant offsets of the displacement [m] and force [N].
    displacement_drift : float
        Drift of the displacement per cycle, linear in time. [m]
    sampling_jitter : float
        Each sampling instant moves at random by up to this share of the sampling interval
        either way (0 <= jitter < 0.5). [1]
    seed : int
        Seed of the random numbers (noise and jitter).

    Returns
    -------
    displacement, force : numpy.ndarray
        ``cycles * samples_per_cycle`` samples. [m], [N]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 10.
    """
    ratio = np.atleast_1d(np.asarray(aspect_ratio, dtype=np.float64))
    if ratio.ndim != 1:
        raise ValueError("aspect_ratio must be one value or one per cycle")
    cycles = ratio.size if cycles is None else int(cycles)
    if cycles < 1 or ratio.size not in (1, cycles):
        raise ValueError(
            f"cycles must be >= 1 and match the {ratio.size} aspect ratios; got {cycles!r}"
        )
    if int(samples_per_cycle) < MIN_SAMPLES:
        raise ValueError(f"samples_per_cycle must be >= {MIN_SAMPLES}; got {samples_per_cycle!r}")
    if not 0.0 <= sampling_jitter < 0.5:
        raise ValueError(f"sampling_jitter must satisfy 0 <= jitter < 0.5; got {sampling_jitter!r}")
    n = int(samples_per_cycle)
    rng = np.random.default_rng(seed)
    half_width = amplitude if groove_half_width is None else groove_half_width
    instants = np.arange(cycles * n) + rng.uniform(-sampling_jitter, sampling_jitter, cycles * n)
    phase = instants.reshape(cycles, n) / n + start_phase
    # Two passes over each cycle from rest; the second is the steady loop.
    imposed = -amplitude * np.cos(2.0 * np.pi * np.concatenate([phase, phase + 1.0], axis=1))
    force = np.asarray(
        simulate(imposed, load, stiffness, mu, np.broadcast_to(ratio, (cycles,)), half_width)
    )[:, n:].ravel()
    displacement = imposed[:, n:].ravel() + displacement_offset + displacement_drift * instants / n
    displacement = displacement + rng.normal(0.0, 1.0, displacement.size) * displacement_noise
    force = force + force_offset + rng.normal(0.0, 1.0, force.size) * force_noise
    return displacement, force


#: The shipped example's parameters (SI): the paper's Example 2 rig, a groove deepening from flat.
EXAMPLE = {
    "amplitude": 50e-6,
    "load": 450.0,
    "stiffness": 35e6,
    "mu": 0.8,
    "final_aspect_ratio": 0.2,
    "test_cycles": 300_000,
    "recorded_every": 2000,
    "samples_per_cycle": 160,
    "displacement_noise": 0.25e-6,
    "force_noise": 4.0,
    "displacement_offset": 3.0e-6,
    "force_offset": 6.0,
    "displacement_drift": 2.0e-6,
    "seed": 20160101,
}

_HEADER = """\
# SYNTHETIC DATA, not a measurement: made by ecofmaps.measured.synthetic.example_recording().
# The model's fretting loops (Jin, Sun & Shipway 2016) for the paper's Example 2 rig:
# P = 450 N, S = 35 MN/m, mu = 0.8, amplitude 50 um = groove half-width x_o, with a groove
# whose depth grows as z_o/x_o = 0.2 * sqrt(N / 300000) over a 300 000-cycle test.
# One loop of 160 samples is recorded every 2000 cycles (the cycle column), starting at
# zero displacement on the rise. Added: noise of 0.25 um and 4 N (0.5 % of the amplitude,
# about 1 % of Q*), offsets of 3 um and 6 N, and a displacement drift of 2 um over the test.
# ECoF rises with the groove while the GICoF stays at mu = 0.8.
# Columns: test cycle number, displacement [um], tangential force [N].
"""


def example_recording():
    """The shipped example: each sample's test cycle [1], displacement [m] and force [N]."""
    p = EXAMPLE
    recorded = np.arange(1, p["test_cycles"] // p["recorded_every"] + 1) * p["recorded_every"]
    ratio = p["final_aspect_ratio"] * np.sqrt(recorded / p["test_cycles"])
    drift = p["displacement_drift"] / recorded.size
    displacement, force = _on_rig(p, ratio, p["samples_per_cycle"], 0.0, drift, p["seed"])
    return np.repeat(recorded, p["samples_per_cycle"]), displacement, force


def _on_rig(p, ratio, samples_per_cycle, offset, drift, seed):
    """:func:`synthetic_recording` on the rig of ``p`` from zero on the rise, offset more."""
    return synthetic_recording(
        *(p[k] for k in ("amplitude", "load", "stiffness", "mu")),
        ratio,
        samples_per_cycle=samples_per_cycle,
        start_phase=0.25,
        displacement_offset=p["displacement_offset"] + offset,
        displacement_drift=drift,
        seed=seed,
        **{k: p[k] for k in ("displacement_noise", "force_noise", "force_offset")},
    )


def write_example(path):
    """Write :func:`example_recording` to ``path`` as the shipped CSV file; its Path."""
    cycle, x, q = example_recording()
    rows = "\n".join(f"{c:d},{d:.4f},{f:.3f}" for c, d, f in zip(cycle, x * 1e6, q, strict=True))
    return write_text(path, f"{_HEADER}cycle,displacement,force\n{rows}\n")


def example_path() -> Path:
    """Path of the shipped example recording (see :func:`example_recording`)."""
    return Path(str(importlib.resources.files("ecofmaps") / "data" / "synthetic_fretting_test.csv"))


#: Parameters of the shipped example scar profile (SI units).
SCAR_EXAMPLE = {
    "depth": 80e-6,  # of the flat bottom below the unworn surface [m]
    "half_width": 500e-6,  # [m]: D/W = 0.16, the paper's Example 2 (z_o = 8 um, x_o = 50 um)
    "flat_fraction": 0.4,  # flat bottom over the half-width; parabolic walls
    "hump_height": 5e-6,  # a less worn centre [m]
    "hump_width": 80e-6,  # its standard deviation [m]
    "ridge_height": 4e-6,  # ploughing ridges beside the edges [m]
    "ridge_width": 150e-6,  # [m]
    "roughness": 0.4e-6,  # amplitude of the worn surface's waviness [m]
    "roughness_wavelength": 45e-6,  # [m]
    "tilt": 0.004,  # the specimen's tilt in the profilometer [1]
    "offset": 12e-6,  # height of the unworn surface at x = 0 [m]
    "noise": 0.05e-6,  # profilometer noise, standard deviation [m]
    "spacing": 2e-6,  # sample spacing [m]
    "length": 2.7e-3,  # trace length [m]
    "centre": 1.34e-3,  # scar centre in the trace [m]
    "seed": 20161125,
}

_SCAR_HEADER = """\
# SYNTHETIC DATA, not a measurement: made by ecofmaps.measured.synthetic.scar_example_trace().
# A profilometer trace across a cylinder-on-flat fretting scar like the paper's Example 2
# (depth over half-width D/W = 0.16: 80 um deep, 500 um half-width): a flat bottom (40 % of
# the half-width) with parabolic walls, a 5 um hump at the less worn centre, 4 um ploughing
# ridges 150 um wide beside the edges, and a 0.4 um waviness of the worn surface. As
# recorded: tilted by 0.004 (0.23 degrees), offset by 12 um, with 0.05 um noise, sampled
# every 2 um over 2.7 mm. ecofmaps.read_scar_profile levels it on the unworn shoulders.
# Columns: position x [um], height z [um].
"""


def scar_example_trace():
    """The shipped example scar profile as recorded: positions and heights [m]."""
    p = SCAR_EXAMPLE
    rng = np.random.default_rng(p["seed"])
    x = np.arange(round(p["length"] / p["spacing"]) + 1) * p["spacing"]
    u = x - p["centre"]
    width, flat = p["half_width"], p["flat_fraction"] * p["half_width"]
    s = np.clip((np.abs(u) - flat) / (width - flat), 0.0, 1.0)
    inside = np.abs(u) < width
    z = np.where(inside, -p["depth"] * (1.0 - s * s), 0.0)
    z += np.where(inside, p["hump_height"] * np.exp(-0.5 * (u / p["hump_width"]) ** 2), 0.0)
    v = (np.abs(u) - width) / p["ridge_width"]
    z += np.where((v > 0.0) & (v < 1.0), p["ridge_height"] * np.sin(np.pi * v) ** 2, 0.0)
    phase = rng.uniform(0.0, 2.0 * np.pi, 3)
    waves = sum(
        np.sin(2.0 * np.pi * u / (p["roughness_wavelength"] * k) + f)
        for k, f in zip((1.0, 1.7, 2.9), phase, strict=True)
    )
    z += np.where(inside, p["roughness"] / 3.0 * waves * (1.0 - s * s), 0.0)
    z += p["offset"] + p["tilt"] * x + p["noise"] * rng.normal(size=x.size)
    return x, z


def write_scar_example(path):
    """Write :func:`scar_example_trace` to ``path`` as the shipped CSV file (µm); its Path."""
    x, z = scar_example_trace()
    rows = "\n".join(f"{a:.1f},{b:.4f}" for a, b in zip(x * 1e6, z * 1e6, strict=True))
    return write_text(path, f"{_SCAR_HEADER}x,z\n{rows}\n")


def scar_example_path() -> Path:
    """Path of the shipped example scar profile (see :func:`scar_example_trace`)."""
    return Path(str(importlib.resources.files("ecofmaps") / "data" / "synthetic_scar_profile.csv"))


_EXAMPLE_ONLY = ("test_cycles", "recorded_every", "samples_per_cycle", "seed")
#: The default parameters of :func:`long_recording`: :data:`EXAMPLE`'s rig, sensors, groove, drift.
LONG_TEST = {k: v for k, v in EXAMPLE.items() if k not in _EXAMPLE_ONLY}


def long_recording(cycles, samples_per_cycle=200, *, block_cycles=4096, seed=0, **parameters):
    r"""A long fretting test made block by block in bounded memory: :func:`synthetic_recording`,
    cycle :math:`N` in the groove :math:`z_o/x_o = r_f \sqrt{N/N_{total}}`, :math:`x_o = \Delta^*`.

    Parameters
    ----------
    cycles : int
        Number of cycles of the test (every one recorded). [1]
    samples_per_cycle : int
        Samples per cycle (>= 8). [1]
    block_cycles : int
        Cycles simulated at a time (the memory: a few arrays of that many cycles). [1]
    seed : int
        Seed of the noise: block ``k`` uses a stream derived from ``(seed, k)``.
    **parameters
        Any of :data:`LONG_TEST` (SI, as for :func:`synthetic_recording`): ``final_aspect_ratio``
        is :math:`r_f` [1], ``displacement_drift`` the drift over the whole test [m].

    Yields
    ------
    cycle : numpy.ndarray of int64
        The 1-based test cycle of each sample of the block. [1]
    displacement, force : numpy.ndarray
        The recorded signals of the block. [m], [N]

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 10.
    """
    if unknown := set(parameters) - set(LONG_TEST):
        raise TypeError(f"unknown parameters: {', '.join(sorted(unknown))}")
    p = {**LONG_TEST, **parameters}
    for name, value in (("cycles", cycles), ("block_cycles", block_cycles)):
        if isinstance(value, bool) or not int(value) == value >= 1:
            raise ValueError(f"{name} must be an integer >= 1; got {value!r}")
    cycles, block_cycles, n = int(cycles), int(block_cycles), int(samples_per_cycle)
    drift = p["displacement_drift"] / cycles  # per cycle
    for index, first in enumerate(range(0, cycles, block_cycles)):
        count = min(block_cycles, cycles - first)
        # Every block is simulated at the full size (one compilation), then cut.
        number = np.arange(first + 1, first + block_cycles + 1)
        ratio = p["final_aspect_ratio"] * np.sqrt(np.minimum(number, cycles) / cycles)
        block_seed = int(np.random.SeedSequence([seed, index]).generate_state(1)[0])
        displacement, force = _on_rig(p, ratio, n, drift * first, drift, block_seed)
        yield np.repeat(number[:count], n), displacement[: count * n], force[: count * n]


def write_long_recording(
    path,
    cycles,
    samples_per_cycle=200,
    *,
    format=None,
    cycle_numbers=False,
    chunk_samples=1 << 20,
    overwrite=False,
    block_cycles=4096,
    seed=0,
    **parameters,
):
    """Write :func:`long_recording` to a file or store, block by block.

    Parameters
    ----------
    path : str or os.PathLike
        ``.tdms``, ``.h5``/``.nc``, ``.zarr`` or ``.csv``.
    cycles, samples_per_cycle, block_cycles, seed, **parameters
        As for :func:`long_recording`.
    format : str, optional
        The format, if not the suffix's (:class:`ecofmaps.io.writers.RecordingWriter`).
    cycle_numbers : bool
        Also write the cycle number of each sample (a ``cycle`` column).
    chunk_samples : int
        Samples per chunk (zarr, HDF5) or per TDMS segment.
    overwrite : bool
        Replace an existing file (only once the new one is complete).

    Returns
    -------
    path : pathlib.Path
        The file, written atomically: displacement [m] and force [N] (SI, float64, with
        their units), in the TDMS group ``recording`` or at the store's root.

    Examples
    --------
    >>> import tempfile, pathlib, ecofmaps
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "test.zarr"
    >>> _ = write_long_recording(path, cycles=20, samples_per_cycle=50)
    >>> ecofmaps.read_recording(path).size
    1000
    """
    blocks = long_recording(
        cycles, samples_per_cycle, block_cycles=block_cycles, seed=seed, **parameters
    )
    attrs = {
        "title": "SYNTHETIC DATA, not a measurement: ecofmaps.measured.synthetic.long_recording",
        "cycles": int(cycles),
        "samples_per_cycle": int(samples_per_cycle),
        "block_cycles": int(block_cycles),
        "seed": int(seed),
        **{name: float(value) for name, value in {**LONG_TEST, **parameters}.items()},
    }
    options = dict(format=format, chunk_samples=chunk_samples, overwrite=overwrite, attrs=attrs)
    with RecordingWriter(path, cycle=cycle_numbers, **options) as writer:
        for cycle, displacement, force in blocks:
            writer.write(displacement, force, cycle if cycle_numbers else None)
    return Path(path)
