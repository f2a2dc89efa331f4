"""The steady-loop model (ecofmaps.model) against brute force, limits and the paper."""

import itertools
import subprocess
import sys
import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.optimize import brentq

import ecofmaps
from ecofmaps import model
from ecofmaps.model.core import _artanh_excess
from ecofmaps.paper import EXAMPLE_2
from ecofmaps.units import DOMAIN

ARGUMENTS = ("amplitude", "load", "stiffness", "mu", "aspect_ratio", "groove_half_width")


# --- independent brute force: eq. 9, 12 and 16 written out again, solved by SciPy --------


def traction(x, load, mu, k):
    """Eq. 9, forward slip: Q_+(x) = P (mu + k x) / (1 - mu k x)."""
    return load * (mu + k * x) / (1.0 - mu * k * x)


def brute_force(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width):
    """delta* by brentq on eq. 16 and E_d by quad of eq. 12."""
    k = 2.0 * aspect_ratio * groove_half_width / groove_half_width**2
    locking = np.inf if k == 0 else 1.0 / (mu * k)
    upper = min(amplitude, locking * (1.0 - 1e-15))

    def residual(x):
        return x + traction(x, load, mu, k) / stiffness - amplitude

    slip = upper if residual(upper) <= 0 else brentq(residual, 0.0, upper, xtol=1e-300, rtol=1e-15)
    energy, _ = quad(traction, -slip, slip, args=(load, mu, k), epsabs=0.0, epsrel=1e-13, limit=200)
    return slip, 2.0 * energy


def random_points(count, seed):
    """Points over the whole valid gross-slip domain, a tenth of them with a rigid rig."""
    rng = np.random.default_rng(seed)
    points = dict(
        amplitude=10 ** rng.uniform(-6.5, -3.5, count),
        load=10 ** rng.uniform(0, 4, count),
        mu=10 ** rng.uniform(-1.5, 0.5, count),
        aspect_ratio=np.where(rng.random(count) < 0.1, 0.0, 10 ** rng.uniform(-4, 0, count)),
        groove_half_width=None,
    )
    points["groove_half_width"] = points["amplitude"] * 10 ** rng.uniform(-0.5, 1, count)
    # stiffness through the compliance ratio mu*lam in (0, 0.98): always gross slip
    mu_lam = rng.uniform(0.0, 0.98, count)
    with np.errstate(divide="ignore"):
        points["stiffness"] = points["load"] * points["mu"] / (mu_lam * points["amplitude"])
    points["stiffness"][rng.random(count) < 0.1] = np.inf
    # rigid points must stay below self-locking (mu * kappa < 1)
    kappa = 2 * points["aspect_ratio"] * points["amplitude"] / points["groove_half_width"]
    keep = (points["stiffness"] < np.inf) | (points["mu"] * kappa < 0.98)
    return {name: value[keep] for name, value in points.items()}


@pytest.fixture(scope="module")
def domain():
    points = random_points(700, seed=2016)
    assert len(points["mu"]) >= 500
    return points


def test_slip_amplitude_and_energy_against_brute_force(domain):
    """Closed forms (eq. 16 quadratic root, corrected eq. 14) vs brentq + quad: 1e-10."""
    slip = np.asarray(ecofmaps.slip_amplitude(**domain))
    energy = np.asarray(ecofmaps.dissipated_energy(**domain))
    ecof = np.asarray(ecofmaps.energy_cof(**domain))
    expected = np.array(
        [brute_force(*(domain[name][i] for name in ARGUMENTS)) for i in range(len(slip))]
    )
    np.testing.assert_allclose(slip, expected[:, 0], rtol=1e-10, atol=0)
    np.testing.assert_allclose(energy, expected[:, 1], rtol=1e-10, atol=0)
    # eq. 1 from the brute-force numbers
    np.testing.assert_allclose(
        ecof, expected[:, 1] / (4 * domain["load"] * expected[:, 0]), rtol=1e-10, atol=0
    )


