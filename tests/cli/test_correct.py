"""`ecofmaps correct`: one point, CSV tables, errors naming file and line, atomic output."""

import csv
import io
import os

import numpy as np
import pytest

import ecofmaps
from ecofmaps.io.files import MANIFEST, record_written
from tests.cli.commands import run

EXAMPLE_2 = ["--amplitude", "50um", "--load", "450N", "--stiffness", "35MN/m"]


def printed(out: str, label: str) -> str:
    """The value printed on the line starting with ``label``."""
    line = next(line for line in out.splitlines() if line.strip().startswith(label))
    return line.split()[-1]


def test_one_point(capsys):
    status, out, err = run(capsys, "correct", "--ecof", "0.83", *EXAMPLE_2, "--aspect-ratio", "0.2")
    assert status == 0 and err == ""
    mu = float(ecofmaps.correct_ecof(0.83, 50e-6, 450.0, 35e6, 0.2))
    assert float(printed(out, "contact coefficient")) == pytest.approx(mu, rel=5e-6)  # 6 digits
    assert float(printed(out, "contact CoF over energy CoF")) == pytest.approx(mu / 0.83, rel=5e-6)
    assert len(printed(out, "contact coefficient").replace("0.", "", 1)) >= 4
    assert "regime" not in out  # a corrected value is a gross-slip loop


def test_one_point_from_the_scar(capsys):
    status, out, _ = run(
        capsys, "correct", "--ecof", "0.83", *EXAMPLE_2, "--scar-depth", "8um",
        "--scar-half-width", "40 µm",
    )  # fmt: skip
    assert status == 0
    assert "0.2 (scar 8 µm deep, 40 µm half-width)" in out
    mu = float(ecofmaps.correct_ecof(0.83, 50e-6, 450.0, 35e6, 0.2))
    assert float(printed(out, "contact coefficient")) == pytest.approx(mu, rel=5e-6)


POINT = "--ecof 0.83 --amplitude 50um --load 450N --stiffness 35MN/m"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        ("--ecof 5 --amplitude 50um --load 450N --stiffness 35MN/m --aspect-ratio 0.2",
         "ecof = 5 cannot be corrected"),
        (POINT, "give --aspect-ratio, or both --scar-depth"),
        (POINT + " --aspect-ratio 0.2 --scar-depth 8um --scar-half-width 40um",
         "give --aspect-ratio, or both"),
        (POINT + " --scar-depth 8um", "give --aspect-ratio, or both"),
        ("--ecof 0.83 --amplitude 50um --aspect-ratio 0.2", "give --load, --stiffness"),
        (POINT + " --aspect-ratio 0.2 --out x.csv", "--out writes a corrected TABLE"),
        # z_o/x_o = 5 and λ = P/(SΔ*) = 1e-3: μ_E falls from 9.43 to 5.68 as μ rises
        ("--ecof 7 --amplitude 50um --load 450N --stiffness 9000MN/m --aspect-ratio 5",
         "three contact CoFs"),
    ],
)  # fmt: skip
def test_one_point_errors(capsys, argv, message):
    status, out, err = run(capsys, "correct", *argv.split())
    assert status == 2 and out == ""
    assert message in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ("--amplitude 450N", "argument --amplitude: '450N' is not a length"),
        ("--ecof 0", "argument --ecof: '0' is out of range: the energy coefficient of friction "
         "must satisfy 0 < μ_E < inf"),
        ("--load inf", "argument --load: 'inf' is out of range"),
        ("--scar-half-width 0um", "argument --scar-half-width: '0um' is out of range"),
        ("--scar-depth -1um", "argument --scar-depth: '-1um' is out of range"),
    ],
)  # fmt: skip
def test_options_are_read_and_checked_by_argparse(capsys, change, message):
    """Quantities are read with units and range-checked naming the option (status 2)."""
    options = dict(zip(*[iter(f"{POINT} --aspect-ratio 0.2".split())] * 2, strict=True))
    options.update(dict([change.split()]))
    if "--scar" in change:
        del options["--aspect-ratio"]
        options = {"--scar-depth": "8um", "--scar-half-width": "40um", **options}
        options.update(dict([change.split()]))
    status, _, err = run(capsys, "correct", *[f"{key}={value}" for key, value in options.items()])
    assert status == 2 and message in err.splitlines()[-1] and "Traceback" not in err


# --- tables -------------------------------------------------------------------------------

TABLE = """\
source,ecof,amplitude_um,load_N,stiffness_MN_per_m,aspect_ratio,scar_depth_um,scar_half_width_um
Example 2,0.8308,50,450,35,0.2,,
"rigid, deep",0.9,25,200,inf,,3,40

flat,0.7,50,450,35,0,,
"""


def write(path, text):
    path.write_text(text, encoding="utf-8")
    return path


