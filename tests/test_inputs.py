"""Inputs of the public API: pint Quantities in any unit, refused types, float64."""

import jax
import numpy as np
import pint
import pytest

import ecofmaps
from ecofmaps import _inputs
from ecofmaps.paper import EXAMPLE_2 as EXAMPLE_2_SI

UNITS = pint.UnitRegistry()
Q_ = UNITS.Quantity

EXAMPLE_2_UNITS = dict(
    amplitude=Q_(50, "um"),
    load=Q_(0.45, "kN"),
    stiffness=Q_(35, "N/um"),
    mu=0.8,
    aspect_ratio=Q_(20, "percent"),
)


@pytest.mark.parametrize(
    "function",
    [
        ecofmaps.slip_amplitude,
        ecofmaps.dissipated_energy,
        ecofmaps.energy_cof,
        ecofmaps.max_force,
        ecofmaps.slip_regime,
    ],
)
def test_quantities_are_converted_to_si(function):
    """Converted by pint's factors: equal to the SI call up to the rounding of the conversion."""
    expected = function(**EXAMPLE_2_SI)
    assert float(function(**EXAMPLE_2_UNITS)) == pytest.approx(float(expected), rel=1e-15)
    # positionally too, and a Quantity wrapping an array
    amplitude = Q_(np.array([25.0, 50.0]), "um")
    got = function(amplitude, *list(EXAMPLE_2_UNITS.values())[1:])
    reference = function(np.array([25e-6, 50e-6]), 450.0, 35e6, 0.8, 0.2)
    np.testing.assert_allclose(np.asarray(got), np.asarray(reference), rtol=1e-15)


def test_quantities_everywhere_in_the_api():
    ecof = ecofmaps.energy_cof(**EXAMPLE_2_SI)
    mu = ecofmaps.correct_ecof(ecof, **{k: EXAMPLE_2_UNITS[k] for k in ("amplitude", "load")},
                               stiffness=Q_(35, "MN/m"), scar_depth=Q_(8, "um"),
                               scar_half_width=Q_(0.04, "mm"))  # fmt: skip
    assert float(mu) == pytest.approx(0.8, rel=1e-12)
    low, high = ecofmaps.correct_ecof(
        ecof,
        **EXAMPLE_2_SI | {"mu": None}
        and {"amplitude": Q_(50, "um"), "load": 450.0, "stiffness": 35e6},
        aspect_ratio=(0.1, 0.3),
    )
    assert float(low) < 0.8 < float(high)
    grid = ecofmaps.compute_map(Q_([50.0, 100.0], "1/mm"), 0.2, Q_(50, "um"), 0.8, cache=False)
    expected = ecofmaps.compute_map(np.array([5e4, 1e5]), 0.2, 50e-6, 0.8, cache=False)
    np.testing.assert_allclose(grid.ecof.values, expected.ecof.values, rtol=1e-15)
    displacement, force = ecofmaps.fretting_loop(**EXAMPLE_2_UNITS)
    reference = ecofmaps.fretting_loop(**EXAMPLE_2_SI)
    np.testing.assert_allclose(np.asarray(force), np.asarray(reference[1]), rtol=1e-14)
    results = ecofmaps.analyze_loops(
        Q_(np.asarray(displacement) * 1e6, "um"), Q_(np.asarray(force), "N"), Q_(450, "N")
    )
    assert float(results.gicof[0]) == pytest.approx(0.8, rel=1e-9)
    recording = ecofmaps.synthetic_recording(
        Q_(50, "um"), Q_(450, "N"), Q_(35, "MN/m"), 0.8, 0.2, displacement_noise=Q_(0.1, "um")
    )
    same = ecofmaps.synthetic_recording(50e-6, 450.0, 35e6, 0.8, 0.2, displacement_noise=1e-7)
    np.testing.assert_allclose(recording[0], same[0], rtol=1e-14)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"amplitude": Q_(35, "MN/m")}, r"amplitude must be a length \[m\].*dimension"),
        ({"load": Q_(450, "m")}, r"load must be a force \[N\]"),
        ({"stiffness": Q_(35, "N")}, r"stiffness must be a stiffness \[N/m\]"),
        ({"mu": Q_(0.8, "m")}, r"mu must be a dimensionless"),
        ({"amplitude": "50um"}, r"amplitude must be a real number .* got '50um'"),
        ({"load": True}, r"load must be a real number .* got True"),
        ({"mu": np.array([True, False])}, r"mu must be a real number"),
        ({"aspect_ratio": None}, r"exactly one way: aspect_ratio .* or profile .* got neither"),
        ({"stiffness": ["35e6"]}, r"stiffness must be a real number"),
    ],
)
def test_wrong_dimensions_and_types_are_refused_by_name(change, message):
    with pytest.raises(ValueError, match=message):
        ecofmaps.energy_cof(**{**EXAMPLE_2_SI, **change})


