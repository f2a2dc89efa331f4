"""The map cache against computing: write, read and compute side by side, run as a script.

    python tests/benchmarks/bench_cache.py              # 1e7 points closed form, 1e6 on profiles
    python tests/benchmarks/bench_cache.py --quick      # small sizes, a few seconds
    python tests/benchmarks/bench_cache.py --folder DIR # the cache on another disk

For each map: computing it warm (``cache=False``, after compilation), storing it in the cache
(``cached_dataset`` on a miss, given the computed map: the file image with its chunks'
checksums, written and renamed) and reading it back (``cached_dataset`` on a hit: opened,
checked, loaded), best of ``--repeat`` runs each, and the ratios of writing and reading to
computing. A closed-form map is cached by default only if writing costs at most 1.2 and
reading at most 0.3 times computing it (docs/performance.md, "The cache").
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository

from ecofmaps import compute_map, flat_bottomed_profile, w_shaped_profile
from ecofmaps.maps import cache

LOAD = 450.0  # [N]

#: Ratios to computing a closed-form map at or under which caching it by default pays.
WRITE_LIMIT, READ_LIMIT = 1.2, 0.3


def best(function, repeat: int) -> float:
    """Least wall time of ``repeat`` calls of ``function()``. [s]"""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def closed_form_grid(points: int) -> dict:
    """1000 x 1000 x 5 amplitudes x 2 μ at 1e7 points; fewer values of S/P and z_o/x_o below."""
    side = round(math.sqrt(points / 10))
    return dict(
        stiffness_ratio=np.geomspace(1e4, 3e5, side),  # [1/m]
        aspect_ratio=np.linspace(0.0, 0.4, side),
        amplitude=np.linspace(10e-6, 60e-6, 5),  # [m]
        mu=np.array([0.5, 0.8]),
        load=LOAD,
    )


def profile_grid(points: int, scar) -> dict:
    """S/P x 5 amplitudes at one μ on ``scar``."""
    return dict(
        stiffness_ratio=np.geomspace(1e4, 3e5, max(points // 5, 1)),
        amplitude=np.linspace(40e-6, 60e-6, 5),
        mu=0.8,
        load=LOAD,
        profile=scar,
    )


def measured(name: str, grid: dict, folder: Path, repeat: int) -> tuple:
    """Compute, write and read times of the map of ``grid`` [s], and its file size [byte]."""
    computed = compute_map(**grid, cache=False)  # compiles
    compute = best(lambda: compute_map(**grid, cache=False), repeat)
    inputs = {"grid": np.arange(3.0), "name": float(len(name))}

    def write():
        cache.clear_cache(folder)
        cache.cached_dataset(name, inputs, lambda: computed, folder)

    def read():
        cache.cached_dataset(name, inputs, _never_computed, folder)

    write_time = best(write, repeat)
    read_time = best(read, repeat)
    (entry,) = cache.cache_entries(folder)
    cache.clear_cache(folder)
    return compute, write_time, read_time, entry.size


def _never_computed():
    raise AssertionError("the benchmark's read missed the cache")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes, a few seconds")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each (default 3)")
    parser.add_argument(
        "--folder", type=Path, default=None, help="cache folder (default: a temporary one)"
    )
    args = parser.parse_args(argv)
    depth, width = 20e-6, 100e-6
    maps = {
        "closed form": closed_form_grid(10**5 if args.quick else 10**7),
        "flat-bottomed": profile_grid(
            10**3 if args.quick else 10**6, flat_bottomed_profile(depth, width, 0.4, samples=1000)
        ),
        "W-shaped": profile_grid(
            10**3 if args.quick else 10**5, w_shaped_profile(depth, width, 0.3, samples=1000)
        ),
    }
    print(f"== cache: write and read against computing, best of {args.repeat} ==")
    print("load average {:.1f} {:.1f} {:.1f} on {} cores".format(*os.getloadavg(), os.cpu_count()))
    print(
        f"{'map':>14} {'points':>9} {'file':>9} {'compute':>8} {'write':>8} {'read':>8} "
        f"{'write/compute':>14} {'read/compute':>13}"
    )
    print(f"{'':>14} {'':>9} {'[MB]':>9} {'[s]':>8} {'[s]':>8} {'[s]':>8}")
    with tempfile.TemporaryDirectory(prefix="bench-cache-", dir=args.folder) as folder:
        for name, grid in maps.items():
            points = math.prod(np.size(v) for k, v in grid.items() if k not in ("load", "profile"))
            compute, write, read, size = measured(
                name.replace(" ", "_").replace("-", "_"), grid, Path(folder), args.repeat
            )
            print(
                f"{name:>14} {points:9.2e} {size / 1e6:9.3g} {compute:8.3f} {write:8.3f} "
                f"{read:8.3f} {write / compute:14.2f} {read / compute:13.2f}"
            )
    print(
        f"caching a closed-form map pays if write/compute <= {WRITE_LIMIT} and read/compute "
        f"<= {READ_LIMIT}"
    )
    print("load average {:.1f} {:.1f} {:.1f} after".format(*os.getloadavg()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
