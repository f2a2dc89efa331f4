"""Recording files and ``ecofmaps loops``: formats, columns, units, damaged files, output."""

import io
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import ecofmaps
from ecofmaps.io.files import MANIFEST, record_written
from ecofmaps.io.tables import RESULT_COLUMNS, results_table
from ecofmaps.measured.synthetic import EXAMPLE, example_path, synthetic_recording
from ecofmaps.paper import EXAMPLE_2 as POINT
from ecofmaps.paper import LOAD
from tests.cli.commands import run_loops as run
from tests.recordings import write_csv

CONTACT_COLUMNS = (
    "opening_ratio",
    "contact_amplitude_um",
    "contact_energy_ratio",
    "contact_opening_ratio",
)
# with a recorded load only, with the rig's stiffness only
COLUMNS = [c for c in RESULT_COLUMNS if c != "normal_load_N" and c not in CONTACT_COLUMNS]
RESOLVED_COLUMNS = ("mu_resolved", "mu_resolved_se", "aspect_ratio")


@pytest.fixture(scope="module")
def recording():
    """Four whole cycles of the model (Example 2), 200 samples each: Δ [m], Q [N]."""
    displacement, force = synthetic_recording(**POINT, cycles=5)
    return displacement[:801], force[:801]


def test_results_table_units(recording):
    results = ecofmaps.analyze_loops(*recording, LOAD, resolve=True)
    table = results_table(results)
    assert list(table.columns) == COLUMNS
    plain = results_table(ecofmaps.analyze_loops(*recording, LOAD))  # without the resolved ones
    assert list(plain.columns) == [c for c in COLUMNS if c not in RESOLVED_COLUMNS]
    np.testing.assert_allclose(table.amplitude_um, results.amplitude * 1e6, rtol=1e-15)
    np.testing.assert_allclose(table.dissipated_energy_mJ, results.dissipated_energy * 1e3)
    np.testing.assert_allclose(table.stiffness_MN_per_m, results.stiffness / 1e6, rtol=1e-15)
    assert table.regime.tolist() == ["gross slip"] * 4


# --- the command -----------------------------------------------------------------------------


def test_loops_command(tmp_path, capsys, recording):
    """One file: exactly the issue's columns, the analysis's values in µm, N, mJ, MN/m."""
    path = write_csv(tmp_path / "test.csv", *recording)
    out = tmp_path / "results.csv"
    status, stdout, _ = run(capsys, path, "--load", "450N", "--out", out)
    assert status == 0
    assert f"wrote {out}: 4 cycles" in stdout
    table = pd.read_csv(out)
    assert list(table.columns) == COLUMNS
    expected = results_table(ecofmaps.analyze_loops(*recording, LOAD, resolve=True))
    np.testing.assert_array_equal(table.cycle, [1, 2, 3, 4])
    for column in COLUMNS[1:]:
        if column in ("regime", "quality"):
            assert table[column].tolist() == expected[column].tolist()
            continue
        if column == "mu_resolved_se":  # noise-free: the sampling of the reversals (a branch's
            # last slip sample short of the next stick level) and the file's digits bound it
            assert (table[column] < 5e-4).all() and (expected[column] < 5e-4).all()
            continue
        np.testing.assert_allclose(table[column], expected[column], rtol=1e-5, err_msg=column)
    np.testing.assert_allclose(table.mu_resolved, POINT["mu"], rtol=1e-6)
    assert table.quality.tolist() == ["ok"] * 4
    np.testing.assert_allclose(table.gicof, POINT["mu"], rtol=1e-6)
    np.testing.assert_allclose(table.stiffness_MN_per_m, 35.0, rtol=1e-6)
    assert table.regime.tolist() == ["gross slip"] * 4


