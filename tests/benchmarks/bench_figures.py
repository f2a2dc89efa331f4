"""How long ``ecofmaps figures`` takes, as whole processes, cold and warm (pytest does not
collect this file).

    python tests/benchmarks/bench_figures.py                        # every figure, best of 3
    python tests/benchmarks/bench_figures.py --repeat 1 --only fig8 # a few seconds

Cold is a run from an empty cache (a fresh ``ECOFMAPS_CACHE``: no maps, no compiled JAX
kernels); warm is a run after one that filled that cache; kernels is a run whose numbers were
removed from the cache but whose JAX kernels were kept (what JAX's compilation cache alone
saves). Side by side, the floor: a process that imports the figures' style (matplotlib,
xarray) and draws one empty figure to PNG, the least any run pays. Each row gives the
minimum, median and maximum wall time of ``--repeat`` runs, and the least CPU time (user +
system, every process of the run), with the targets and the machine's load average: on a
shared machine it matters.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: Targets on a 2-core machine. [s]
TARGETS = {"cold": 8.0, "warm": 4.0}

FLOOR = (
    "import io, ecofmaps.figures.style\n"
    "from matplotlib.figure import Figure\n"
    "figure = Figure(layout='constrained')\n"
    "figure.add_subplot().set_title('empty')\n"
    "figure.savefig(io.BytesIO(), format='png', dpi=150)\n"
)


def timed_process(command, environment) -> tuple[float, float]:
    """Wall time and CPU time (user + system of the process and its children) of a run. [s]"""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, env=environment, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.PIPE, timeout=1800)  # fmt: skip
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return wall, cpu


def figures_command(out: Path, only, jobs) -> list[str]:
    command = [sys.executable, "-m", "ecofmaps.cli", "figures", "--out", str(out)]
    if only:
        command += ["--only", *only]
    if jobs:
        command += ["--jobs", str(jobs)]
    return command


def measured_runs(repeat: int, only, jobs, folder: Path) -> dict[str, list[tuple[float, float]]]:
    """``repeat`` cold and warm runs of the command, and of the floor."""
    runs = {"cold": [], "warm": [], "kernels": [], "floor": []}
    for index in range(repeat):
        cache = folder / f"cache-{index}"
        environment = {**os.environ, "ECOFMAPS_CACHE": str(cache)}
        # Each run writes into a folder of its own (the command refuses a non-empty one).
        run = {kind: figures_command(folder / f"out-{kind}-{index}", only, jobs) for kind in runs}
        runs["cold"].append(timed_process(run["cold"], environment))  # an empty cache
        runs["warm"].append(timed_process(run["warm"], environment))  # the cache it filled
        for path in cache.glob("*.nc"):  # the numbers go, JAX's compiled kernels stay
            path.unlink()
        runs["kernels"].append(timed_process(run["kernels"], environment))
        runs["floor"].append(timed_process([sys.executable, "-c", FLOOR], environment))
    return runs


def table(runs) -> str:
    """The runs side by side: wall time min / median / max, least CPU time, target."""
    lines = [f"{'run':<8}{'min':>8}{'median':>8}{'max':>8}{'cpu':>8}{'target':>8}   [s]"]
    for name, times in runs.items():
        walls = sorted(wall for wall, _ in times)
        target = TARGETS.get(name)
        lines.append(
            f"{name:<8}{walls[0]:8.2f}{statistics.median(walls):8.2f}{walls[-1]:8.2f}"
            f"{min(cpu for _, cpu in times):8.2f}" + (f"{target:8.1f}" if target else f"{'':>8}")
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each kind (default 3)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="only these figures")
    parser.add_argument("--jobs", type=int, default=None, help="passed to ecofmaps figures")
    args = parser.parse_args(argv)
    what = " ".join(args.only) if args.only else "every figure"
    print(f"== figures: ecofmaps figures ({what}), {args.repeat} run(s) each ==")
    print("load average {:.1f} {:.1f} {:.1f} on {} cores".format(*os.getloadavg(), os.cpu_count()))
    with tempfile.TemporaryDirectory(prefix="bench-figures-") as folder:
        runs = measured_runs(args.repeat, args.only, args.jobs, Path(folder))
    print(table(runs))
    print("load average {:.1f} {:.1f} {:.1f} after".format(*os.getloadavg()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