def test_max_force_is_traction_at_slip_amplitude(domain):
    """Q* = Q_+(delta*) (eq. 9) and, with compliance, Q* = S (Delta* - delta*) (eq. 10)."""
    peak = np.asarray(ecofmaps.max_force(**domain))
    slip = np.asarray(ecofmaps.slip_amplitude(**domain))
    k = 2 * domain["aspect_ratio"] / domain["groove_half_width"]
    np.testing.assert_allclose(peak, traction(slip, domain["load"], domain["mu"], k), rtol=1e-12)
    finite = np.isfinite(domain["stiffness"])
    deflection = domain["stiffness"][finite] * (domain["amplitude"] - slip)[finite]
    np.testing.assert_allclose(peak[finite], deflection, rtol=1e-9)


# --- limits and the paper ---------------------------------------------------------------


def test_flat_groove():
    """z_o = 0: delta* = Delta* - mu P/S, E_d = 4 mu P delta*, mu_E = mu (Coulomb loop)."""
    point = dict(EXAMPLE_2, aspect_ratio=0.0)
    slip = 50e-6 - 0.8 * 450 / 35e6
    assert float(ecofmaps.slip_amplitude(**point)) == pytest.approx(slip, rel=1e-15)
    assert float(ecofmaps.dissipated_energy(**point)) == pytest.approx(4 * 0.8 * 450 * slip, 1e-15)
    assert float(ecofmaps.energy_cof(**point)) == 0.8


def test_rigid_rig_slips_the_whole_amplitude():
    """S = inf: delta* = Delta* for any groove below self-locking (Figure 7a, rigid)."""
    aspect = np.linspace(0.0, 0.6, 13)
    slip = ecofmaps.slip_amplitude(50e-6, 450.0, np.inf, 0.8, aspect)
    np.testing.assert_array_equal(np.asarray(slip), 50e-6)


@pytest.mark.parametrize("aspect_ratio", [1e-300, 1e-200, 1e-100, 1e-30, 1e-12, 1e-8, 1e-5])
def test_vanishing_groove_is_continuous(aspect_ratio):
    """z_o -> 0: no 0/0; mu_E - mu = (1 + mu^2)/mu * u^2/3 to leading order."""
    point = dict(EXAMPLE_2, aspect_ratio=aspect_ratio)
    slip = float(ecofmaps.slip_amplitude(**point))
    flat = 50e-6 - 0.8 * 450 / 35e6
    assert slip == pytest.approx(flat, rel=aspect_ratio + 1e-15)
    u = 0.8 * 2 * aspect_ratio / 50e-6 * slip
    ecof = float(ecofmaps.energy_cof(**point))
    assert ecof == pytest.approx(0.8 + (1 + 0.64) / 0.8 * u**2 / 3, rel=2e-16)


@pytest.mark.parametrize("stiffness", [1e12, 1e16, 1e20, 1e100])
def test_stiff_rig_tends_to_rigid(stiffness):
    """S -> inf joins the rigid limit smoothly, with no loss of digits."""
    for name in ("slip_amplitude", "energy_cof", "dissipated_energy"):
        function = getattr(ecofmaps, name)
        stiff = float(function(**dict(EXAMPLE_2, stiffness=stiffness)))
        rigid = float(function(**dict(EXAMPLE_2, stiffness=np.inf)))
        assert stiff == pytest.approx(rigid, rel=1e-4 * 1e12 / stiffness + 1e-15)


@pytest.mark.parametrize("margin", [1e-3, 1e-6, 1e-9, 1e-12])
def test_near_the_stick_limit(margin):
    """mu lambda -> 1: delta* -> 0 linearly, digits kept (brute force with mpmath-free algebra)."""
    stiffness = 450 * 0.8 / (50e-6 * (1 - margin))
    point = dict(EXAMPLE_2, stiffness=stiffness)
    slip = float(ecofmaps.slip_amplitude(**point))
    expected, _ = brute_force(*(point.get(n, 50e-6) for n in ARGUMENTS))
    assert slip == pytest.approx(expected, rel=1e-6)
    # first order in the margin: c/b with c = 1 - lam mu, b = 1 + mu kappa + lam kappa
    lam = 450 / (stiffness * 50e-6)
    c = 50e-6 * (1 - lam * 0.8)
    assert slip == pytest.approx(c / (1 + (0.8 + lam) * 0.4), rel=2 * margin)
    assert float(ecofmaps.energy_cof(**point)) == pytest.approx(0.8, rel=margin)


