"""The benchmark script runs (``--quick``), so it cannot rot; it measures nothing here."""

import importlib.util
import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # the benchmark scripts' smoke runs

BENCH = Path(__file__).parent / "benchmarks" / "bench_maps.py"


def load_bench():
    spec = importlib.util.spec_from_file_location("bench_maps", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_quick_run_prints_every_section(capsys):
    """Every section runs; the maps section's NumPy and SciPy agree with compute_map."""
    bench = load_bench()
    assert bench.main(["--quick"]) == 0
    out = capsys.readouterr().out
    for name in bench.SECTIONS:
        assert f"== {name} ==" in out
    maps = out.split("== maps ==")[1].split("\n== ")[0]
    rows = [line.split() for line in maps.splitlines() if re.match(r"\s*\d\.\d+e\+0\d\s", line)]
    assert len(rows) == 2  # 1e4 and 1e5 points in quick mode
    for row in rows:
        assert float(row[-1]) < 1e-12  # max relative difference, NumPy vs JAX
        assert float(row[3]) > 0 and float(row[4]) > 0  # points per second
    scipy = re.search(r"SciPy per point .* max rel diff (\S+)", maps)
    assert scipy and float(scipy.group(1)) < 1e-10  # brentq + quad vs JAX


def test_resolved_section(capsys):
    """The 'resolved' section: resolve_loops and the lean NumPy both read μ = 0.8 (0.5 %)."""
    bench = load_bench()
    assert bench.main(["--only", "resolved", "--quick"]) == 0
    out = capsys.readouterr().out
    rows = [
        line.split() for line in out.splitlines() if re.match(r"\s*\d+\s+\d\.\d+e\+0\d\s", line)
    ]
    assert len(rows) == 1  # 1e3 cycles in quick mode
    for row in rows:
        assert all(float(value) > 0 for value in row[2:6])  # samples per second
        assert float(row[-2]) < 0.005 and float(row[-1]) < 0.005  # median |μ/0.8 - 1|


def test_long_loops_bench_runs(tmp_path, capsys):
    """``bench_long_loops.py`` on a short test: every run and the ceiling print a time."""
    path = Path(__file__).parent / "benchmarks" / "bench_long_loops.py"
    spec = importlib.util.spec_from_file_location("bench_long_loops", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    arguments = ["--samples", "1e5", "--repeat", "1", "--formats", "zarr", "--no-resolve"]
    assert bench.main([*arguments, "--folder", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    for name in ("memory", "threads", "workers 1", "workers 2"):
        found = re.search(rf"  {name}\s+(\S+) s\s+(\S+) samples/s\s+peak\s+(\S+) GB", out)
        assert found and all(float(value) > 0 for value in found.groups()), name
    ceiling = re.search(r"one process (\S+) s, two (\S+) s: (\S+)x", out)
    assert ceiling and all(float(value) > 0 for value in ceiling.groups())


def test_cache_bench_runs(tmp_path, capsys):
    """``bench_cache.py --quick``: each map's compute, write and read times and their ratios."""
    path = Path(__file__).parent / "benchmarks" / "bench_cache.py"
    spec = importlib.util.spec_from_file_location("bench_cache", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.main(["--quick", "--repeat", "1", "--folder", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    for name in ("closed form", "flat-bottomed", "W-shaped"):
        found = re.search(rf"{name}\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)", out)
        assert found and all(float(value) > 0 for value in found.groups()), name
    assert list(tmp_path.iterdir()) == []  # its cache folder removed
