"""Correcting reported ECoF values (ecofmaps.correction) against the model, brute force and maps."""

import functools
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.optimize import brentq

import ecofmaps
from ecofmaps import model
from ecofmaps.correction import (
    AMBIGUOUS_ECOF_MIN,
    LAMBDA_INFINITY,
    CorrectionStatus,
    Interval,
    contact_cof,
    ecof_fall,
    outcomes,
)
from ecofmaps.paper import AMPLITUDE, LOAD, STIFFNESS
from tests.brute_force import steady_loop

EXAMPLE_2 = dict(amplitude=AMPLITUDE, load=LOAD, stiffness=STIFFNESS)  # and mu, z_o/x_o
CORRECTED = int(CorrectionStatus.CORRECTED)


def stiffness_for(lam, amplitude=50e-6, load=450.0):
    """The stiffness giving the compliance ratio lam = P/(S Δ*) (inf for lam = 0). [N/m]"""
    lam = np.asarray(lam, dtype=float)
    with np.errstate(divide="ignore"):
        return load / (lam * amplitude)


def ecof_curve(mu, kappa, lam):
    """μ_E(μ) at fixed (κ, λ) from the model's core (the forward function being inverted)."""
    return np.asarray(mu * model.ecof_ratio(jnp.asarray(mu), kappa, lam))


@jax.jit
@functools.partial(jax.vmap, in_axes=(0, None, None))
@jax.grad
def _slope(mu, kappa, lam):
    return mu * model.ecof_ratio(mu, kappa, lam)


def ecof_slope(mu, kappa, lam):
    """dμ_E/dμ by jax.grad of the forward core, one point at a time (vmap)."""
    return np.asarray(_slope(jnp.asarray(mu), kappa, lam))


# --- the paper's Example 2 ----------------------------------------------------------------


def test_example_2_corrects_to_mu():
    """Section 3 / Figure 8: μ = 0.8, z_o/x_o = 0.2 give μ_E about 4 % above μ (≈ 0.8308)."""
    ecof = float(ecofmaps.energy_cof(**EXAMPLE_2, mu=0.8, aspect_ratio=0.2))
    assert ecof == pytest.approx(0.8308, abs=5e-5)
    mu = float(ecofmaps.correct_ecof(ecof, **EXAMPLE_2, aspect_ratio=0.2))
    assert mu == pytest.approx(0.8, rel=1e-13)
    # the value as a paper would print it, 0.8308, is within its rounding of μ = 0.8
    rounded = float(ecofmaps.correct_ecof(0.8308, **EXAMPLE_2, aspect_ratio=0.2))
    slope = ecof_slope(np.array([0.8]), 0.4, 450.0 / (35e6 * 50e-6))[0]
    assert abs(rounded - 0.8) <= abs(0.8308 - ecof) / slope * 1.01
    factor = float(ecofmaps.correction_factor(ecof, **EXAMPLE_2, aspect_ratio=0.2))
    assert factor == pytest.approx(0.8 / ecof, rel=1e-13)


def test_scar_dimensions_give_the_aspect_ratio():
    """Eq. 11: z_o/x_o = D/W; Example 2's groove (Figure 10): 8.0 µm deep over 40 µm."""
    by_ratio = ecofmaps.correct_ecof(0.83, **EXAMPLE_2, aspect_ratio=8.0 / 40.0)
    by_scar = ecofmaps.correct_ecof(0.83, **EXAMPLE_2, scar_depth=8e-6, scar_half_width=40e-6)
    assert float(by_scar) == pytest.approx(float(by_ratio), rel=1e-15)


def test_flat_scar_changes_nothing():
    """A flat groove (z_o = 0): μ_E = μ exactly (eq. 15 in the limit), for any rig."""
    ecof = np.array([0.05, 0.5, 1.2, 3.0])
    mu = ecofmaps.correct_ecof(ecof, 50e-6, 450.0, np.array([35e6, 1e8, 5e8, np.inf]), 0.0)
    np.testing.assert_array_equal(np.asarray(mu), ecof)


