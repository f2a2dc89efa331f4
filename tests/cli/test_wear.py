"""``ecofmaps wear`` on files: results tables as ``ecofmaps loops --out`` writes them and scar
profiles as labs have them, against the closed forms of the Mindlin oracle."""

import re
import warnings

import numpy as np
import pandas as pd
import pytest

import ecofmaps
from ecofmaps.cli.main import main
from ecofmaps.io.tables import results_csv
from tests import mindlin
from tests.lab_cases import (
    ALPHA,
    CYCLES,
    DELTA_T,
    HALF_WIDTH,
    LENGTH,
    LOAD,
    MU,
    recorded_test,
    round_scar,
)

STIFFNESS, THRESHOLD = 35e6, 5.0


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """Three tests' tables and profiles (x, z in µm), and their closed forms."""
    folder = tmp_path_factory.mktemp("wear")
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, STIFFNESS)
    files, truths = [], []
    for i, factor in enumerate((1.5, 2.0, 3.0)):
        results, sums = recorded_test(factor * at, STIFFNESS, CYCLES[:9])
        (folder / f"test{i}.csv").write_text(results_csv(results))
        x, z, area = mindlin.grown_groove(sums["energy"], ALPHA, LENGTH, HALF_WIDTH, THRESHOLD,
                                          10e-9, seed=i)  # fmt: skip
        trace = pd.DataFrame({"x_um": x * 1e6, "z_um": z * 1e6})
        trace.to_csv(folder / f"scar{i}.csv", index=False)
        files += [folder / f"test{i}.csv", "--profile", folder / f"scar{i}.csv"]
        truths.append((sums["energy"], area * LENGTH, sums["slip"], sums["nominal"]))
    return folder, files, truths


def run(capsys, *arguments):
    status = main(["wear", *map(str, arguments)])
    out, err = capsys.readouterr()
    return status, out, err


def test_wear_of_a_campaign_on_files(campaign, capsys):
    folder, files, truths = campaign
    tables = files[::3]
    profiles = [a for f in files[2::3] for a in ("--profile", f)]
    out = folder / "wear.csv"
    status, text, err = run(capsys, *tables, *profiles, "--length", "5mm", "--rig-stiffness",
                            "35MN/m", "--out", out)  # fmt: skip
    assert status == 0, err
    assert "gross slip" in text and "threshold energy" in text and f"wrote {out}" in text
    table = pd.read_csv(out)
    energy, volume, slip, nominal = np.array(truths).T
    np.testing.assert_allclose(table.cumulated_energy_J, energy, rtol=0.03)
    np.testing.assert_allclose(table.wear_volume_mm3 * 1e-9, volume, rtol=0.03)
    alpha = table.energy_wear_coefficient_um3_per_J * 1e-18
    np.testing.assert_allclose(alpha, volume / energy, rtol=0.03)
    np.testing.assert_allclose(table.archard_slip_mm3_per_Nm * 1e-9, volume / slip, rtol=0.03)
    np.testing.assert_allclose(table.archard_nominal_mm3_per_Nm * 1e-9, volume / nominal, rtol=0.03)
    assert (table.sliding_condition == "gross slip").all()
    assert "campaign: no transition to gross slip: results never cross" in text
    again = run(capsys, *tables, *profiles, "--length", "5mm", "--out", out)
    assert again[0] == 2 and "--overwrite" in again[2]


@pytest.mark.parametrize(
    "arguments, message",
    [
        (["--length", "5"], "'5' has no unit"),
        ([], "one of the arguments --length --sphere is required"),
        (["--length", "5mm", "--sphere"], "--sphere: not allowed with argument --length"),
        (["--length", "5mm", "--profile", "{scar}"], "one --profile per test: 1 tests"),
        (["--length", "5mm", "--out", "{table}"], "would write over the input file"),
    ],
)
def test_bad_input_is_one_line(campaign, capsys, arguments, message):
    _, files, _ = campaign
    arguments = [a.format(scar=files[2], table=files[0]) for a in arguments]
    status, _, err = run(capsys, files[0], "--profile", files[2], *arguments)
    assert status == 2 and message in err and len(err.splitlines()) == 1


def test_a_table_without_energies_or_a_profile_without_a_scar(campaign, capsys, tmp_path):
    _, files, _ = campaign
    table = pd.read_csv(files[0]).drop(columns="dissipated_energy_mJ")
    table.to_csv(tmp_path / "no_energy.csv", index=False)
    status, _, err = run(
        capsys, tmp_path / "no_energy.csv", "--profile", files[2], "--length", "5mm"
    )
    assert status == 2 and "no_energy.csv: results: no 'dissipated_energy'" in err
    flat = pd.DataFrame({"x": np.arange(100.0), "z": np.zeros(100)})
    flat.to_csv(tmp_path / "flat.csv", index=False)
    status, _, err = run(capsys, files[0], "--profile", tmp_path / "flat.csv", "--length", "5mm")
    assert status == 2 and "flat.csv" in err and "no depression" in err


