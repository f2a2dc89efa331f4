"""``ecofmaps loops --scar-profile`` on files: a recording made on a known parabolic groove,
closed on that groove's profile (and not on one half as deep), its energy wear, the closure's
figure and the report's rows; bad input."""

import html
import re

import numpy as np
import pandas as pd
import pytest

import ecofmaps
from ecofmaps.cli.main import main
from tests import mindlin
from tests.lab_cases import ALPHA, DELTA_T, LOAD, MU, recorded_cycles, recorded_test

DEPTH, HALF_WIDTH = 12e-6, 60e-6  # z_o/x_o = 0.2
LENGTH = 5e-3


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """The recording (µm, N) and the profiles of its groove and of one half as deep (µm)."""
    folder = tmp_path_factory.mktemp("scar")
    displacement, force = ecofmaps.synthetic_recording(
        50e-6, 450.0, 35e6, 0.8, DEPTH / HALF_WIDTH, HALF_WIDTH, cycles=4, samples_per_cycle=400,
        force_noise=0.5, displacement_noise=5e-9, seed=1,
    )  # fmt: skip
    table = {"displacement_um": np.asarray(displacement) * 1e6, "force_N": np.asarray(force)}
    pd.DataFrame(table).to_csv(folder / "test.csv", index=False)
    x = np.linspace(-4 * HALF_WIDTH, 4 * HALF_WIDTH, 961)
    noise = 5e-9 * np.random.default_rng(0).standard_normal(x.size)
    for name, depth in (("scar", DEPTH), ("half", DEPTH / 2)):
        z = np.where(np.abs(x) < HALF_WIDTH, depth * ((x / HALF_WIDTH) ** 2 - 1), 0.0) + noise
        pd.DataFrame({"x_um": x * 1e6, "z_um": z * 1e6}).to_csv(folder / f"{name}.csv")
    return folder


def run(capsys, *arguments):
    status = main(["loops", *map(str, arguments)])
    out, err = capsys.readouterr()
    return status, out, err


def _closure(text):
    """The closure's loop residual [%] and scar residual [% of the depth] in ``text``."""
    found = re.search(r"the loop ([\d.]+)% of Q\* off .* \(([\d.]+)% of its depth\)", text)
    return float(found[1]), float(found[2])


def test_the_closure_and_the_wear_on_files(files, capsys):
    status, out, err = run(capsys, files / "test.csv", "--load", "450N", "--rig-stiffness",
                           "35MN/m", "--scar-profile", files / "scar.csv", "--length", "5mm",
                           "--out", files / "t.csv", "--plots", files / "plots", "--report",
                           files / "r.html")  # fmt: skip
    assert status == 0, err
    loop, scar = _closure(out)
    assert loop < 0.5 and scar < 1.0  # the force noise is 0.5 N of Q* = 580 N
    volume = float(re.search(r"energy wear \(line, .*scar.csv\): V = ([\d.]+) ± ", out)[1])
    assert volume * 1e-9 == pytest.approx(4 / 3 * DEPTH * HALF_WIDTH * LENGTH, rel=0.01)
    assert (files / "plots" / "test_closure.png").stat().st_size > 0
    page = html.unescape((files / "r.html").read_text(encoding="utf-8"))
    row = re.search(r"loop-scar closure \([^)]*scar.csv\)</th><td>(cycle 4, [^<]*)<", page)
    assert row is not None and _closure(row[1]) == (loop, scar)
    assert re.search(r"energy wear \(line, [^)]*scar.csv\)</th><td>V = ", page)


def test_a_scar_half_as_deep_does_not_close(files, capsys):
    status, _, err = run(capsys, files / "test.csv", "--load", "450N", "--rig-stiffness",
                         "35MN/m", "--scar-profile", files / "half.csv")  # fmt: skip
    assert status == 0, err
    loop, scar = _closure(err)  # without --out the lines go to standard error
    assert loop > 5 and scar > 5


@pytest.mark.parametrize(
    "arguments, message",
    [
        (["--length", "5mm"], "--length or --sphere reads the wear on a --scar-profile"),
        (["--scar-profile", "{scar}", "--length", "5"], "'5' has no unit"),
        (["{test}", "--scar-profile", "{scar}"], "--scar-profile is the scar of one recording"),
        (["--scar-profile", "{scar}", "--no-resolve"], "without --no-resolve"),
        (["--scar-profile", "{test}"], "test.csv"),
        (["--scar-profile", "{scar}", "--out", "{scar}"], "would write over the input file"),
    ],
)
def test_bad_input_is_one_line(files, capsys, arguments, message):
    named = {"scar": files / "scar.csv", "test": files / "test.csv"}
    arguments = [a.format(**named) for a in arguments]
    status, _, err = run(capsys, files / "test.csv", *arguments, "--load", "450N")
    assert status == 2 and message in err and len(err.splitlines()) == 1, err


def test_the_wear_of_a_test_recorded_every_500th_cycle_printed_and_in_the_report(tmp_path, capsys):
    """A gross-slip test on a sphere recorded every 500th cycle (a cycle column) and a groove
    grown by V = α ΣE_d: ΣE_d, V, α and both k within 3 % of their closed forms, printed and
    in the report."""
    stiffness = 35e6
    amplitude = 2.5 * mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    applied, force, cycle = recorded_cycles(amplitude, stiffness)
    recording = {"displacement_um": applied * 1e6, "force_N": force, "cycle": cycle}
    pd.DataFrame(recording).to_csv(tmp_path / "test.csv", index=False)
    sums = recorded_test(amplitude, stiffness)[1]
    x, z, area = mindlin.grown_groove(sums["energy"], ALPHA, LENGTH, 150e-6, noise=20e-9)
    pd.DataFrame({"x_um": x * 1e6, "z_um": z * 1e6}).to_csv(tmp_path / "scar.csv", index=False)
    status, out, err = run(capsys, tmp_path / "test.csv", "--load", "450N", "--cycle-col",
                           "cycle", "--scar-profile", tmp_path / "scar.csv", "--length", "5mm",
                           "--out", tmp_path / "t.csv", "--report", tmp_path / "r.html",
                           )  # fmt: skip
    assert status == 0, err
    volume = area * LENGTH
    archard = {"k_δ": volume / sums["slip"] * 1e9, "k_Δ": volume / sums["nominal"] * 1e9}
    truths = {"ΣE_d": sums["energy"], "V": volume * 1e9, "α": ALPHA * 1e18, **archard}
    page = html.unescape((tmp_path / "r.html").read_text(encoding="utf-8"))
    page = re.sub(r"\\u([0-9a-f]{4})", lambda code: chr(int(code[1], 16)), page)  # JSON's
    for text in (out, page):
        for symbol, truth in truths.items():
            found = re.search(rf"{symbol}(?:</th><td>| = )([\d.]+) ± ", text)
            assert float(found[1]) == pytest.approx(truth, rel=0.03), symbol