def test_example_2_ecof_is_about_four_percent_above_mu():
    """Section 4 / Figure 8: at S = 35 MN/m, z_o/x_o = 0.2, mu_E is about 4 % above mu."""
    ratio = float(ecofmaps.energy_cof(**EXAMPLE_2)) / 0.8
    assert 1.035 < ratio < 1.045


def test_compliance_lowers_peak_force_and_energy():
    """Figure 5: the compliant rig's loop has a lower Q* and a smaller area than the rigid one."""
    rigid = dict(EXAMPLE_2, stiffness=np.inf)
    assert float(ecofmaps.max_force(**EXAMPLE_2)) < float(ecofmaps.max_force(**rigid))
    assert float(ecofmaps.dissipated_energy(**EXAMPLE_2)) < float(
        ecofmaps.dissipated_energy(**rigid)
    )
    assert float(ecofmaps.slip_amplitude(**EXAMPLE_2)) < float(ecofmaps.slip_amplitude(**rigid))


def test_figure_7_and_8_statements():
    """Fig. 7a: delta* falls with z_o/x_o, faster for softer rigs. Fig. 7b: E_d rises with
    stiffness at every z_o/x_o, and rises with z_o/x_o for stiff rigs but falls for soft ones.
    Fig. 8: mu_E/mu rises with z_o/x_o and with S."""
    aspect = np.linspace(0.0, 0.3, 31)
    stiffness = np.array([[20e6], [35e6], [50e6], [100e6], [np.inf]])
    args = dict(amplitude=50e-6, load=450.0, stiffness=stiffness, mu=0.8, aspect_ratio=aspect)
    slip = np.asarray(ecofmaps.slip_amplitude(**args))
    energy = np.asarray(ecofmaps.dissipated_energy(**args))
    ratio = np.asarray(ecofmaps.energy_cof(**args)) / 0.8
    assert np.all(np.diff(slip[:-1], axis=1) < 0)
    assert np.all(np.diff(slip[:-1, 0] - slip[:-1, -1]) < 0)  # softer: larger drop
    assert np.all(np.diff(energy, axis=0) > 0)
    assert np.all(np.diff(energy[-1]) > 0) and np.all(np.diff(energy[0]) < 0)
    assert np.all(np.diff(ratio[:, 1:], axis=1) > 0)
    assert np.all(np.diff(ratio[:, 1:], axis=0) > 0)


# --- the dimensionless core ---------------------------------------------------------------


def test_core_collapse_on_compliance_ratio():
    """mu_E/mu depends on (Delta*, S/P) only through lambda = P/(S Delta*) (x_o = Delta*)."""
    small = ecofmaps.energy_cof(25e-6, 450.0, 70e6, 0.8, 0.2)
    large = ecofmaps.energy_cof(**EXAMPLE_2)
    assert float(small) == pytest.approx(float(large), rel=1e-14)
    core = model.ecof_ratio(0.8, 0.4, 450.0 / (35e6 * 50e-6))
    assert float(core) * 0.8 == pytest.approx(float(large), rel=1e-14)


def test_artanh_series_joins_direct_formula():
    """artanh(u)/u - 1: series below 1/2, direct above; both sides agree at the joint."""
    u = np.array([0.5 - 1e-12, 0.5, 0.5 + 1e-12, 1e-3, 0.3, 0.9])
    got = np.asarray(_artanh_excess(jnp.asarray(u), jnp.asarray(1 - u)))
    expected = [sum(x ** (2 * n) / (2 * n + 1) for n in range(1, 200)) if x < 0.6 else 0 for x in u]
    expected[-1] = np.arctanh(0.9) / 0.9 - 1
    np.testing.assert_allclose(got, expected, rtol=5e-15)