# --- round trips over the domain ----------------------------------------------------------


@given(
    mu=st.floats(1e-3, 10.0),
    aspect_ratio=st.floats(0.0, 1.0),
    lam=st.one_of(st.just(0.0), st.floats(1e-4, 10.0)),
    amplitude=st.floats(1e-6, 1e-3),
    load=st.floats(1.0, 1e4),
)
def test_round_trip(mu, aspect_ratio, lam, amplitude, load):
    """correct_ecof(energy_cof(μ, ...), ...) == μ to 1e-12; the residual in μ_E to 1e-13.

    z_o/x_o <= 1 (κ <= 2): μ_E(μ) rises monotonically for every λ >= 1e-4 there (see
    test_fall_region), so the inversion is unique and must succeed.
    """
    if mu * lam >= 0.999 or (lam == 0.0 and 2.0 * mu * aspect_ratio >= 0.999):
        return  # no gross slip / self-locking: there is no ECoF to correct
    point = dict(
        amplitude=amplitude, load=load, stiffness=float(stiffness_for(lam, amplitude, load))
    )
    ecof = float(ecofmaps.energy_cof(**point, mu=mu, aspect_ratio=aspect_ratio))
    corrected, status = ecofmaps.correct_ecof(
        ecof, **point, aspect_ratio=aspect_ratio, return_status=True
    )
    assert int(status) == CORRECTED
    assert float(corrected) == pytest.approx(mu, rel=1e-12)
    again = float(ecofmaps.energy_cof(**point, mu=float(corrected), aspect_ratio=aspect_ratio))
    assert again == pytest.approx(ecof, rel=1e-13)


@pytest.mark.slow
def test_round_trip_dense():
    """10^5 random points over μ ∈ [1e-3, 10], z_o/x_o ∈ [0, 1], λ ∈ {0} ∪ [1e-4, 10]."""
    rng = np.random.default_rng(4)
    count = 10**5
    mu = 10 ** rng.uniform(-3, 1, count)
    ratio = rng.uniform(0.0, 1.0, count)
    lam = np.where(rng.random(count) < 0.1, 0.0, 10 ** rng.uniform(-4, 1, count))
    keep = (mu * lam < 0.999) & ((lam > 0) | (2 * mu * ratio < 0.999))
    mu, ratio, lam = mu[keep], ratio[keep], lam[keep]
    stiffness = stiffness_for(lam)
    ecof = np.asarray(ecofmaps.energy_cof(50e-6, 450.0, stiffness, mu, ratio))
    corrected, status = ecofmaps.correct_ecof(
        ecof, 50e-6, 450.0, stiffness, ratio, return_status=True
    )
    assert np.all(np.asarray(status) == CORRECTED)
    np.testing.assert_allclose(np.asarray(corrected), mu, rtol=1e-13)
    again = np.asarray(ecofmaps.energy_cof(50e-6, 450.0, stiffness, np.asarray(corrected), ratio))
    np.testing.assert_allclose(again, ecof, rtol=1e-13)


# quad may report that roundoff stops it short of epsrel=1e-13; it still reaches ~1e-14.
@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_against_brentq_on_brute_force():
    """μ by SciPy brentq on μ_E(μ) from brentq on eq. 16 + quad of eq. 12 (tests/brute_force)."""
    rng = np.random.default_rng(11)
    for _ in range(8):
        amplitude = rng.uniform(10e-6, 100e-6)
        load = rng.uniform(50.0, 1000.0)
        stiffness = rng.uniform(10e6, 100e6)
        ratio = rng.uniform(0.0, 0.5)
        mu_max = stiffness * amplitude / load
        ecof = rng.uniform(0.1, 0.9) * min(mu_max, 2.0)

        def residual(mu, point=(amplitude, load, stiffness), ratio=ratio, ecof=ecof):
            return steady_loop(*point, mu, ratio)["ecof"] - ecof

        expected = brentq(residual, 1e-9, ecof, xtol=1e-15, rtol=1e-15)
        mu = float(ecofmaps.correct_ecof(ecof, amplitude, load, stiffness, ratio))
        assert mu == pytest.approx(expected, rel=1e-11)


