"""The `ecofmaps` command: top level and `ecofmaps model`."""

import re
import subprocess
import sys
import warnings

import pytest

from ecofmaps.cli import build_parser, main, model


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


@pytest.mark.parametrize(
    ("arguments", "said"),
    [
        (["--amplitude", "50"], "--amplitude 50 is 50 m; did you mean 50um?"),
        (["--stiffness", "35"], "--stiffness 35 is 35 N/m; did you mean 35MN/m?"),
        (["--amplitude", "0.00000005"], "--amplitude 0.00000005 is 5e-08 m"),
        (["--load", "450000"], "--load 450000 is 450000 N; did you mean 450000mN?"),
        (["--groove-half-width", "40"], "--groove-half-width 40 is 40 m; did you mean 40um?"),
    ],
)
def test_a_bare_number_implausible_in_si_is_warned_with_the_unit_meant(capsys, arguments, said):
    assert main(["model", *arguments]) == 0
    out, err = capsys.readouterr()
    assert err.startswith(f"ecofmaps model: warning: {said}") and err.count("\n") == 1
    assert out.startswith("ecofmaps ")  # and the command goes on with the number as given


@pytest.mark.parametrize(
    "arguments",
    [
        ["--amplitude", "50um"],
        ["--amplitude", "0.00005"],
        ["--stiffness", "inf"],
        ["--load", "450"],
    ],
)
def test_a_plausible_or_unit_bearing_number_is_not_warned(capsys, arguments):
    assert main(["model", *arguments]) == 0
    assert capsys.readouterr().err == ""


def test_warnings_print_as_the_command_s_lines(capsys, monkeypatch):
    """A warning the work raises: one line ``ecofmaps COMMAND: warning:``, no source line."""
    work = model.run

    def warned(args):
        warnings.warn("first\nsecond", UserWarning, stacklevel=1)
        return work(args)

    monkeypatch.setattr(model, "run", warned)
    assert main(["model"]) == 0
    assert capsys.readouterr().err == "ecofmaps model: warning: first second\n"


def test_every_option_has_help_in_the_group_it_belongs_to():
    commands = build_parser()._subparsers._group_actions[0].choices
    for name, command in commands.items():
        for action in command._actions:
            assert action.help or action.dest == "==SUPPRESS==", (name, action.option_strings)
            said = getattr(action.type, "option", None)  # the option a bare number's warning names
            assert said is None or said in action.option_strings, (name, said)
    groups = {g.title: [a.dest for a in g._group_actions] for g in commands["loops"]._action_groups}
    assert "nan_policy" not in groups["long tests"]
    assert "nan_policy" in groups["options"] and "workers" in groups["long tests"]
