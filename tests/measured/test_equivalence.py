"""analyze_loops, rewritten to work block by block, against its former padded implementation.

The reference is a frozen copy of ``ecofmaps.measured.cycles`` and ``analysis`` as they were
before the rewrite (``tests/measured/reference``, commit 78c1a42). On each recording every
per-cycle quantity must agree to 1e-12, relative to the quantity or, for one that can be
near zero (a centre, a crossing), to its natural scale in that cycle (Δ* for displacements,
Q* for forces, 4Δ*Q* for the energy, Q*/P for coefficients); the cycles found, their labels,
the regimes and the counts of dropped samples must be the same. The plausibility checks
(issue 9, ecofmaps.measured.quality) came after: a value the reference gave may now be NaN,
but only where the cycle's ``quality`` says why, and every cycle of the gross-slip
recordings here must be ``'ok'``.
"""

import warnings

import numpy as np
import pytest

import ecofmaps
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.measure import _PER_CYCLE
from ecofmaps.measured.quality import ALL, REASONS, SEPARATOR, LoopQualityWarning
from ecofmaps.measured.synthetic import example_recording, synthetic_recording
from tests.measured.reference.analysis import analyze_loops as reference_analysis
from tests.measured.test_analysis import mindlin_recording, ploughing_recording

LOAD = 450.0
EXAMPLE_2 = dict(amplitude=50e-6, load=LOAD, stiffness=35e6, mu=0.8, aspect_ratio=0.2)
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
PARTIAL_SLIP = ("partial slip (Mindlin)", "no gross slip")


def noisy(point, cycles, seed, **options):
    """A recording of the model with the noise, offsets and drift of a rig (issue 5)."""
    max_force = float(ecofmaps.max_force(**point))
    return synthetic_recording(
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


def recordings():
    """Name and maker of (displacement, force, cycle) of each recording compared."""

    def labelled():
        displacement, force = noisy(EXAMPLE_2, 12, 7, start_phase=0.3)
        jumps = np.repeat(np.arange(12) * 1e-6, 200)  # a new offset for each loop
        cycle = np.repeat(np.arange(1, 13) * 100, 200)
        return displacement + jumps, force + 3e3 * jumps, cycle

    def shipped():
        cycle, displacement, force = example_recording()
        return displacement, force, cycle

    flat = dict(EXAMPLE_2, aspect_ratio=0.0)
    return {
        "Example 2, noise, offsets, drift": lambda: (*noisy(EXAMPLE_2, 40, 1), None),
        "jittered clock": lambda: (*noisy(EXAMPLE_2, 30, 2, sampling_jitter=0.4), None),
        "flat groove": lambda: (*noisy(flat, 20, 3), None),
        "stiff rig, low friction": lambda: (
            *noisy(dict(EXAMPLE_2, stiffness=80e6, mu=0.4, aspect_ratio=0.3), 20, 4),
            None,
        ),
        "139 samples per cycle, starting mid-stroke": lambda: (
            *noisy(EXAMPLE_2, 25, 5, samples_per_cycle=139, start_phase=0.37),
            None,
        ),
        "noise-free": lambda: (*synthetic_recording(**EXAMPLE_2, cycles=6), None),
        "sparse: 16 samples per cycle": lambda: (
            *synthetic_recording(**flat, cycles=5, samples_per_cycle=16),
            None,
        ),
        "ploughing peaks": lambda: (*ploughing_recording(0.3 * 0.8 * LOAD, 20, noise=True), None),
        "partial slip (Mindlin)": lambda: (*mindlin_recording(0.9), None),
        "no gross slip": lambda: (*noisy(dict(EXAMPLE_2, stiffness=5e6), 8, 6), None),
        "a single loop": lambda: (
            *synthetic_recording(**EXAMPLE_2, cycles=1, start_phase=0.25),
            None,
        ),
        "shipped example (labelled)": shipped,
        "labelled, new offset each loop": labelled,
    }


RECORDINGS = recordings()


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

    Where ``new`` is NaN and ``old`` is not, the cycle's ``quality`` must give a reason
    that reaches the quantity (the padded implementation did no such checks).
    """
    np.testing.assert_array_equal(new.cycle, old.cycle)
    known = new.regime.values != ecofmaps.INVALID  # a refused cycle has no regime
    codes = {"gross slip": ecofmaps.GROSS_SLIP, "partial slip": ecofmaps.NO_GROSS_SLIP}
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
        allowed = TOLERANCE * np.maximum(np.abs(b), natural)[both]
        difference = np.abs(a[both] - b[both])
        assert np.all(difference <= allowed), (name, float(np.max(difference / allowed)))


@pytest.mark.parametrize("name", RECORDINGS)
def test_same_numbers_as_the_padded_implementation(name):
    displacement, force, cycle = RECORDINGS[name]()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LoopQualityWarning)  # partial slip, flagged
        new = analyze_loops(displacement, force, LOAD, cycle)
    assert_same(new, reference_analysis(displacement, force, LOAD, cycle))
    if name not in PARTIAL_SLIP:  # clean recordings of gross slip: every cycle plausible
        assert (new.quality == "ok").all(), new.attrs["quality_summary"]


def test_same_loops_for_plotting():
    """``keep_loops=True``: the same centred (cycle, point) loops, NaN-padded alike."""
    displacement, force = noisy(EXAMPLE_2, 8, 8, sampling_jitter=0.3)
    new = analyze_loops(displacement, force, LOAD, keep_loops=True)
    old = reference_analysis(displacement, force, LOAD, keep_loops=True)
    for name, scale in (("loop_displacement", 50e-6), ("loop_force", 450.0)):
        np.testing.assert_array_equal(new[name].isnull(), old[name].isnull())
        np.testing.assert_allclose(new[name], old[name], rtol=0, atol=TOLERANCE * scale)
    np.testing.assert_array_equal(new.point, old.point)