@pytest.mark.slow
def test_several_files_and_plots(tmp_path, capsys, recording):
    """Several files add a first 'file' column; --plots writes two PNGs per file."""
    first = write_csv(tmp_path / "a.csv", *recording)
    displacement, force = recording
    second = write_csv(tmp_path / "b.txt", displacement * 2, force, separator=" ")
    out, plots = tmp_path / "all.csv", tmp_path / "plots"
    status, _, _ = run(capsys, first, second, "--load", "0.45kN", "--out", out, "--plots", plots)
    assert status == 0
    table = pd.read_csv(out)
    assert list(table.columns) == ["file", *COLUMNS]
    assert table.file.tolist() == [str(first)] * 4 + [str(second)] * 4
    np.testing.assert_allclose(table.amplitude_um[4:], 100.0, rtol=1e-9)
    for name in ("a", "b"):
        for kind in ("loops", "evolution"):
            png = plots / f"{name}_{kind}.png"
            assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_table_to_stdout(tmp_path, capsys, recording):
    path = write_csv(tmp_path / "test.csv", *recording)
    status, stdout, _ = run(capsys, path, "--load", "450N")
    assert status == 0
    assert stdout.splitlines()[0] == ",".join(COLUMNS)
    assert len(stdout.splitlines()) == 5


def test_example(tmp_path, capsys):
    """The shipped example: ECoF rises by about 4 % while the GICoF stays at μ = 0.8."""
    out = tmp_path / "example.csv"
    status, stdout, _ = run(capsys, "--example", "--out", out)
    assert status == 0
    assert "GICoF median 0.80" in stdout
    table = pd.read_csv(out)
    cycles = EXAMPLE["test_cycles"] // EXAMPLE["recorded_every"]
    assert len(table) == cycles
    assert table.cycle.iloc[-1] == EXAMPLE["test_cycles"]
    assert abs(table.gicof.median() / EXAMPLE["mu"] - 1) < 0.01
    assert (table.regime == "gross slip").all()
    first, last = table.ecof.iloc[:10].mean(), table.ecof.iloc[-10:].mean()
    assert 0.998 < first / EXAMPLE["mu"] < 1.004  # a flat scar: μ_E = μ
    # The model's μ_E at the final groove z_o/x_o = 0.2 (about 4 % above μ, Section 4).
    final = float(
        ecofmaps.energy_cof(EXAMPLE["amplitude"], LOAD, EXAMPLE["stiffness"], EXAMPLE["mu"], 0.2)
    )
    assert abs(last / final - 1) < 0.005
    assert example_path().is_file()
    # a constant amplitude: ΣE_d added under the summary, nothing about a transition
    lines = stdout.splitlines()
    assert len(lines) == 3 and lines[1].startswith("  synthetic_fretting_test.csv: 150 cycles")
    energy = float(re.fullmatch(r"    ΣE_d = (\S+) ± \S+ J over cycles 1 to 300000", lines[2])[1])
    every = np.interp(
        np.arange(1, table.cycle.iloc[-1] + 1), table.cycle, table.dissipated_energy_mJ
    )
    assert energy == pytest.approx(every.sum() * 1e-3, rel=1e-5)


def test_damaged_file_writes_nothing(tmp_path, capsys, recording):
    """A bad cell in a single file stops the command: the old output stays as it was."""
    bad = write_csv(tmp_path / "bad.csv", *recording)
    lines = bad.read_text().splitlines()
    lines[57] = "12.5,oops"
    bad.write_text("\n".join(lines) + "\n")
    out = tmp_path / "results.csv"
    out.write_text("previous results\n")
    record_written([out])  # as if ecofmaps had written it: --overwrite may replace it
    status, stdout, stderr = run(
        capsys, bad, "--load", "450N", "--out", out, "--plots", tmp_path / "plots", "--overwrite"
    )
    assert status == 2
    assert (
        stderr == f"ecofmaps: error: {bad}, line 58: non-numeric value 'oops' in column 'force'\n"
    )
    assert stdout == ""
    assert out.read_text() == "previous results\n"
    assert not (tmp_path / "plots").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [MANIFEST, "bad.csv", "results.csv"]


def test_a_damaged_file_in_a_batch_is_named_and_the_others_written(tmp_path, capsys, recording):
    """A bad cell in the second of two files: one error line naming its file and line, the
    first file's rows and plots written, exit status 1."""
    good = write_csv(tmp_path / "good.csv", *recording)
    bad = write_csv(tmp_path / "bad.csv", *recording)
    lines = bad.read_text().splitlines()
    lines[57] = "12.5,oops"
    bad.write_text("\n".join(lines) + "\n")
    out = tmp_path / "results.csv"
    status, _, stderr = run(
        capsys, good, bad, "--load", "450N", "--out", out, "--plots", tmp_path / "plots"
    )
    assert status == 1
    assert stderr.strip().splitlines()[-1] == (
        f"ecofmaps loops: error: {bad}, line 58: non-numeric value 'oops' in column 'force'"
    )
    table = pd.read_csv(out)
    assert set(table.file) == {str(good)} and len(table) == 4
    plots = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert plots and all(name.startswith("good") for name in plots)