def test_refusals_reach_every_entry_point():
    with pytest.raises(ValueError, match="load must be a force"):
        ecofmaps.analyze_loops(np.zeros(10), np.zeros(10), Q_(450, "m"))
    with pytest.raises(ValueError, match="ecof must be a real number"):
        ecofmaps.correct_ecof("0.8", 50e-6, 450.0, 35e6, 0.2)
    with pytest.raises(ValueError, match="amplitude must be a length"):
        ecofmaps.compute_map(5e4, 0.2, Q_(50, "N"), 0.8, cache=False)
    with pytest.raises(ValueError, match=r"load must be a real number .* got None"):
        ecofmaps.compute_loops(35e6, 0.2, 50e-6, None, 0.8)


def test_plain_arrays_still_jit_and_vmap():
    energy_cof = jax.jit(ecofmaps.energy_cof)
    assert float(energy_cof(**EXAMPLE_2_SI)) == float(ecofmaps.energy_cof(**EXAMPLE_2_SI))
    batched = jax.vmap(ecofmaps.energy_cof, in_axes=(0, None, None, None, None))
    values = batched(np.array([25e-6, 50e-6]), 450.0, 35e6, 0.8, 0.2)
    assert values.shape == (2,) and values.dtype == np.float64


def test_scar_profiles_keep_units():
    """A trace in mm and µm is the trace in metres, not 1000 times larger."""
    x = np.linspace(-100e-6, 100e-6, 401)
    z = np.where(np.abs(x) < 50e-6, 10e-6 * ((x / 50e-6) ** 2 - 1), 0.0)
    si = ecofmaps.scar_profile(x, z, smoothing=0)
    measured = ecofmaps.scar_profile(Q_(x * 1e3, "mm"), Q_(z * 1e6, "um"), smoothing=0)
    assert float(measured.half_width) == pytest.approx(50e-6, rel=1e-9)
    assert float(measured.depth) == pytest.approx(10e-6, rel=1e-9)
    for got, expected in zip(measured, si, strict=True):
        np.testing.assert_allclose(np.asarray(got), np.asarray(expected), rtol=1e-12, atol=0)
    wider = ecofmaps.scar_profile(x, z, half_width=Q_(45, "um"), smoothing=Q_(0, "m"))
    assert float(wider.half_width) == pytest.approx(45e-6, rel=1e-12)
    with pytest.raises(ValueError, match=r"z must be a length \[m\]"):
        ecofmaps.scar_profile(x, Q_(z, "N"))
    with pytest.raises(ValueError, match=r"x must be a real number"):
        ecofmaps.scar_profile(["a"] * 401, z)


@pytest.mark.parametrize(
    ("function", "lengths"),
    [
        (ecofmaps.parabolic_profile, ("depth", "half_width")),
        (ecofmaps.flat_bottomed_profile, ("depth", "half_width")),
        (ecofmaps.w_shaped_profile, ("depth", "half_width")),
        (ecofmaps.ridged_profile, ("depth", "half_width", "ridge_height", "ridge_width")),
    ],
)
def test_profile_families_keep_units(function, lengths):
    si = dict(zip(lengths, (10e-6, 50e-6, 2e-6, 10e-6), strict=False))
    in_units = dict(zip(lengths, (Q_(10, "um"), Q_(0.05, "mm"), Q_(2, "um"), Q_(1e-2, "mm")),
                        strict=False))  # fmt: skip
    for got, expected in zip(function(**in_units, extent=3.0), function(**si, extent=3.0),
                             strict=True):  # fmt: skip
        np.testing.assert_allclose(np.asarray(got), np.asarray(expected), rtol=1e-12)
    with pytest.raises(ValueError, match=rf"{lengths[-1]} must be a length \[m\]"):
        function(**{**si, lengths[-1]: Q_(1.0, "N")})


def test_a_broadcast_too_large_for_memory_is_refused_before_it_is_made():
    """(1e5, 1) x (1, 1e5) is 1e10 points, 80 GB; JAX aborted the interpreter."""
    column, row = np.full((100_000, 1), 50e-6), np.full((1, 100_000), 450.0)
    assert np.broadcast_shapes(column.shape, row.shape) == (100_000, 100_000)
    memory = _inputs.available_memory()
    if memory is not None and memory > 8e10:
        pytest.skip("this machine has 80 GB free")
    message = r"energy_cof: .*\(100000, 100000\), 1e\+10 points: 80 GB .* chunks=\.\.\."
    with pytest.raises(MemoryError, match=message):
        ecofmaps.energy_cof(column, row, 35e6, 0.8, 0.2)
    with pytest.raises(MemoryError, match=r"correct_ecof: .*1e\+10 points"):
        ecofmaps.correct_ecof(0.8, column, row, 35e6, 0.2)
    with pytest.raises(MemoryError, match=r"slip_amplitude: .*1e\+10 points"):
        jax.jit(ecofmaps.slip_amplitude)(column, row, 35e6, 0.8, 0.2)  # shapes of tracers


