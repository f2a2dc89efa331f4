"""Odd and bad input through the command line: one line, status != 0, inputs kept.

Each case drives the ``ecofmaps`` command with an input a new user might give and checks
the outcome: the exit status, the one-line message naming the option or file, the input
files unchanged and no output left behind.
"""

import os
import signal
import subprocess
import sys

import numpy as np
import pytest

from ecofmaps import read_recording
from ecofmaps.cli import main
from ecofmaps.maps import tiles
from tests.cli.commands import interrupted_run


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


def one_line_error(err: str) -> bool:
    return err.count("\n") == 1 and err.startswith("ecofmaps: error: ") and "Traceback" not in err


@pytest.fixture
def recording(tmp_path):
    """The shipped example, copied: a recording a command must never write over."""
    from ecofmaps.measured.synthetic import example_path

    path = tmp_path / "rec.csv"
    path.write_bytes(example_path().read_bytes())
    return path


# --- no command writes over its input --------------------------------------------------------


def test_loops_refuses_to_write_results_over_the_recording(tmp_path, capsys, recording):
    before = recording.read_bytes()
    status, out, err = run(capsys, "loops", recording, "--load", "450N", "--out", recording)
    assert status == 2 and out == "" and one_line_error(err)
    assert f"--out {recording} would write over the input file" in err
    assert recording.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rec.csv"]


def test_loops_refuses_plots_over_an_input(tmp_path, capsys):
    from ecofmaps.measured.synthetic import example_path

    # A recording named like the plot the command would write for it.
    tricky = tmp_path / "rec_loops.png"
    tricky.write_bytes(example_path().read_bytes())
    renamed = tmp_path / "rec.csv"
    renamed.write_bytes(example_path().read_bytes())
    status, _, err = run(capsys, "loops", renamed, tricky, "--load", "450N", "--plots", tmp_path)
    assert status == 2 and one_line_error(err) and "--plots" in err


def test_correct_refuses_to_write_over_its_table(tmp_path, capsys):
    table = tmp_path / "t.csv"
    text = "ecof,amplitude_um,load_N,stiffness_MN_per_m,aspect_ratio\n0.83,50,450,35,0.2\n"
    table.write_text(text)
    status, _, err = run(capsys, "correct", table, "--out", table)
    assert status == 2 and one_line_error(err) and "would write over the input file" in err
    assert table.read_text() == text


def test_the_same_file_by_another_name_is_refused(tmp_path, capsys, recording):
    link = tmp_path / "link.csv"
    link.symlink_to(recording)
    before = recording.read_bytes()
    status, _, err = run(capsys, "loops", recording, "--load", "450N", "--out", link)
    assert status == 2 and "would write over the input file" in err
    assert recording.read_bytes() == before


# --- messages name what the user typed ------------------------------------------------------


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["correct", "--ecof", "0.83", "--amplitude", "50um", "--load", "450N", "--stiffness",
          "35MN/m", "--scar-depth", "8um", "--scar-half-width", "0um"],
         "argument --scar-half-width: '0um' is out of range"),
        (["correct", "--ecof", "0.83", "--amplitude", "50um", "--load", "450N", "--stiffness",
          "35MN/m", "--scar-depth=-8um", "--scar-half-width", "40um"],
         "argument --scar-depth: '-8um' is out of range"),
        (["loops", "--example", "--load", "inf"], "argument --load: 'inf' is out of range"),
        (["loops", "--example", "--load", "-450N"], "argument --load: expected one argument (a "
         "value that begins with '-' is written --load=VALUE)"),
        (["loops", "--example", "--force-unit", ""], "argument --force-unit: an empty unit"),
        (["loops", "--example", "--load", "450N", "--skip-rows", "-1"],
         "argument --skip-rows: '-1' is not a whole number of lines >= 0"),
        (["loops", "--example", "--force-unit", "0N"], "'0N' is not a unit"),
        (["loops", "--example", "--force-unit", "um"], "--force-unit: 'um' is not a force"),
        (["loops", "--example", "--cycle-col", "Force"],
         "--force-col and --cycle-col name the same column 'force'"),
        (["map", "--stiffness-ratio", "0.1/um", "--aspect-ratio", "0.1,0.2,0.1", "--amplitude",
          "50um", "--mu", "0.8", "--out", "x.nc"], "repeats the value 0.1"),
        (["model", "--amplitude", "true"], "argument --amplitude: cannot read 'true'"),
    ],
)  # fmt: skip
def test_errors_name_the_option(tmp_path, monkeypatch, capsys, argv, message):
    monkeypatch.chdir(tmp_path)
    status, out, err = run(capsys, *argv)
    assert status == 2 and out == "" and one_line_error(err)
    assert message in err
    assert list(tmp_path.iterdir()) == []