def test_slip_position_handles_negative_b():
    """The root below the locking point for a far negative target (b < 0 branch)."""
    mu, kappa, lam, target = 0.8, 2.0, 0.1, -5.0
    xi = float(model.slip_position(target, mu, kappa, lam))
    assert mu * kappa * xi < 1
    residual = xi + lam * (mu + kappa * xi) / (1 - mu * kappa * xi) - target
    assert abs(residual) < 1e-14 * abs(target)


# --- regimes and bad input --------------------------------------------------------------


def test_no_gross_slip():
    """mu lambda >= 1: the contact sticks; delta* = 0, E_d = 0, mu_E = NaN (with a warning)."""
    point = dict(EXAMPLE_2, stiffness=5e6)
    assert int(ecofmaps.slip_regime(**point)) == ecofmaps.NO_GROSS_SLIP
    assert float(ecofmaps.slip_amplitude(**point)) == 0.0
    assert float(ecofmaps.dissipated_energy(**point)) == 0.0
    assert float(ecofmaps.max_force(**point)) == pytest.approx(5e6 * 50e-6)
    with pytest.warns(ecofmaps.RegimeWarning, match="no gross slip"):
        assert np.isnan(ecofmaps.energy_cof(**point))
    boundary = dict(EXAMPLE_2, stiffness=450 * 0.8 / 50e-6)
    assert int(ecofmaps.slip_regime(**boundary)) == ecofmaps.NO_GROSS_SLIP


def test_self_locking():
    """Rigid rig with mu kappa >= 1 jams on the flank: NaN and the SELF_LOCKING code."""
    point = dict(EXAMPLE_2, stiffness=np.inf, aspect_ratio=1 / 1.6)
    assert int(ecofmaps.slip_regime(**point)) == ecofmaps.SELF_LOCKING
    for name in ("slip_amplitude", "dissipated_energy", "energy_cof", "max_force"):
        with pytest.warns(ecofmaps.RegimeWarning, match="self-locking"):
            assert np.isnan(getattr(ecofmaps, name)(**point))
    # any compliance keeps the root below the locking point
    soft = dict(point, stiffness=1e15)
    assert int(ecofmaps.slip_regime(**soft)) == ecofmaps.GROSS_SLIP
    assert np.isfinite(ecofmaps.energy_cof(**soft))


BAD_INPUTS = [
    ("amplitude", 0.0, "0 < amplitude < inf"),
    ("amplitude", -1e-6, "0 < amplitude < inf"),
    ("amplitude", np.inf, "0 < amplitude < inf"),
    ("load", 0.0, "0 < load < inf"),
    ("load", np.nan, "0 < load < inf"),
    ("stiffness", 0.0, "0 < stiffness <= inf"),
    ("stiffness", -3e6, "0 < stiffness <= inf"),
    ("stiffness", np.nan, "0 < stiffness <= inf"),
    ("mu", 0.0, "0 < mu < inf"),
    ("mu", -0.2, "0 < mu < inf"),
    ("aspect_ratio", -0.1, "0 <= aspect_ratio < inf"),
    ("aspect_ratio", np.nan, "0 <= aspect_ratio < inf"),
    ("groove_half_width", 0.0, "0 < groove_half_width < inf"),
    ("groove_half_width", "wide", "groove_half_width must be a real number"),
]


@pytest.mark.parametrize(("name", "value", "message"), BAD_INPUTS)
@pytest.mark.parametrize(
    "function", ["slip_amplitude", "dissipated_energy", "energy_cof", "max_force", "slip_regime"]
)
def test_bad_input_raises(function, name, value, message):
    point = {**EXAMPLE_2, "groove_half_width": 50e-6, name: value}
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        getattr(ecofmaps, function)(**point)