def test_a_netcdf_table_reads_as_its_csv(campaign, capsys, tmp_path):
    _, files, _ = campaign
    results = recorded_test(2 * mindlin.transition_amplitude(MU, LOAD, DELTA_T, STIFFNESS),
                             STIFFNESS, CYCLES[:3])[0]  # fmt: skip
    results.to_netcdf(tmp_path / "test.nc")
    (tmp_path / "test.csv").write_text(results_csv(results))
    outputs = [run(capsys, tmp_path / f"test.{kind}", "--profile", files[2], "--length", "5mm")
               for kind in ("nc", "csv")]  # fmt: skip
    assert [status for status, _, _ in outputs] == [0, 0]
    values = [[float(v) for v in re.findall(r"  ([\d.e+-]+) ± ", out)] for _, out, _ in outputs]
    assert len(values[0]) == 5
    np.testing.assert_allclose(values[0], values[1], rtol=1e-5)  # the table's 6 digits


def test_wear_of_a_sphere_on_files(tmp_path, capsys):
    """A round scar traced through its centre (x, z in µm): V, α and k within 3 % of the
    closed forms, printed and in --out."""
    results, sums = recorded_test(2 * mindlin.transition_amplitude(MU, LOAD, DELTA_T, STIFFNESS),
                                  STIFFNESS)  # fmt: skip
    (tmp_path / "test.csv").write_text(results_csv(results))
    volume = ALPHA * sums["energy"]
    x, z, _ = round_scar(volume, 500e-6, noise=50e-9)
    pd.DataFrame({"x_um": x * 1e6, "z_um": z * 1e6}).to_csv(tmp_path / "scar.csv", index=False)
    out = tmp_path / "wear.csv"
    status, text, err = run(capsys, tmp_path / "test.csv", "--profile", tmp_path / "scar.csv",
                            "--sphere", "--out", out)  # fmt: skip
    assert status == 0, err
    assert "wear volume" in text and "energy wear coefficient" in text
    test = pd.read_csv(out).iloc[0]
    assert test.cumulated_energy_J == pytest.approx(sums["energy"], rel=0.03)
    assert test.wear_volume_mm3 * 1e-9 == pytest.approx(volume, rel=0.03)
    assert test.energy_wear_coefficient_um3_per_J * 1e-18 == pytest.approx(ALPHA, rel=0.05)
    assert test.archard_slip_mm3_per_Nm == pytest.approx(volume / sums["slip"] * 1e9, rel=0.03)
    nominal = volume / sums["nominal"] * 1e9
    assert test.archard_nominal_mm3_per_Nm == pytest.approx(nominal, rel=0.03)


def test_a_campaign_across_the_transition(tmp_path, capsys):
    """Four tests from 0.7 to 1.4 Δ_t: Δ_t, δ_t and μ_t printed and in a last row of --out."""
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, STIFFNESS)
    tables, profiles = [], []
    for i, factor in enumerate((0.7, 0.9, 1.1, 1.4)):
        applied = mindlin.sweep([factor * at] * 3)
        _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, STIFFNESS)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a sphere's stick is curved
            results = ecofmaps.analyze_loops(applied, force, LOAD)
        (tmp_path / f"test{i}.csv").write_text(results_csv(results))
        x, z, _ = mindlin.grown_groove(1e4, ALPHA, LENGTH, HALF_WIDTH, noise=10e-9, seed=i)
        pd.DataFrame({"x_um": x * 1e6, "z_um": z * 1e6}).to_csv(tmp_path / f"scar{i}.csv")
        tables.append(tmp_path / f"test{i}.csv")
        profiles += ["--profile", tmp_path / f"scar{i}.csv"]
    out = tmp_path / "wear.csv"
    status, text, err = run(capsys, *tables, *profiles, "--length", "5mm", "--rig-stiffness",
                            "35MN/m", "--out", out)  # fmt: skip
    assert status == 0, err
    assert "campaign: transition to gross slip" in text
    campaign = pd.read_csv(out).set_index("test").loc["campaign"]
    assert campaign.transition_amplitude_um == pytest.approx(at * 1e6, rel=0.05)
    assert campaign.transition_mu == pytest.approx(MU, rel=0.03)
    contact = campaign.transition_amplitude_um - campaign.transition_mu * LOAD / STIFFNESS * 1e6
    assert campaign.transition_contact_amplitude_um == pytest.approx(contact, rel=1e-4)
    assert campaign.transition_amplitude_se_um > 0