def test_too_few_samples_names_the_last_line(tmp_path, capsys, recording):
    displacement, force = recording
    short = write_csv(tmp_path / "short.csv", displacement[:120], force[:120])
    status, _, stderr = run(capsys, short, "--load", "450N")
    assert status == 2
    assert stderr.startswith(f"ecofmaps: error: {short}, line 122: too few samples for one cycle")
    assert stderr.count("\n") == 1


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ([], "give one or more recording FILEs, or --example"),
        (["--example", "x.csv"], "give one or more recording FILEs, or --example"),
        (["x.csv"], "--load is required"),
        (["x.csv", "--load", "0N"], "argument --load: '0N' is out of range"),
        (["x.csv", "--load", "inf"], "argument --load: 'inf' is out of range"),
        (["--example", "--displacement-unit", ""], "argument --displacement-unit: an empty unit"),
        (["--example", "--displacement-unit", "0um"], "'0um' is not a unit"),
        (
            ["--example", "--force-col", "displacement"],
            "--displacement-col and --force-col name the same column 'displacement'",
        ),
        (["missing.csv", "--load", "450N"], "missing.csv: no such file"),
        (["--example", "--out", "no/such/dir/r.csv"], "its directory does not exist"),
        (["--example", "--displacement-unit", "N"], "is not a length"),
    ],
)
def test_command_errors(tmp_path, capsys, monkeypatch, arguments, message):
    monkeypatch.chdir(tmp_path)
    status, _, stderr = run(capsys, *arguments)
    assert status == 2
    assert message in stderr
    assert stderr.count("\n") == 1 and "Traceback" not in stderr


# --- the loops read along the stroke, the checks, the sign convention --------------------------


def test_resolved_writes_the_reading_along_the_stroke(tmp_path, capsys, recording):
    """--resolved writes resolve_loops's Dataset; its per-cycle values are the table's."""
    path = write_csv(tmp_path / "test.csv", *recording)
    out, resolved = tmp_path / "results.csv", tmp_path / "resolved.nc"
    status, stdout, _ = run(capsys, path, "--load", "450N", "--out", out, "--resolved", resolved)
    assert status == 0 and f"the loops read along the stroke in {resolved}" in stdout
    with xr.open_dataset(resolved, engine="h5netcdf") as stored:
        stored = stored.load()
    assert set(stored.dims) == {"cycle", "position"} and stored.position.size == 201
    table = pd.read_csv(out)
    np.testing.assert_allclose(table.mu_resolved, stored.mu_resolved, rtol=1e-5)
    np.testing.assert_allclose(stored.mu.sel(position=0.0, method="nearest"), 0.8, rtol=1e-5)


def test_no_resolve_gives_the_fast_table(tmp_path, capsys, recording):
    path = write_csv(tmp_path / "test.csv", *recording)
    status, stdout, stderr = run(capsys, path, "--load", "450N", "--no-resolve")
    assert status == 0
    header = stdout.splitlines()[0].split(",")
    assert "mu_resolved" not in header and header[-1] == "quality"
    assert stderr.startswith("test.csv: 4 cycles: 4 ok")  # the summary, beside the table


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--resolved", "r.nc", "--no-resolve"], "not --no-resolve"),
        (["--resolved", "no/such/dir/r.nc"], "cannot write no/such/dir/r.nc (--resolved)"),
    ],
)
def test_resolved_option_errors(tmp_path, capsys, monkeypatch, recording, options, message):
    monkeypatch.chdir(tmp_path)
    path = write_csv(tmp_path / "test.csv", *recording)
    status, _, stderr = run(capsys, path, "--load", "450N", *options)
    assert status == 2 and message in stderr and stderr.count("\n") == 1


