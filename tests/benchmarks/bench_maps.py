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
import functools
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


def closed_forms(xp, stiffness_ratio, aspect_ratio, amplitude, mu, load) -> dict:
    """The closed forms of compute_map, written once for NumPy (xp=np) and JAX (xp=jnp).

    Eq. 16 (slip ratio d, cancellation-free quadratic root), the corrected eq. 13-15
    (mu_E/mu = 1 + (1 + mu^2)/mu^2 (artanh(u)/u - 1), u = mu kappa d, with the library's
    artanh), eq. 12 and eq. 9, over an (S/P, z_o/x_o, amplitude) grid at one mu.
    """
    s = stiffness_ratio[:, None, None]
    a = amplitude[None, None, :]
    kappa = 2.0 * aspect_ratio[None, :, None]  # x_o = amplitude
    lam = 1.0 / (s * a)  # P/(S amplitude)
    mu_kappa = mu * kappa
    h = mu_kappa + lam * kappa - 1.0
    d = 2.0 * (1.0 - lam * mu) / (h + 2.0 + xp.sqrt(h * h + 4.0 * lam * kappa * (1.0 + mu * mu)))
    stick = mu * lam >= 1.0
    locked = (lam == 0.0) & (mu_kappa >= 1.0)
    d = xp.where(stick, 0.0, xp.where(locked, xp.nan, d))
    u = mu_kappa * d
    slipping = u > 0.0
    excess = xp.arctanh(u) / xp.where(slipping, u, 1.0) - 1.0
    ratio = xp.where(slipping, 1.0 + (1.0 + mu * mu) / (mu * mu) * excess, 1.0)
    ratio = xp.where(d > 0.0, ratio, xp.nan)
    slope = kappa * d
    return {
        "slip_amplitude": a * d,
        "slip_ratio": d,
        "ecof": mu * ratio,
        "ecof_ratio": ratio,
        "compliance_ratio": lam[:, 0, :],  # over S/P and amplitude, as in compute_map
        "regime": xp.where(stick, 1, xp.where(locked, 2, 0)).astype(xp.int32),
        "dissipated_energy": xp.where(stick, 0.0, 4.0 * load * a * d * mu * ratio),
        "max_force": load * xp.where(stick, 1.0 / lam, (mu + slope) / (1.0 - mu * slope)),
    }


def numpy_map(stiffness_ratio, aspect_ratio, amplitude, mu, load) -> dict:
    """The leanest honest baseline: the closed forms in plain vectorised NumPy (float64)."""
    with np.errstate(divide="ignore", invalid="ignore"):  # 1/0 = inf for a rigid rig
        return closed_forms(np, stiffness_ratio, aspect_ratio, amplitude, mu, load)


@functools.cache
def _jit_closed_forms():
    import jax
    import jax.numpy as jnp

    return jax.jit(functools.partial(closed_forms, jnp))


def jit_map(stiffness_ratio, aspect_ratio, amplitude, mu, load) -> dict:
    """The hardware-ish floor: the same closed forms in one jax.jit, float64, as NumPy arrays.

    XLA fuses the formulas into a few passes over the grid and writes the same outputs as
    compute_map (the grid's arrays, and compliance_ratio over S/P and amplitude); nothing
    else: no validation, no tiles, no Dataset.
    """
    import jax

    with jax.enable_x64(True):
        values = _jit_closed_forms()(stiffness_ratio, aspect_ratio, amplitude, mu, load)
        return {name: np.asarray(value) for name, value in values.items()}


# Coefficients 1/(2n+1), n = 28..1, of artanh(u)/u - 1 = sum u^(2n)/(2n+1) for |u| < 1/2.
_SERIES = tuple(1.0 / (2 * n + 1) for n in range(28, 0, -1))