def test_bad_array_input_names_the_index():
    with pytest.raises(ValueError, match=r"at index \(2,\) \(1 of 3 values\)"):
        ecofmaps.energy_cof(50e-6, 450.0, 35e6, np.array([0.5, 0.8, -1.0]), 0.2)


#: Finite values just beyond each argument's bound in ecofmaps.units.DOMAIN, and far beyond.
BEYOND_THE_DOMAIN = [
    (name, value)
    for name in ARGUMENTS
    for value in (DOMAIN[name][1] * 10, 1e308, DOMAIN[name][0] / 10)
    if value > 0
]


@pytest.mark.parametrize(("name", "value"), BEYOND_THE_DOMAIN)
@pytest.mark.parametrize("function", ["slip_amplitude", "energy_cof", "dissipated_energy"])
def test_a_finite_value_beyond_the_domain_is_named(function, name, value):
    """Not NaN with 'invalid input': the argument, its bounds (the command line's) and value."""
    low, high = DOMAIN[name]
    rigid = ", or inf: a rigid rig" if name == "stiffness" else ""
    said = f"{name} must satisfy {low:g} <= {name} <= {high:g} ["
    point = {**EXAMPLE_2, "groove_half_width": 50e-6, name: value}
    with pytest.raises(ValueError) as refused:
        getattr(ecofmaps, function)(**point)
    assert str(refused.value).startswith(said)
    assert str(refused.value).endswith(f"] (the model's domain{rigid}); got {value!r}")
    with pytest.raises(ValueError) as refused:  # one element of an array: named, not NaN
        ecofmaps.max_force(**{**point, name: np.array([EXAMPLE_2.get(name, 50e-6), value])})
    assert str(refused.value).endswith(f"; got {value!r} at index (1,) (1 of 2 values)")


def test_the_model_is_defined_at_every_corner_of_its_domain():
    """Each combination of the domain's bounds (and a rigid rig): a regime, never 'invalid',
    and finite numbers in gross slip: the bounds keep the model's products finite."""
    ends = [(*DOMAIN[name], *((np.inf,) if name == "stiffness" else ())) for name in ARGUMENTS]
    corners = np.array(list(itertools.product(*ends))).T
    regime = np.asarray(ecofmaps.slip_regime(*corners))
    assert set(regime.tolist()) == {
        ecofmaps.GROSS_SLIP,
        ecofmaps.NO_GROSS_SLIP,
        ecofmaps.SELF_LOCKING,
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ecofmaps.RegimeWarning)  # NaN when stuck or locked
        for function in ("slip_amplitude", "dissipated_energy", "energy_cof", "max_force"):
            values = np.asarray(getattr(ecofmaps, function)(*corners))
            assert np.isfinite(values[regime == ecofmaps.GROSS_SLIP]).all(), function


def test_a_traced_value_beyond_the_domain_is_not_checked():
    """A tracer has no value to look at: under jit the formulas run (NaN with the INVALID
    code where they overflow); a concrete argument of a traced call is still checked."""
    ecof = jax.jit(ecofmaps.energy_cof)(50e-6, 450.0, 35e6, 0.8, 1e308)
    assert (
        np.isnan(ecof)
        and int(jax.jit(ecofmaps.slip_regime)(50e-6, 450.0, 35e6, 0.8, 1e308)) == ecofmaps.INVALID
    )
    with pytest.raises(ValueError, match="aspect_ratio must satisfy 0 <= aspect_ratio <= 1e"):
        jax.jit(lambda mu: ecofmaps.energy_cof(50e-6, 450.0, 35e6, mu, 1e308))(0.8)


