"""The `ecofmaps` command: top level and `ecofmaps model`."""

import re
import subprocess
import sys

import pytest

from ecofmaps.cli import main


def test_model_prints_example_2_with_units(capsys):
    assert main(["model"]) == 0
    out = capsys.readouterr().out
    assert "50 µm" in out and "450 N" in out and "35 MN/m" in out
    assert "gross slip" in out
    assert "32.7302 µm" in out  # δ*, eq. 16
    assert "48.946 mJ" in out  # E_d, eq. 12
    assert "μ_E/μ    1.0385" in out  # about 4 % (Section 4)


def test_model_takes_units_and_a_rigid_rig(capsys):
    assert main(["model", "--stiffness", "inf", "--amplitude", "0.03mm"]) == 0
    out = capsys.readouterr().out
    assert "inf (rigid)" in out and re.search(r"slip amplitude +δ\* +30 µm", out)


def test_model_without_gross_slip_says_so(capsys):
    assert main(["model", "--stiffness", "5MN/m"]) == 0
    out = capsys.readouterr().out
    assert "no gross slip" in out and "undefined" in out


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["model", "--amplitude", "35MN/m"], "argument --amplitude: '35MN/m' is not a length"),
        (
            ["model", "--load=-3N"],
            "argument --load: '-3N' is out of range: the normal load must satisfy 0 < P < inf [N]",
        ),
        (["model", "--mu", "abc"], "argument --mu: cannot read 'abc'"),
        (["frobnicate"], "invalid choice: 'frobnicate'"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(arguments, message, capsys):
    assert main(arguments) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and err.startswith("ecofmaps: error: ")


def test_console_script_help_and_version():
    run = subprocess.run(
        [sys.executable, "-m", "ecofmaps.cli", "--help"], capture_output=True, text=True
    )
    assert run.returncode == 0
    assert "model" in run.stdout
    run = subprocess.run(
        [sys.executable, "-m", "ecofmaps.cli", "--version"], capture_output=True, text=True
    )
    assert run.stdout.startswith("ecofmaps ")