def test_rigid_rig_and_the_locking_point():
    """Rigid rig (S = ∞): δ* = Δ*, μ_E runs to ∞ as μ -> 1/κ; every ECoF > 0 is corrected."""
    ecof = np.array([0.01, 0.5, 1.0, 5.0])
    mu = np.asarray(ecofmaps.correct_ecof(ecof, 50e-6, 450.0, np.inf, 0.5))  # κ = 1
    assert np.all(mu < 1.0) and np.all(np.diff(mu) > 0)
    again = ecofmaps.energy_cof(50e-6, 450.0, np.inf, mu, 0.5)
    np.testing.assert_allclose(np.asarray(again), ecof, rtol=1e-12)
    # Near locking μ_E ≈ ln(2/(1 - μκ)) - 1 is too steep for a 1e-12 residual: at μ_E = 30,
    # one ulp of μ moves it by 5e-5. The answer is the float64 whose neighbours bracket it.
    mu = float(ecofmaps.correct_ecof(30.0, 50e-6, 450.0, np.inf, 0.5))
    neighbours = np.array(
        [np.nextafter(np.nextafter(mu, 0), 0), np.nextafter(np.nextafter(mu, 2), 2)]
    )
    below, above = np.asarray(ecofmaps.energy_cof(50e-6, 450.0, np.inf, neighbours, 0.5))
    assert below < 30.0 < above
    # Past float64: μ_E = 50 needs 1 - μκ ≈ 1e-22; the answer is the float next to 1/κ.
    mu = float(ecofmaps.correct_ecof(50.0, 50e-6, 450.0, np.inf, 0.5))
    assert mu == pytest.approx(1.0, rel=4e-16)


# --- which ECoFs can be reached -----------------------------------------------------------


def test_ecof_stays_below_the_stick_line():
    """μ_E < (1 - δ*/Δ*)/λ < 1/λ over gross slip, and μ_E -> 1/λ as μ -> 1/λ."""
    for lam in (0.01, 0.257, 1.0, 5.0):
        for kappa in (0.0, 0.4, 2.0, 50.0):
            mu = (1.0 / lam) * np.concatenate(
                [np.linspace(1e-4, 0.999, 2000), 1 - np.geomspace(1e-3, 1e-9, 50)]
            )
            ecof = ecof_curve(mu, kappa, lam)
            d = np.asarray(model.slip_ratio(jnp.asarray(mu), kappa, lam))
            assert np.all(ecof < (1.0 - d) / lam * (1 + 1e-12)) and np.all(ecof >= mu)
            assert ecof[-1] == pytest.approx(1.0 / lam, rel=1e-8)


def test_unreachable_ecof():
    """μ_E >= SΔ*/P: NaN and NO_GROSS_SLIP in arrays; ValueError for one point; a warning."""
    limit = 35e6 * 50e-6 / 450.0  # 3.889: no gross-slip loop of Example 2's rig reaches it
    ecof = np.array([0.83, limit * (1 - 1e-9), limit * (1 + 1e-9), 2 * limit])
    mu, status = ecofmaps.correct_ecof(ecof, **EXAMPLE_2, aspect_ratio=0.2, return_status=True)
    np.testing.assert_array_equal(np.asarray(status), [0, 0, 1, 1])
    assert np.isnan(np.asarray(mu)[2:]).all()
    just_below = float(np.asarray(mu)[1])
    assert just_below < limit
    assert float(
        ecofmaps.energy_cof(**EXAMPLE_2, mu=just_below, aspect_ratio=0.2)
    ) == pytest.approx(ecof[1], rel=1e-12)
    with pytest.raises(ValueError, match=r"ecof = 5 cannot be corrected: .* 3\.88889"):
        ecofmaps.correct_ecof(5.0, **EXAMPLE_2, aspect_ratio=0.2)
    with pytest.warns(ecofmaps.RegimeWarning, match="1 of 2 point.*stiffness \\* amplitude"):
        mu = ecofmaps.correct_ecof([0.83, 5.0], **EXAMPLE_2, aspect_ratio=0.2)
    assert np.isnan(np.asarray(mu)[1]) and np.isfinite(np.asarray(mu)[0])