def test_invalid_inside_jit_is_nan_with_regime_code():
    """Traced inputs cannot raise: NaN and INVALID instead."""
    ecof = jax.jit(ecofmaps.energy_cof)(50e-6, 450.0, 35e6, -0.8, 0.2)
    code = jax.jit(ecofmaps.slip_regime)(50e-6, 450.0, 35e6, -0.8, 0.2)
    assert np.isnan(ecof) and int(code) == ecofmaps.INVALID
    codes = jax.vmap(lambda p: ecofmaps.slip_regime(50e-6, p, 35e6, 0.8, 0.2))(
        jnp.array([450.0, 0.0, jnp.nan, 1e9])
    )
    assert codes.tolist() == [
        ecofmaps.GROSS_SLIP,
        ecofmaps.INVALID,
        ecofmaps.INVALID,
        ecofmaps.NO_GROSS_SLIP,
    ]


# --- JAX transformations and dtype ------------------------------------------------------


def test_vmap_over_grid_equals_scalar_calls():
    mus = jnp.linspace(0.2, 1.2, 6)
    aspects = jnp.linspace(0.0, 0.3, 5)
    grid = jax.vmap(
        jax.vmap(lambda m, r: ecofmaps.energy_cof(50e-6, 450.0, 35e6, m, r), (None, 0)),
        (0, None),
    )(mus, aspects)
    scalar = np.array(
        [[float(ecofmaps.energy_cof(50e-6, 450.0, 35e6, float(m), float(r))) for r in aspects]
         for m in mus]
    )  # fmt: skip
    np.testing.assert_array_equal(np.asarray(grid), scalar)
    broadcast = ecofmaps.energy_cof(50e-6, 450.0, 35e6, mus[:, None], aspects)
    np.testing.assert_allclose(np.asarray(broadcast), scalar, rtol=1e-15)


#: d mu_E / d(each of the five arguments), compiled once for every test that takes it.
_ECOF_GRADIENT = jax.grad(ecofmaps.energy_cof, argnums=(0, 1, 2, 3, 4))


@pytest.mark.parametrize("argument", [0, 1, 2, 3, 4])
def test_grad_matches_finite_differences(argument):
    """d mu_E / d(each argument) at Example 2 vs a central difference (rel 1e-7)."""
    values = [EXAMPLE_2[name] for name in ARGUMENTS[:5]]
    gradient = float(_ECOF_GRADIENT(*values)[argument])
    step = values[argument] * 1e-5

    def at(delta):
        shifted = list(values)
        shifted[argument] += delta
        return float(ecofmaps.energy_cof(*shifted))

    difference = (at(step) - at(-step)) / (2 * step)
    assert gradient == pytest.approx(difference, rel=1e-7)


@pytest.mark.parametrize(
    "function",
    [ecofmaps.slip_amplitude, ecofmaps.energy_cof, ecofmaps.dissipated_energy, ecofmaps.max_force],
)
def test_grad_matches_finite_differences_over_the_domain(domain, function):
    """Every partial derivative at every point of the domain (rigid rigs and flat grooves
    included) vs a central difference, compared as d f/d ln x in units of f (per unit x at
    x = 0, where a one-sided second-order difference stays in the domain). At S = inf the
    derivative in S is 0, the limit of -Q d(P/S)/dS."""
    values = [np.asarray(domain[name], dtype=np.float64) for name in ARGUMENTS]
    gradients = jax.vmap(jax.grad(function, argnums=tuple(range(6))))(*values)
    at_point = np.asarray(function(*values))

    def shifted(index, delta):
        moved = list(values)
        moved[index] = values[index] + delta
        return np.asarray(function(*moved))

    for index, name in enumerate(ARGUMENTS):
        x = values[index]
        rigid, edge = np.isinf(x), x == 0.0
        step = np.where(rigid, 0.0, np.where(edge, 1e-7, 1e-6 * x))
        with np.errstate(invalid="ignore"):  # 0/0 at S = inf, replaced by 0
            central = (shifted(index, step) - shifted(index, np.where(edge, 0, -step))) / (2 * step)
            one_sided = (4 * shifted(index, step) - shifted(index, 2 * step) - 3 * at_point) / (
                2 * step
            )
        difference = np.where(rigid, 0.0, np.where(edge, one_sided, central))
        gradient = np.asarray(gradients[index])
        scale = np.abs(at_point) / np.where(rigid | edge, 1.0, np.abs(x))
        error = np.abs(gradient - difference) / scale
        assert np.all(np.isfinite(gradient)), f"{function.__name__}: d/d {name} not finite"
        assert np.all(error < 1e-6), f"{function.__name__}: d/d {name} off by {error.max():.2g}"


