"""Running ``ecofmaps`` commands for the command-line tests: in-process, or as a process
interrupted with Ctrl-C."""

import signal
import subprocess
import time

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