# --- where μ_E(μ) falls: the domain of a unique inversion -------------------------------


def dense_extrema(kappa, lam, count=400_000):
    """Local maxima and minima of μ_E(μ) on a dense log grid over the gross-slip range."""
    top = 1.0 / lam
    mu = np.geomspace(1e-4 / kappa, top * (1 - 1e-9), count)
    ecof = ecof_curve(mu, kappa, lam)
    turns = np.flatnonzero(np.diff(np.sign(np.diff(ecof))) != 0) + 1
    return mu[turns], ecof[turns]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("kappa", "lam"), [(10.0, 1e-3), (10.0, 1e-2), (100.0, 0.05), (2.3, 1e-6), (1000.0, 0.07)]
)
def test_fall_against_a_dense_scan(kappa, lam):
    """ecof_fall finds the local maximum and minimum of μ_E(μ) of a dense scan, in 1/κ < μ < 1."""
    mu, ecof = dense_extrema(kappa, lam)
    assert mu.size == 2 and 1.0 / kappa < mu[0] < mu[1] < 1.0
    high, low = ecof_fall(kappa, lam)
    np.testing.assert_allclose([float(high), float(low)], ecof, rtol=1e-9)


@pytest.mark.slow
def test_fall_region():
    """μ_E(μ) rises for κ <= 1 (all λ) and for λ >= λ_∞ (all κ); it falls just inside.

    The bounds the correction relies on to skip the scan for a fall (module docstring),
    checked on dense grids of dμ_E/dμ, and the limit λ_∞ = LAMBDA_INFINITY as κ -> ∞.
    """
    rising = [(kappa, lam) for kappa in (0.5, 1.0) for lam in (1e-12, 1e-6, 1e-3, 0.05, 1.0)]
    rising += [(kappa, outcomes._FALL_LAMBDA) for kappa in (10.0, 1e3, 1e6)]
    rising += [(kappa, LAMBDA_INFINITY) for kappa in (1e4, 1e8)]
    for kappa, lam in rising:
        mu = np.geomspace(1e-4 / kappa, (1 - 1e-9) / lam, 100_000)
        assert np.all(ecof_slope(mu, kappa, lam) > 0), (kappa, lam)
        assert np.isnan(float(ecof_fall(kappa, lam)[0]))
    for kappa, lam in [(1.2, 1e-100), (2.0, 1e-8), (1e6, 0.0705), (1e8, 0.0710)]:
        mu = np.geomspace(1.0 / kappa, 1.0, 100_000)
        assert np.any(ecof_slope(mu, kappa, lam) < 0), (kappa, lam)
    # Only ECoFs above 1.6 can be ambiguous: the fall's bottom, over the whole region.
    kappa, lam = np.meshgrid(np.geomspace(1.001, 1e8, 40), np.geomspace(1e-12, LAMBDA_INFINITY, 40))
    low = np.asarray(ecof_fall(kappa, lam)[1])
    assert np.isfinite(low).mean() > 0.5 and np.nanmin(low) > AMBIGUOUS_ECOF_MIN


