"""Running ``ecofmaps`` commands for the command-line tests: in-process, or as a process
interrupted with Ctrl-C."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import ecofmaps
from ecofmaps import cli


def run(capsys, *argv):
    """Run the command in-process; return (exit status, stdout, stderr)."""
    try:
        status = cli.main([str(a) for a in argv])
    except SystemExit as stop:  # argparse errors and --help
        status = stop.code
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def run_loops(capsys, *arguments):
    """``ecofmaps loops ARGS``: exit status, stdout, stderr."""
    status = cli.main(["loops", *map(str, arguments)])
    out, err = capsys.readouterr()
    return status, out, err


def interrupted_run(command, wait_for: str, delay: float, env=None):
    """Run ``command``, press Ctrl-C ``delay`` s after it printed ``wait_for`` (on standard
    output for ``ecofmaps map``, else on standard error)."""
    process = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    started = (process.stdout if "map" in command else process.stderr).readline()
    assert wait_for in started, started
    time.sleep(delay)
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=300)
    return process.returncode, stdout, stderr


def on_a_full_disk(folder, *argv):
    """``ecofmaps ARGV`` as a process, ``folder`` a 64 kB tmpfs with 20 kB free, mounted in a
    user namespace (no privilege needed; skipped where it is not allowed): exit status,
    stderr, and the names left in ``folder``."""
    folder.mkdir()
    mount = 'mount -t tmpfs -o size=64k tmpfs "$0" && head -c 45056 /dev/zero > "$0/filler"'
    probe = subprocess.run(["unshare", "-rm", "sh", "-c", mount, folder], capture_output=True)
    if probe.returncode != 0:
        pytest.skip("cannot mount a tmpfs in a user namespace here")
    script = f'{mount} || exit 99; "$@"; status=$?; ls -A "$0"; exit $status'
    ecofmaps_ = [sys.executable, "-m", "ecofmaps.cli", *map(str, argv)]
    env = {**os.environ, "PYTHONPATH": str(Path(ecofmaps.__file__).parents[1])}
    done = subprocess.run(
        ["unshare", "-rm", "sh", "-c", script, folder, *ecofmaps_],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    return done.returncode, done.stderr, done.stdout.split()
