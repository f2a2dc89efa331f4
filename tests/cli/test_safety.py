"""Guard rails of the command line: no command replaces a file or folder it did not write,
``--overwrite`` replaces only what ecofmaps wrote, and too many workers or a scheduler that is
not one are refused at once, naming the option."""

import errno
import http.server
import os
import socket
import threading

import dask.array
import numpy as np
import pytest

import ecofmaps
from ecofmaps import _parallel
from ecofmaps.cli import figures
from ecofmaps.io.files import MANIFEST, record_written, written_by_ecofmaps
from ecofmaps.measured.synthetic import example_path, synthetic_recording
from ecofmaps.paper import EXAMPLE_2
from tests.cli.commands import on_a_full_disk, run

SHORT = ["--example", "--no-resolve"]  # the shipped example, 24000 samples: a few seconds


def thesis(folder):
    """A folder holding a user's file."""
    folder.mkdir()
    (folder / "thesis.txt").write_text("chapter 1")
    return folder


@pytest.mark.parametrize("option", ["--out", "--resolved"])
@pytest.mark.parametrize("overwrite", [[], ["--overwrite"]])
def test_an_output_onto_a_users_folder_is_refused_and_the_folder_kept(
    tmp_path, capsys, option, overwrite
):
    """The folder, and what is in it, stay exactly as they were, even with --overwrite."""
    folder = thesis(tmp_path / "results")
    status, stdout, stderr = run(capsys, "loops", "--example", option, folder, *overwrite)
    assert status == 2 and stdout == ""
    assert stderr.startswith(
        f"ecofmaps: error: {option} {folder} is a folder that ecofmaps did not write"
    )
    assert stderr.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results"]
    assert [p.name for p in folder.iterdir()] == ["thesis.txt"]
    assert (folder / "thesis.txt").read_text() == "chapter 1"


@pytest.mark.slow
def test_plots_into_a_folder_in_use_need_overwrite_and_keep_the_users_files(tmp_path, capsys):
    plots = thesis(tmp_path / "plots")
    argv = ["loops", *SHORT, "--plots", plots]
    status, _, stderr = run(capsys, *argv)
    assert status == 2
    assert f"--plots {plots} is a folder that is not empty" in stderr and "--overwrite" in stderr
    loops = plots / f"{example_path().stem}_loops.png"
    loops.write_bytes(b"a user's picture")  # the name ecofmaps would write: never replaced
    status, _, stderr = run(capsys, *argv, "--overwrite")
    assert status == 2 and f"--plots {loops} is a file that ecofmaps did not write" in stderr
    assert loops.read_bytes() == b"a user's picture"
    loops.unlink()
    status, _, stderr = run(capsys, *argv, "--overwrite")
    assert status == 0, stderr
    written = sorted(p.name for p in plots.iterdir())
    stem = example_path().stem
    assert written == [MANIFEST, f"{stem}_evolution.png", f"{stem}_loops.png", "thesis.txt"]
    assert (plots / "thesis.txt").read_text() == "chapter 1"
    assert written_by_ecofmaps(loops) and not written_by_ecofmaps(plots / "thesis.txt")
    before = loops.stat().st_mtime_ns
    assert run(capsys, *argv, "--overwrite")[0] == 0  # its own files: replaced
    assert loops.stat().st_mtime_ns != before and (plots / "thesis.txt").exists()


def test_a_file_ecofmaps_wrote_and_someone_changed_is_not_replaced(tmp_path, capsys):
    out = tmp_path / "r.csv"
    assert run(capsys, "loops", *SHORT, "--out", out)[0] == 0
    assert written_by_ecofmaps(out)
    status, _, stderr = run(capsys, "loops", *SHORT, "--out", out)
    assert status == 2
    assert stderr == f"ecofmaps: error: --out {out} exists already: --overwrite replaces it\n"
    with open(out, "a", encoding="utf-8") as stream:
        stream.write("my notes\n")  # edited by hand: no longer what ecofmaps wrote
    assert not written_by_ecofmaps(out)
    status, _, stderr = run(capsys, "loops", *SHORT, "--out", out, "--overwrite")
    assert status == 2 and "is a file that ecofmaps did not write (or that changed since" in stderr
    assert out.read_text().endswith("my notes\n")