@pytest.mark.slow
def test_ambiguous_ecof():
    """Deep groove (z_o/x_o = 5) and stiff rig (λ = 1e-3): μ_E falls from 9.43 to 5.68."""
    lam, ratio = 1e-3, 5.0
    stiffness = float(stiffness_for(lam))
    high, low = (float(v) for v in ecof_fall(2 * ratio, lam))
    ecof = np.array([1.0, low * 0.999, low, 7.0, high, high * 1.001, 500.0])
    mu, status = ecofmaps.correct_ecof(ecof, 50e-6, 450.0, stiffness, ratio, return_status=True)
    np.testing.assert_array_equal(np.asarray(status), [0, 0, 2, 2, 2, 0, 0])
    # brute force: count the contact CoFs giving each value on a dense scan of μ_E(μ)
    grid = np.geomspace(1e-5, (1 - 1e-12) / lam, 2_000_000)
    curve = ecof_curve(grid, 2 * ratio, lam)
    for value, code, corrected in zip(ecof, np.asarray(status), np.asarray(mu), strict=True):
        crossings = np.count_nonzero(np.diff(np.sign(curve - value)) != 0)
        if code == CORRECTED:
            assert crossings == 1
            assert float(ecof_curve(np.array([corrected]), 2 * ratio, lam)[0]) == pytest.approx(
                value, rel=1e-12
            )
        elif value not in (low, high):
            assert crossings == 3
    with pytest.raises(ValueError, match="three contact CoFs"):
        ecofmaps.correct_ecof(7.0, 50e-6, 450.0, stiffness, ratio)


@pytest.mark.slow
def test_traced_equals_concrete():
    """Under jax.jit and jax.vmap (NaN + status, no exceptions) as for concrete arrays."""
    ecof = jnp.array([0.5, 0.83, 7.0, 5.0, 1.0])
    stiffness = jnp.array([35e6, 35e6, float(stiffness_for(1e-3)), 35e6, -1.0])
    ratio = jnp.array([0.1, 0.2, 5.0, 0.2, 0.2])
    point = dict(amplitude=50e-6, load=450.0)
    concrete = ecofmaps.correct_ecof(
        ecof[:4], **point, stiffness=stiffness[:4], aspect_ratio=ratio[:4], return_status=True
    )

    def one(e, s, r):
        return ecofmaps.correct_ecof(e, **point, stiffness=s, aspect_ratio=r, return_status=True)

    for function in (jax.jit(one), jax.vmap(one)):
        mu, status = function(ecof, stiffness, ratio)
        np.testing.assert_array_equal(
            np.asarray(status), [0, 0, 2, 1, int(CorrectionStatus.INVALID)]
        )
        np.testing.assert_allclose(np.asarray(mu)[:4], np.asarray(concrete[0]), rtol=1e-15)
        assert mu.dtype == jnp.float64 and status.dtype == jnp.int32
    core = jax.jit(jax.vmap(contact_cof))(ecof[:4], 2 * ratio[:4], 450.0 / (stiffness[:4] * 50e-6))
    np.testing.assert_allclose(np.asarray(core[0]), np.asarray(concrete[0]), rtol=1e-15)


# --- unknown scar: an interval of aspect ratios ------------------------------------------


@given(
    mu=st.floats(0.05, 2.0),
    low=st.floats(0.0, 0.6),
    width=st.floats(0.0, 0.4),
    where=st.floats(0.0, 1.0),
    lam=st.floats(0.02, 2.0),
)
def test_interval_contains_the_true_mu(mu, low, width, where, lam):
    """The interval for z_o/x_o ∈ [a, b] holds the μ behind the ECoF of any z_o/x_o in it."""
    if mu * lam >= 0.99:
        return
    high = low + width
    true_ratio = low + where * width
    point = dict(amplitude=50e-6, load=450.0, stiffness=float(stiffness_for(lam)))
    ecof = float(ecofmaps.energy_cof(**point, mu=mu, aspect_ratio=true_ratio))
    interval, status = ecofmaps.correct_ecof(
        ecof, **point, aspect_ratio=(low, high), return_status=True
    )
    assert isinstance(interval, Interval) and int(status) == CORRECTED
    assert float(interval.low) <= mu * (1 + 1e-12) and mu <= float(interval.high) * (1 + 1e-12)
    # the ends are the corrections at the ends: the deeper scar gives the smaller μ
    assert float(interval.low) == float(ecofmaps.correct_ecof(ecof, **point, aspect_ratio=high))
    assert float(interval.high) == float(ecofmaps.correct_ecof(ecof, **point, aspect_ratio=low))
    factors = ecofmaps.correction_factor(ecof, **point, aspect_ratio=(low, high))
    assert float(factors.low) == float(interval.low) / ecof
    assert float(factors.high) == float(interval.high) / ecof