def numpy_series_map(stiffness_ratio, aspect_ratio, amplitude, mu, load) -> dict:
    """The closed forms of compute_map in NumPy, with the model's series for artanh(u)/u - 1.

    Eq. 16 (slip ratio d, cancellation-free quadratic root), the corrected eq. 13-15
    (mu_E/mu with a 28-term series for artanh(u)/u - 1 at small u, masked), eq. 12 and
    eq. 9. Not the leanest NumPy (see numpy_map): kept to compare with earlier reports.
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


IMPLEMENTATIONS = {
    "compute_map": lambda g: compute_map(**g, cache=False),
    "NumPy lean": lambda g: numpy_map(*_axes(g), MU, LOAD),
    "NumPy series": lambda g: numpy_series_map(*_axes(g), MU, LOAD),
    "jit floor": lambda g: jit_map(*_axes(g), MU, LOAD),
}


def _axes(grid: dict) -> list[np.ndarray]:
    return [grid[k] for k in ("stiffness_ratio", "aspect_ratio", "amplitude")]


def own_peak_memory() -> int:
    """This process's peak resident memory, VmHWM. [byte]"""
    with open("/proc/self/status", encoding="ascii") as status:
        line = next(line for line in status if line.startswith("VmHWM:"))
    return int(line.split()[1]) * 1024


def one_process(name: str, points: int, repeats: int) -> dict:
    """Time ``IMPLEMENTATIONS[name]`` on a Figure 11 grid of ``points`` in a fresh process.

    The first call (compilation and all) is followed by ``repeats`` timed calls; the
    process's peak resident memory (VmHWM) is read at its end.
    """
    import json
    import subprocess

    command = [sys.executable, __file__, "--child", name, str(points), str(repeats)]
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    if result.returncode:
        return {"error": result.stderr.strip().splitlines()[-1:]}
    return json.loads(result.stdout.splitlines()[-1])


def _child(name: str, points: int, repeats: int) -> None:
    import json

    grid = figure_11_grid(points)
    call = IMPLEMENTATIONS[name]
    start = time.perf_counter()
    call(grid)
    first = time.perf_counter() - start
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        call(grid)
        best = min(best, time.perf_counter() - start)
    points = math.prod(a.size for a in _axes(grid))
    print(json.dumps({"points": points, "first": first, "best": best, "peak": own_peak_memory()}))


# ecofmaps map run in a fresh interpreter that reports its own peak memory at the end (the
# child's ru_maxrss would not do: Linux carries the parent's peak over into it at exec).
_CLI_CHILD = """
import sys
from ecofmaps.cli import main
status = main(sys.argv[1:])
with open("/proc/self/status", encoding="ascii") as file:
    peak = next(line for line in file if line.startswith("VmHWM:")).split()[1]
print(f"status {status} VmHWM {peak}")
"""


def map_into_zarr(points: int, directory: Path) -> dict:
    """``ecofmaps map --out FILE.zarr`` on a Figure 11-like grid without load, in a subprocess.

    Returns the wall time, the command's peak resident memory (its VmHWM, read by the
    process itself at the end) and the store's size on disk; the store is removed
    afterwards.
    """
    import shutil
    import subprocess

    grid = figure_11_grid(points)
    rows, columns = grid["stiffness_ratio"].size, grid["aspect_ratio"].size
    out = directory / "bench-map.zarr"
    command = [
        sys.executable, "-c", _CLI_CHILD, "map", "--stiffness-ratio",
        f"0.01/um:0.3/um:{rows}", "--aspect-ratio", f"0:0.4:{columns}", "--amplitude",
        "25um,50um", "--mu", "0.8", "--quiet", "--out", str(out),
    ]  # fmt: skip
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    elapsed = time.perf_counter() - start
    size = sum(f.stat().st_size for f in out.rglob("*") if f.is_file()) if out.exists() else 0
    shutil.rmtree(out, ignore_errors=True)
    last = result.stdout.strip().splitlines()[-1:] or [""]
    if not last[0].startswith("status 0 "):
        return {"error": result.stderr.strip().splitlines()[-1:]}
    return {
        "points": rows * columns * 2,
        "time": elapsed,
        "peak": int(last[0].split()[-1]) * 1024,
        "size": size,
    }