def test_convert_and_correct_follow_the_same_rule(tmp_path, capsys):
    store = tmp_path / "example.zarr"
    store.mkdir()
    (store / "notes.txt").write_text("mine")
    status, _, stderr = run(capsys, "convert", example_path(), store, "--overwrite")
    assert status == 2
    assert f"the destination {store} is a folder that ecofmaps did not write" in stderr
    assert [p.name for p in store.iterdir()] == ["notes.txt"]
    store = tmp_path / "mine.zarr"
    assert run(capsys, "convert", example_path(), store)[0] == 0
    assert written_by_ecofmaps(store)
    status, _, stderr = run(capsys, "convert", example_path(), store)
    assert status == 2 and "exists already: --overwrite replaces it" in stderr
    assert run(capsys, "convert", example_path(), store, "--overwrite")[0] == 0
    table = tmp_path / "table.csv"
    table.write_text(
        "ecof,amplitude_um,load_N,stiffness_MN_per_m,aspect_ratio\n0.8,50,450,35,0.2\n"
    )
    out = tmp_path / "corrected.csv"
    out.write_text("a user's table")
    status, _, stderr = run(capsys, "correct", table, "--out", out, "--overwrite")
    assert status == 2 and f"--out {out} is a file that ecofmaps did not write" in stderr
    assert out.read_text() == "a user's table"
    out.unlink()
    assert run(capsys, "correct", table, "--out", out)[0] == 0
    assert run(capsys, "correct", table, "--out", out)[0] == 2
    assert run(capsys, "correct", table, "--out", out, "--overwrite")[0] == 0


def test_the_manifest_lists_what_was_written_and_ignores_a_damaged_one(tmp_path):
    mine, theirs = tmp_path / "a.csv", tmp_path / "b.csv"
    mine.write_text("1")
    theirs.write_text("2")
    record_written([mine, tmp_path / "never-written.csv"])
    assert written_by_ecofmaps(mine) and not written_by_ecofmaps(theirs)
    assert not written_by_ecofmaps(tmp_path / "never-written.csv")
    (tmp_path / MANIFEST).write_text("{not json")
    assert not written_by_ecofmaps(mine)  # nothing counts as written: nothing is replaced
    record_written([theirs])
    assert written_by_ecofmaps(theirs) and not written_by_ecofmaps(mine)


def test_too_many_workers_are_refused_naming_the_option_and_the_limit(tmp_path, capsys):
    cores = os.cpu_count()
    status, _, stderr = run(capsys, "loops", "--example", "--workers", str(cores + 1))
    assert status == 2 and stderr.count("\n") == 1
    limit = f"argument --workers: {cores + 1} is more than this machine can run: {cores} cores"
    assert limit in stderr
    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=3)
    for scheduler in (None, "threads", "processes"):
        with pytest.raises(ValueError, match=r"^workers=1000 is more than this machine can run"):
            ecofmaps.analyze_loops(displacement, force, 450.0, scheduler=scheduler, workers=1000)


def test_the_memory_bounds_the_worker_processes(monkeypatch):
    import psutil

    class Memory:
        available = 3 * _parallel.WORKER_MEMORY // 2  # room for one worker

    monkeypatch.setattr(psutil, "virtual_memory", Memory)
    monkeypatch.setattr(os, "cpu_count", lambda: 8)
    limit, why = _parallel.worker_limit(processes=True)
    assert limit == 1 and "GiB of memory available" in why
    assert _parallel.worker_limit(processes=False) == (8, "8 cores (os.cpu_count())")
    with pytest.raises(ValueError, match="workers=2 is more than this machine can run"):
        _parallel.Runner(2, cluster=True)


@pytest.fixture
def not_a_scheduler():
    """Two addresses that are no dask scheduler: an HTTP server, and one that never answers."""

    class Quiet(http.server.BaseHTTPRequestHandler):
        def log_message(self, *arguments):  # not on the test's standard error
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Quiet)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    silent = socket.create_server(("127.0.0.1", 0))  # accepts, never answers
    yield {
        "http": f"tcp://127.0.0.1:{server.server_address[1]}",
        "silent": f"tcp://127.0.0.1:{silent.getsockname()[1]}",
    }
    server.shutdown()
    server.server_close()
    silent.close()


@pytest.mark.parametrize("kind", ["http", "silent"])
def test_a_scheduler_address_that_is_not_one_fails_in_seconds(
    tmp_path, capsys, monkeypatch, not_a_scheduler, kind
):
    """A client of such an address waited for good; now one line, within the timeout."""
    monkeypatch.setattr(_parallel, "CONNECT_TIMEOUT", 1.0)
    address = not_a_scheduler[kind]
    out = tmp_path / "r.csv"
    status, stdout, stderr = run(capsys, "loops", "--example", "--scheduler", address, "--out", out)
    assert status == 2 and stdout == ""
    assert stderr.startswith(f"ecofmaps: error: no dask scheduler at {address}: ")
    assert stderr.count("\n") == 1
    assert list(tmp_path.iterdir()) == []
    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=3)
    lazy = [
        dask.array.from_array(np.asarray(series), chunks=200) for series in (displacement, force)
    ]
    with pytest.raises(_parallel.SchedulerError, match=f"no dask scheduler at {address}"):
        ecofmaps.analyze_loops(*lazy, 450.0, scheduler=address)