def test_interval_of_arrays_and_its_failures():
    ecof = np.array([0.83, 0.83, 5.0])
    interval, status = ecofmaps.correct_ecof(
        ecof, **EXAMPLE_2, aspect_ratio=(np.array([0.0, 0.1, 0.1]), 0.3), return_status=True
    )
    np.testing.assert_array_equal(np.asarray(status), [0, 0, 1])
    assert float(interval.high[0]) == pytest.approx(0.83, rel=1e-15)  # the flat end
    assert np.isnan(np.asarray(interval.low)[2]) and np.isnan(np.asarray(interval.high)[2])
    assert np.all(np.asarray(interval.low)[:2] < np.asarray(interval.high)[:2])


# --- bad input ----------------------------------------------------------------------------

GOOD = dict(ecof=0.83, **EXAMPLE_2, aspect_ratio=0.2)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (dict(ecof=0.0), r"ecof must satisfy 0 < ecof < inf"),
        (dict(ecof=np.nan), r"ecof must satisfy"),
        (dict(ecof=[0.8, -1.0]), r"ecof .* at index \(1,\)"),
        (dict(amplitude=-5e-6), r"amplitude must satisfy 0 < amplitude < inf \[m\]"),
        (dict(load=0.0), r"load must satisfy 0 < load < inf \[N\]"),
        (dict(stiffness=0.0), r"stiffness must satisfy 0 < stiffness <= inf \[N/m\]"),
        (dict(aspect_ratio=-0.1), r"aspect_ratio must satisfy 0 <= aspect_ratio < inf"),
        (dict(aspect_ratio=None), r"give the groove aspect ratio: aspect_ratio, or both"),
        (dict(scar_depth=1e-6, scar_half_width=1e-5), r"one way: .* not both"),
        (dict(aspect_ratio=None, scar_depth=1e-6), r"give the groove aspect ratio"),
        (
            dict(aspect_ratio=None, scar_depth=-1e-6, scar_half_width=1e-5),
            r"scar_depth must satisfy",
        ),
        (dict(aspect_ratio=None, scar_depth=1e-6, scar_half_width=0.0), r"scar_half_width must"),
        (dict(aspect_ratio=(0.1, 0.2, 0.3)), r"interval \(low, high\) of two values"),
        (dict(aspect_ratio=(0.3, 0.1)), r"low <= high"),
        (dict(aspect_ratio=(-0.1, 0.1)), r"aspect_ratio low must satisfy"),
        (dict(ecof=1e308), r"ecof must satisfy 1e-06 <= ecof <= 1000 \[1\] \(the model's domain"),
        (dict(aspect_ratio=(0.1, 1e308)), r"aspect_ratio high must satisfy 0 <= aspect_ratio"),
        (
            dict(stiffness=[35e6, 1e308]),
            r"\(the model's domain, or inf: a rigid rig\); got 1e\+308 at",
        ),
    ],
)
def test_bad_input_is_named(change, message):
    with pytest.raises(ValueError, match=message):
        ecofmaps.correct_ecof(**{**GOOD, **change})


def test_results_are_float64():
    with jax.enable_x64(False):
        mu = ecofmaps.correct_ecof(np.float32(0.83), **EXAMPLE_2, aspect_ratio=0.2)
    assert mu.dtype == jnp.float64


