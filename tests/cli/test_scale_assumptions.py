"""The command line adds the units it assumed to the messages of an implausible scale, found
by their type (ImplausibleScaleWarning, ImplausibleScaleError), not by their words."""

from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.paper import EXAMPLE_2 as POINT
from tests.cli.commands import run_loops as run
from tests.recordings import write_csv

ASSUMED = "has no unit and was read in"


def test_only_the_scale_warning_names_the_assumed_units(tmp_path, capsys):
    """--load 1N: the scale warning names the force column's assumed unit; the summary of
    flagged cycles, though it lists implausible-cof, is a quality warning and does not."""
    path = write_csv(tmp_path / "test.csv", *synthetic_recording(**POINT, cycles=5))
    status, _, err = run(capsys, path, "--load", "1N", "--out", tmp_path / "r.csv")
    assert status == 0, err
    lines = err.splitlines()
    scale = [line for line in lines if "is the load right" in line]
    flagged = [line for line in lines if "cycles flagged" in line]
    assert len(scale) == 1 and "the force column 'force' has no unit and was read in N" in scale[0]
    assert len(flagged) == 1 and "implausible-cof" in flagged[0]
    assert ASSUMED not in flagged[0]


def test_an_error_that_is_not_of_scale_names_no_assumption(tmp_path, capsys):
    """Played backwards, every loop runs anticlockwise: refused without a word on units."""
    displacement, force = synthetic_recording(**POINT, cycles=5)
    path = write_csv(tmp_path / "test.csv", displacement[::-1], force[::-1])
    status, _, err = run(capsys, path, "--load", "450N", "--out", tmp_path / "r.csv")
    assert status == 2 and "anticlockwise" in err
    assert ASSUMED not in err
