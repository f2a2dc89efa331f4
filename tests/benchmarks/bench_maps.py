"""Speed benchmarks of ecofmaps, run as a script (pytest does not collect this file).

    python tests/benchmarks/bench_maps.py            # every section, full sizes
    python tests/benchmarks/bench_maps.py --quick    # small sizes, a few seconds
    python tests/benchmarks/bench_maps.py --only maps

Each section is a function ``section(quick: bool) -> None`` that prints its own table; add
yours to ``SECTIONS`` (name -> function). Times are the best of several repeats, with the
machine's load average printed alongside: on a shared machine it matters.
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository, for tests/

from ecofmaps.maps import compute_map
from tests.brute_force import steady_loop


def timed(function) -> tuple[float, float]:
    """Wall time and CPU time (user + system, all threads) of one call of ``function()``. [s]"""
    before = resource.getrusage(resource.RUSAGE_SELF)
    start = time.perf_counter()
    function()
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_SELF)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return wall, cpu


def load_average() -> str:
    return "load average {:.1f} {:.1f} {:.1f} on {} cores".format(*os.getloadavg(), os.cpu_count())


# ---------------------------------------------------------------------------------------
# maps: compute_map against plain NumPy and per-point SciPy
# ---------------------------------------------------------------------------------------

LOAD = 450.0  # [N]
MU = 0.8
AMPLITUDE = np.array([25e-6, 50e-6])  # [m], Figure 11


def figure_11_grid(points: int) -> dict:
    """A Figure 11-like grid of about ``points`` points: S/P x z_o/x_o x two amplitudes."""
    rows = round(math.sqrt(points / 2.0 / 0.8))
    columns = round(points / 2.0 / rows)
    return dict(
        stiffness_ratio=np.geomspace(1e4, 3e5, rows),  # [1/m]
        aspect_ratio=np.linspace(0.0, 0.4, columns),
        amplitude=AMPLITUDE,
        mu=MU,
        load=LOAD,
    )


# Coefficients 1/(2n+1), n = 28..1, of artanh(u)/u - 1 = sum u^(2n)/(2n+1) for |u| < 1/2.
_SERIES = tuple(1.0 / (2 * n + 1) for n in range(28, 0, -1))


def numpy_map(stiffness_ratio, aspect_ratio, amplitude, mu, load) -> dict:
    """The closed forms of compute_map in plain vectorised NumPy (float64), no JAX.

    Eq. 16 (slip ratio d, cancellation-free quadratic root), the corrected eq. 13-15
    (mu_E/mu with a series for artanh(u)/u - 1 at small u), eq. 12 and eq. 9.
    """
    s = stiffness_ratio[:, None, None]
    a = amplitude[None, None, :]
    kappa = 2.0 * aspect_ratio[None, :, None]  # x_o = amplitude
    lam = 1.0 / (s * a)  # P/(S amplitude)
    mu_kappa = mu * kappa
    h = mu_kappa + lam * kappa - 1.0
    root = np.sqrt(h * h + 4.0 * lam * kappa * (1.0 + mu * mu))
    d = 2.0 * (1.0 - lam * mu) / (h + 2.0 + root)
    stick = mu * lam >= 1.0
    locked = (lam == 0.0) & (mu_kappa >= 1.0)
    regime = np.where(stick, 1, np.where(locked, 2, 0)).astype(np.int32)
    d = np.where(stick, 0.0, np.where(locked, np.nan, d))
    u = mu_kappa * d
    excess = np.empty_like(u)
    small = np.abs(u) < 0.5
    u2 = u[small] ** 2
    series = np.zeros_like(u2)
    for coefficient in _SERIES:
        series = (series + coefficient) * u2
    excess[small] = series
    large = u[~small]
    excess[~small] = np.arctanh(large) / large - 1.0
    ratio = np.where(d > 0.0, 1.0 + (1.0 + mu * mu) / (mu * mu) * excess, np.nan)
    slope = kappa * d
    peak = np.where(stick, 1.0 / lam, (mu + slope) / (1.0 - mu * slope))
    return {
        "slip_amplitude": a * d,
        "slip_ratio": d,
        "ecof": mu * ratio,
        "ecof_ratio": ratio,
        "compliance_ratio": lam[:, 0, :],  # over S/P and amplitude, as in compute_map
        "regime": regime,
        "dissipated_energy": np.where(stick, 0.0, 4.0 * load * a * d * mu * ratio),
        "max_force": load * peak,
    }


def max_relative_difference(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    if not np.array_equal(np.isnan(a), np.isnan(b)):
        return math.inf
    ok = ~np.isnan(a) & (a != 0.0)
    return float(np.max(np.abs(a[ok] - b[ok]) / np.abs(a[ok]), initial=0.0))


def scipy_points(grid: dict, count: int, seed: int = 0) -> list[tuple[dict, dict]]:
    """``count`` random grid indices (i, j, k) with the brentq + quad results there."""
    rng = np.random.default_rng(seed)
    results = []
    for _ in range(count):
        index = dict(
            stiffness_ratio=int(rng.integers(grid["stiffness_ratio"].size)),
            aspect_ratio=int(rng.integers(grid["aspect_ratio"].size)),
            amplitude=int(rng.integers(grid["amplitude"].size)),
        )
        reference = steady_loop(
            amplitude=float(grid["amplitude"][index["amplitude"]]),
            load=LOAD,
            stiffness=float(grid["stiffness_ratio"][index["stiffness_ratio"]]) * LOAD,
            mu=MU,
            aspect_ratio=float(grid["aspect_ratio"][index["aspect_ratio"]]),
        )
        results.append((index, reference))
    return results


def maps(quick: bool) -> None:
    """Points per second of compute_map (cache off), NumPy and SciPy, and their ratios.

    JAX and NumPy run alternately, ``repeats`` times each, and the best wall and CPU times
    are kept, so both see the same machine load. "compile" is the first call's extra time.
    """
    sizes = [10**4, 10**5] if quick else [10**4, 10**5, 10**6, 10**7]
    repeats = 2 if quick else 5
    print(f"compute_map (cache off, jit, float64) vs plain NumPy; {load_average()}")
    print(
        f"{'points':>9} {'grid':>12} {'compile':>8} {'JAX':>9} {'NumPy':>9} "
        f"{'JAX/NumPy':>9} {'JAX/NumPy':>9} {'max rel':>8}"
    )
    print(
        f"{'':>9} {'':>12} {'[s]':>8} {'[pt/s]':>9} {'[pt/s]':>9} {'wall':>9} {'CPU':>9} "
        f"{'diff':>8}"
    )
    jax_speed = {}
    for size in sizes:
        grid = figure_11_grid(size)
        axes = [grid[k] for k in ("stiffness_ratio", "aspect_ratio", "amplitude")]
        points = math.prod(a.size for a in axes)
        first, _ = timed(lambda g=grid: compute_map(**g, cache=False))  # compiles
        jax_wall = jax_cpu = numpy_wall = numpy_cpu = math.inf
        for _ in range(repeats):
            wall, cpu = timed(lambda g=grid: compute_map(**g, cache=False))
            jax_wall, jax_cpu = min(jax_wall, wall), min(jax_cpu, cpu)
            wall, cpu = timed(lambda a=axes: numpy_map(*a, MU, LOAD))
            numpy_wall, numpy_cpu = min(numpy_wall, wall), min(numpy_cpu, cpu)
        result = compute_map(**grid, cache=False)
        reference = numpy_map(*axes, MU, LOAD)
        difference = max(max_relative_difference(result[n], reference[n]) for n in reference)
        del result, reference
        jax_speed[size] = points / jax_wall
        shape = "x".join(str(a.size) for a in axes)
        print(
            f"{points:9.2e} {shape:>12} {first - jax_wall:8.2f} {points / jax_wall:9.3g} "
            f"{points / numpy_wall:9.3g} {numpy_wall / jax_wall:9.1f} {numpy_cpu / jax_cpu:9.1f} "
            f"{difference:8.1e}"
        )
    grid = figure_11_grid(10**4)
    count = 20 if quick else 200
    start = time.perf_counter()
    samples = scipy_points(grid, count)
    scipy_speed = count / (time.perf_counter() - start)
    result = compute_map(**grid, cache=False)
    difference = 0.0
    for index, reference in samples:
        value = result.isel(index)
        for name, expected in reference.items():
            difference = max(difference, max_relative_difference(value[name], expected))
    largest = max(sizes)
    print(
        f"SciPy per point (brentq on eq. 16 + quad of eq. 12), {count} points: "
        f"{scipy_speed:.3g} pt/s; JAX/SciPy at {largest:.0e} points: "
        f"{jax_speed[largest] / scipy_speed:.3g}; max rel diff {difference:.1e}"
    )


# ---------------------------------------------------------------------------------------
# loops: analyze_loops on long noisy recordings
# ---------------------------------------------------------------------------------------


def loops(quick: bool) -> None:
    """Samples per second of analyze_loops on recordings of 200 samples per cycle.

    Ten simulated cycles of the paper's Example 2 are repeated to length, and fresh noise
    (1 % of Q*, 0.5 % of Δ*), offsets and a drift are added, so every cycle differs. The
    best of ``repeats`` calls is kept; the median GICoF against μ = 0.8 checks the result.
    """
    from ecofmaps.measured.analysis import analyze_loops
    from ecofmaps.measured.synthetic import synthetic_recording

    point = dict(amplitude=50e-6, load=LOAD, stiffness=35e6, mu=MU, aspect_ratio=0.2)
    samples_per_cycle = 200
    base_x, base_q = synthetic_recording(**point, cycles=10, samples_per_cycle=samples_per_cycle)
    sizes = [10**3, 10**4] if quick else [10**3, 10**4, 3 * 10**4]
    repeats = 2 if quick else 3
    rng = np.random.default_rng(0)
    print(f"analyze_loops, {samples_per_cycle} samples per cycle; {load_average()}")
    print(f"{'cycles':>7} {'samples':>9} {'wall':>7} {'CPU':>7} {'speed':>10} {'GICoF/μ-1':>10}")
    print(f"{'':>7} {'':>9} {'[s]':>7} {'[s]':>7} {'[sample/s]':>10} {'median':>10}")
    for cycles in sizes:
        copies = cycles // 10
        size = base_x.size * copies
        displacement = np.tile(base_x, copies) + 0.25e-6 * rng.normal(size=size) + 3e-6
        displacement += 2e-6 * np.arange(size) / size  # drift
        force = np.tile(base_q, copies) + 6.0 * rng.normal(size=size) + 5.0
        best = (math.inf, math.inf)
        for _ in range(repeats):
            best = min(best, timed(lambda d=displacement, f=force: analyze_loops(d, f, LOAD)))
        result = analyze_loops(displacement, force, LOAD)
        error = float(np.median(result.gicof / MU - 1.0))
        wall, cpu = best
        print(
            f"{result.cycle.size:7d} {size:9.2e} {wall:7.2f} {cpu:7.2f} {size / wall:10.3g} "
            f"{error:+10.1e}"
        )


# ---------------------------------------------------------------------------------------
# correction: correct_ecof against a per-value SciPy brentq inversion
# ---------------------------------------------------------------------------------------


def correction(quick: bool) -> None:
    """Corrections per second of correct_ecof (1e6 values) and of per-value SciPy brentq.

    Test conditions drawn over the range of the paper's rigs (Δ* 10-100 µm, P 50-1000 N,
    S 10-100 MN/m, z_o/x_o 0-0.5, μ 0.1-1.5 in gross slip); the ECoFs are the model's,
    so the true μ is known. SciPy inverts one value at a time with brentq on μ_E(μ), once
    on the NumPy closed form (numpy_map) and once on brute force (brentq on eq. 16 + quad
    of eq. 12, tests/brute_force.py); both run on a sample and are extrapolated.
    """
    import warnings

    from scipy.integrate import IntegrationWarning
    from scipy.optimize import brentq

    from ecofmaps import correct_ecof, energy_cof

    count = 10**5 if quick else 10**6
    sample = 20 if quick else 200
    repeats = 2 if quick else 5
    rng = np.random.default_rng(0)
    amplitude = rng.uniform(10e-6, 100e-6, count)
    load = rng.uniform(50.0, 1000.0, count)
    stiffness = rng.uniform(10e6, 100e6, count)
    ratio = rng.uniform(0.0, 0.5, count)
    mu = rng.uniform(0.1, 1.5, count)
    mu = np.minimum(mu, 0.95 * stiffness * amplitude / load)  # gross slip
    ecof = np.asarray(energy_cof(amplitude, load, stiffness, mu, ratio))
    arguments = (ecof, amplitude, load, stiffness, ratio)
    first, _ = timed(lambda: correct_ecof(*arguments).block_until_ready())  # compiles
    best = (math.inf, math.inf)
    for _ in range(repeats):
        best = min(best, timed(lambda: correct_ecof(*arguments).block_until_ready()))
    corrected = np.asarray(correct_ecof(*arguments))
    error = max_relative_difference(mu, corrected)
    wall, cpu = best

    def closed_form(m, i):
        return numpy_map(
            np.array([stiffness[i] / load[i]]), np.array([ratio[i]]), np.array([amplitude[i]]),
            m, load[i],
        )["ecof"].item() - ecof[i]  # fmt: skip

    def brute_force(m, i):
        return steady_loop(amplitude[i], load[i], stiffness[i], m, ratio[i])["ecof"] - ecof[i]

    print(f"correct_ecof (jit, float64) vs per-value SciPy brentq; {load_average()}")
    print(f"{'values':>9} {'compile':>8} {'wall':>7} {'CPU':>7} {'speed':>10} {'max rel':>8}")
    print(f"{'':>9} {'[s]':>8} {'[s]':>7} {'[s]':>7} {'[value/s]':>10} {'err μ':>8}")
    print(
        f"{count:9.2e} {first - wall:8.2f} {wall:7.3f} {cpu:7.3f} {count / wall:10.3g} {error:8.1e}"
    )
    for name, residual in (("NumPy closed form", closed_form), ("brute force", brute_force)):
        start = time.perf_counter()
        with warnings.catch_warnings():  # quad: roundoff stops it short of epsrel=1e-13
            warnings.simplefilter("ignore", IntegrationWarning)
            roots = [
                brentq(residual, 1e-9, ecof[i], args=(i,), xtol=1e-15, rtol=8.9e-16)
                for i in range(sample)
            ]
        speed = sample / (time.perf_counter() - start)
        difference = max_relative_difference(np.array(roots), corrected[:sample])
        print(
            f"SciPy brentq on the {name}, {sample} values: {speed:.3g} value/s, "
            f"{count / speed:.3g} s for {count:.0e} (extrapolated); correct_ecof/SciPy "
            f"{count / wall / speed:.3g}; max rel diff {difference:.1e}"
        )


# ---------------------------------------------------------------------------------------
# profile: energy_cof on a scar profile against per-point SciPy first passage
# ---------------------------------------------------------------------------------------


def profile(quick: bool) -> None:
    """Points per second of energy_cof on one 1000-sample scar profile over (S/P, Δ*) grids.

    Two profiles of the Example 2 aspect ratio (D/W = 0.2, W = 100 µm): a flat-bottomed
    scar, where the pad never jumps, and a W-shaped one, where it jumps over the hump on
    the softest rigs (those points take the O(N) jump pass). The grid is square in S/P
    (1e4-3e5 /m) and Δ* (10-100 µm), μ = 0.8, the scaled mapping (one set of tables). The
    baseline is the tests' brute force per point (tests/brute_force.py: NumPy first-passage
    scan and SciPy brentq for the loop's ends, SciPy quad split at every sample for E_d), on
    a sample of the grid and extrapolated; the closed form on the parabola of the same D/W
    is shown for scale. Best of ``repeats`` warm calls.
    """
    import warnings

    from ecofmaps import (
        RegimeWarning,
        energy_cof,
        flat_bottomed_profile,
        w_shaped_profile,
    )
    from ecofmaps.model.on_profile import steady_numbers
    from tests.brute_force import ProfileBruteForce

    depth, width = 20e-6, 100e-6
    profiles = {
        "flat-bottomed": flat_bottomed_profile(depth, width, 0.4, samples=1000),
        "W-shaped": w_shaped_profile(depth, width, 0.3, samples=1000),
    }
    sizes = [10**4] if quick else [10**4, 10**5, 10**6]
    repeats = 2 if quick else 3
    sample = 3 if quick else 20
    print(f"energy_cof on a 1000-sample profile (jit, float64) vs SciPy; {load_average()}")
    print(
        f"{'profile':>14} {'points':>9} {'compile':>8} {'wall':>9} {'CPU':>9} {'closed':>9} "
        f"{'jumps':>6} {'vs SciPy':>9}"
    )
    print(
        f"{'':>14} {'':>9} {'[s]':>8} {'[pt/s]':>9} {'[pt/s]':>9} {'[pt/s]':>9} {'[%]':>6} "
        f"{'wall':>9}"
    )
    rng = np.random.default_rng(0)
    for name, scar in profiles.items():
        scipy_speed, difference = math.nan, 0.0
        for size in sizes:
            side = round(math.sqrt(size))
            ratio = np.geomspace(1e4, 3e5, side)[:, None]  # [1/m]
            amplitude = np.linspace(10e-6, 100e-6, side)[None, :]
            stiffness = ratio * LOAD

            def run(scar=scar, amplitude=amplitude, stiffness=stiffness):
                energy_cof(amplitude, LOAD, stiffness, MU, profile=scar).block_until_ready()

            def closed(amplitude=amplitude, stiffness=stiffness):
                energy_cof(amplitude, LOAD, stiffness, MU, depth / width).block_until_ready()

            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RegimeWarning)  # no gross slip on soft rigs
                first, _ = timed(run)
                best = (math.inf, math.inf)
                for _ in range(repeats):
                    best = min(best, timed(run))
                closed_wall = min(timed(closed)[0] for _ in range(repeats + 1))
                numbers = steady_numbers(scar, amplitude, LOAD, stiffness, MU)
            points = side * side
            wall, cpu = best
            ecof = np.asarray(numbers["ecof_ratio"]) * MU
            slip = np.asarray(numbers["slip_ratio"])
            if math.isnan(scipy_speed):
                gross = np.flatnonzero(np.isfinite(ecof.ravel()) & (slip.ravel() > 0))
                chosen = rng.choice(gross, size=min(sample, gross.size), replace=False)
                start = time.perf_counter()
                for k in chosen:
                    i, j = np.unravel_index(k, ecof.shape)
                    reference = ProfileBruteForce(
                        scar.position, scar.slope, float(amplitude[0, j]), LOAD,
                        float(stiffness[i, 0]), MU, float(scar.half_width),
                    ).steady_loop()  # fmt: skip
                    difference = max(difference, abs(reference["ecof"] / ecof[i, j] - 1.0))
                scipy_speed = chosen.size / (time.perf_counter() - start)
            jumps = _jump_fraction(scar, amplitude, stiffness)
            print(
                f"{name:>14} {points:9.2e} {first - wall:8.2f} {points / wall:9.3g} "
                f"{points / cpu:9.3g} {points / closed_wall:9.3g} {100 * jumps:6.2f} "
                f"{points / wall / scipy_speed:9.3g}"
            )
        print(
            f"{name:>14}: SciPy brute force per point, {sample} points: {scipy_speed:.3g} pt/s; "
            f"max rel diff of μ_E {difference:.1e}"
        )


def _jump_fraction(scar, amplitude, stiffness) -> float:
    """Fraction of the grid's gross-slip points where the pad jumps (the O(N) pass runs)."""
    from ecofmaps.model import on_profile

    prepared = on_profile._prepare(
        *on_profile._inputs(amplitude, LOAD, stiffness, MU, None), scar.half_width, False
    )
    mu, key, lam, _ = (np.asarray(v) for v in prepared)
    unique, group = on_profile._groups(mu, key)
    loops, _ = on_profile._shared(scar, unique, group, lam, False)
    gross = np.asarray(loops.regime) == 0
    return float(np.mean(~np.asarray(loops.monotone)[gross])) if gross.any() else 0.0


# ---------------------------------------------------------------------------------------

#: The benchmark sections, run in this order; append yours.
SECTIONS = {
    "maps": maps,
    "loops": loops,
    "correction": correction,
    "profile": profile,
}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes, a few seconds")
    parser.add_argument("--only", nargs="+", choices=list(SECTIONS), help="run only these")
    args = parser.parse_args(argv)
    for name in args.only or SECTIONS:
        print(f"== {name} ==")
        SECTIONS[name](args.quick)
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
