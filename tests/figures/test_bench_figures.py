"""The figures' benchmark script runs (one short run of each kind), so it cannot rot; it
measures nothing here."""

import importlib.util
import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # the benchmark script's smoke run

BENCH = Path(__file__).parents[1] / "benchmarks" / "bench_figures.py"


def test_short_run_prints_cold_warm_and_floor(capsys):
    spec = importlib.util.spec_from_file_location("bench_figures", BENCH)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.main(["--repeat", "1", "--only", "fig8", "--jobs", "1"]) == 0
    out = capsys.readouterr().out
    assert "== figures: ecofmaps figures (fig8), 1 run(s) each ==" in out
    for name, target in (("cold", "8.0"), ("warm", "4.0"), ("kernels", ""), ("floor", "")):
        row = re.search(rf"^{name}\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s*(\S*)$", out, re.MULTILINE)
        assert row, name
        assert all(float(value) > 0 for value in row.groups()[:4]), row.group(0)
        assert row.group(5) == target
