"""The recordings benchmark's steps run (in this process, on a tiny test), so the script
cannot rot; every way of reading gives the sums the format's own library gives."""

import importlib.util
import json
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # the benchmark script's smoke run

BENCH = Path(__file__).parents[1] / "benchmarks" / "bench_recordings.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_recordings", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_way_reads_the_same(tmp_path, capsys, bench):
    paths = bench.make_files(tmp_path, 4000, csv_share=0.5)
    assert set(paths) == {"zarr", "tdms", "h5", "raw", "csv"}
    capsys.readouterr()
    for kind, (path, size) in paths.items():
        results = {}
        for mode in ["raw"] if kind == "raw" else ["library", "whole", "blocks", "dask"]:
            if mode == "dask" and kind == "csv":
                continue
            bench.child(mode, str(path), kind)
            results[mode] = json.loads(capsys.readouterr().out)
        baseline = results.pop("raw", None) or results.pop("library")
        assert size == (4000 if kind != "csv" else 2000)
        for mode, result in results.items():
            assert result["samples"] == size, (kind, mode)
            assert result["sum"] == pytest.approx(baseline["sum"], rel=1e-12), (kind, mode)
            assert result["wall"] > 0 and result["peak_mb"] > 0