def maps(quick: bool, scratch: Path | None = None) -> None:
    """compute_map against the lean NumPy, the NumPy with the series, a minimal jax.jit.

    1. Warm, in this process: the implementations run alternately, ``repeats`` times each,
       and the best wall and CPU times are kept, so all see the same machine load; the
       largest relative difference between them checks the values. "compile" is the
       first call's extra time. Then SciPy per point, and the small-grid overhead.
    2. Large grids, each implementation in a fresh process: best of 2 after a first call,
       and the process's peak resident memory (VmHWM); sizes that would need more than
       60 % of the memory available are skipped. The scaling exponent is the slope of
       log(time) against log(points) over these sizes.
    3. Block by block into a zarr store (``ecofmaps map --out FILE.zarr``, in a subprocess,
       into ``scratch``): time and peak resident memory; 1e9 points in the full run when
       the disk has room.
    """
    from ecofmaps.maps.grid import _map_kernel

    sizes = [10**4, 10**5] if quick else [10**4, 10**5, 10**6, 10**7]
    repeats = 2 if quick else 5
    names = list(IMPLEMENTATIONS)
    print(
        f"compute_map (cache off, float64) vs NumPy and jax.jit of its formulas; {load_average()}"
    )
    print(
        f"{'points':>9} {'grid':>13} {'compile':>7} {'map':>9} {'lean':>9} {'series':>9} "
        f"{'floor':>9} {'map/lean':>8} {'map/lean':>8} {'map/ser.':>8} {'floor/':>7} {'max rel':>8}"
    )
    print(
        f"{'':>9} {'':>13} {'[s]':>7} {'[pt/s]':>9} {'[pt/s]':>9} {'[pt/s]':>9} {'[pt/s]':>9} "
        f"{'wall':>8} {'CPU':>8} {'wall':>8} {'map':>7} {'diff':>8}"
    )
    for size in sizes:
        grid = figure_11_grid(size)
        points = math.prod(a.size for a in _axes(grid))
        first, _ = timed(lambda g=grid: compute_map(**g, cache=False))  # compiles
        for name in names[1:]:
            IMPLEMENTATIONS[name](grid)  # warm (compiles the floor)
        best = {name: (math.inf, math.inf) for name in names}
        for _ in range(repeats):
            for name in names:
                wall, cpu = timed(lambda g=grid, n=name: IMPLEMENTATIONS[n](g))
                best[name] = (min(best[name][0], wall), min(best[name][1], cpu))
        result = compute_map(**grid, cache=False)
        difference = 0.0
        for name in names[1:]:
            reference = IMPLEMENTATIONS[name](grid)
            difference = max(
                difference, *(max_relative_difference(result[n], reference[n]) for n in reference)
            )
        del result, reference
        wall = {name: best[name][0] for name in names}
        shape = "x".join(str(a.size) for a in _axes(grid))
        print(
            f"{points:9.2e} {shape:>13} {first - wall['compute_map']:7.2f} "
            + " ".join(f"{points / wall[n]:9.3g}" for n in names)
            + f" {wall['NumPy lean'] / wall['compute_map']:8.2f}"
            f" {best['NumPy lean'][1] / best['compute_map'][1]:8.2f}"
            f" {wall['NumPy series'] / wall['compute_map']:8.2f}"
            f" {wall['jit floor'] / wall['compute_map']:7.2f} {difference:8.1e}"
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
    print(
        f"SciPy per point (brentq on eq. 16 + quad of eq. 12), {count} points: "
        f"{scipy_speed:.3g} pt/s; compute_map/SciPy at {points:.0e} points: "
        f"{points / wall['compute_map'] / scipy_speed:.3g}; max rel diff {difference:.1e}"
    )
    _small_grid_overhead(grid, _map_kernel, 50 if quick else 500)
    _large_grids(quick)
    _into_zarr(quick, scratch)


def _small_grid_overhead(grid: dict, kernel, repeats: int) -> None:
    """compute_map's time at 1e4 points against its kernel's alone (best of ``repeats``)."""
    import jax

    axes = [np.atleast_1d(grid[k]) for k in ("stiffness_ratio", "aspect_ratio", "amplitude")]
    axes.append(np.atleast_1d(np.float64(MU)))

    def kernel_alone():
        with jax.enable_x64(True):
            return {n: np.asarray(v) for n, v in kernel(*axes, np.float64(LOAD)).items()}

    kernel_alone()
    best = {"map": math.inf, "kernel": math.inf}
    for _ in range(repeats):
        best["map"] = min(best["map"], timed(lambda: compute_map(**grid, cache=False))[0])
        best["kernel"] = min(best["kernel"], timed(kernel_alone)[0])
    overhead = best["map"] - best["kernel"]
    points = math.prod(a.size for a in axes)
    print(
        f"small grid ({points:.0e} points): compute_map {1e3 * best['map']:.3f} ms, its jit "
        f"kernel alone {1e3 * best['kernel']:.3f} ms: {1e3 * overhead:.3f} ms of validation "
        f"and Dataset ({overhead / best['kernel']:.2f}x the kernel)"
    )


def _large_grids(quick: bool) -> None:
    """Each implementation in its own process: its first call, its best later one, its peak.

    The first call is what a user computing one large map sees (compilation included, a
    fraction of a second): fresh memory for every result. Later calls may reuse memory the
    previous call freed (XLA's allocator keeps it, NumPy returns it to the system), which
    on a virtual machine, where touching fresh memory is costly, flatters the jit floor.
    """
    from ecofmaps.maps.tiles import available_memory

    sizes = [10**5, 3 * 10**5] if quick else [10**7, 3 * 10**7, 10**8, 2 * 10**8]
    names = ["compute_map", "jit floor", "NumPy lean"]
    print(f"large grids, each in its own process: first call, best of 2 later; {load_average()}")
    print(
        f"{'points':>9} "
        + " ".join(f"{n[:11]:>11} {'':>9} {'peak':>5}" for n in names)
        + f" {'map/floor':>9} {'map/floor':>9} {'map/lean':>8}"
    )
    print(
        f"{'[pt/s]':>9} " + " ".join(f"{'first':>11} {'best':>9} {'[GB]':>5}" for _ in names)
        + f" {'first':>9} {'best':>9} {'best':>8}"
    )  # fmt: skip
    per_point: dict[str, float] = {}
    times: dict[str, list[tuple[int, float, float]]] = {n: [] for n in names}
    for size in sizes:
        cells, runs = [], {}
        for name in names:
            free = available_memory() or math.inf
            if name in per_point and per_point[name] * size > 0.75 * free:
                cells.append(f"{'(memory)':>11} {'':>9} {'':>5}")
                continue
            run = one_process(name, size, 2)
            if "error" in run:
                cells.append(f"{'failed':>11} {'':>9} {'':>5}")
                print(f"  {name} at {size:.0e} points failed: {run['error']}")
                continue
            per_point[name] = run["peak"] / run["points"]
            runs[name] = run
            times[name].append((run["points"], run["first"], run["best"]))
            points = run["points"]
            cells.append(
                f"{points / run['first']:11.3g} {points / run['best']:9.3g} "
                f"{run['peak'] / 1e9:5.2f}"
            )
        ratios = []
        for other, key in (("jit floor", "first"), ("jit floor", "best"), ("NumPy lean", "best")):
            ok = {other, "compute_map"} <= set(runs)
            ratio = runs[other][key] / runs["compute_map"][key] if ok else math.nan
            ratios.append(f"{ratio:9.2f}" if ok else f"{'':>9}")
        print(f"{size:9.0e} " + " ".join(cells) + " " + " ".join(ratios))
    for name in names:
        if len(times[name]) >= 2:
            x = np.log([p for p, _, _ in times[name]])
            first = np.polyfit(x, np.log([f for _, f, _ in times[name]]), 1)[0]
            best = np.polyfit(x, np.log([b for _, _, b in times[name]]), 1)[0]
            print(
                f"  {name}: time ~ points^{first:.2f} (first call), ^{best:.2f} (best) over "
                f"{times[name][0][0]:.0e} to {times[name][-1][0]:.0e} points"
            )


def _into_zarr(quick: bool, scratch: Path | None) -> None:
    import shutil
    import tempfile

    sizes = [10**5] if quick else [10**8, 10**9]
    with tempfile.TemporaryDirectory(dir=scratch) as directory:
        print(f"block by block into zarr (ecofmaps map --out FILE.zarr, no load); {load_average()}")
        for size in sizes:
            needed = 40 * size  # bytes on disk, with room to spare (about 20 B/point written)
            if shutil.disk_usage(directory).free < needed:
                print(f"  {size:.0e} points: skipped, {needed / 1e9:.0f} GB of free disk needed")
                continue
            run = map_into_zarr(size, Path(directory))
            if "error" in run:
                print(f"  {size:.0e} points: failed: {run['error']}")
                continue
            print(
                f"  {run['points']:.3g} points: {run['time']:.1f} s, "
                f"{run['points'] / run['time']:.3g} pt/s, peak RSS {run['peak'] / 1e9:.2f} GB, "
                f"store {run['size'] / 1e9:.2f} GB"
            )


# ---------------------------------------------------------------------------------------
# loops: analyze_loops against a lean NumPy pass, and its peak memory
# ---------------------------------------------------------------------------------------

SAMPLES_PER_CYCLE = 200


def loop_recording(cycles: int, seed: int = 0):
    """A noisy recording of ``cycles`` cycles of 200 samples (Example 2, Section 3).

    Ten simulated cycles are repeated to length, and fresh noise (1 % of Q*, 0.5 % of Δ*),
    offsets and a drift are added in place, a chunk at a time, so that every cycle differs
    and nothing but the two arrays is held. [m], [N]
    """
    from ecofmaps.measured.synthetic import synthetic_recording

    point = dict(amplitude=50e-6, load=LOAD, stiffness=35e6, mu=MU, aspect_ratio=0.2)
    base = synthetic_recording(**point, cycles=10, samples_per_cycle=SAMPLES_PER_CYCLE)
    displacement, force = (np.tile(values, cycles // 10) for values in base)
    rng = np.random.default_rng(seed)
    chunk = 1 << 20
    for a in range(0, displacement.size, chunk):
        b = min(a + chunk, displacement.size)
        drift = 2e-6 * np.arange(a, b) / displacement.size
        displacement[a:b] += 0.25e-6 * rng.normal(size=b - a) + 3e-6 + drift
        force[a:b] += 6.0 * rng.normal(size=b - a) + 5.0
    return displacement, force


def lean_loops(displacement, force, samples_per_cycle=SAMPLES_PER_CYCLE):
    """The leanest honest per-cycle pass: loop area and amplitude on a (cycle, sample) view.

    The recording is cut every ``samples_per_cycle`` samples (no reversal detection, no
    centring, no drift); the area is the closed trapezoidal sum, as in analyze_loops.
    """
    x = displacement.reshape(-1, samples_per_cycle)
    q = force.reshape(-1, samples_per_cycle)
    amplitude = 0.5 * (x.max(axis=1) - x.min(axis=1))
    closing = (q[:, 0] + q[:, -1]) * (x[:, 0] - x[:, -1])
    area = 0.5 * (np.einsum("ij,ij->i", q[:, 1:] + q[:, :-1], np.diff(x, axis=1)) + closing)
    return amplitude, area


def _status(key: str) -> int:
    """A memory figure of this process from /proc/self/status. [B]"""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(key):
                return int(line.split()[1]) * 1024
    raise KeyError(key)


def memory_child(samples: int) -> None:
    """Run in a fresh process: peak memory of one analyze_loops call, printed as numbers.

    The recording is made first; the peak resident size (VmHWM) is then reset (Linux
    ``clear_refs``), so the peak measured is that of the call, on top of the process
    with its recording.
    """
    from ecofmaps.measured.analysis import analyze_loops

    displacement, force = loop_recording(samples // SAMPLES_PER_CYCLE)
    analyze_loops(displacement[:20_000], force[:20_000], LOAD)  # imports and first calls
    with open("/proc/self/clear_refs", "w") as refs:
        refs.write("5")  # reset the peak resident size
    before = _status("VmRSS:")
    start = time.perf_counter()
    analyze_loops(displacement, force, LOAD)
    wall = time.perf_counter() - start
    print(before, _status("VmHWM:"), displacement.nbytes + force.nbytes, wall)


def loops_peak_memory(samples: int):
    """Resident memory before and at the peak of analyze_loops in a fresh process. [B]"""
    import subprocess

    command = [sys.executable, __file__, "--memory-child", str(samples)]
    done = subprocess.run(command, capture_output=True, text=True, check=True)
    before, peak, size, wall = done.stdout.split()
    return int(before), int(peak), int(size), float(wall)


def loops(quick: bool) -> None:
    """Samples per second of analyze_loops and of the lean NumPy pass; peak memory.

    Both run alternately on the same recordings (200 samples per cycle, see
    loop_recording), ``repeats`` times each, best wall and CPU times kept. The lean pass
    (lean_loops) only computes each cycle's loop area and amplitude on a reshaped view:
    the floor for any per-cycle analysis in NumPy. The ratios analyze_loops / floor of the
    CPU and of the wall times are printed side by side (on a shared machine, run with
    OMP_NUM_THREADS=1 and compare the CPU ratio); --quick includes the 10⁴ cycles (2·10⁶
    samples). The median GICoF against μ = 0.8 and
    the median difference of the two loop areas check the results. Memory: one call on a
    large recording in a fresh process (loops_peak_memory), above the memory before the call
    ("extra") and in all, relative to the recording's two float64 arrays.
    """
    from ecofmaps.measured.analysis import analyze_loops

    sizes = [10**3, 10**4] if quick else [10**3, 10**4, 10**5]
    repeats = 5
    print(f"analyze_loops vs lean NumPy, {SAMPLES_PER_CYCLE} samples per cycle; {load_average()}")
    header = ("cycles", "samples", "wall", "CPU", "analyze", "analyze", "lean", "lean")
    extra = f"{'/floor':>7} {'/floor':>7} {'GICoF/μ-1':>10} {'E_d':>8}"
    print(" ".join(f"{h:>9}" for h in header), extra)
    units = ("", "", "[s]", "[s]", "wall [/s]", "CPU [/s]", "wall [/s]", "CPU [/s]")
    extra = f"{'CPU':>7} {'wall':>7} {'median':>10} {'diff':>8}"
    print(" ".join(f"{u:>9}" for u in units), extra)
    for cycles in sizes:
        displacement, force = loop_recording(cycles, seed=cycles)
        size = displacement.size
        wall = cpu = lean_wall = lean_cpu = math.inf
        for _ in range(repeats):
            w, c = timed(lambda d=displacement, f=force: analyze_loops(d, f, LOAD))
            wall, cpu = min(wall, w), min(cpu, c)
            w, c = timed(lambda d=displacement, f=force: lean_loops(d, f))
            lean_wall, lean_cpu = min(lean_wall, w), min(lean_cpu, c)
        result = analyze_loops(displacement, force, LOAD)
        error = float(np.median(result.gicof / MU - 1.0))
        area = lean_loops(displacement, force)[1][: result.cycle.size]
        difference = float(np.median(np.abs(result.dissipated_energy.values / area - 1.0)))
        row = (result.cycle.size, size, wall, cpu)
        print(
            f"{row[0]:9d} {row[1]:9.2e} {row[2]:9.3f} {row[3]:9.3f} {size / wall:9.3g} "
            f"{size / cpu:9.3g} {size / lean_wall:9.3g} {size / lean_cpu:9.3g} "
            f"{cpu / lean_cpu:7.1f} {wall / lean_wall:7.1f} {error:+10.1e} {difference:8.1e}"
        )
    print("peak resident memory of one call, in a fresh process (reset after the recording)")
    header = ("", "samples", "input", "extra", "extra/", "peak/", "speed")
    print(f"{header[0]:>20}", " ".join(f"{h:>9}" for h in header[1:]))
    units = ("", "", "[MiB]", "[MiB]", "input", "input", "wall [/s]")
    print(f"{units[0]:>20}", " ".join(f"{u:>9}" for u in units[1:]))
    large = 2 * 10**6 if quick else 10**8
    before, peak, size, wall = loops_peak_memory(large)
    extra = peak - before
    print(
        f"{'analyze_loops':>20} {large:9.2e} {size / 2**20:9.0f} {extra / 2**20:9.0f} "
        f"{extra / size:9.2f} {peak / size:9.2f} {large / wall:9.3g}"
    )


# ---------------------------------------------------------------------------------------
# resolved: resolve_loops against a lean NumPy reading of the same formula
# ---------------------------------------------------------------------------------------


def numpy_resolved(displacement, force, load, stiffness, samples_per_cycle, threshold, points):
    """mu_resolved and z_o/x_o of loops laid end to end, in plain vectorised NumPy.

    The leanest honest reading of the formula: each cycle a row of a reshaped view (the
    recording starts on a reversal), centred on its means, ξ = Δ - Q/S with S given, the
    samples beyond ``threshold`` of the reversal's ξ on each branch taken as slip, both
    branches interpolated linearly onto ``points`` positions over the central 80 % of their
    common range, μ(ξ) and g(ξ) from the angle formulae, their mean and the slope of g.
    No stiffness, no checks, no standard error, no Dataset.
    """
    n = samples_per_cycle
    x = displacement.reshape(-1, n)
    q = force.reshape(-1, n)
    x = x - x.mean(axis=1, keepdims=True)
    q = q - q.mean(axis=1, keepdims=True)
    xi = x - q / stiffness
    half = n // 2
    rising, falling = xi[:, : half + 1], -xi[:, half:][:, ::-1]  # both run up in ξ
    rising_q, falling_q = q[:, : half + 1], -q[:, half:][:, ::-1]
    cycles = xi.shape[0]
    branches = []
    for position, value, start in (
        (rising, rising_q, rising[:, :1]),
        (falling, falling_q, -xi[:, half : half + 1]),
    ):
        slip = position > start + threshold
        key = np.sort(np.where(slip, position, np.inf), axis=1)
        order = np.argsort(np.where(slip, position, np.inf), axis=1)
        branches.append((key, np.take_along_axis(value, order, axis=1), slip.sum(axis=1)))
    # The falling branch was turned through the centre: its forces are -Q_-(-ξ).
    low = np.maximum(branches[0][0][:, 0], -branches[1][0][np.arange(cycles), branches[1][2] - 1])
    high = np.minimum(branches[0][0][np.arange(cycles), branches[0][2] - 1], -branches[1][0][:, 0])
    central = 0.8 * np.minimum(high, -low)
    unit = np.linspace(-1.0, 1.0, points)
    at = central[:, None] * unit
    rows = 4.0 * np.arange(cycles)[:, None]
    values = []
    for (key, value, count), sign in zip(branches, (1.0, -1.0), strict=True):
        where = sign * at
        scale = 2.0 * np.abs(key[np.isfinite(key)]).max()
        flat = np.where(np.isfinite(key), key / scale, 0.75) + rows
        right = np.searchsorted(flat.ravel(), (where / scale + rows).ravel()).reshape(at.shape)
        left = np.clip(right - 1 - key.shape[1] * np.arange(cycles)[:, None], 0, None)
        left = np.minimum(left, (count - 2)[:, None])
        x0 = np.take_along_axis(key, left, axis=1)
        x1 = np.take_along_axis(key, left + 1, axis=1)
        q0 = np.take_along_axis(value, left, axis=1)
        q1 = np.take_along_axis(value, left + 1, axis=1)
        values.append(sign * (q0 + (where - x0) / (x1 - x0) * (q1 - q0)))
    up, down = np.arctan(values[0] / load), np.arctan(values[1] / load)
    mu = np.tan(0.5 * (up - down))
    slope = np.tan(0.5 * (up + down))
    centred = at - at.mean(axis=1, keepdims=True)
    k = np.sum(centred * (slope - slope.mean(axis=1, keepdims=True)), axis=1) / np.sum(
        centred**2, axis=1
    )
    amplitude = 0.5 * (x.max(axis=1) - x.min(axis=1))
    return mu.mean(axis=1), 0.5 * k * amplitude


def resolved(quick: bool) -> None:
    """Samples per second of resolve_loops (and of its part after analyze_loops) and NumPy.

    Loops of 200 samples, groove z_o/x_o = 0.2, the paper's Example 2: ten simulated cycles
    repeated to length with fresh noise (0.25 µm, 4 N), offsets and loop labels. JAX is not
    involved; the best of ``repeats`` calls is kept. The medians of mu_resolved/μ - 1 and
    of the lean NumPy's check the results.
    """
    from ecofmaps.measured.analysis import analyze_loops, resolve_loops
    from ecofmaps.measured.resolve import resolve_analyzed_loops
    from ecofmaps.measured.synthetic import synthetic_recording

    point = dict(amplitude=50e-6, load=LOAD, stiffness=35e6, mu=MU, aspect_ratio=0.2)
    samples_per_cycle = 200
    base_x, base_q = synthetic_recording(**point, cycles=10, samples_per_cycle=samples_per_cycle)
    sizes = [10**3] if quick else [10**3, 3 * 10**3, 10**4]
    repeats = 2 if quick else 3
    rng = np.random.default_rng(0)
    print(f"resolve_loops, {samples_per_cycle} samples per cycle; {load_average()}")
    print(
        f"{'cycles':>7} {'samples':>9} {'resolve':>10} {'resolve':>10} {'after':>10} "
        f"{'NumPy':>10} {'time':>8} {'μ/μ-1':>8} {'μ/μ-1':>8}"
    )
    print(
        f"{'':>7} {'':>9} {'wall':>10} {'CPU':>10} {'analysis':>10} {'CPU':>10} "
        f"{'resolve/':>8} {'median':>8} {'NumPy':>8}"
    )
    print(
        f"{'':>7} {'':>9} {'[sample/s]':>10} {'[sample/s]':>10} {'CPU':>10} {'[sample/s]':>10} "
        f"{'NumPy':>8}"
    )
    for cycles in sizes:
        copies = cycles // 10
        size = base_x.size * copies
        displacement = np.tile(base_x, copies) + 0.25e-6 * rng.normal(size=size) + 3e-6
        force = np.tile(base_q, copies) + 4.0 * rng.normal(size=size) + 6.0
        label = np.repeat(np.arange(cycles), samples_per_cycle)
        analysis = analyze_loops(displacement, force, LOAD, label, keep_loops=True)
        calls = {
            "resolve": functools.partial(resolve_loops, displacement, force, LOAD, cycle=label),
            "after": functools.partial(resolve_analyzed_loops, analysis),
            "numpy": functools.partial(
                numpy_resolved, displacement, force, LOAD, 35e6, samples_per_cycle, 1.1e-6, 201
            ),
        }
        best = {name: (math.inf, math.inf) for name in calls}
        for _ in range(repeats):  # alternately, so that all see the same machine load
            for name, call in calls.items():
                wall, cpu = timed(call)
                best[name] = (min(best[name][0], wall), min(best[name][1], cpu))
        result = resolve_analyzed_loops(analysis)
        lean, _ = calls["numpy"]()
        error = float(np.nanmedian(np.abs(result.mu_resolved / MU - 1.0)))
        lean_error = float(np.nanmedian(np.abs(lean / MU - 1.0)))
        print(
            f"{cycles:7d} {size:9.2e} {size / best['resolve'][0]:10.3g} "
            f"{size / best['resolve'][1]:10.3g} {size / best['after'][1]:10.3g} "
            f"{size / best['numpy'][1]:10.3g} {best['resolve'][1] / best['numpy'][1]:8.1f} "
            f"{error:8.1e} {lean_error:8.1e}"
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
    first, _ = timed(lambda: correct_ecof(*arguments))  # compiles
    best = (math.inf, math.inf)
    for _ in range(repeats):
        best = min(best, timed(lambda: correct_ecof(*arguments)))
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
    import jax

    # The steady numbers and the jump fraction call the model's kernels directly, outside the
    # public entry points that switch JAX's 64-bit mode on: switch it on here.
    with jax.enable_x64(True):
        _profile_section(quick)


def _profile_section(quick: bool) -> None:
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

            # Concrete calls return NumPy arrays: computed, nothing left to wait for.
            def run(scar=scar, amplitude=amplitude, stiffness=stiffness):
                energy_cof(amplitude, LOAD, stiffness, MU, profile=scar)

            def closed(amplitude=amplitude, stiffness=stiffness):
                energy_cof(amplitude, LOAD, stiffness, MU, depth / width)

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

    *_, prepared = on_profile._points(scar, amplitude, LOAD, stiffness, MU, None, "scaled")
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
    "resolved": resolved,
    "profile": profile,
}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes, a few seconds")
    parser.add_argument("--only", nargs="+", choices=list(SECTIONS), help="run only these")
    parser.add_argument("--memory-child", type=int, help=argparse.SUPPRESS)
    parser.add_argument(
        "--scratch", type=Path, default=None,
        help="directory for the maps section's zarr stores (default: the system's temporary)",
    )  # fmt: skip
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)  # one_process's work
    args = parser.parse_args(argv)
    if args.memory_child:  # a fresh process of loops_peak_memory
        memory_child(args.memory_child)
        return 0
    if args.child:
        name, points, repeats = args.child
        _child(name, int(points), int(repeats))
        return 0
    for name in args.only or SECTIONS:
        print(f"== {name} ==")
        if name == "maps":
            maps(args.quick, args.scratch)
        else:
            SECTIONS[name](args.quick)
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
