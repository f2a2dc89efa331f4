"""An independent oracle: a sphere-on-flat contact obeying Mindlin's law behind a rig spring.

The contact is an Iwan model: ``ELEMENTS`` Jenkins elements (a spring in series with a
Coulomb slider) in parallel, whose slip displacements are spread so that the first loading
interpolates Mindlin's δ(Q) = δ_t[1 − (1 − Q/μP)^(2/3)] at every element's slip; unloading
and reloading then follow Masing's rule for any drive history. The rig's spring S is in
series: the applied displacement is Δ = δ + Q/S. Each step of the drive is solved exactly
(the force is piecewise linear in δ). Also the closed forms of the steady loops, and a
groove grown by an energy law for the wear tests. Nothing here imports ecofmaps.
"""

from __future__ import annotations

import numpy as np

ELEMENTS = 400
A_T = 0.2  # Mindlin's energy ratio at the transition, on the contact's displacement
B_T = 2 ** (1 / 3) - 1  # and its opening ratio


class Contact:
    """A Mindlin sphere-on-flat contact (friction ``mu``, load ``load`` [N], slip onset
    displacement ``delta_t`` [m]) as an Iwan model, at rest and unloaded."""

    def __init__(self, mu, load, delta_t, elements=ELEMENTS):
        self.mu, self.load, self.delta_t = mu, load, delta_t
        # nodes dense at both ends: small loops, and full slip where the curve bends hardest
        s = 0.5 - 0.5 * np.cos(np.pi * np.arange(elements + 1) / elements)
        u = 1.0 - (1.0 - s) ** 2
        q = mu * load * (1.0 - (1.0 - u) ** 1.5)
        chords = np.diff(q) / np.diff(u * delta_t)
        self.k = chords - np.append(chords[1:], 0.0)  # each element's stiffness [N/m]
        self.phi = u[1:] * delta_t  # its slip displacement [m]
        self.extension = np.zeros(elements)  # each spring's stretch [m]
        self.delta = 0.0

    @property
    def force(self):
        return float(self.k @ self.extension)

    def first_loading(self, delta):
        """Force of the first loading at contact displacements ``delta`` (0 ≤ δ). [N]"""
        d = np.asarray(delta, dtype=float)[..., None]
        return (self.k * np.minimum(d, self.phi)).sum(-1)

    def step(self, applied, stiffness):
        """Move to the applied displacement ``applied`` behind a rig of ``stiffness``: the
        contact displacement δ with δ + Q(δ)/S = Δ, solved exactly; returns (δ, Q)."""
        target = applied - self.delta - self.force / stiffness
        sign = 1.0 if target >= 0.0 else -1.0
        e, k, phi = sign * self.extension, self.k, self.phi
        breaks = phi - e  # each element slips once δ moved this far (>= 0)
        order = np.argsort(breaks)
        b, k, e, phi = breaks[order], k[order], e[order], phi[order]
        sticking = k.sum() - np.concatenate([[0.0], np.cumsum(k)])[:-1]
        # h(d) = d + ΔQ(d)/S at each break, ΔQ the rise of the force from its value now
        rise = np.cumsum(np.diff(np.concatenate([[0.0], b])) * sticking)
        h = b + rise / stiffness
        goal = abs(target)
        if goal >= h[-1]:
            d = b[-1] + (goal - h[-1])
        else:
            d = float(np.interp(goal, np.concatenate([[0.0], h]), np.concatenate([[0.0], b])))
        self.extension = sign * np.minimum(self.extension * sign + d, self.phi)
        self.delta += sign * d
        return self.delta, self.force


def drive(contact, applied, stiffness):
    """Contact displacement and force at each applied displacement of ``applied`` [m]."""
    out = np.array([contact.step(a, stiffness) for a in applied])
    return out[:, 0], out[:, 1]


def sweep(amplitudes, samples=200):
    """An applied displacement of one sine cycle at each amplitude in turn, with a cycle at
    the first amplitude before and at the last after (the ones a recording cuts off),
    ``samples`` per cycle. [m]"""
    amplitudes = np.asarray(amplitudes, dtype=float)
    amplitudes = np.concatenate([amplitudes[:1], amplitudes, amplitudes[-1:]])
    wave = np.sin(2 * np.pi * np.arange(samples) / samples)
    return np.concatenate([(a * wave) for a in amplitudes] + [[0.0]])


# --- closed forms (Mindlin 1953, Masing) -------------------------------------------------


def slip_amplitude_closed(psi, delta_t):
    """The contact's displacement amplitude of a steady partial-slip loop, ψ = Q*/μP. [m]"""
    return delta_t * (1.0 - (1.0 - psi) ** (2 / 3))


def energy_closed(psi, mu, load, delta_t):
    """Energy dissipated by a steady partial-slip loop of the contact. [J]"""
    return (
        (24 / 5)
        * mu
        * load
        * delta_t
        * (1.0 - (1.0 - psi) ** (5 / 3) - (5 * psi / 6) * (1.0 + (1.0 - psi) ** (2 / 3)))
    )


def gross_slip_loop(amplitude, mu, load, delta_t, stiffness):
    """Closed forms of a steady gross-slip loop at the applied ``amplitude``: its energy
    E_d [J], half opening at Q = 0 (the slip δ*) [m]; Δ* ≥ δ_t + μP/S."""
    contact = amplitude - mu * load / stiffness
    energy = 0.8 * mu * load * delta_t + 4 * mu * load * (contact - delta_t)
    slip = contact - 2 * delta_t * (1 - 2 ** (-2 / 3))
    return energy, slip


def transition_amplitude(mu, load, delta_t, stiffness):
    """Δ_t = δ_t + μP/S. [m]"""
    return delta_t + mu * load / stiffness


# --- a groove grown by an energy law -------------------------------------------------------


def grown_groove(energy, alpha, length, half_width, threshold=0.0, noise=0.0, seed=0):
    """A profilometer trace (x, z) [m] across a parabolic groove whose worn area is
    α(ΣE_d − E_th)/L, with pile-up ridges beside it (not worn) and white noise."""
    area = alpha * max(energy - threshold, 0.0) / length
    depth = 3 * area / (4 * half_width)
    x = np.linspace(-4 * half_width, 4 * half_width, 1601)
    z = np.where(np.abs(x) < half_width, depth * ((x / half_width) ** 2 - 1.0), 0.0)
    ridge = 0.3 * depth * np.exp(-0.5 * ((np.abs(x) - 1.3 * half_width) / (0.1 * half_width)) ** 2)
    rng = np.random.default_rng(seed)
    return x, z + ridge + noise * rng.standard_normal(x.size), area