# --- the same correction read off a map ---------------------------------------------------


@pytest.fixture(scope="module")
def fig11_map():
    """A Figure 11-like map over S/P, z_o/x_o, two amplitudes and μ."""
    return ecofmaps.compute_map(
        stiffness_ratio=np.geomspace(2e4, 3e5, 40),
        aspect_ratio=np.linspace(0.0, 0.4, 21),
        amplitude=np.array([25e-6, 50e-6]),
        mu=np.linspace(0.2, 1.4, 25),
        cache=False,
    )


def interpolation_bound(values, coordinates):
    """Largest error of linear interpolation along each axis: max h^2 |f''| / 8 per cell."""
    bound = 0.0
    for axis, x in enumerate(coordinates):
        if x.size < 3:
            continue
        f = np.moveaxis(values, axis, -1)
        h = np.diff(x)
        second = 2 * (np.diff(f, axis=-1)[..., 1:] / h[1:] - np.diff(f, axis=-1)[..., :-1] / h[:-1])
        second /= h[1:] + h[:-1]
        cell = np.maximum(h[1:], h[:-1]) ** 2 / 8.0
        bound += float(np.nanmax(np.abs(second) * cell))
    return bound


def test_lookup_agrees_with_the_exact_inversion(fig11_map):
    """To the map's resolution: the interpolation error in μ_E over the slope dμ_E/dμ.

    The bound is Σ_i max(h_i² |∂²μ_E/∂x_i²|)/8 over the map's axes (P/S, z_o/x_o, μ; the
    two amplitudes are both grid values here), with the second derivatives taken from
    the map itself, divided by the smallest dμ_E/dμ on it.
    """
    rng = np.random.default_rng(7)
    count = 3000
    stiffness_ratio = 10 ** rng.uniform(math.log10(2e4), math.log10(3e5), count)
    ratio = rng.uniform(0.0, 0.4, count)
    amplitude = rng.choice([25e-6, 50e-6], count)
    mu = rng.uniform(0.25, 1.35, count)
    load = 450.0
    lam = 1.0 / (stiffness_ratio * amplitude)
    keep = mu * lam < 0.9
    stiffness = stiffness_ratio[keep] * load
    args = (amplitude[keep], load, stiffness, ratio[keep])
    ecof = np.asarray(ecofmaps.energy_cof(args[0], load, stiffness, mu[keep], args[3]))
    exact = np.asarray(ecofmaps.correct_ecof(ecof, *args))
    looked_up, status = ecofmaps.lookup_correction(fig11_map, ecof, *args, return_status=True)
    inside = status == CORRECTED
    assert inside.mean() > 0.9
    # points whose interpolation cells hold no NaN (no gross slip) are read off the map
    ecof_map = fig11_map.ecof.transpose("stiffness_ratio", "aspect_ratio", "amplitude", "mu").values
    coordinates = [
        1.0 / fig11_map.stiffness_ratio.values[::-1],
        fig11_map.aspect_ratio.values,
        fig11_map.mu.values,
    ]
    by_axis = ecof_map[::-1]  # P/S ascending
    bound = max(interpolation_bound(by_axis[:, :, i, :], coordinates) for i in range(2))
    slope = np.nanmin(np.diff(ecof_map, axis=-1) / np.diff(fig11_map.mu.values))
    tolerance = bound / slope
    error = np.abs(looked_up[inside] - exact[inside])
    assert 1e-6 < tolerance < 0.01  # the resolution of this map
    assert np.max(error) <= tolerance
    # a finer map in μ and z_o/x_o comes closer, about as the square of the steps
    finer = ecofmaps.compute_map(
        stiffness_ratio=fig11_map.stiffness_ratio.values, aspect_ratio=np.linspace(0.0, 0.4, 41),
        amplitude=np.array([25e-6, 50e-6]), mu=np.linspace(0.2, 1.4, 49), cache=False,
    )  # fmt: skip
    again, status_again = ecofmaps.lookup_correction(finer, ecof, *args, return_status=True)
    both = inside & (status_again == CORRECTED)
    assert np.max(np.abs(again[both] - exact[both])) < np.max(error[both[inside]]) / 2


