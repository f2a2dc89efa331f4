"""Ugly recordings for the tests: the model's loops with what real rigs add (noise, drift,
periodic and random chatter, backlash, sweeps, digitising, microslip, ploughing), with the truth."""

import difflib
from typing import NamedTuple

import numpy as np

#: The kinds of :func:`ugly_recording`: name -> what is wrong with it.
UGLY_KINDS = {
    "clean": "the model's loops with white noise of 0.05 um and 0.5 N",
    "noise": "white noise of 0.5 um and 8 N (1 % of the amplitude, 2 % of Q*)",
    "offsets": "offsets of 5 um and 20 N, a drift of 1 um per cycle, and white noise",
    "chatter": "friction that chatters +-30 % at 7.37 periods per cycle (not the drive's)",
    "random-chatter": "friction that jumps at random along the stroke (+-15 %, a few samples long)",
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
    "random-chatter": {"random_chatter": 0.15, "displacement_noise": 0.05e-6, "force_noise": 0.5},
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

#: Correlation length of the random chatter, in samples.
_RANDOM_CHATTER_SAMPLES = 4.0


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
        Seed of the random numbers (noise, the chatter's phase and its random jumps).

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
    * ``'chatter'`` and ``'random-chatter'``: the contact's friction varies in time,
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
    >>> from tests.measured.ugly import ugly_recording
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
    if "random_chatter" in flaw:
        kernel = np.exp(-0.5 * (np.arange(-12, 13) / _RANDOM_CHATTER_SAMPLES) ** 2)
        smooth = np.convolve(rng.normal(size=t.size), kernel / np.sqrt(np.sum(kernel**2)), "same")
        friction *= 1.0 + flaw["random_chatter"] * np.clip(smooth, -2.5, 2.5)
    contact = _play(imposed, flaw["backlash"]) if "backlash" in flaw else imposed
    if "microslip" in flaw:
        force = _microslip_force(contact, rig["load"], rig["mu"], flaw["microslip"])[0]
        nowhere = np.full(t.size, np.nan)
        return imposed[0] + force / rig["stiffness"], force, np.ones(t.size), nowhere
    k = 2.0 * rig["aspect_ratio"] / rig["groove_half_width"]
    x = _slide(contact, friction[None, :], rig["load"], rig["stiffness"], k, flaw.get("ploughing"))
    force = rig["stiffness"] * (contact[0] - x[0])
    return imposed[0], force, np.abs(np.diff(x[0], prepend=0.0)), friction
