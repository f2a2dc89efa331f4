"""docs/api.md: its table of the functions that work under jax.grad is the truth."""

import inspect
import pathlib
import re

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import ecofmaps
from ecofmaps import paper

TABLE = pathlib.Path(__file__).parents[1] / "docs" / "api.md"
ROW = re.compile(r"^\| `(\w+)` \| (yes|no) \| (yes|no) \| (yes|no) \|", re.MULTILINE)
RIG = (paper.AMPLITUDE, paper.LOAD, paper.STIFFNESS)  # the paper's Example 2: Δ*, P, S


def documented():
    """{function name: (jit, vmap, grad)} from the table, 'yes' as True."""
    return {
        m[1]: tuple(v == "yes" for v in m.groups()[1:]) for m in ROW.finditer(TABLE.read_text())
    }


def public_functions():
    return {n for n in ecofmaps.__all__ if inspect.isfunction(getattr(ecofmaps, n, None))}


def total(value):
    """The sum of every float leaf of a result (a tuple of arrays, a Dataset's arrays, ...)."""
    return sum(jnp.sum(jnp.asarray(leaf, dtype=float)) for leaf in jax.tree_util.tree_leaves(value))


LOOP = ecofmaps.fretting_loop(*RIG, 0.8, 0.2, num=64)
TRACE = np.linspace(-100e-6, 100e-6, 401)
HEIGHTS = np.where(np.abs(TRACE) < 50e-6, 10e-6 * ((TRACE / 50e-6) ** 2 - 1), 0.0)

# A scalar function of one number through each public function that takes numbers. None:
# the function takes a file, a Dataset or no number at all (its row must say no).
RECIPES = {
    "correct_ecof": (0.8308, lambda e: ecofmaps.correct_ecof(e, *RIG, 0.2)),
    "correction_factor": (0.8308, lambda e: ecofmaps.correction_factor(e, *RIG, 0.2)),
    "dissipated_energy": (0.8, lambda m: ecofmaps.dissipated_energy(*RIG, m, 0.2)),
    "energy_cof": (0.8, lambda m: ecofmaps.energy_cof(*RIG, m, 0.2)),
    "max_force": (0.8, lambda m: ecofmaps.max_force(*RIG, m, 0.2)),
    "slip_amplitude": (0.8, lambda m: ecofmaps.slip_amplitude(*RIG, m, 0.2)),
    "fretting_loop": (0.8, lambda m: ecofmaps.fretting_loop(*RIG, m, 0.2, num=16)[1][3]),
    "simulate": (0.8, lambda m: total(ecofmaps.simulate(
        jnp.linspace(-50e-6, 50e-6, 20), *RIG[1:], m, 0.2, groove_half_width=50e-6))),
    "slip_regime": (0.8, lambda m: ecofmaps.slip_regime(*RIG, m, 0.2)),
    "compute_map": (0.8, lambda m: total(ecofmaps.compute_map(5e4, 0.2, 50e-6, m, cache=False))),
    "compute_universal_map": (
        0.8, lambda m: total(ecofmaps.compute_universal_map(0.1, 0.2, m, cache=False))),
    "compute_loops": (0.8, lambda m: total(ecofmaps.compute_loops(35e6, 0.2, 50e-6, 450.0, m))),
    "analyze_loops": (1.0, lambda f: total(ecofmaps.analyze_loops(LOOP[0], LOOP[1] * f, 450.0))),
    "fit_loop": (1.0, lambda f: total(ecofmaps.fit_loop(LOOP[0], LOOP[1] * f, 450.0))),
    "resolve_loops": (1.0, lambda f: total(ecofmaps.resolve_loops(LOOP[0], LOOP[1] * f, 450.0,
                                                                  35e6))),
    "scar_profile": (1.0, lambda f: total(ecofmaps.scar_profile(TRACE, HEIGHTS * f))),
    "parabolic_profile": (10e-6, lambda d: total(ecofmaps.parabolic_profile(d, 50e-6))),
    "flat_bottomed_profile": (10e-6, lambda d: total(ecofmaps.flat_bottomed_profile(d, 50e-6))),
    "w_shaped_profile": (10e-6, lambda d: total(ecofmaps.w_shaped_profile(d, 50e-6))),
    "ridged_profile": (10e-6, lambda d: total(ecofmaps.ridged_profile(d, 50e-6, 1e-6, 5e-6))),
    "synthetic_recording": None,  # a Dataset of NumPy noise; slow to build
    "lookup_correction": None,  # reads a map Dataset
    "read_recording": None,
    "read_scar_profile": None,
    "long_recording": None,
    "write_long_recording": None,
    "write_map": None,
    "cache_entries": None,
    "clear_cache": None,
    "scar_example_path": None,
    "sliding_condition": None,  # reads a Dataset of results
    "transition": None,
    "energy_wear": None,
    "loop_scar_closure": None,
}  # fmt: skip


def test_every_public_function_is_in_the_table_once():
    names = [m[1] for m in ROW.finditer(TABLE.read_text())]
    assert sorted(names) == sorted(public_functions())
    assert set(RECIPES) == public_functions()
    # Without a number to differentiate (a file, a Dataset), a function cannot work under grad.
    assert [n for n, recipe in RECIPES.items() if recipe is None and documented()[n][2]] == []


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(n for n, (_, _, grad) in documented().items() if grad))
def test_grad_works_where_the_table_says_yes(name):
    x, recipe = RECIPES[name]
    step = 1e-5 * x
    expected = (float(recipe(x + step)) - float(recipe(x - step))) / (2 * step)
    assert float(jax.grad(recipe)(x)) == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize(
    "name", sorted(n for n, (_, _, grad) in documented().items() if not grad and RECIPES.get(n))
)
def test_grad_fails_where_the_table_says_no(name):
    x, recipe = RECIPES[name]
    with pytest.raises(Exception, match=r"(?i)tracer|traced|real-valued"):
        jax.grad(recipe)(x)
