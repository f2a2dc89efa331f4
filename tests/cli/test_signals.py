"""Ctrl-C and SIGTERM on real ``ecofmaps`` processes: exit 130 or 143, one line on standard
error and no traceback (not from dask's worker processes either), no temporary file left; only
the documented resume folder ``<out>.partial`` is kept."""

import os
import signal
import subprocess
import sys
import time

import pytest

from ecofmaps.io.files import TEMPORARY_NAME
from ecofmaps.measured.synthetic import write_long_recording

pytestmark = [
    pytest.mark.slow,  # signals to real processes
    pytest.mark.skipif(os.name != "posix", reason="POSIX signals and process groups"),
]


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A synthetic test of 1e6 samples (zarr): some seconds of analysis on two workers."""
    path = tmp_path_factory.mktemp("signals") / "test.zarr"
    return write_long_recording(path, cycles=5000, samples_per_cycle=200)


def started(command, cwd):
    """``command`` in a process group of its own, as a shell runs a job."""
    return subprocess.Popen(
        command, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True,
    )  # fmt: skip


def wait_for(path, process, timeout=240.0):
    """Wait until ``path`` exists (the run got that far), while ``process`` runs."""
    end = time.monotonic() + timeout
    while not path.exists():
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < end, f"{path} did not appear"
        time.sleep(0.05)


def leftovers(folder):
    """Temporary files anywhere under ``folder``."""
    return [p for p in folder.rglob("*") if TEMPORARY_NAME.match(p.name) or p.suffix == ".tmp"]


@pytest.mark.parametrize(
    ("sent", "status", "words"),
    [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated (SIGTERM)")],
)
def test_a_signal_to_the_whole_group_with_two_workers(tmp_path, recording, sent, status, words):
    """Ctrl-C on a terminal (and ``kill`` of a job) reaches the workers too: one line only."""
    out = tmp_path / "r.csv"
    command = [
        sys.executable, "-m", "ecofmaps.cli", "loops", str(recording), "--load", "450N",
        "--out", str(out), "--workers", "2", "--no-resolve",
    ]  # fmt: skip
    process = started(command, tmp_path)
    wait_for(tmp_path / "r.csv.partial" / "file0-cycles.npz", process)  # the workers run
    os.killpg(process.pid, sent)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == status, stderr
    assert stdout == "" and "Traceback" not in stderr
    assert stderr.count("\n") == 1 and stderr.startswith(f"ecofmaps: {words}; ")
    assert "run the same command with --resume to continue" in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv.partial"]
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize(("sent", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_during_an_analysis_in_memory_leaves_nothing(tmp_path, recording, sent, status):
    """No workers: the table's temporary file is removed, nothing else was written."""
    out = tmp_path / "r.csv"
    command = [sys.executable, "-m", "ecofmaps.cli", "loops", str(recording), "--load", "450N",
               "--out", str(out)]  # fmt: skip
    process = started(command, tmp_path)
    end = time.monotonic() + 240.0
    while not any(TEMPORARY_NAME.match(p.name) for p in tmp_path.iterdir()):  # the table begun
        assert process.poll() is None and time.monotonic() < end, process.communicate()
        time.sleep(0.05)
    time.sleep(0.5)
    os.killpg(process.pid, sent)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == status, stderr
    assert stdout == "" and "Traceback" not in stderr and stderr.count("\n") == 1
    assert stderr.endswith("; no output was left half written\n")
    assert list(tmp_path.iterdir()) == []


def test_sigterm_during_a_zarr_map_leaves_no_store(tmp_path):
    out = tmp_path / "big.zarr"
    command = [
        sys.executable, "-m", "ecofmaps.cli", "map", "--stiffness-ratio", "0.01/um:0.3/um:4000",
        "--aspect-ratio", "0:0.3:2500", "--amplitude", "25um,50um", "--mu", "0.8", "--load",
        "450N", "--chunk-points", "100000", "--out", str(out),
    ]  # fmt: skip
    process = started(command, tmp_path)
    first = process.stdout.readline()
    assert first.startswith("ecofmaps map: 20,000,000 points, "), first
    time.sleep(1.5)
    process.send_signal(signal.SIGTERM)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 143, stderr
    assert stderr == "ecofmaps: terminated (SIGTERM); no output was left half written\n"
    assert stdout == "" and list(tmp_path.iterdir()) == []  # the size line read above