@pytest.mark.parametrize(
    "function", [ecofmaps.slip_amplitude, ecofmaps.dissipated_energy, ecofmaps.max_force]
)
def test_grad_is_finite_and_right_with_no_gross_slip(function):
    """With no gross slip (muP/S >= amplitude) slip and E_d are 0 and Q* = S amplitude: each
    partial derivative equals a central difference (rel 1e-7), none NaN (d E_d/d mu was: the
    NaN of mu_E, undefined there, times where's zero)."""
    values = [0.5e-6, 450.0, 35e6, 0.8, 0.2, 50e-6]
    assert int(ecofmaps.slip_regime(*values)) == int(ecofmaps.Regime.NO_GROSS_SLIP)
    gradients = jax.grad(function, argnums=tuple(range(6)))(*values)
    for index, gradient in enumerate(gradients):
        step = values[index] * 1e-6
        moved = [[v + sign * step * (k == index) for k, v in enumerate(values)] for sign in (1, -1)]
        difference = (float(function(*moved[0])) - float(function(*moved[1]))) / (2 * step)
        assert float(gradient) == pytest.approx(difference, rel=1e-7, abs=1e-12), index


def test_grad_is_finite_at_a_flat_groove():
    """The series branch keeps gradients finite at z_o = 0 (d mu_E/d r = 0 there)."""
    gradient = _ECOF_GRADIENT(50e-6, 450.0, 35e6, 0.8, 0.0)
    assert float(gradient[3]) == 1.0 and float(gradient[4]) == 0.0


def test_results_are_float64_even_with_x64_switched_off():
    with jax.enable_x64(False):
        result = ecofmaps.energy_cof(**EXAMPLE_2)
        code = ecofmaps.slip_regime(**EXAMPLE_2)
    assert result.dtype == jnp.float64
    assert code.dtype == jnp.int32
    assert float(result) == pytest.approx(0.8307990199151581, rel=1e-15)