def test_the_memory_check_counts_only_new_points(monkeypatch):
    monkeypatch.setattr(_inputs, "available_memory", lambda: 8 * 1000)
    with pytest.raises(MemoryError, match=r"\(50, 50\), 2\.5e\+03 points: 2e-05 GB"):
        ecofmaps.energy_cof(np.full((50, 1), 50e-6), np.full((1, 50), 450.0), 35e6, 0.8, 0.2)
    # 2000 points of aligned inputs add none: the arrays exist already.
    values = ecofmaps.energy_cof(np.full(2000, 50e-6), np.full(2000, 450.0), 35e6, 0.8, 0.2)
    assert values.shape == (2000,)
    monkeypatch.setattr(_inputs, "available_memory", lambda: None)  # unknown: no check
    assert ecofmaps.energy_cof(
        np.full((50, 1), 50e-6), 450.0, 35e6, np.full(50, 0.8), 0.2
    ).shape == (50, 50)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: ecofmaps.energy_cof(np.ones(3), 450.0, 35e6, 0.8, np.ones(4)),
         r"energy_cof: the shapes of amplitude \(3,\) and aspect_ratio \(4,\) do not broadcast"),
        (lambda: ecofmaps.slip_regime(np.ones((2, 3)), 450.0, np.ones((3, 2)), 0.8, 0.2),
         r"slip_regime: the shapes of amplitude \(2, 3\) and stiffness \(3, 2\)"),
        (lambda: ecofmaps.correct_ecof(np.ones(3), 50e-6, 450.0, np.full(2, 35e6), 0.2),
         r"correct_ecof: the shapes of ecof \(3,\) and stiffness \(2,\)"),
        (lambda: ecofmaps.energy_cof(50e-6, [450.0, 10**400], 35e6, 0.8, 0.2),
         r"load holds an integer beyond float64's largest number, 1.8e308 \[N\]"),
        (lambda: ecofmaps.correct_ecof(0.83, 50e-6, 450.0, 35e6, 10**400),
         r"aspect_ratio holds an integer beyond float64's"),
    ],
)  # fmt: skip
def test_shape_and_overflow_errors_name_the_arguments(call, message):
    with pytest.raises(ValueError, match=message):
        call()


LOOP_SI = ecofmaps.fretting_loop(**EXAMPLE_2_SI, num=64)


@pytest.mark.parametrize(
    ("function", "si", "in_units", "wrong"),
    [
        (
            ecofmaps.simulate,
            dict(displacement=np.linspace(-50e-6, 50e-6, 9), load=450.0, stiffness=35e6,
                 mu=0.8, aspect_ratio=0.2, groove_half_width=50e-6),
            dict(displacement=Q_(np.linspace(-50, 50, 9), "um"), load=Q_(0.45, "kN"),
                 stiffness=Q_(35, "N/um"), groove_half_width=Q_(0.05, "mm")),
            dict(groove_half_width=Q_(50, "N")),
        ),
        (
            ecofmaps.fit_loop,
            dict(displacement=np.asarray(LOOP_SI[0]), force=np.asarray(LOOP_SI[1]), load=450.0),
            dict(displacement=Q_(np.asarray(LOOP_SI[0]) * 1e3, "mm"),
                 force=Q_(np.asarray(LOOP_SI[1]) * 1e-3, "kN"), load=Q_(450, "N")),
            dict(force=Q_(np.asarray(LOOP_SI[1]), "m")),
        ),
        (
            ecofmaps.correction_factor,
            dict(ecof=0.83, amplitude=50e-6, load=450.0, stiffness=35e6, scar_depth=8e-6,
                 scar_half_width=40e-6),
            dict(amplitude=Q_(0.05, "mm"), stiffness=Q_(35, "MN/m"), scar_depth=Q_(8, "um"),
                 scar_half_width=Q_(40e-6, "m")),
            dict(scar_depth=Q_(8, "N/m")),
        ),
    ],
)  # fmt: skip
def test_lengths_and_forces_keep_their_units(function, si, in_units, wrong):
    """Quantities in any unit give the SI result; a wrong dimension names the parameter."""

    def numbers(result):
        if isinstance(result, ecofmaps.LoopFit):  # fitted: converged to a tolerance
            return [result.mu, result.stiffness, result.aspect_ratio, result.load]
        return jax.tree_util.tree_leaves(result)

    expected = numbers(function(**si))
    got = numbers(function(**{**si, **in_units}))
    rtol = 1e-6 if function is ecofmaps.fit_loop else 1e-9  # SI values differ by rounding
    for value, reference in zip(got, expected, strict=True):
        np.testing.assert_allclose(np.asarray(value), np.asarray(reference), rtol=rtol)
    (name,) = wrong
    with pytest.raises(ValueError, match=rf"^{name} must be a"):
        function(**{**si, **wrong})
