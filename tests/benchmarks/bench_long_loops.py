"""``ecofmaps loops`` on a long test: peak memory and samples/s, out of core against in memory.

    python tests/benchmarks/bench_long_loops.py                   # 2e8 samples
    python tests/benchmarks/bench_long_loops.py --samples 2e7     # a moderate size
    python tests/benchmarks/bench_long_loops.py --folder DIR      # keep (and reuse) the files
    python tests/benchmarks/bench_long_loops.py --no-resolve      # the analysis only

A long synthetic test (:func:`ecofmaps.measured.synthetic.write_long_recording`: the
example's rig, a deepening groove, noise, offsets and drift; 200 samples a cycle) is written
once as zarr and converted to TDMS. Each run is a fresh process whose wall time and peak
resident memory (the sum over it and its children, sampled every 50 ms, so the worker
processes of a local cluster count) are reported; each is repeated ``--repeat`` times and
the best time kept. The runs:

- ``memory``: the in-memory path, the baseline: ``ecofmaps loops`` with the whole
  recording read into NumPy and analysed as one chunk of the pipeline, one thread; the time of
  the analysis alone is printed beside the time of the whole command;
- ``threads``: ``ecofmaps loops FILE --load 450N --out r.csv --quiet``, the default for a
  file this long: out of core on the threads of the process (one per core);
- ``workers 1``, ``workers 2``: the same with ``--workers 1`` and ``--workers 2`` (a local
  dask cluster of that many single-threaded processes).

Targets: peak memory under 2 GB out of core; samples/s of ``workers 1`` within
20 % of ``memory`` (per core); ``workers 2`` at least 1.6x ``workers 1``. The machine's load
is printed before and after: numbers taken while other programs run are noisy. The runs
take turns (each round runs every one once), so a machine that slows down for a while
slows them all alike; the best round of each is kept.

The machine's own ceiling for two processes is measured beside them (``ceiling``): the
measuring tasks of the same analysis (most of its time; :mod:`ecofmaps.measured.pipeline`,
the cycles found first, not timed) in one plain process, then split between two forked
processes, without dask. On a machine whose two cores share a memory bus (or are two
threads of one core) two processes do not run twice as fast, and no scheduler can do better.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository

SAMPLES_PER_CYCLE = 200
CHUNK = 1 << 20
LOAD = "450N"
_MEMORY_SCRIPT = """
import sys, time
import ecofmaps.io.binary, ecofmaps.cli.loops_long as analysis
from ecofmaps.cli import main
ecofmaps.io.binary.LAZY_SAMPLES = 1 << 62  # read whole, analyse in memory
spent = []
inner = analysis._analyse  # the pipeline on one recording (one chunk in memory)
def timed(*args, **kwargs):
    start = time.perf_counter()
    try:
        return inner(*args, **kwargs)
    finally:
        spent.append(time.perf_counter() - start)
analysis._analyse = timed
status = main(["loops", *sys.argv[1:]])
print("analysed", spent[0], file=sys.stderr)
sys.exit(status)
"""

_CEILING_SCRIPT = """
import functools, multiprocessing, sys, time
from ecofmaps._parallel import Runner, _call
from ecofmaps.io import read_recording
from ecofmaps.io.tables import results_csv
from ecofmaps.measured.pipeline import Analysis, LoopOptions, Reading, measure_chunk

def measure(tasks):
    start = time.perf_counter()
    for index in tasks:
        _call(measure_chunk, ANALYSIS._task(index, LINES, False))
    return time.perf_counter() - start

if __name__ == "__main__":
    recording = read_recording(sys.argv[1], lazy=True)
    options = LoopOptions(float(sys.argv[2]))
    with Runner() as runner:
        ANALYSIS = Analysis(recording.displacement, recording.force, recording.cycle,
                            options=options, runner=runner,
                            reading=Reading(resolve=sys.argv[3] == "resolve"))
    LINES = functools.partial(results_csv, header=False)
    tasks = range(len(ANALYSIS.tasks))
    fork = multiprocessing.get_context("fork")
    with fork.Pool(1) as pool:
        one = pool.map(measure, [list(tasks)])[0]
    with fork.Pool(2) as pool:
        two = max(pool.map(measure, [list(tasks[0::2]), list(tasks[1::2])]))
    print(one, two)