def test_lookup_statuses_and_errors(fig11_map):
    point = EXAMPLE_2  # S/P = 7.8e4 /m
    ecof = np.array([0.83, 0.1, 0.83, 0.83, 5.0])
    mu, status = ecofmaps.lookup_correction(
        fig11_map, ecof, **{**point, "amplitude": [50e-6, 50e-6, 50e-6, 60e-6, 50e-6]},
        aspect_ratio=[0.2, 0.2, 0.5, 0.2, 0.2], return_status=True,
    )  # fmt: skip
    # below the map's μ range; z_o/x_o and Δ* off the map; unreachable
    np.testing.assert_array_equal(status, [0, 4, 4, 4, 1])
    assert np.isnan(mu[1:]).all()
    assert float(mu[0]) == pytest.approx(
        float(ecofmaps.correct_ecof(0.83, **point, aspect_ratio=0.2)), abs=1e-3
    )
    with pytest.raises(
        ValueError, match="cannot be read off the map: the point or the ECoF is outside"
    ):
        ecofmaps.lookup_correction(fig11_map, 0.83, **point, aspect_ratio=0.5)
    with pytest.warns(ecofmaps.RegimeWarning, match="lookup_correction is NaN at 1 of 2"):
        ecofmaps.lookup_correction(fig11_map, [0.83, 0.83], **point, aspect_ratio=[0.2, 0.5])
    with pytest.raises(ValueError, match="'mu' dimension"):
        ecofmaps.lookup_correction(fig11_map.isel(mu=0), 0.83, **point, aspect_ratio=0.2)
    with pytest.raises(ValueError, match="no aspect_ratio interval"):
        ecofmaps.lookup_correction(fig11_map, 0.83, **point, aspect_ratio=(0.1, 0.2))


def test_lookup_on_a_map_with_scalar_coordinates():
    """A map at one amplitude and one aspect ratio (scalar coordinates), rigid rig included."""
    one = ecofmaps.compute_map(
        np.array([5e4, 1e5, 2e5, np.inf]), 0.2, 50e-6, np.linspace(0.5, 1.2, 141), cache=False
    )
    ecof = np.array([0.83, 0.9])
    stiffness = np.array([450.0 * 1e5, np.inf])
    mu = ecofmaps.lookup_correction(
        one, ecof, 50e-6, 450.0, stiffness, scar_depth=10e-6, scar_half_width=50e-6
    )
    exact = np.asarray(ecofmaps.correct_ecof(ecof, 50e-6, 450.0, stiffness, 0.2))
    np.testing.assert_allclose(mu, exact, atol=1e-4)
    _, status = ecofmaps.lookup_correction(
        one, 0.83, 60e-6, 450.0, 450.0 * 1e5, 0.2, return_status=True
    )
    assert int(status) == int(CorrectionStatus.OUTSIDE_MAP)


@pytest.mark.slow
def test_benchmark_section_agrees_with_scipy(capsys):
    """The 'correction' benchmark (quick): μ recovered, and SciPy's brentq gives the same."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parents[1] / "benchmarks" / "bench_maps.py"
    spec = importlib.util.spec_from_file_location("bench_maps", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    bench.correction(quick=True)
    out = capsys.readouterr().out
    row = next(line.split() for line in out.splitlines() if line.strip().startswith("1.00e+05"))
    assert float(row[4]) > 0 and float(row[5]) < 1e-13  # speed; max rel error of μ
    differences = [
        float(line.rsplit(" ", 1)[1])
        for line in out.splitlines()
        if line.startswith("SciPy brentq")
    ]
    assert len(differences) == 2 and max(differences) < 1e-12