_DOMAIN_OPTIONS = {
    "model": ["--amplitude", "--load", "--stiffness", "--mu", "--aspect-ratio",
              "--groove-half-width"],
    "correct": ["--ecof", "--amplitude", "--load", "--stiffness", "--aspect-ratio",
                "--scar-depth", "--scar-half-width"],
    "map": ["--stiffness-ratio", "--aspect-ratio", "--amplitude", "--mu", "--load"],
}  # fmt: skip


@pytest.mark.parametrize(
    ("command", "option", "value"),
    [
        (command, option, value)
        for command, options in _DOMAIN_OPTIONS.items()
        for option in options
        for value in ("1e308", "1e-300")
        if value == "1e308" or option not in ("--aspect-ratio", "--scar-depth")  # 0: flat
    ],
)
def test_values_beyond_the_models_domain_are_refused(tmp_path, capsys, command, option, value):
    """Not 'regime invalid' or 'inf µm' with exit 0: the option, its bounds and unit."""
    argv = [command, f"{option}={value}", "--out", tmp_path / "m.nc"][
        : 4 if command == "map" else 2
    ]
    status, out, err = run(capsys, *argv)
    assert status == 2 and out == "" and one_line_error(err), err
    assert f"argument {option}: '{value}' is beyond the model's domain: the " in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["loops", "rec.csv", "--lod", "450N"],
         "--lod 450N; did you mean --load? (see 'ecofmaps loops --help')"),
        (["correct", "--stifness", "35MN/m"],
         "did you mean --stiffness? (see 'ecofmaps correct --help')"),
        (["figures", "--whatever"], "--whatever (see 'ecofmaps figures --help')"),
    ],
)  # fmt: skip
def test_an_unknown_argument_names_the_subcommands_help(capsys, argv, expected):
    """An argument the subcommand does not know: one line naming that subcommand's --help
    (not the top level's), with the option like it."""
    status, out, err = run(capsys, *argv)
    assert status == 2 and out == ""
    assert one_line_error(err) and err.startswith("ecofmaps: error: unrecognized arguments: ")
    assert expected in err


