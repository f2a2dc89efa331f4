"""Derivatives of the correction: jax.grad, jit and vmap of correct_ecof (implicit function)."""

import ast
import pathlib

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import ecofmaps
from ecofmaps import model
from ecofmaps.correction import CorrectionStatus, contact_cof, outcomes
from ecofmaps.paper import AMPLITUDE, ASPECT_RATIO, LOAD, STIFFNESS

EXAMPLE_2 = (0.8308, AMPLITUDE, LOAD, STIFFNESS, ASPECT_RATIO)  # and its μ_E (μ = 0.8)
NAMES = ("ecof", "amplitude", "load", "stiffness", "aspect_ratio")
# Central differences with a relative step of 1e-5: truncation ~1e-10 and rounding
# ~1e-16/1e-5 = 1e-11 of the value, so 1e-7 relative is a tight but safe tolerance.
STEP = 1e-5
RTOL = 1e-7


def corrected(ecof, amplitude, load, stiffness, aspect_ratio):
    return ecofmaps.correct_ecof(ecof, amplitude, load, stiffness, aspect_ratio=aspect_ratio)


def central_difference(function, args, index):
    """d function / d args[index] by central differences (concrete, float64)."""
    step = STEP * abs(args[index])
    up, down = list(args), list(args)
    up[index] += step
    down[index] -= step
    return (float(function(*up)) - float(function(*down))) / (2.0 * step)


@pytest.mark.parametrize(
    "point",
    [
        EXAMPLE_2,
        (0.3, 20e-6, 100.0, 5e6, 0.05),  # compliant rig, shallow groove
        (1.2, 80e-6, 900.0, 200e6, 0.6),  # stiff rig, deep groove (rising branch)
    ],
)
def test_grad_matches_central_differences(point):
    gradient = jax.grad(corrected, argnums=tuple(range(5)))(*point)
    for index, name in enumerate(NAMES):
        expected = central_difference(corrected, point, index)
        assert float(gradient[index]) == pytest.approx(expected, rel=RTOL), name


@pytest.mark.slow
def test_grad_is_the_reciprocal_slope_of_the_forward_model():
    """d mu / d mu_E = 1 / (d mu_E / d mu) at fixed test conditions (implicit function)."""
    ecof = jnp.linspace(0.1, 1.5, 8)
    kappa, lam = 0.4, 450.0 / (35e6 * 50e-6)
    slope_of_root = jax.vmap(jax.grad(lambda e: contact_cof(e, kappa, lam)[0]))(ecof)
    mu, _ = contact_cof(ecof, kappa, lam)
    _, slope = outcomes.ecof_and_slope(mu, kappa, lam)
    np.testing.assert_allclose(slope_of_root, 1.0 / slope, rtol=1e-13)
    # The same through the SI entry point: kappa = 2 z_o/x_o = 0.4.
    si = jax.vmap(jax.grad(lambda e: corrected(e, 50e-6, 450.0, 35e6, 0.2)))(ecof)
    np.testing.assert_allclose(si, 1.0 / slope, rtol=1e-13)


@pytest.mark.slow
def test_grad_of_the_factor_and_of_a_rigid_rig_and_of_scar_dimensions():
    def factor(ecof, depth):
        return ecofmaps.correction_factor(
            ecof, 50e-6, 450.0, np.inf, scar_depth=depth, scar_half_width=50e-6
        )

    point = (0.5, 10e-6)
    gradient = jax.grad(factor, argnums=(0, 1))(*point)
    for index in (0, 1):
        assert float(gradient[index]) == pytest.approx(
            central_difference(factor, point, index), rel=RTOL
        )


@pytest.mark.slow
def test_jit_vmap_and_grad_compose():
    points = [np.array([0.6, 0.8308, 1.0]), 50e-6, 450.0, np.array([20e6, 35e6, 80e6]), 0.2]
    batched = jax.jit(jax.vmap(jax.grad(corrected), in_axes=(0, None, None, 0, None)))
    got = batched(*points)
    one_by_one = [
        jax.grad(corrected)(e, 50e-6, 450.0, s, 0.2)
        for e, s in zip(points[0], points[3], strict=True)
    ]
    np.testing.assert_allclose(got, one_by_one, rtol=1e-14)
    values = jax.jit(corrected)(*EXAMPLE_2)
    assert float(values) == float(corrected(*EXAMPLE_2))  # the primal is the concrete one


def test_concrete_calls_still_raise_and_traced_ones_give_nan():
    with pytest.raises(ValueError, match="cannot be corrected"):
        corrected(5.0, 50e-6, 450.0, 35e6, 0.2)  # above S Δ*/P = 3.89: no gross slip
    value, gradient = jax.value_and_grad(corrected)(5.0, 50e-6, 450.0, 35e6, 0.2)
    assert np.isnan(value) and gradient == 0.0  # no error under grad: NaN, a constant
    mu, status = jax.jit(
        lambda e: ecofmaps.correct_ecof(e, 50e-6, 450.0, 35e6, 0.2, return_status=True)
    )(5.0)
    assert np.isnan(mu) and status == CorrectionStatus.NO_GROSS_SLIP


@pytest.mark.slow
def test_grad_of_an_interval_end():
    """The low end comes from the deeper scar only: no derivative in the shallow end."""

    def ends(low_ratio, high_ratio):
        interval = ecofmaps.correct_ecof(0.5, 50e-6, 450.0, 35e6, (low_ratio, high_ratio))
        return interval.low + 2.0 * interval.high

    gradient = jax.grad(ends, argnums=(0, 1))(0.1, 0.3)
    expected_high = central_difference(lambda r: corrected(0.5, 50e-6, 450.0, 35e6, r), [0.1], 0)
    expected_low = central_difference(lambda r: corrected(0.5, 50e-6, 450.0, 35e6, r), [0.3], 0)
    assert float(gradient[0]) == pytest.approx(2.0 * expected_high, rel=RTOL)
    assert float(gradient[1]) == pytest.approx(expected_low, rel=RTOL)


def test_forward_model_is_inverted_exactly_where_the_gradient_is_taken():
    """The custom derivative is that of the root the solver returns (not of a stale guess)."""
    mu = corrected(*EXAMPLE_2)
    kappa = 2 * EXAMPLE_2[4]
    lam = EXAMPLE_2[2] / (EXAMPLE_2[3] * EXAMPLE_2[1])
    assert float(mu * model.ecof_ratio(mu, kappa, lam)) == pytest.approx(EXAMPLE_2[0], rel=1e-12)


CORRECTION = pathlib.Path(ecofmaps.correction.__file__).parent


def correction_imports(path):
    """(module-level?, imported module, imported names) for each import of a correction module."""
    tree = ast.parse(path.read_text())
    top = {id(node) for node in tree.body}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(
            "ecofmaps.correction"
        ):
            yield id(node) in top, node.module, [alias.name for alias in node.names]


def test_correction_modules_import_no_private_names_and_no_circle():
    graph = {}
    for path in sorted(CORRECTION.glob("*.py")):
        name = f"ecofmaps.correction.{path.stem}"
        graph[name] = set()
        for at_top, module, names in correction_imports(path):
            assert at_top, f"{path.name} imports {module} inside a function"
            assert not [n for n in names if n.startswith("_")], f"{path.name}: {names}"
            graph[name].add(module)

    def reaches(start, goal, seen=()):
        return any(n == goal or (n not in seen and reaches(n, goal, (*seen, n)))
                   for n in graph.get(start, ()))  # fmt: skip

    circles = [name for name in graph if reaches(name, name)]
    assert circles == []