def test_import_leaves_jax_configuration_alone():
    """A library must not change its host's global state: 64-bit mode stays off."""
    script = (
        "import jax, ecofmaps; "
        "print(jax.config.jax_enable_x64, ecofmaps.energy_cof(5e-5, 450.0, 35e6, 0.8, 0.2).dtype, "
        "jax.numpy.asarray(1.0).dtype)"
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["False", "float64", "float32"]


def test_tracing_without_64_bit_mode_is_refused_clearly():
    with jax.enable_x64(False), pytest.raises(ValueError, match="jax_enable_x64"):
        jax.jit(ecofmaps.energy_cof)(50e-6, 450.0, 35e6, 0.8, 0.2)


def test_core_has_no_python_loop_over_points():
    """The traced program does not grow with the number of points."""
    for function in (model.slip_ratio, model.ecof_ratio, model.normalized_energy):

        def size(n, function=function):
            x = jnp.ones(n)
            return len(jax.make_jaxpr(function)(x, x, x).jaxpr.eqns)

        assert size(3) == size(3000)


# --- properties over the whole domain ----------------------------------------------------

domain_points = st.fixed_dictionaries(
    dict(
        amplitude=st.floats(1e-7, 1e-3),
        load=st.floats(1e-1, 1e4),
        compliance=st.one_of(st.just(0.0), st.floats(1e-12, 0.999)),  # mu * lambda
        mu=st.floats(1e-3, 5.0),
        aspect_ratio=st.floats(0.0, 2.0),
        width=st.floats(0.3, 10.0),  # groove half-width over amplitude
    )
)


def si(point):
    stiffness = (
        np.inf
        if point["compliance"] == 0
        else point["load"] * point["mu"] / (point["compliance"] * point["amplitude"])
    )
    return dict(
        amplitude=point["amplitude"],
        load=point["load"],
        stiffness=stiffness,
        mu=point["mu"],
        aspect_ratio=point["aspect_ratio"],
        groove_half_width=point["width"] * point["amplitude"],
    )


def gross_slip(args):
    return int(ecofmaps.slip_regime(**args)) == ecofmaps.GROSS_SLIP


@given(domain_points)
def test_property_slip_within_amplitude_and_ecof_above_mu(point):
    args = si(point)
    if not gross_slip(args):
        return
    slip = float(ecofmaps.slip_amplitude(**args))
    assert 0 < slip <= args["amplitude"]
    assert float(ecofmaps.energy_cof(**args)) >= args["mu"]


@given(domain_points, st.floats(1.0001, 3.0))
def test_property_slip_non_increasing_in_mu_and_aspect_ratio(point, factor):
    args = si(point)
    more_friction = dict(args, mu=args["mu"] * factor)
    deeper = dict(args, aspect_ratio=args["aspect_ratio"] * factor)
    if not (gross_slip(args) and gross_slip(more_friction) and gross_slip(deeper)):
        return
    slip = float(ecofmaps.slip_amplitude(**args))
    assert float(ecofmaps.slip_amplitude(**more_friction)) <= slip * (1 + 1e-14)
    assert float(ecofmaps.slip_amplitude(**deeper)) <= slip * (1 + 1e-14)


# Tribologically meaningful points (mu up to 2, groove slope at the stroke end up to 4):
# here the loop is not a sliver whose shoelace sum cancels, so its area tests E_d.
physical_points = st.fixed_dictionaries(
    dict(
        amplitude=st.floats(1e-7, 1e-3),
        load=st.floats(1e-1, 1e4),
        compliance=st.one_of(st.just(0.0), st.floats(1e-9, 0.99)),
        mu=st.floats(0.05, 2.0),
        aspect_ratio=st.floats(0.0, 1.0),
        width=st.floats(0.5, 10.0),
    )
)


@given(physical_points)
def test_property_loop_area_is_dissipated_energy(point):
    """Shoelace area of the steady loop (401 points a branch) vs E_d. The chords cut the
    curved slip branches: the worst relative error over a grid of this domain is 4.7e-4, most
    of it near the locking point; the tolerance is 1e-3. A rigid rig within 1e-12 of
    locking (1 - mu*kappa < 1e-12; hypothesis finds mu equal to the width) is left out: there
    Q_+ spans more than 28 e-folds along the branch and 401 points give errors of 1e-3 and
    more (1.3e-3 at 1e-15), while float64 fixes 1 - mu*kappa itself only to 1e-16."""
    args = si(point)
    if not gross_slip(args):
        return
    kappa = 2.0 * args["aspect_ratio"] * args["amplitude"] / args["groove_half_width"]
    if np.isinf(args["stiffness"]) and 1.0 - args["mu"] * kappa < 1e-12:
        return
    displacement, force = (np.asarray(a) for a in ecofmaps.fretting_loop(**args, num=401))
    area = np.sum((force[1:] + force[:-1]) / 2 * np.diff(displacement))  # ∮ Q dΔ, closed polygon
    assert area == pytest.approx(float(ecofmaps.dissipated_energy(**args)), rel=1e-3)


@given(domain_points)
def test_property_ecof_round_trip_through_energy(point):
    """mu_E = E_d / (4 P delta*) (eq. 1) on every gross-slip point."""
    args = si(point)
    if not gross_slip(args):
        return
    energy = float(ecofmaps.dissipated_energy(**args))
    slip = float(ecofmaps.slip_amplitude(**args))
    ecof = float(ecofmaps.energy_cof(**args))
    assert ecof == pytest.approx(energy / (4 * args["load"] * slip), rel=1e-13)