def test_a_force_recorded_against_the_displacement(tmp_path, capsys, recording):
    """The other sign convention is refused with the way out; --flip-force reads it."""
    displacement, force = recording
    path = write_csv(tmp_path / "flipped.csv", displacement, -force)
    status, _, stderr = run(capsys, path, "--load", "450N")
    assert status == 2 and stderr.count("\n") == 1
    assert "no plausible cycle" in stderr and "anticlockwise" in stderr and "flip" in stderr
    status, stdout, _ = run(capsys, path, "--load", "450N", "--flip-force")
    table = pd.read_csv(io.StringIO(stdout))
    assert status == 0 and table.quality.tolist() == ["ok"] * 4
    np.testing.assert_allclose(table.gicof, 0.8, rtol=1e-6)


def test_flagged_cycles_are_one_line_warnings_and_nan(tmp_path, capsys, recording):
    """A cycle with a dead force channel: NaN with its reason, one warning line naming the file."""
    displacement, force = recording
    force = force.copy()
    force[200:400] = force[200]  # the second cycle: the channel stuck
    path = write_csv(tmp_path / "stuck.csv", displacement, force)
    status, stdout, stderr = run(capsys, path, "--load", "450N")
    table = pd.read_csv(io.StringIO(stdout))
    assert status == 0
    flagged = table[table.quality != "ok"]
    assert len(flagged) >= 1 and flagged.ecof.isna().all() and flagged.gicof.isna().all()
    warnings = [line for line in stderr.splitlines() if "warning" in line]
    assert warnings and all(
        line.startswith("ecofmaps loops: warning: stuck.csv: ") for line in warnings
    )
    assert "Traceback" not in stderr and ".py:" not in stderr


def test_a_latin1_export_warns_in_one_line_of_the_command(tmp_path, capsys, recording):
    """An old rig PC's export (Latin-1): its warning is one line of ``ecofmaps loops``,
    without Python's source line."""
    path = write_csv(tmp_path / "old_pc.csv", *recording, header=("displacement [µm]", "force"))
    path.write_bytes(
        path.read_text(encoding="utf-8").replace("# a", "# Prüfstand: a").encode("latin-1")
    )
    status, _, stderr = run(capsys, path, "--load", "450N", "--no-resolve")
    assert status == 0
    assert stderr.splitlines()[0] == (
        f"ecofmaps loops: warning: {path}, line 1: byte 0xfc is not UTF-8; the file is read "
        "as Latin-1 from this line on (numbers are the same in both)"
    )
    assert "Warning" not in stderr and ".py:" not in stderr


def test_the_summary_reads_the_gross_slip_cycles_only():
    """The summary line's medians and first and last ECoF are over the cycles in gross
    slip (its regime code), with the cycles without a value left out."""
    from ecofmaps.cli.loops import _summary
    from ecofmaps.model.regimes import GROSS_SLIP, PARTIAL_SLIP

    gross, stuck = int(GROSS_SLIP), int(PARTIAL_SLIP)
    results = xr.Dataset(
        {
            "regime": ("cycle", np.array([stuck, gross, gross, stuck, gross, gross, stuck])),
            "gicof": ("cycle", [9.0, 0.7, np.nan, 9.0, 0.9, 0.8, 9.0]),
            "ecof": ("cycle", [9.0, np.nan, 0.61, 9.0, 0.62, 0.63, 9.0]),
            "quality": ("cycle", np.array(["ok"] * 7, dtype=object)),
        },
        coords={"cycle": np.arange(1, 8)},
        attrs={"quality_summary": "7 cycles: 7 ok", "incomplete_cycles": 1},
    )
    line = _summary(Path("rig.csv"), results, recording=None)
    assert line == (
        "rig.csv: 7 cycles: 7 ok (1 incomplete dropped); mixed slip (the regime changes at "
        "cycles 2, 4, 5, 7); GICoF median 0.8000; "
        "ECoF 0.6100 (first) to 0.6300 (last)"
    )
    none = results.assign(regime=results.regime * 0 + stuck)
    assert _summary(Path("rig.csv"), none, None) == (
        "rig.csv: 7 cycles: 7 ok (1 incomplete dropped); partial slip"
    )
    none.attrs["cycles_from"] = "displacement reversals"
    assert _summary(Path("rig.csv"), none, None) == (
        "rig.csv: 7 cycles: 7 ok (1 incomplete dropped: partial, where the recording starts "
        "or ends mid-cycle); partial slip"
    )


