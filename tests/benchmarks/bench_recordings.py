"""Reading recordings: throughput and peak memory of each format, run as a script.

    python tests/benchmarks/bench_recordings.py                  # 2e8 samples (16 s of
                                                                 # simulation per 5e7)
    python tests/benchmarks/bench_recordings.py --samples 2e7    # a moderate size
    python tests/benchmarks/bench_recordings.py --quick          # a few seconds

A long synthetic test (:func:`ecofmaps.measured.synthetic.write_long_recording`: the
example's rig, a deepening groove, noise and drift) is written once as zarr and converted
(:func:`ecofmaps.io.convert_recording`, block by block) to TDMS, HDF5 and CSV (the CSV at a
tenth of the size: text is slow to write). Each format is then read in a fresh process,
which reports its wall time and its peak resident memory (VmHWM), in four ways (each run
``--repeat`` times, in turn, the best time kept: the first read of a file may come from the
disk, the others from the page cache, where it fits):

- ``library``: the format's own library reads both columns whole (h5py, zarr, npTDMS,
  pandas for CSV): the leanest honest baseline for that format;
- ``whole``: ``read_recording(path, lazy=False)``, the in-memory path;
- ``blocks``: ``recording_blocks(path, samples=2**22)``, each block summed, the way an
  out-of-core analysis goes through a file: memory bounded by a few blocks;
- ``dask``: ``read_recording(path, lazy=True)`` and a dask sum of both columns on the
  threaded scheduler.

``raw`` reads the same samples from a flat float64 file with ``numpy.fromfile``: the floor
of the page cache and memory copies.
The memory of a process that has imported ecofmaps and its readers and read nothing
(``idle``) is printed too.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository

SAMPLES_PER_CYCLE = 200
BLOCK = 1 << 22
LIBRARIES = ("raw", "library", "whole", "blocks", "dask")


def load_average() -> str:
    return "load average {:.1f} {:.1f} {:.1f} on {} cores".format(*os.getloadavg(), os.cpu_count())


def _peak_mb() -> float:
    """Peak resident memory of this process [MB]: VmHWM, which starts afresh at exec
    (ru_maxrss does not: a child would report its parent's peak)."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _library_read(path: Path, kind: str):
    """Both columns read whole by the format's own library."""
    import numpy as np

    if kind == "raw":
        data = np.fromfile(path, dtype=np.float64)
        return data[0::2].sum() + data[1::2].sum()
    if kind == "h5":
        import h5py

        with h5py.File(path, "r") as handle:
            return handle["displacement"][:].sum() + handle["force"][:].sum()
    if kind == "zarr":
        import zarr

        group = zarr.open_group(str(path), mode="r")
        return group["displacement"][:].sum() + group["force"][:].sum()
    if kind == "tdms":
        from nptdms import TdmsFile

        with TdmsFile.open(path) as handle:
            group = handle["recording"]
            return group["displacement"][:].sum() + group["force"][:].sum()
    import pandas as pd

    frame = pd.read_csv(path, comment="#", usecols=[0, 1])
    return frame.iloc[:, 0].to_numpy().sum() + frame.iloc[:, 1].to_numpy().sum()


def child(mode: str, path: str, kind: str) -> None:
    """Run one measurement in this (fresh) process and print it as JSON."""
    import dask.array
    import h5py  # noqa: F401
    import nptdms  # noqa: F401
    import zarr  # noqa: F401

    import ecofmaps.io.binary  # noqa: F401
    from ecofmaps.io import read_recording, recording_blocks

    start = time.perf_counter()
    samples = 0
    if mode in ("raw", "library"):
        total = _library_read(Path(path), kind)
        samples = -1
    elif mode == "whole":
        recording = read_recording(path, lazy=False)
        total = recording.displacement.sum() + recording.force.sum()
        samples = recording.size
    elif mode == "blocks":
        total = 0.0
        for block in recording_blocks(path, samples=BLOCK):
            total += block.displacement.sum() + block.force.sum()
            samples += block.size
    elif mode == "dask":
        import dask

        recording = read_recording(path, lazy=True, chunks=BLOCK)
        (d, f) = dask.compute(recording.displacement.sum(), recording.force.sum())
        total = d + f
        samples = recording.size
    else:
        total = 0.0
    wall = time.perf_counter() - start
    result = {"wall": wall, "peak_mb": _peak_mb(), "samples": samples, "sum": float(total)}
    print(json.dumps(result))


def measure(mode: str, path: Path, kind: str, repeat: int = 1) -> dict:
    """Fresh processes, ``repeat`` of them: the best wall time, the largest peak memory."""
    results = []
    for _ in range(repeat):
        output = subprocess.run(
            [sys.executable, __file__, "--child", mode, str(path), kind],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
        results.append(json.loads(output.strip().splitlines()[-1]))
    best = min(results, key=lambda result: result["wall"])
    return {**best, "peak_mb": max(result["peak_mb"] for result in results)}


def make_files(folder: Path, samples: int, csv_share: float) -> dict:
    """The long test as zarr, then converted to the other formats: kind -> (path, samples)."""
    import numpy as np

    from ecofmaps.io import convert_recording, recording_blocks
    from ecofmaps.measured.synthetic import write_long_recording

    cycles = max(samples // SAMPLES_PER_CYCLE, 1)
    samples = cycles * SAMPLES_PER_CYCLE
    paths = {"zarr": (folder / "long.zarr", samples)}
    start = time.perf_counter()
    write_long_recording(paths["zarr"][0], cycles, SAMPLES_PER_CYCLE, chunk_samples=BLOCK)
    print(
        f"  generated {cycles * SAMPLES_PER_CYCLE:.3g} samples as zarr in "
        f"{time.perf_counter() - start:.1f} s (simulation included)"
    )
    for kind, suffix in (("tdms", ".tdms"), ("h5", ".h5")):
        paths[kind] = (folder / f"long{suffix}", samples)
        start = time.perf_counter()
        convert_recording(paths["zarr"][0], paths[kind][0], chunk_samples=BLOCK)
        wall = time.perf_counter() - start
        print(
            f"  converted zarr -> {kind} in {wall:.1f} s "
            f"({cycles * SAMPLES_PER_CYCLE / wall:.3g} samples/s)"
        )
    paths["raw"] = (folder / "long.f8", samples)
    with open(paths["raw"][0], "wb") as stream:
        for block in recording_blocks(paths["zarr"][0], samples=BLOCK):
            np.column_stack([block.displacement, block.force]).tofile(stream)
    if csv_share > 0:
        csv_cycles = max(int(cycles * csv_share), 1)
        paths["csv"] = (folder / "long.csv", csv_cycles * SAMPLES_PER_CYCLE)
        start = time.perf_counter()
        write_long_recording(paths["csv"][0], csv_cycles, SAMPLES_PER_CYCLE, chunk_samples=BLOCK)
        print(
            f"  wrote {csv_cycles * SAMPLES_PER_CYCLE:.3g} samples as CSV in "
            f"{time.perf_counter() - start:.1f} s"
        )
    return paths


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=float, default=2e8, help="samples in the test")
    parser.add_argument("--quick", action="store_true", help="2e5 samples, a few seconds")
    parser.add_argument("--csv-share", type=float, default=0.1, help="CSV size / samples")
    parser.add_argument("--dir", default=None, help="where to write (default: a temporary)")
    parser.add_argument("--repeat", type=int, default=2, help="runs of each, best time kept")
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(*args.child)
        return 0
    samples = int(2e5 if args.quick else args.samples)
    folder = Path(tempfile.mkdtemp(prefix="bench_recordings_", dir=args.dir))
    print(f"== recordings == {samples:.3g} samples, {load_average()}")
    try:
        paths = make_files(folder, samples, args.csv_share)
        idle = measure("idle", paths["zarr"][0], "zarr")
        print(f"  idle process (ecofmaps and readers imported): {idle['peak_mb']:.0f} MB")
        print(
            f"  {'format':7s} {'way':8s} {'samples':>9s} {'s':>7s} {'samples/s':>10s} "
            f"{'vs library':>10s} {'peak MB':>8s} {'over idle':>9s}  same sum"
        )
        for kind, (path, size) in paths.items():
            modes = ["raw"] if kind == "raw" else ["library", "whole", "blocks"]
            if kind in ("zarr", "tdms", "h5"):
                modes.append("dask")
            for mode in modes:
                result = measure(mode, path, kind, args.repeat)
                if mode in ("library", "raw"):
                    library = result
                same = abs(result["sum"] - library["sum"]) <= 1e-9 * abs(library["sum"])
                print(
                    f"  {kind:7s} {mode:8s} {size:9.3g} {result['wall']:7.2f} "
                    f"{size / result['wall']:10.3g} {library['wall'] / result['wall']:10.2f} "
                    f"{result['peak_mb']:8.0f} {result['peak_mb'] - idle['peak_mb']:9.0f}  "
                    f"{'yes' if same else 'NO'}"
                )
        print(f"  input as float64 pairs: {16 * samples / 2**20:.0f} MB; {load_average()}")
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