"""


def load_average() -> str:
    return "load average {:.2f} {:.2f} {:.2f} on {} cores".format(*os.getloadavg(), os.cpu_count())


def measured(command: list[str]) -> tuple[float, float, str]:
    """Run ``command``; its wall time [s], peak memory of it and its children [GB], stdout."""
    import psutil

    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    watched = psutil.Process(process.pid)
    peak = 0
    while process.poll() is None:
        try:
            tree = [watched, *watched.children(recursive=True)]
            peak = max(peak, sum(p.memory_info().rss for p in tree if p.is_running()))
        except psutil.Error:
            pass
        time.sleep(0.05)
    wall = time.perf_counter() - start
    out, err = process.communicate()
    if process.returncode:
        raise RuntimeError(f"{' '.join(command)} failed:\n{err}")
    return wall, peak / 1e9, out + err


def make_files(folder: Path, samples: int) -> dict:
    from ecofmaps.io import convert_recording
    from ecofmaps.measured.synthetic import write_long_recording

    cycles = samples // SAMPLES_PER_CYCLE
    paths = {"zarr": folder / f"long{samples}.zarr", "tdms": folder / f"long{samples}.tdms"}
    if not paths["zarr"].exists():
        start = time.perf_counter()
        write_long_recording(paths["zarr"], cycles, SAMPLES_PER_CYCLE, chunk_samples=CHUNK)
        print(f"  wrote {paths['zarr']} in {time.perf_counter() - start:.0f} s")
    if not paths["tdms"].exists():
        start = time.perf_counter()
        convert_recording(paths["zarr"], paths["tdms"], chunk_samples=CHUNK)
        print(f"  converted it to {paths['tdms']} in {time.perf_counter() - start:.0f} s")
    return paths


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=float, default=2e8)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--folder", type=Path, default=None)
    parser.add_argument("--formats", default="zarr,tdms")
    parser.add_argument(
        "--no-resolve", action="store_true",
        help="pass --no-resolve to every run (the analysis without the reading along the stroke)",
    )  # fmt: skip
    args = parser.parse_args(argv)
    extra = ["--no-resolve"] if args.no_resolve else []
    samples = int(args.samples) // SAMPLES_PER_CYCLE * SAMPLES_PER_CYCLE
    folder = args.folder or Path(tempfile.mkdtemp(prefix="ecofmaps-bench-"))
    folder.mkdir(parents=True, exist_ok=True)
    print(
        f"ecofmaps loops {' '.join(extra)} on a long test of {samples:.3g} samples; "
        f"{load_average()}"
    )
    paths = make_files(folder, samples)
    ecofmaps = [sys.executable, "-m", "ecofmaps.cli"]
    for kind in args.formats.split(","):
        path = paths[kind]
        print(f"\n{kind}: {path}")
        runs = {
            "memory": [sys.executable, "-c", _MEMORY_SCRIPT, str(path), "--load", LOAD],
            "threads": [*ecofmaps, "loops", str(path), "--load", LOAD, "--quiet"],
            "workers 1": [*ecofmaps, "loops", str(path), "--load", LOAD, "--quiet",
                          "--workers", "1"],
            "workers 2": [*ecofmaps, "loops", str(path), "--load", LOAD, "--quiet",
                          "--workers", "2"],
        }  # fmt: skip
        ceiling = [sys.executable, "-c", _CEILING_SCRIPT, str(path), LOAD[:-1],
                   "no-resolve" if args.no_resolve else "resolve"]  # fmt: skip
        best, alone = {}, []
        out = folder / "r.csv"
        for _ in range(args.repeat):  # rounds: each run once per round
            for name, command in runs.items():
                out.unlink(missing_ok=True)
                wall, peak, printed = measured([*command, *extra, "--out", str(out)])
                if name not in best or wall < best[name][0]:
                    best[name] = (wall, peak, printed)
            alone.append([float(t) for t in measured(ceiling)[2].split()[:2]])
        for name, (wall, peak, printed) in best.items():
            line = (
                f"  {name:<10} {wall:7.1f} s  {samples / wall:9.3g} samples/s  peak {peak:5.2f} GB"
            )
            if name == "memory":
                analysing = float(printed.split()[-1])
                line += f"  (analysis {analysing:.1f} s: {samples / analysing:.3g} samples/s)"
            print(line, flush=True)
        memory, one, two = best["memory"][0], best["workers 1"][0], best["workers 2"][0]
        single, double = min(t[0] for t in alone), min(t[1] for t in alone)
        print(
            f"  workers 1 / memory: {memory / one:.2f} of the speed; "
            f"workers 2 / workers 1: {one / two:.2f}x; threads / workers 1: "
            f"{one / best['threads'][0]:.2f}x\n"
            f"  ceiling: the measuring tasks alone, no dask: one process {single:.1f} s, two "
            f"{double:.1f} s: {single / double:.2f}x"
        )
    print(f"\n{load_average()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