def read_csv(text):
    return list(csv.DictReader(io.StringIO(text)))


def test_table_to_file(tmp_path, capsys):
    table = write(tmp_path / "ecof.csv", TABLE)
    out = tmp_path / "corrected.csv"
    status, stdout, err = run(capsys, "correct", table, "--out", out)
    assert status == 0 and err == ""
    assert f"wrote {out}: 3 rows corrected" in stdout
    rows = read_csv(out.read_text(encoding="utf-8"))
    assert list(rows[0]) == [*TABLE.splitlines()[0].split(","), "mu", "correction_factor"]
    # every input cell kept as written
    assert [r["source"] for r in rows] == ["Example 2", "rigid, deep", "flat"]
    assert rows[1]["stiffness_MN_per_m"] == "inf" and rows[1]["aspect_ratio"] == ""
    expected = np.asarray(
        ecofmaps.correct_ecof(
            np.array([0.8308, 0.9, 0.7]), np.array([50e-6, 25e-6, 50e-6]),
            np.array([450.0, 200.0, 450.0]), np.array([35e6, np.inf, 35e6]),
            np.array([0.2, 3.0 / 40.0, 0.0]),
        )
    )  # fmt: skip
    mu = np.array([float(r["mu"]) for r in rows])
    np.testing.assert_allclose(mu, expected, rtol=1e-9)  # 10 significant digits
    factor = np.array([float(r["correction_factor"]) for r in rows])
    np.testing.assert_allclose(factor, expected / np.array([0.8308, 0.9, 0.7]), rtol=1e-9)
    assert mu[0] == pytest.approx(0.8, abs=2e-6) and mu[2] == 0.7  # Example 2; flat scar


def test_table_to_stdout(tmp_path, capsys):
    table = write(tmp_path / "ecof.csv", TABLE)
    status, stdout, _ = run(capsys, "correct", table)
    assert status == 0
    assert len(read_csv(stdout)) == 3


def test_table_as_a_spreadsheet_writes_it(tmp_path, capsys):
    """';' with decimal commas and '#' comments in, the same separator and commas out."""
    lab = "# rig 2\n" + TABLE.replace(",", ";").replace('"rigid; deep"', "rigid deep")
    lab = lab.replace("0.8308", "0,8308").replace("0.9", "0,9").replace("0.2;", "0,2;")
    _, reference, _ = run(capsys, "correct", write(tmp_path / "ecof.csv", TABLE))
    status, stdout, err = run(capsys, "correct", write(tmp_path / "lab.csv", lab))
    assert status == 0 and err == ""
    expected = [row[-2:] for row in csv.reader(io.StringIO(reference))]
    got = [row[-2:] for row in csv.reader(io.StringIO(stdout), delimiter=";")]
    assert got == [[cell.replace(".", ",") for cell in row] for row in expected]
    status, _, err = run(capsys, "correct", write(tmp_path / "bad.csv", lab + "flat;0,7;x\n"))
    assert status != 0 and f"{tmp_path / 'bad.csv'}, line 7: " in err


HEADER = "ecof,amplitude_um,load_N,stiffness_MN_per_m,aspect_ratio\n"
SCARS = "ecof,amplitude_um,load_N,stiffness_MN_per_m,scar_depth_um,scar_half_width_um\n"
BAD_TABLES = [
    # (text, line, message): the table cannot be read, nothing is written
    ("", 1, "the file is empty"),
    (HEADER, 1, "no data rows"),
    ("ecof,amplitude_um,stiffness_MN_per_m,aspect_ratio\n0.8,50,35,0.2\n", 1,
     "missing column(s) load_N"),
    ("ecof,amplitude_um,load_N,stiffness_MN_per_m\n0.8,50,450,35\n", 1,
     "missing column(s) aspect_ratio (or scar_depth_um + scar_half_width_um)"),
    ("ecof,amplitude_um,load_N,stiffness_MN_per_m,aspect_ratio,mu\n0.8,50,450,35,0.2,1\n", 1,
     "column(s) mu would be overwritten"),
    (HEADER.replace("aspect_ratio", "aspect_ratio,status") + "0.8,50,450,35,0.2,x\n", 1,
     "column(s) status would be overwritten"),
    ("ecof,ecof,amplitude_um,load_N,stiffness_MN_per_m,aspect_ratio\n", 1,
     "repeated column(s) ecof"),
    (HEADER + "0.8,50,450,35\n", 2, "4 fields, but the header has 5 columns"),
]  # fmt: skip


