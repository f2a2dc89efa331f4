"""Plausibility of scale on the command line: a wrong load or unit is
flagged or refused with a message that names the assumption and the option."""

import pandas as pd

from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.paper import EXAMPLE_2 as POINT
from tests.cli.commands import run_loops as run
from tests.recordings import write_csv


def test_a_wrong_load_flags_every_cycle_and_names_the_load(tmp_path, capsys):
    path = write_csv(tmp_path / "test.csv", *synthetic_recording(**POINT, cycles=13))
    out = tmp_path / "r.csv"
    status, _, err = run(capsys, path, "--load", "1N", "--out", out)
    assert status == 0, err
    table = pd.read_csv(out)
    assert (table.quality == "implausible-cof").all() and table.ecof.isnull().all()
    assert "test.csv" in err and "load of 1 N: is the load right" in err and "--load" in err
    assert "the force column 'force' has no unit and was read in N" in err


def test_millimetres_in_a_column_without_a_unit_are_refused(tmp_path, capsys):
    displacement, force = synthetic_recording(**POINT, cycles=4)
    path = tmp_path / "test.csv"
    # a file written in mm, read in µm (no unit in the header): an amplitude of 0.05 µm
    write_csv(path, displacement * 1e-3, force)
    status, _, err = run(capsys, path, "--load", "450N", "--out", tmp_path / "r.csv")
    assert status == 2
    assert "implausible-amplitude" in err and "--displacement-unit" in err
    assert "the displacement column 'displacement' has no unit and was read in um" in err
    assert not (tmp_path / "r.csv").exists()


def test_a_damper_stroke_of_millimetres_is_reciprocating_sliding(tmp_path, capsys):
    displacement, force = synthetic_recording(**POINT, cycles=4)
    path = write_csv(tmp_path / "damper.csv", displacement * 256, force)  # 12.8 mm
    status, printed, err = run(capsys, path, "--load", "450N", "--out", tmp_path / "r.csv")
    assert status == 0 and "metres" not in err
    assert "reciprocating sliding (amplitude 12.8 mm)" in printed


def test_a_recorded_normal_load_is_used_sample_by_sample(tmp_path, capsys):
    """``--load Fz``: a load cell's channel that swings by ±20 % gives the contact's μ in
    every cycle; the same recording with its mean load as one value does not."""
    import numpy as np

    displacement, force = synthetic_recording(**POINT, cycles=6)
    load = POINT["load"] * (1.0 + 0.2 * np.sin(2.0 * np.pi * np.arange(force.size) / 777.0))
    path = tmp_path / "load_cell.csv"
    lines = ["displacement [m],force [N],Fz [N]"]
    lines += [
        f"{float(d)!r},{float(q)!r},{float(p)!r}"
        for d, q, p in zip(displacement, force * load / POINT["load"], load, strict=True)
    ]
    path.write_text("\n".join(lines) + "\n")
    out = tmp_path / "r.csv"
    status, _, err = run(capsys, path, "--load", "Fz", "--out", out)
    assert status == 0, err
    table = pd.read_csv(out)
    np.testing.assert_allclose(table.gicof, 0.8, atol=1e-4)
    np.testing.assert_allclose(table.mu_resolved, 0.8, atol=1e-4)
    status, _, err = run(capsys, path, "--load", f"{load.mean()}N", "--out", tmp_path / "c.csv")
    assert status == 0, err
    assert np.abs(pd.read_csv(tmp_path / "c.csv").gicof - 0.8).max() > 0.05


def test_a_recorded_load_that_steps_gives_each_cycle_at_its_own_load(tmp_path, capsys):
    """``--load Fz`` stepping 300 -> 450 -> 600 N: a ``normal_load_N`` column, and each
    cycle's forces and stiffness at its own load (the rig's 35 MN/m, not 52 to 26)."""
    from tests.recordings import load_steps

    displacement, force, load = load_steps()
    path = tmp_path / "steps.csv"
    rows = zip(displacement, force, load, strict=True)
    lines = [
        "displacement [m],force [N],Fz [N]",
        *(f"{d:.17g},{q:.17g},{p:.17g}" for d, q, p in rows),
    ]
    path.write_text("\n".join(lines) + "\n")
    status, _, err = run(capsys, path, "--load", "Fz", "--out", tmp_path / "r.csv")
    assert status == 0, err
    table = pd.read_csv(tmp_path / "r.csv")
    middle = table.iloc[[1, 5, 9]]  # each step's second cycle of four
    assert list(middle.normal_load_N) == [300.0, 450.0, 600.0]
    assert (abs(middle.stiffness_MN_per_m - 35.0) < 1e-3).all()
    assert (abs(middle.max_force_N / middle.normal_load_N - middle.cof_max) < 1e-5).all()


def test_a_load_column_that_is_not_there_is_named(tmp_path, capsys):
    path = write_csv(tmp_path / "test.csv", *synthetic_recording(**POINT, cycles=4))
    status, _, err = run(capsys, path, "--load", "Fz", "--out", tmp_path / "r.csv")
    assert status == 2 and "Fz" in err and "test.csv" in err


def test_a_negative_load_sample_with_nan_policy_raise_is_named_once(tmp_path, capsys):
    """``--load Fz --nan-policy raise`` and one sample of Fz negative: the error names the load,
    its sample and cycle, the hint of compression, and the file and line once."""
    displacement, force = synthetic_recording(**POINT, cycles=4)
    lines = ["displacement [m],force [N],Fz [N]"]
    lines += [f"{float(d)!r},{float(q)!r},450.0" for d, q in zip(displacement, force, strict=True)]
    lines[1 + 500] = lines[1 + 500].rsplit(",", 1)[0] + ",-450.0"
    path = tmp_path / "fz.csv"
    path.write_text("\n".join(lines) + "\n")
    out = tmp_path / "r.csv"
    status, _, err = run(capsys, path, "--load", "Fz", "--nan-policy", "raise", "--out", out)
    assert status == 2 and not out.exists()
    assert f"{path}, line 502: the recorded normal load at sample 500 (cycle" in err
    assert "is -450 N, not positive" in err and "--nan-policy skip flags its cycle" in err
    assert "-Fz" in err and err.count("line ") == 1