def test_rig_stiffness_reads_the_regime_on_the_contact(tmp_path, capsys):
    """A sphere (the Mindlin oracle) 10 % beyond its transition behind a 35 MN/m rig: partial
    slip on the applied displacement, gross slip on the contact's with --rig-stiffness, whose
    ratios are then columns of the table; a stiffness that is not positive is one line."""
    from tests import mindlin

    stiffness = 35e6
    at = mindlin.transition_amplitude(0.8, LOAD, 6e-6, stiffness)
    applied = mindlin.sweep([1.1 * at] * 3, 200)
    _, force = mindlin.drive(mindlin.Contact(0.8, LOAD, 6e-6), applied, stiffness)
    path = write_csv(tmp_path / "sphere.csv", applied, force)
    status, bare, _ = run(capsys, path, "--load", "450N", "--no-resolve")
    assert status == 0
    table = pd.read_csv(io.StringIO(bare))
    assert table.regime.tolist() == ["partial slip"] * 4
    assert not set(CONTACT_COLUMNS) & set(table.columns)
    status, out, _ = run(capsys, path, "--load", "450N", "--no-resolve", "--rig-stiffness",
                         "35MN/m")  # fmt: skip
    assert status == 0
    table = pd.read_csv(io.StringIO(out))
    assert table.regime.tolist() == ["gross slip"] * 4
    contact = table.amplitude_um - table.max_force_N / stiffness * 1e6
    np.testing.assert_allclose(table.contact_amplitude_um, contact, rtol=1e-5)
    assert (table.contact_energy_ratio > 0.2).all()
    status, _, err = run(capsys, path, "--load", "450N", "--rig-stiffness", "-1MN/m")
    assert status != 0 and "rig_stiffness" in err.replace("-", "_") and "Traceback" not in err


@pytest.mark.parametrize("rig", [None, 35e6])
def test_a_sweep_prints_its_transition(tmp_path, capsys, rig):
    """The Mindlin oracle swept from 0.45 to 1.8 Δ_t, two cycles at each amplitude, as a CSV
    file: the summary gives Δ_t within 5 % and μ_t within 3 % with the rig's stiffness; δ_t
    needs it, or the spring fitted behind the sphere's stick, which stands for it."""
    from tests import mindlin

    at = mindlin.transition_amplitude(0.8, LOAD, 6e-6, 35e6)
    applied = mindlin.sweep(np.repeat(np.linspace(0.45, 1.8, 20) * at, 2), 200)
    _, force = mindlin.drive(mindlin.Contact(0.8, LOAD, 6e-6), applied, 35e6)
    path = write_csv(tmp_path / "sweep.csv", applied, force)
    options = [] if rig is None else ["--rig-stiffness", "35MN/m"]
    status, _, err = run(capsys, path, "--load", "450N", "--no-resolve", *options)
    assert status == 0, err
    found = re.search(
        r"\n  transition to gross slip: Δ_t = (\S+) ± \S+ µm, δ_t = (.+), "
        r"μ_t = Q\*/P = (\S+)",
        err,
    )
    amplitude, contact, mu = found.groups()
    assert float(mu) == pytest.approx(0.8, rel=0.03)
    assert float(amplitude) == pytest.approx(at * 1e6, rel=0.05)
    if rig is None:
        return
    contact_at = float(amplitude) - float(mu) * LOAD / 35e6 * 1e6  # δ_t = Δ_t - μ_t P/S
    assert float(contact.split()[0]) == pytest.approx(contact_at, abs=0.01)  # printed to 0.01
    docs = (Path(__file__).parents[2] / "docs" / "lab.md").read_text()
    assert "".join(f"    {line.strip()}\n" for line in err.splitlines()[-2:]) in docs


def test_the_help_names_every_column_of_the_table(capsys):
    """``ecofmaps loops --help`` lists each column the table can hold."""
    status, out, _ = run(capsys, "--help")
    assert status == 0
    text = " ".join(out.split())
    missing = [column for column in RESULT_COLUMNS if column not in text]
    assert not missing, missing