def test_a_grid_too_large_for_memory_is_refused_before_allocating(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(tiles, "available_memory", lambda: 5 * 10**8)  # 0.5 GB free
    status, _, err = run(
        capsys,
        "map",
        "--stiffness-ratio",
        "0.01/um:0.3/um:3000",
        "--aspect-ratio",
        "0:0.3:3000",
        "--amplitude",
        "25um,50um",
        "--mu",
        "0.8",
        "--no-cache",
        "--chunk-points",
        "1e9",
        "--out",
        tmp_path / "big.nc",
    )  # fmt: skip  (at once in memory: below --chunk-points it would be block by block)
    assert status == 2 and "ecofmaps: error: the grid of 1.8e+07 points needs about" in err
    assert "more than the 0.5 GB available" in err and "--chunk-points" in err
    assert list(tmp_path.iterdir()) == []


def test_an_unexpected_failure_is_one_line_with_status_1(capsys, monkeypatch):
    from ecofmaps.cli import model

    def broken(args):
        raise KeyError("a bug")

    monkeypatch.setattr(model, "run", broken)
    status, _, err = run(capsys, "model")
    assert status == 1 and err.count("\n") == 1
    assert err.startswith("ecofmaps: error: unexpected KeyError: 'a bug' (a bug: please report")


# --- Ctrl-C -----------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0.0, 0.2])
def test_ctrl_c_exits_130_with_one_line_and_leaves_no_output(tmp_path, delay):
    """Ctrl-C during a map run: status 130, one line, no output file."""
    out = tmp_path / "m.nc"
    command = [
        sys.executable, "-m", "ecofmaps.cli", "map", "--stiffness-ratio", "0.01/um:0.3/um:1500",
        "--aspect-ratio", "0:0.3:1500", "--amplitude", "25um,50um", "--mu", "0.8", "--load",
        "450N", "--no-cache", "--out", str(out),
    ]  # fmt: skip
    status, stdout, stderr = interrupted_run(command, "ecofmaps map: 4,500,000 points", delay)
    assert status == 130, stderr
    assert stderr == "ecofmaps: interrupted; no output was left half written\n"
    assert stdout == "" and list(tmp_path.iterdir()) == []  # the size line read before


@pytest.mark.slow
def test_ctrl_c_during_figures_keeps_whole_files_only(tmp_path):
    """Ctrl-C after the first figure: status 130; what is there is whole, nothing half written."""
    env = {**os.environ, "ECOFMAPS_CACHE": str(tmp_path / "cache")}
    command = [sys.executable, "-m", "ecofmaps.cli", "figures", "--out", str(tmp_path / "figs")]
    status, _, stderr = interrupted_run(command, "ecofmaps figures: 9 figure(s)", 0.5, env)
    assert status == 130, stderr
    assert stderr.splitlines()[-1] == "ecofmaps: interrupted; no output was left half written"
    assert "Traceback" not in stderr
    figs = tmp_path / "figs"  # removed if the Ctrl-C came before the first figure
    for path in figs.iterdir() if figs.exists() else ():
        assert path.suffix == ".png" and path.read_bytes().endswith(b"IEND\xaeB`\x82")


def test_the_first_ctrl_c_stops_writes_at_the_next_safe_point(tmp_path):
    """The first Ctrl-C only sets a flag (raising inside JAX's extensions would crash them):
    the next atomic write raises instead of landing, and so does leaving the block."""
    from ecofmaps._interrupts import check_interrupted, interrupts_stop_writes
    from ecofmaps.io.files import atomic_path

    path = tmp_path / "out.txt"
    with pytest.raises(KeyboardInterrupt), interrupts_stop_writes() as interrupted:
        signal.raise_signal(signal.SIGINT)  # returns: nothing raised yet
        assert interrupted.is_set()
        with pytest.raises(KeyboardInterrupt), atomic_path(path) as temporary:
            temporary.write_text("half")
        assert list(tmp_path.iterdir()) == []
    assert interrupted.is_set()
    check_interrupted()  # outside the block: nothing to stop
    with atomic_path(path) as temporary:  # and writes work again
        temporary.write_text("whole")
    assert path.read_text() == "whole"


def test_a_second_ctrl_c_stops_at_once():
    from ecofmaps._interrupts import interrupts_stop_writes

    with pytest.raises(KeyboardInterrupt), interrupts_stop_writes():  # leaving raises too
        signal.raise_signal(signal.SIGINT)  # the first: a flag
        with pytest.raises(KeyboardInterrupt):
            signal.raise_signal(signal.SIGINT)  # the second: at once


def test_a_reading_warning_is_one_line_of_the_command(tmp_path, capsys, recording):
    """Not Python's two lines ('...: RecordingWarning: ...' and the source line)."""
    latin = tmp_path / "latin.csv"
    latin.write_bytes(recording.read_bytes() + "# café\n".encode("latin-1"))
    status, _, err = run(capsys, "loops", latin, "--load", "450N", "--no-resolve")
    lines = [line for line in err.splitlines() if "warning" in line or "Warning" in line]
    assert status == 0 and len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"ecofmaps loops: warning: {latin}, line ")
    assert lines[0].endswith(
        "is not UTF-8; the file is read as Latin-1 from this line on (numbers are the same in both)"
    )


def header_file(tmp_path, header, cells=lambda x, q: f"{x},{q}", name="rec.csv"):
    """A recording of 20 loops under ``header``, each line's cells made by ``cells``."""
    t = np.linspace(0.0, 40.0 * np.pi, 4000)
    x, q = 50e-6 * np.sin(t), 300.0 * np.tanh(5.0 * np.sin(t + 0.3))
    lines = [header, *(cells(a, b) for a, b in zip(x, q, strict=True))]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(
    ("header", "cells", "options", "message"),
    [
        (
            "displacement [foo],force [N]", None, [],
            "line 1: the displacement column 'displacement [foo]' is in 'foo', which is not a "
            "known unit (known: m, mm, um, µm, μm, nm, in and the others pint reads): write a "
            "known unit in the header, or name the column with --displacement-col and give its "
            "unit with --displacement-unit",
        ),
        (
            "displacement [m],force [N]", lambda x, q: f"{x},", [],
            "line 1: the force column 'force [N]' holds no number: all its 4000 samples are "
            "missing; is it the right column?",
        ),
        (
            "displacement [m],force [N],force [N]", lambda x, q: f"{x},{q},{q}", [],
            "line 1: several force columns match 'force': 'force [N]' (#2), 'force [N]' (#3); "
            "choose one with --force-col by its position, e.g. '#2'",
        ),
        (
            "displacement [m],force [N],force [N]", lambda x, q: f"{x},{q},{q}",
            ["--force-col", "force [N]"],
            "line 1: several force columns match 'force [N]': 'force [N]' (#2), 'force [N]' "
            "(#3); choose one with --force-col by its position, e.g. '#2'",
        ),
        (
            "cycle,displacement [m],force [N]", lambda x, q: f",{x},{q}", [],
            "line 1: the cycle column 'cycle' holds no number: all its 4000 samples are "
            "missing; --cycle-col none reads no cycle column",
        ),
    ],
)  # fmt: skip
def test_reading_errors_blame_the_right_thing_and_name_the_options(
    tmp_path, capsys, header, cells, options, message
):
    path = header_file(tmp_path, header, cells or (lambda x, q: f"{x},{q}"))
    status, out, err = run(capsys, "loops", path, "--load", "450N", "--no-resolve", *options)
    assert status == 2 and out == "" and one_line_error(err)
    assert err == f"ecofmaps: error: {path}, {message}\n"


