"""Ctrl-C and SIGTERM with ``--workers 2`` at the awkward moments: while
the cluster starts, and after dask restarted a worker killed with SIGKILL (the new worker
still importing). Exit 130 or 143, exactly one line on standard error (no traceback from the
workers, no "Task exception was never retrieved"), no temporary file, no process of the
command left, and the resume folder ``<out>.partial`` only when the line says so. (A signal
to the whole group in the middle of the run is in ``test_signals.py``.)"""

import os
import signal
import subprocess
import sys
import time

import psutil
import pytest

from ecofmaps.io.files import TEMPORARY_NAME
from ecofmaps.measured.synthetic import write_long_recording

pytestmark = [
    pytest.mark.slow,  # signals to real worker processes
    pytest.mark.skipif(os.name != "posix", reason="POSIX signals and process groups"),
]

WORDS = {signal.SIGINT: (130, "interrupted"), signal.SIGTERM: (143, "terminated (SIGTERM)")}


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A synthetic test of 6e5 samples (zarr): a few seconds of analysis on two workers."""
    path = tmp_path_factory.mktemp("interrupts") / "test.zarr"
    return write_long_recording(path, cycles=3000, samples_per_cycle=200)


def started(recording, folder):
    """``ecofmaps loops --workers 2`` in a process group of its own, as a shell runs a job."""
    command = [
        sys.executable, "-m", "ecofmaps.cli", "loops", str(recording), "--load", "450N",
        "--out", str(folder / "r.csv"), "--workers", "2", "--no-resolve",
    ]  # fmt: skip
    return subprocess.Popen(
        command, cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True,
    )  # fmt: skip


def workers(process) -> set:
    """The pids of the command's worker processes (started by multiprocessing's spawn)."""
    try:
        children = psutil.Process(process.pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return set()
    found = set()
    for child in children:
        try:
            if "multiprocessing.spawn" in " ".join(child.cmdline()):
                found.add(child.pid)
        except psutil.NoSuchProcess:
            continue
    return found


def until(condition, process, what, timeout=120.0):
    """Wait until ``condition()`` holds while ``process`` runs."""
    end = time.monotonic() + timeout
    while not condition():
        assert process.poll() is None, (what, process.communicate())
        assert time.monotonic() < end, f"{what}: not within {timeout} s"
        time.sleep(0.02)


def send(process, sent):
    """Ctrl-C reaches the whole group (a terminal sends it so); SIGTERM only the command, as
    ``kill PID`` sends it."""
    if sent == signal.SIGINT:
        os.killpg(process.pid, sent)
    else:
        process.send_signal(sent)


def assert_stopped_cleanly(process, sent, folder):
    status, words = WORDS[sent]
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == status, stderr
    assert stdout == "" and stderr.count("\n") == 1, stderr
    assert stderr.startswith(f"ecofmaps: {words}; "), stderr
    assert "Traceback" not in stderr and "Task exception" not in stderr
    left = [p for p in folder.rglob("*") if TEMPORARY_NAME.match(p.name) or p.suffix == ".tmp"]
    assert left == []
    if "run the same command with --resume to continue" in stderr:
        assert sorted(p.name for p in folder.iterdir()) == ["r.csv.partial"]
    else:
        assert stderr.endswith("; no output was left half written\n")
        assert list(folder.iterdir()) == []
    end = time.monotonic() + 20.0  # the workers end with the command
    while True:
        try:
            os.killpg(process.pid, 0)
        except ProcessLookupError:
            break
        assert time.monotonic() < end, "processes of the command are left running"
        time.sleep(0.1)


@pytest.mark.parametrize("sent", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_cluster_starts(tmp_path, recording, sent):
    """The signal comes as the worker processes are being started (Ctrl-C was ignored then,
    and lost: the run went on to the end)."""
    process = started(recording, tmp_path)
    until(lambda: workers(process), process, "worker processes")
    send(process, sent)
    assert_stopped_cleanly(process, sent, tmp_path)


@pytest.mark.parametrize("sent", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_after_a_worker_was_killed_and_restarted(tmp_path, recording, sent):
    """A worker killed with SIGKILL while the blocks are measured: dask starts another,
    and the signal comes while it starts (a worker started then did not ignore Ctrl-C, and
    printed a traceback from its imports)."""
    process = started(recording, tmp_path)
    cycles = tmp_path / "r.csv.partial" / "file0-cycles.npz"
    until(cycles.exists, process, "the cycles found")  # the workers run
    before = workers(process)
    os.kill(max(before), signal.SIGKILL)
    until(lambda: workers(process) - before, process, "a new worker")
    send(process, sent)
    assert_stopped_cleanly(process, sent, tmp_path)