@pytest.mark.parametrize(("text", "line", "message"), BAD_TABLES)
def test_bad_table_names_file_and_line(tmp_path, capsys, text, line, message):
    """One-line error naming file and line; an existing OUT is left exactly as it was."""
    table = write(tmp_path / "bad.csv", text)
    out = write(tmp_path / "out.csv", "previous results\n")
    os.utime(out, (1_000_000_000, 1_000_000_000))
    record_written([out])  # as if ecofmaps had written it: --overwrite may replace it
    status, stdout, err = run(capsys, "correct", table, "--out", out, "--overwrite")
    assert status == 2 and stdout == ""
    assert f"{table}, line {line}: " in err and message in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert out.read_text(encoding="utf-8") == "previous results\n"
    assert out.stat().st_mtime == 1_000_000_000
    listed = sorted(p.name for p in tmp_path.iterdir())
    assert listed == [MANIFEST, "bad.csv", "out.csv"]  # no temp left


BAD_ROWS = [
    # (row, message, status): the row gets NaN, the others are corrected
    ("0.8,50,450,,0.2", "stiffness_MN_per_m = '' is not a number", "invalid"),
    ("0.8,50,450,35,abc", "aspect_ratio = 'abc' is not a number", "invalid"),
    ("0.8,50,-450,35,0.2", "load_N must satisfy 0 < load_N < inf, got -450", "invalid"),
    ("9,50,450,35,0.2", "ecof = 9 cannot be corrected: it is at or above", "no gross slip"),
]


@pytest.mark.parametrize(("row", "message", "label"), BAD_ROWS)
def test_a_bad_row_gets_nan_and_its_reason_the_others_are_corrected(
    tmp_path, capsys, row, message, label
):
    table = write(
        tmp_path / "lit.csv", HEADER + "0.83,50,450,35,0.2\n" + row + "\n0.7,50,450,35,0\n"
    )
    out = tmp_path / "corrected.csv"
    status, stdout, err = run(capsys, "correct", table, "--out", out)
    assert status == 1
    assert err.startswith(f"ecofmaps correct: error: {table}, line 3: ")
    assert message in err and len(err.splitlines()) == 1
    assert f"wrote {out}: 2 of 3 rows corrected, 1 not (NaN, the reason in" in stdout
    rows = read_csv(out.read_text(encoding="utf-8"))
    assert [r["status"] for r in rows] == ["corrected", label, "corrected"]
    assert rows[1]["mu"] == rows[1]["correction_factor"] == "nan"
    good = ecofmaps.correct_ecof(np.array([0.83, 0.7]), 50e-6, 450.0, 35e6, np.array([0.2, 0.0]))
    np.testing.assert_allclose([float(rows[0]["mu"]), float(rows[2]["mu"])], good, rtol=1e-9)


def test_every_bad_row_is_named_and_a_table_of_good_rows_has_no_status(tmp_path, capsys):
    rows = ["9,50,450,35,0.2", "0.8,50,450,35,0.2", "0.8,x,450,35,0.2"]
    table = write(tmp_path / "lit.csv", HEADER + "\n".join(rows) + "\n")
    status, stdout, err = run(capsys, "correct", table)
    lines = err.splitlines()
    assert status == 1 and len(lines) == 2
    assert lines[0].startswith(f"ecofmaps correct: error: {table}, line 2: ecof = 9 ")
    assert lines[1].startswith(f"ecofmaps correct: error: {table}, line 4: amplitude_um = 'x'")
    assert [r["status"] for r in read_csv(stdout)] == ["no gross slip", "corrected", "invalid"]
    status, stdout, err = run(capsys, "correct", write(tmp_path / "good.csv", HEADER + rows[1]))
    assert status == 0 and err == "" and "status" not in stdout


def test_rows_given_by_the_scar_one_way_only(tmp_path, capsys):
    rows = ["0.8,50,450,35,8,", "0.8,50,450,35,8,0", "0.83,50,450,35,8,40"]
    table = write(tmp_path / "scars.csv", SCARS + "\n".join(rows) + "\n")
    status, stdout, err = run(capsys, "correct", table)
    assert status == 1 and len(err.splitlines()) == 2
    assert "line 2: give the aspect ratio one way" in err
    assert "line 3: scar_half_width_um must satisfy 0 < scar_half_width_um < inf" in err
    assert [r["status"] for r in read_csv(stdout)] == ["invalid", "invalid", "corrected"]


def test_table_command_errors(tmp_path, capsys):
    table = write(tmp_path / "ecof.csv", TABLE)
    status, _, err = run(capsys, "correct", table, "--ecof", "0.8")
    assert status == 2 and "give a TABLE or one point's options, not both (--ecof)" in err
    status, _, err = run(capsys, "correct", tmp_path / "missing.csv")
    assert status == 2 and "missing.csv" in err
    status, _, err = run(capsys, "correct", table, "--out", tmp_path / "no" / "out.csv")
    assert status == 2 and "its directory does not exist" in err
    binary = tmp_path / "binary.csv"
    binary.write_bytes(b"\xff\xfe\x00ecof")
    status, _, err = run(capsys, "correct", binary)
    assert status == 2 and "line 1: not a UTF-8 text file" in err