def test_a_missing_file_is_named_with_the_nearest_name_and_group_with_its_option(
    tmp_path, capsys, recording
):
    status, out, err = run(capsys, "loops", tmp_path / "rec.cs", "--load", "450N")
    assert status == 2 and out == "" and one_line_error(err)
    assert err == f"ecofmaps: error: {tmp_path / 'rec.cs'}: no such file: did you mean " \
        f"'{recording}'?\n"  # fmt: skip
    with pytest.raises(FileNotFoundError, match="no such file: did you mean"):  # an OSError
        read_recording(tmp_path / "rec.cs")
    status, _, err = run(capsys, "convert", tmp_path / "other.csv", tmp_path / "o.zarr")
    assert status == 2 and err == f"ecofmaps: error: {tmp_path / 'other.csv'}: no such file\n"
    status, _, err = run(capsys, "loops", recording, "--load", "450N", "--group", "Rig")
    assert status == 2 and one_line_error(err) and "group (--group) applies to TDMS" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rec.csv"]


def test_columns_named_alike_are_chosen_by_position_and_a_cycle_column_ignored(tmp_path, capsys):
    path = header_file(tmp_path, "displacement [m],force [N],force [N]", lambda x, q: f"{x},0,{q}")
    status, out, _ = run(
        capsys, "loops", path, "--load", "450N", "--no-resolve", "--force-col", "#3"
    )
    assert status == 0 and out.count(",gross slip,ok\n") == 19, out  # the force, not zeros
    labelled = header_file(tmp_path, "cycle,displacement [m],force [N]", lambda x, q: f"7,{x},{q}")
    status, out, _ = run(
        capsys, "loops", labelled, "--load", "450N", "--no-resolve", "--cycle-col", "none"
    )
    assert status == 0 and out.count(",gross slip,ok\n") == 19, out  # cut at the reversals
    status, out, err = run(capsys, "loops", labelled, "--load", "450N", "--cycle-col", "")
    assert status == 2 and err == (
        "ecofmaps: error: --cycle-col '' names no column: give a name or 'none'\n"
    )


def test_errors_of_the_reading_name_the_options_not_python_keywords():
    from ecofmaps.cli.main import option_names

    assert option_names("skip_rows must be a non-negative integer; got -1") == (
        "--skip-rows must be a non-negative integer; got -1"
    )
    assert (
        option_names("force_unit='m' is not a force unit") == "--force-unit 'm' is not a force unit"
    )
    assert (
        option_names("choose one with load_column (--load COLUMN)")
        == "choose one with --load COLUMN"
    )
    assert (
        option_names("/data/force_unit.csv: cycle_column.x")
        == "/data/force_unit.csv: cycle_column.x"
    )


# --- the help, and a reader of the output that goes ------------------------------------------


def test_the_help_of_convert_gives_the_largest_chunk_of_a_store(capsys):
    status, out, _ = run(capsys, "convert", "--help")
    assert status == 0 and (
        "--chunk-samples N samples per block read, and per chunk of the store (at most 131072, "
        "and no more than the recording) (default 1048576)"
    ) in " ".join(out.split())


@pytest.mark.parametrize(
    "argv", [["--help"], ["model", "--amplitude", "50um"], ["loops", "--example", "--load", "450N"]]
)
def test_a_reader_that_goes_ends_the_command_quietly(argv):
    """``ecofmaps ... | head``: the pipe closes before the output comes; no traceback, no
    line about the pipe, the status of Unix tools (141, or 0 if nothing was lost)."""
    process = subprocess.Popen(
        [sys.executable, "-m", "ecofmaps.cli", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    process.stdout.close()
    stderr = process.communicate(timeout=300)[1]
    assert process.returncode in (0, 141) and stderr == b""