def test_figures_into_a_folder_in_use_need_overwrite(tmp_path, capsys):
    """Refused before any drawing; with --overwrite a user's file of a figure's name is kept."""
    out = thesis(tmp_path / "figures")
    status, _, stderr = run(capsys, "figures", "--out", out, "--only", "fig8")
    assert status == 2 and f"--out {out} is a folder that is not empty" in stderr
    (out / "fig8.png").write_bytes(b"a user's picture")
    status, _, stderr = run(capsys, "figures", "--out", out, "--only", "fig8", "--overwrite")
    assert (
        status == 2 and f"--out {out / 'fig8.png'} is a file that ecofmaps did not write" in stderr
    )
    assert sorted(p.name for p in out.iterdir()) == ["fig8.png", "thesis.txt"]
    assert (out / "fig8.png").read_bytes() == b"a user's picture"


@pytest.mark.parametrize("failure", [OSError(errno.ENOSPC, "No space left"), KeyboardInterrupt()])
def test_figures_that_fail_remove_only_the_empty_folders_they_made(
    tmp_path, capsys, monkeypatch, failure
):
    """A full disk or Ctrl-C before the first file, or a bad --format: no folder made is left,
    a folder that was there is kept."""

    def fails(*args):
        raise failure

    monkeypatch.setattr(figures, "_write_figure_group", fails)
    made, there = tmp_path / "new" / "figures", tmp_path / "there"
    there.mkdir()
    for out, more in [(made, []), (there, []), (made, ["--format", "bmp"])]:
        status, _, _ = run(capsys, "figures", "--out", out, "--only", "fig8", "--jobs", 1, *more)
        assert status in (2, 130)
    assert list(tmp_path.iterdir()) == [there] and list(there.iterdir()) == []


@pytest.mark.parametrize("device", ["/dev/null", "/dev/full"])
def test_an_output_onto_a_device_is_refused_as_not_a_regular_file(capsys, device):
    status, stdout, stderr = run(capsys, "loops", *SHORT, "--out", device)
    assert status == 2 and stdout == ""
    assert stderr == (
        f"ecofmaps: error: --out {device} is not a regular file (a device, pipe or socket)\n"
    )


@pytest.mark.parametrize("looped", ["input", "--out"])
def test_symbolic_links_in_a_loop_are_named_with_the_remedy(tmp_path, capsys, looped):
    (tmp_path / "a.csv").symlink_to(tmp_path / "b.csv")
    (tmp_path / "b.csv").symlink_to(tmp_path / "a.csv")
    source, out = (tmp_path / "a.csv", tmp_path / "o.csv")
    if looped == "--out":
        source, out = example_path(), tmp_path / "a.csv"
    status, stdout, stderr = run(capsys, "loops", source, "--load", "450N", "--out", out)
    assert status == 2 and stdout == ""
    assert stderr == (
        f"ecofmaps: error: {tmp_path / 'a.csv'}: symbolic links that point to each other in "
        "a loop: remove or correct the link\n"
    )


def test_a_full_disk_names_the_file_and_leaves_no_empty_plots_folder(tmp_path, capsys, monkeypatch):
    import errno

    from matplotlib.figure import Figure

    def full(self, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Figure, "savefig", full)
    plots = tmp_path / "plots"
    status, _, stderr = run(capsys, "loops", *SHORT, "--plots", plots, "--out", tmp_path / "o.csv")
    assert status == 2
    loops = plots / f"{example_path().stem}_loops.png"
    assert stderr == f"ecofmaps: error: [Errno 28] No space left on device: '{loops}'\n"
    assert not plots.exists()


@pytest.mark.slow
@pytest.mark.parametrize("command", ["loops", "convert"])
def test_an_hdf5_output_on_a_full_disk_is_one_line_naming_it(tmp_path, command):
    """A real full disk under a netCDF or HDF5 output: one line naming the file, nothing left
    (HDF5 cannot recover from a failed write: its half-written file crashed the process)."""
    full = tmp_path / "full"
    output = full / ("r.nc" if command == "loops" else "c.h5")
    argv = ["loops", "--example", "--out", tmp_path / "r.csv", "--resolved", output]
    if command == "convert":
        argv = ["convert", example_path(), output]
    status, stderr, left = on_a_full_disk(full, *argv)
    assert status == 2, stderr
    assert stderr.startswith("ecofmaps: error: [Errno 28] No space left on device: ")
    assert stderr.endswith(f"free: '{output}'\n") and stderr.count("\n") == 1
    assert left[-1:] == ["filler"] and not any(name.endswith(".tmp") for name in left)


@pytest.mark.slow
def test_a_full_disk_under_a_long_run_says_what_it_left(tmp_path):
    """``--workers 2 --out`` onto a full disk: one line naming the error and the folder kept
    beside --out with what it holds, to go on with --resume (it was said nowhere)."""
    from ecofmaps.measured.synthetic import example_path
    from tests.cli.commands import on_a_full_disk

    out = tmp_path / "full" / "o.csv"
    argv = ("loops", example_path(), "--load", "450N", "--workers", "2", "--out", out)
    status, err, names = on_a_full_disk(tmp_path / "full", *argv)
    assert status == 2 and err.count("\n") == 1 and "No space left on device" in err
    if "o.csv.partial" in names:
        assert f"kept in {out}.partial: run the same command with --resume" in err
    else:
        assert "kept in" not in err
    assert "o.csv" not in names
