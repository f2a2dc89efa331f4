"""Two analyses of the same recording compared quantity by quantity, each to its natural scale.

Every per-cycle quantity must agree to ``TOLERANCE``, relative to the quantity or, for one
that can be near zero (a centre, a crossing), to its natural scale in that cycle (Δ* for
displacements, Q* for forces, 4Δ*Q* for the energy, Q*/P for coefficients).
"""

import numpy as np

import ecofmaps
from ecofmaps.measured.measure import _PER_CYCLE
from ecofmaps.measured.quality import ALL, REASONS, SEPARATOR

TOLERANCE = 1e-12

# The unit of each per-cycle quantity, which sets its natural scale.
DISPLACEMENTS = (
    "amplitude",
    "slip_amplitude",
    "crossing_displacement_forward",
    "crossing_displacement_backward",
    "displacement_offset",
)
FORCES = ("max_force", "force_offset")
COEFFICIENTS = ("ecof", "cof_max", "energy_ratio", "gicof", "gicof_forward", "gicof_backward")
PER_CYCLE = list(_PER_CYCLE)
#: Read through the noise since the padded implementation kept the samples' half ranges
#: (docs/method-loops.md): on its noisy recordings, within the noise's lift of them.
THROUGH_NOISE = {"amplitude": 0.02, "max_force": 0.03, "cof_max": 0.03, "energy_ratio": 0.04}


def scope_of(quality: str) -> set:
    """The quantities a cycle's ``quality`` leaves NaN (every one if refused)."""
    if quality == "ok":
        return set()
    names = set()
    for reason in quality.split(SEPARATOR):
        scope = REASONS[reason][1]
        names |= set(PER_CYCLE) if scope == ALL else set(scope)
    return names


def assert_same(new, old):
    """Every per-cycle quantity of ``new`` equals ``old``'s within ``TOLERANCE``.

    ``old`` is an analysis without the plausibility checks: where ``new`` is NaN and ``old``
    is not, the cycle's ``quality`` must give a reason that reaches the quantity.
    """
    np.testing.assert_array_equal(new.cycle, old.cycle)
    known = new.regime.values != ecofmaps.INVALID  # a refused cycle has no regime
    codes = {"gross slip": ecofmaps.GROSS_SLIP, "partial slip": ecofmaps.PARTIAL_SLIP}
    reference = np.array([codes[text] for text in old.regime.values])
    np.testing.assert_array_equal(new.regime.values[known], reference[known])
    for name in ("incomplete_cycles", "dropped_samples", "cycles_from"):
        assert new.attrs[name] == old.attrs[name], name
    amplitude, max_force = np.abs(old.amplitude.values), np.abs(old.max_force.values)
    scale = {name: amplitude for name in DISPLACEMENTS}
    scale |= {name: max_force for name in FORCES}
    scale |= {name: old.cof_max.values for name in COEFFICIENTS}
    scale |= {"dissipated_energy": 4.0 * amplitude * max_force, "stiffness": 0.0}
    scopes = [scope_of(text) for text in new.quality.values]
    for name, natural in scale.items():
        a, b = new[name].values, old[name].values
        explained = np.array([name in scope for scope in scopes])
        assert not np.any(np.isnan(a) & ~np.isnan(b) & ~explained), name
        assert not np.any(~np.isnan(a) & np.isnan(b)), name
        both = ~np.isnan(a) & ~np.isnan(b)
        allowed = THROUGH_NOISE.get(name, TOLERANCE) * np.maximum(np.abs(b), natural)[both]
        difference = np.abs(a[both] - b[both])
        assert np.all(difference <= allowed), (name, float(np.max(difference / allowed)))
