r"""Synthetic fretting recordings made with the model, and the example shipped in the package.

:func:`synthetic_recording` imposes a sinusoidal displacement on the model
(:func:`ecofmaps.simulate`), one cycle per row so that the groove may change from cycle to
cycle, and adds what a rig's sensors add: offsets, a slow drift, Gaussian noise and, if
asked, an irregular sampling clock. Each cycle is simulated twice over from rest and the
second pass kept, so every recorded loop is the steady loop of its own groove.

:func:`example_recording` is the deterministic generator of the recording shipped as
``ecofmaps/data/synthetic_fretting_test.csv`` (see :func:`example_path`), which
``ecofmaps loops --example`` analyses. :func:`scar_example_trace` generates the synthetic
profilometer trace across a wear scar shipped as
``ecofmaps/data/synthetic_scar_profile.csv`` (see :func:`scar_example_path`).

A long test of 10⁸ samples and more is made by :mod:`ecofmaps.measured.long_test`.
"""

from __future__ import annotations

import difflib
import importlib.resources
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ecofmaps._inputs import si_units
from ecofmaps.io.files import write_text
from ecofmaps.measured.cycles import MIN_SAMPLES
from ecofmaps.model.simulation import simulate

__all__ = [
    "EXAMPLE",
    "EXAMPLE_FILE",
    "SCAR_EXAMPLE",
    "SCAR_EXAMPLE_FILE",
    "UGLY_KINDS",
    "UGLY_RIG",
    "UglyRecording",
    "example_path",
    "example_recording",
    "scar_example_path",
    "scar_example_trace",
    "synthetic_recording",
    "ugly_recording",
    "write_example",
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
    r"""A recording of consecutive fretting cycles under a sinusoidal displacement.

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
        Samples in each cycle (at least :data:`~ecofmaps.measured.cycles.MIN_SAMPLES`). [1]
    start_phase : float
        Phase of the first sample, in cycles: 0 starts at the lowest displacement,
        0.25 at zero displacement on the rise. [1]
    displacement_noise, force_noise : float
        Standard deviations of the Gaussian noise added to the recorded displacement [m]
        and force [N].
    displacement_offset, force_offset : float
        Constant offsets added to the recorded displacement [m] and force [N].
    displacement_drift : float
        Drift of the recorded displacement per cycle, growing linearly in time. [m]
    sampling_jitter : float
        Each sampling instant moves at random by up to this share of the sampling
        interval either way (0 <= jitter < 0.5), for a non-uniform clock. [1]
    seed : int
        Seed of the random numbers (noise and jitter).

    Returns
    -------
    displacement, force : numpy.ndarray
        The recorded signals, ``cycles * samples_per_cycle`` samples. [m], [N]

    Notes
    -----
    The actuator imposes :math:`\Delta(t) = -\Delta^*\cos 2\pi t`; the force is
    :func:`ecofmaps.simulate`'s stick/slip history for it (eq. 9, 10), which does not
    depend on the sampling. The noise, offsets and drift are added to the recorded
    signals only, as a sensor would.

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
    displacement = imposed[:, n:].ravel()
    displacement = (
        displacement
        + displacement_offset
        + displacement_drift * instants / n
        + rng.normal(0.0, 1.0, displacement.size) * displacement_noise
    )
    force = force + force_offset + rng.normal(0.0, 1.0, force.size) * force_noise
    return displacement, force


#: The parameters of the shipped example: the paper's Example 2 rig (Section 3) with a
#: groove that deepens from flat to z_o/x_o = 0.2 over a 300 000-cycle test, one loop
#: recorded every 2000 cycles.
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

#: File name of the shipped example in ``ecofmaps/data``.
EXAMPLE_FILE = "synthetic_fretting_test.csv"

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
    """The shipped example: the cycle number, displacement and force of every sample.

    Returns
    -------
    cycle : numpy.ndarray of int64
        The test cycle at which each recorded loop was taken. [1]
    displacement, force : numpy.ndarray
        [m], [N]

    Notes
    -----
    Deterministic: a fixed seed, see :data:`EXAMPLE` for the parameters.
    """
    p = EXAMPLE
    recorded = np.arange(1, p["test_cycles"] // p["recorded_every"] + 1) * p["recorded_every"]
    ratio = p["final_aspect_ratio"] * np.sqrt(recorded / p["test_cycles"])
    displacement, force = synthetic_recording(
        p["amplitude"],
        p["load"],
        p["stiffness"],
        p["mu"],
        ratio,
        samples_per_cycle=p["samples_per_cycle"],
        start_phase=0.25,
        displacement_noise=p["displacement_noise"],
        force_noise=p["force_noise"],
        displacement_offset=p["displacement_offset"],
        force_offset=p["force_offset"],
        displacement_drift=p["displacement_drift"] / recorded.size,
        seed=p["seed"],
    )
    cycle = np.repeat(recorded, p["samples_per_cycle"])
    return cycle, displacement, force


def write_example(path):
    """Write :func:`example_recording` as the shipped CSV file (atomically).

    Parameters
    ----------
    path : str or os.PathLike
        Destination file.

    Returns
    -------
    path : pathlib.Path
    """
    cycle, displacement, force = example_recording()
    rows = "\n".join(
        f"{c:d},{d:.4f},{f:.3f}" for c, d, f in zip(cycle, displacement * 1e6, force, strict=True)
    )
    return write_text(path, f"{_HEADER}cycle,displacement,force\n{rows}\n")


def example_path() -> Path:
    """Path of the shipped example recording (see :func:`example_recording`)."""
    return Path(str(importlib.resources.files("ecofmaps") / "data" / EXAMPLE_FILE))


# ---------------------------------------------------------------------------------------
# The shipped example scar profile
# ---------------------------------------------------------------------------------------

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

#: File name of the shipped example scar profile in ``ecofmaps/data``.
SCAR_EXAMPLE_FILE = "synthetic_scar_profile.csv"

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
    """The shipped example scar profile as a profilometer records it.

    Returns
    -------
    x, z : numpy.ndarray
        Positions from the start of the trace and heights. [m]

    Notes
    -----
    Deterministic: a fixed seed, see :data:`SCAR_EXAMPLE` for the parameters. The scar is
    the U shape of :func:`ecofmaps.flat_bottomed_profile` with a Gaussian hump at the
    centre, :math:`H\\sin^2(\\pi v)` ridges beside the edges (as
    :func:`ecofmaps.ridged_profile`) and a waviness of random phase in the scar; then the
    tilt, offset and noise of the recording.
    """
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
    """Write :func:`scar_example_trace` as the shipped CSV file (atomically), in µm.

    Parameters
    ----------
    path : str or os.PathLike
        Destination file.

    Returns
    -------
    path : pathlib.Path
    """
    x, z = scar_example_trace()
    rows = "\n".join(f"{a:.1f},{b:.4f}" for a, b in zip(x * 1e6, z * 1e6, strict=True))
    return write_text(path, f"{_SCAR_HEADER}x,z\n{rows}\n")


def scar_example_path() -> Path:
    """Path of the shipped example scar profile (see :func:`scar_example_trace`)."""
    return Path(str(importlib.resources.files("ecofmaps") / "data" / SCAR_EXAMPLE_FILE))


# ---------------------------------------------------------------------------------------
# Ugly recordings with a known truth, for calibrating the analysis
# ---------------------------------------------------------------------------------------

#: The kinds of :func:`ugly_recording`: name -> what is wrong with it.
UGLY_KINDS = {
    "clean": "the model's loops with white noise of 0.05 um and 0.5 N",
    "noise": "white noise of 0.5 um and 8 N (1 % of the amplitude, 2 % of Q*)",
    "offsets": "offsets of 5 um and 20 N, a drift of 1 um per cycle, and white noise",
    "chatter": "friction that chatters +-30 % at 7.37 periods per cycle (not the drive's)",
    "stick-slip": "friction that jumps at random along the stroke (+-15 %, a few samples long)",
    "backlash": "a dead band of +-1.5 um between the actuator and the pad at the reversals",
    "sweep": "the amplitude swept from 30 to 70 um over the recording",
    "sparse": "a digitised loop: 32 points per cycle, 0.5 um and 2 N steps",
    "microslip": "partial slip (Mindlin-Masing) that never reaches gross slip: no mu",
    "ploughing": "friction rising towards the ends of the stroke, beyond 20 um from the centre",
    "combined": "chatter, backlash, offsets, drift and noise together",
}

#: The rig and contact of every kind: the paper's Example 2 (Section 3) on a groove of
#: z_o/x_o = 0.1 with x_o = 50 um.
UGLY_RIG = {
    "amplitude": 50e-6,
    "load": 450.0,
    "stiffness": 35e6,
    "mu": 0.8,
    "aspect_ratio": 0.1,
    "groove_half_width": 50e-6,
}

#: What each kind adds to the model's loop (missing entries are zero or off).
_UGLY = {
    "clean": {"displacement_noise": 0.05e-6, "force_noise": 0.5},
    "noise": {"displacement_noise": 0.5e-6, "force_noise": 8.0},
    "offsets": {
        "displacement_noise": 0.1e-6,
        "force_noise": 1.0,
        "displacement_offset": 5e-6,
        "force_offset": 20.0,
        "displacement_drift": 1e-6,
    },
    "chatter": {"chatter": 0.3, "displacement_noise": 0.05e-6, "force_noise": 0.5},
    "stick-slip": {"stick_slip": 0.15, "displacement_noise": 0.05e-6, "force_noise": 0.5},
    "backlash": {"backlash": 1.5e-6, "displacement_noise": 0.05e-6, "force_noise": 0.5},
    "sweep": {"sweep": (30e-6, 70e-6), "displacement_noise": 0.05e-6, "force_noise": 0.5},
    "sparse": {"samples_per_cycle": 32, "displacement_step": 0.5e-6, "force_step": 2.0},
    "microslip": {"microslip": 0.6, "displacement_noise": 0.05e-6, "force_noise": 0.5},
    "ploughing": {"ploughing": (20e-6, 0.25), "displacement_noise": 0.05e-6, "force_noise": 0.5},
    "combined": {
        "chatter": 0.2,
        "backlash": 1.0e-6,
        "displacement_noise": 0.2e-6,
        "force_noise": 3.0,
        "displacement_offset": 3e-6,
        "force_offset": 10.0,
        "displacement_drift": 0.5e-6,
    },
}

#: Periods of the chatter per drive cycle: not a ratio of small integers.
_CHATTER_FREQUENCY = 7.37

#: Correlation length of the random stick-slip, in samples.
_STICK_SLIP_SAMPLES = 4.0


class UglyRecording(NamedTuple):
    """A recording made by :func:`ugly_recording`, with the truth it was made from."""

    #: The recorded displacement [m] and force [N], one value per sample.
    displacement: np.ndarray
    force: np.ndarray
    #: Cycle number of each sample (each cycle starts at its lowest displacement). [1]
    cycle: np.ndarray
    #: Normal load. [N]
    load: float
    #: Per cycle: the true contact CoF (NaN where none can be read), and the true GICoF. [1]
    mu: np.ndarray
    gicof: np.ndarray


def _play(imposed, band):
    """The pad's side of a dead band of half-width ``band`` (a play operator, along axis 1)."""
    out = np.empty_like(imposed)
    state = imposed[:, 0]
    for j in range(imposed.shape[1]):
        state = np.clip(state, imposed[:, j] - band, imposed[:, j] + band)
        out[:, j] = state
    return out


def _slide(imposed, friction, load, stiffness, k, ploughing=None):
    """Pad position under ``imposed`` (rows of recordings, time along axis 1), eq. 9, 10, 16.

    ``friction`` is μ at each instant; ``ploughing`` = (x_p, p) adds
    :math:`p\\mu((|x| - x_p)/x_p)^2` beyond :math:`|x| > x_p`. The pad sticks while
    :math:`Q_-(x) \\le S(\\Delta - x) \\le Q_+(x)`, else slips to the root of
    :math:`x + Q_\\pm(x)/S = \\Delta` (the cancellation-free root of the quadratic; with
    ploughing, three fixed-point passes of μ at the new position).
    """
    lam = load / stiffness
    x = np.zeros(imposed.shape[0])
    positions = np.empty_like(imposed)

    def local(mu, at):
        if ploughing is None:
            return mu
        start, share = ploughing
        return mu * (1.0 + share * (np.maximum(np.abs(at) - start, 0.0) / start) ** 2)

    def traction(mu, at, s):
        return (s * mu + k * at) / (1.0 - s * mu * k * at)

    for j in range(imposed.shape[1]):
        delta, mu = imposed[:, j], friction[:, j]
        spring = (delta - x) / lam
        s = np.where(spring > traction(local(mu, x), x, 1.0), 1.0, 0.0)
        s = np.where(spring < traction(local(mu, x), x, -1.0), -1.0, s)
        moved = x
        for _ in range(1 if ploughing is None else 4):
            m = local(mu, moved) * s
            b = 1.0 + m * k * delta + lam * k
            c = delta - lam * m
            moved = 2.0 * c / (b + np.sqrt(b * b - 4.0 * m * k * c))
        x = np.where(s != 0.0, moved, x)
        positions[:, j] = x
    return positions


def _microslip_force(imposed_contact, load, mu, reach):
    """Tangential force of a Mindlin contact under Masing's rule, never in gross slip.

    The virgin curve :math:`Q = \\mu P (1 - (1 - u/u_s)^{3/2})` (:math:`u_s` the slip
    displacement, ``reach`` times larger than the amplitude of ``imposed_contact``), each
    branch the curve doubled in both axes from its reversal.
    """
    amplitude = np.max(np.abs(imposed_contact), axis=1, keepdims=True)
    slip = amplitude / reach

    def virgin(u):
        return mu * load * np.sign(u) * (1.0 - (1.0 - np.minimum(np.abs(u) / slip, 1.0)) ** 1.5)

    rising = np.gradient(imposed_contact, axis=1) > 0.0
    top = -amplitude  # branch reversal points: a loop between -amplitude and +amplitude
    from_low = -virgin(amplitude) + 2.0 * virgin((imposed_contact - top) / 2.0)
    from_high = virgin(amplitude) - 2.0 * virgin((amplitude - imposed_contact) / 2.0)
    return np.where(rising, from_low, from_high)


def ugly_recording(kind, *, cycles=30, seed=0):
    r"""A recording whose flaws are known, with the friction it was made from.

    The paper's Example 2 rig (:data:`UGLY_RIG`: :math:`P` = 450 N, :math:`S` = 35 MN/m,
    :math:`\mu` = 0.8, :math:`\Delta^*` = 50 µm) on a parabolic groove of
    :math:`z_o/x_o` = 0.1, simulated sample by sample (eq. 9, 10, 16) under
    :math:`\Delta(t) = -\Delta^*\cos 2\pi t`, 200 samples per cycle, with the flaw of
    ``kind`` (:data:`UGLY_KINDS`). One cycle before the first is simulated and dropped, so
    the recording starts on the steady loop.

    Parameters
    ----------
    kind : str
        One of :data:`UGLY_KINDS`.
    cycles : int
        Number of cycles recorded (>= 1). [1]
    seed : int
        Seed of the random numbers (noise, the chatter's phase, the stick-slip).

    Returns
    -------
    UglyRecording
        ``displacement`` [m], ``force`` [N], ``cycle`` [1], ``load`` [N], and per cycle the
        true ``mu`` and ``gicof`` [1].

    Notes
    -----
    The truth comes from the generator's parameters only:

    * A constant friction :math:`\mu` (every kind but those below): ``mu`` and ``gicof``
      are :math:`\mu`; for the model's loop on any groove the GICoF is :math:`\mu` (eq. 18).
    * ``'chatter'`` and ``'stick-slip'``: the contact's friction varies in time,
      :math:`\mu(t) = \mu(1 + a\sin(2\pi f t + \phi))` with :math:`f` = 7.37 periods per
      cycle and a random phase, or :math:`\mu(1 + a\,n(t))` with :math:`n` Gaussian noise
      smoothed over about four samples. The truth of a cycle is the mean of the friction
      over its sliding phase, weighted by the distance slid:
      :math:`\sum_i \mu(t_i)|x_i - x_{i-1}| / \sum_i |x_i - x_{i-1}|` over the cycle's
      samples, :math:`x` the pad's position: the constant friction that would dissipate
      the same energy on a flat groove. The GICoF's truth is the same number.
    * ``'ploughing'``: the friction rises as
      :math:`\mu(1 + 0.25((|x| - x_p)/x_p)^2)` beyond :math:`|x| > x_p` = 20 µm; the
      truth is :math:`\mu` of the central part, :math:`|x| \le x_p`.
    * ``'backlash'``: the pad's side follows the actuator through a dead band (a play
      operator) and the actuator's displacement is recorded; the truth is :math:`\mu`.
    * ``'sweep'``: the amplitude changes linearly in time from 30 to 70 µm over the
      recording, the groove stays; the truth is :math:`\mu`.
    * ``'sparse'``: 32 samples per cycle, the displacement rounded to 0.5 µm and the
      force to 2 N; the truth is :math:`\mu`.
    * ``'microslip'``: a Mindlin contact under Masing's rule (the pad's displacement
      60 % of the one at which gross slip would start), in series with the rig's spring;
      it never slides, so no friction coefficient can be read: ``mu`` and ``gicof`` are
      NaN.

    Examples
    --------
    >>> from ecofmaps.measured.synthetic import ugly_recording
    >>> recording = ugly_recording("chatter", cycles=3, seed=1)
    >>> recording.displacement.shape, recording.mu.shape
    ((600,), (3,))
    """
    if kind not in UGLY_KINDS:
        close = difflib.get_close_matches(str(kind), UGLY_KINDS, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ValueError(f"kind must be one of {', '.join(UGLY_KINDS)}; got {kind!r}{hint}")
    if int(cycles) < 1:
        raise ValueError(f"cycles must be >= 1; got {cycles!r}")
    flaw = _UGLY[kind]
    cycles = int(cycles)
    rng = np.random.default_rng(seed)
    n = int(flaw.get("samples_per_cycle", 200))
    t = np.arange((cycles + 1) * n) / n  # one cycle to reach the steady loop, dropped
    displacement, force, slid, friction = _ugly_loops(flaw, t, rng)
    # The truth: the friction over each recorded cycle, weighted by the distance slid.
    slid, friction = (values[n:].reshape(cycles, n) for values in (slid, friction))
    mu = np.sum(friction * slid, axis=1) / np.sum(slid, axis=1)
    displacement = (
        displacement[n:]
        + flaw.get("displacement_offset", 0.0)
        + flaw.get("displacement_drift", 0.0) * (t[n:] - 1.0)
        + rng.normal(size=cycles * n) * flaw.get("displacement_noise", 0.0)
    )
    force = (
        force[n:]
        + flaw.get("force_offset", 0.0)
        + rng.normal(size=cycles * n) * flaw.get("force_noise", 0.0)
    )
    if "displacement_step" in flaw:  # digitised
        step = flaw["displacement_step"]
        displacement = np.round(displacement / step) * step
        force = np.round(force / flaw["force_step"]) * flaw["force_step"]
    cycle = np.repeat(np.arange(1, cycles + 1), n)
    return UglyRecording(displacement, force, cycle, UGLY_RIG["load"], mu, mu.copy())


def _ugly_loops(flaw, t, rng):
    """Displacement, force, distance slid and friction at the instants ``t`` [cycles].

    The friction is NaN where the pad never slides (microslip).
    """
    rig = UGLY_RIG
    low, high = flaw.get("sweep", (rig["amplitude"], rig["amplitude"]))
    amplitude = low + (high - low) * np.clip((t - 1.0) / (t[-1] + t[1] - 1.0), 0.0, 1.0)
    imposed = (-amplitude * np.cos(2.0 * np.pi * t))[None, :]
    friction = np.full(t.size, rig["mu"])
    if "chatter" in flaw:
        phase = rng.uniform(0.0, 2.0 * np.pi)
        friction *= 1.0 + flaw["chatter"] * np.sin(2.0 * np.pi * _CHATTER_FREQUENCY * t + phase)
    if "stick_slip" in flaw:
        kernel = np.exp(-0.5 * (np.arange(-12, 13) / _STICK_SLIP_SAMPLES) ** 2)
        smooth = np.convolve(rng.normal(size=t.size), kernel / np.sqrt(np.sum(kernel**2)), "same")
        friction *= 1.0 + flaw["stick_slip"] * np.clip(smooth, -2.5, 2.5)
    contact = _play(imposed, flaw["backlash"]) if "backlash" in flaw else imposed
    if "microslip" in flaw:
        force = _microslip_force(contact, rig["load"], rig["mu"], flaw["microslip"])[0]
        nowhere = np.full(t.size, np.nan)
        return imposed[0] + force / rig["stiffness"], force, np.ones(t.size), nowhere
    k = 2.0 * rig["aspect_ratio"] / rig["groove_half_width"]
    x = _slide(contact, friction[None, :], rig["load"], rig["stiffness"], k, flaw.get("ploughing"))
    force = rig["stiffness"] * (contact[0] - x[0])
    return imposed[0], force, np.abs(np.diff(x[0], prepend=0.0)), friction
