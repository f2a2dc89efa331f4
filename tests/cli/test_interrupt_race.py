"""Ctrl-C and SIGTERM at each point of the end of a long ``ecofmaps loops`` run, made
deterministic: the signal is raised in this process at a chosen point.

The line must tell the truth as it is when written: a ``.partial`` folder kept is named with
the ``--resume`` hint, also when the stop came as an error the signal caused (a worker
stopped by it) or after the last block, before the table was renamed; when the line says
nothing was left, nothing is; a signal once the table is written changes nothing (exit 0).
"""

import argparse
import importlib
import os
import signal
import subprocess
import sys

import pytest

from ecofmaps._interrupts import INTERRUPTED, Interrupted, add_stop_note
from ecofmaps.cli import loops, loops_long
from ecofmaps.io.files import MANIFEST
from ecofmaps.measured.synthetic import write_long_recording
from tests.cli.commands import run_loops as run

#: The module of the command (``ecofmaps.cli.main`` is also the name of its function).
command = importlib.import_module("ecofmaps.cli.main")

pytestmark = pytest.mark.skipif(os.name != "posix", reason="POSIX signals")

SIGNALS = [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated (SIGTERM)")]


@pytest.fixture(scope="module")
def long_test(tmp_path_factory):
    """A long synthetic test of 60 cycles (zarr)."""
    folder = tmp_path_factory.mktemp("race")
    return write_long_recording(folder / "test.zarr", cycles=60, samples_per_cycle=100)


@pytest.fixture(scope="module")
def expected(long_test, tmp_path_factory):
    """The table of the test analysed in memory, without a signal."""
    out = tmp_path_factory.mktemp("expected") / "memory.csv"
    assert command.main(["loops", str(long_test), "--load", "450N", "--out", str(out)]) == 0
    return out.read_text()


def signalled(number):
    """Send ``number`` to this process and wait until the command's handler has seen it, as
    a signal that came at this very point."""
    signal.raise_signal(number)
    while not INTERRUPTED.is_set():  # the handler runs at the next bytecode: no waiting
        pass


def files(folder):
    """The names of the files under ``folder``, temporaries included (but not the record of
    the files the command wrote)."""
    paths = (path for path in folder.rglob("*") if path.name != MANIFEST)
    return sorted(str(path.relative_to(folder)) for path in paths)


@pytest.mark.slow
@pytest.mark.parametrize(("sent", "status", "words"), SIGNALS)
def test_an_error_the_signal_caused_keeps_the_blocks_and_says_so(
    long_test, tmp_path, capsys, small_tasks, on_each_block, sent, status, words
):
    """The signal comes while the third block is measured and stops its worker, whose error
    comes back instead of the block: the two blocks kept are named with the --resume hint
    (the line said that nothing was left before)."""

    def stopping(received):
        if len(received) == 2:
            signalled(sent)
            raise RuntimeError("the worker was stopped by the signal")

    on_each_block(stopping)
    out = tmp_path / "r.csv"
    code, printed, err = run(capsys, long_test, "--load", "450N", "--out", out, "--resume")
    assert code == status and printed == ""
    kept = [name for name in files(tmp_path) if "block" in name]
    assert len(kept) >= 2 and err.count("\n") == 1
    assert err == (
        f"ecofmaps: {words}; {len(kept)} of 6 blocks of {long_test} are kept in "
        f"{out}.partial: run the same command with --resume to continue\n"
    )
    assert not [name for name in files(tmp_path) if name.endswith(".tmp")]


@pytest.mark.parametrize(("sent", "status", "words"), SIGNALS)
def test_a_signal_after_the_last_block_keeps_them_and_says_so(
    long_test, expected, tmp_path, capsys, small_tasks, monkeypatch, sent, status, words
):
    """Every block measured, the table not yet renamed onto --out (the rename checks for the
    signal): the folder holds the whole run, and says so; --resume then writes the table."""
    extras = loops._write_extras
    monkeypatch.setattr(loops, "_write_extras", lambda *a: (signalled(sent), extras(*a)))
    out = tmp_path / "r.csv"
    code, printed, err = run(capsys, long_test, "--load", "450N", "--out", out, "--resume")
    assert code == status and printed == ""
    assert err == (
        f"ecofmaps: {words}; 6 of 6 blocks of {long_test} are kept in {out}.partial: "
        "run the same command with --resume to continue\n"
    )
    assert files(tmp_path) == ["r.csv.partial"] + [
        f"r.csv.partial/{name}"
        for name in sorted(
            [f"file0-block{block:06d}.npz" for block in range(6)]
            + ["file0-cycles.npz", "kept.jsonl", "run.json"]
        )
    ]
    monkeypatch.setattr(loops, "_write_extras", extras)
    code, printed, err = run(capsys, long_test, "--load", "450N", "--out", out, "--resume")
    assert code == 0 and err == ""
    assert out.read_text() == expected and files(tmp_path) == ["r.csv"]


@pytest.mark.parametrize("sent", [signal.SIGINT, signal.SIGTERM])
@pytest.mark.parametrize("where", ["record_written", "finish", "print"])
def test_a_signal_once_the_table_is_written_changes_nothing(
    long_test, expected, tmp_path, capsys, small_tasks, monkeypatch, sent, where
):
    """The table renamed onto --out: a signal just after (before the folder of blocks is
    removed, after, or as the summary is printed) stops nothing: exit 0, the summary
    printed in full, no line on standard error, the folder removed."""
    if where == "record_written":
        written = loops.record_written
        monkeypatch.setattr(loops, "record_written", lambda p: (signalled(sent), written(p)))
    elif where == "finish":
        finish = loops_long.LongRun.finish
        monkeypatch.setattr(loops_long.LongRun, "finish", lambda s: (finish(s), signalled(sent)))
    else:
        summary = loops._summary
        monkeypatch.setattr(loops, "_summary", lambda *a: (signalled(sent), summary(*a))[1])
    out = tmp_path / "r.csv"
    code, printed, err = run(capsys, long_test, "--load", "450N", "--out", out, "--resume")
    assert (code, err) == (0, "")
    assert (
        printed.startswith(f"wrote {out}: 59 cycles\n")
        and f"  {long_test.name}: 59 cycles" in printed
    )
    assert out.read_text() == expected and files(tmp_path) == ["r.csv"]


def test_a_folder_with_nothing_in_it_yet_is_removed_and_the_line_says_so(
    long_test, tmp_path, capsys, monkeypatch
):
    """Stopped before the cycles were found: the folder this run made holds only its record,
    and is removed; the line says that nothing was left, and nothing is."""

    def stopped(*arguments):
        signalled(signal.SIGINT)
        raise KeyboardInterrupt

    monkeypatch.setattr(loops_long, "_analyse", stopped)
    code, printed, err = run(capsys, long_test, "--load", "450N", "--out", tmp_path / "r.csv",
                             "--resume")  # fmt: skip
    assert (code, printed) == (130, "")
    assert err == "ecofmaps: interrupted; no output was left half written\n"
    assert files(tmp_path) == []


def subcommand(monkeypatch, work):
    """Have :func:`ecofmaps.cli.main.main` run ``work(args)`` as its subcommand."""
    parser = argparse.ArgumentParser()
    parser.set_defaults(handler=work)
    monkeypatch.setattr(command, "build_parser", lambda: parser)


def test_the_line_tells_what_is_left_when_it_is_written(tmp_path, monkeypatch, capsys):
    """A block that lands after the stop was raised (a worker finishing as the cluster
    closes): the line, asked of the notes when it is written, names it, not the stop's note
    of when it was raised."""
    block = tmp_path / "block.npz"

    def work(args):
        add_stop_note(lambda: f"{block.name} is kept" if block.exists() else None)
        try:
            signalled(signal.SIGINT)
            raise Interrupted("nothing is kept")  # told when the stop was raised
        finally:
            block.touch()  # the block lands after

    subcommand(monkeypatch, work)
    assert command.main([]) == 130
    assert capsys.readouterr().err == "ecofmaps: interrupted; block.npz is kept\n"
    assert INTERRUPTED.notes is None  # given back with the block: none outside it


def test_a_signal_as_the_command_leaves_its_block_changes_nothing(monkeypatch, capsys):
    """The work done, its status returned: the signal found nothing more to stop."""

    def work(args):
        print("done")
        signalled(signal.SIGTERM)
        return 1

    subcommand(monkeypatch, work)
    assert command.main([]) == 1
    assert capsys.readouterr() == ("done\n", "")


@pytest.mark.parametrize("sent", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_as_the_process_exits_after_its_work_is_ignored(sent):
    """SIGTERM (or Ctrl-C) that comes once ``main`` has returned, as the interpreter exits
    (the acceptance run: SIGTERM just after 'wrote out.csv' ended it with status 143 and no
    line): the process exits with the command's status, without a line or traceback."""
    script = (
        "import atexit, os, signal\n"
        "import importlib\n"
        "command = importlib.import_module('ecofmaps.cli.main')\n"
        "command.main = lambda: (print('wrote out.csv'), 0)[1]\n"
        f"atexit.register(os.kill, os.getpid(), {int(sent)})\n"
        "command.console()\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120
    )
    assert (done.returncode, done.stdout, done.stderr) == (0, "wrote out.csv\n", "")
