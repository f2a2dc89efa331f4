"""`ecofmaps model` and `ecofmaps correct` on a measured scar profile (--scar-profile FILE)."""

import csv
import io

import numpy as np
import pytest

import ecofmaps
from ecofmaps.measured.synthetic import scar_example_path, scar_example_trace
from ecofmaps.model.profiles import ScarProfileWarning
from ecofmaps.paper import AMPLITUDE, LOAD, STIFFNESS
from tests.cli.commands import run

EXAMPLE = scar_example_path()
RIG = ["--amplitude", "50um", "--load", "450N", "--stiffness", "35MN/m"]
POINT = dict(amplitude=AMPLITUDE, load=LOAD, stiffness=STIFFNESS)


def values(out: str, label: str) -> list[str]:
    """The numbers printed on the line starting with ``label`` (profile, then parabola)."""
    line = next(line for line in out.splitlines() if line.strip().startswith(label))
    return [word for word in line.split() if word[0].isdigit()]


@pytest.fixture(scope="module")
def example():
    return ecofmaps.read_scar_profile(EXAMPLE)


def write_trace(path, x_um, z_um, header="x,z"):
    rows = "\n".join(f"{x:.4f},{z:.5f}" for x, z in zip(x_um, z_um, strict=True))
    path.write_text(f"{header}\n{rows}\n", encoding="utf-8")
    return path


# --- ecofmaps model ---------------------------------------------------------------------


@pytest.mark.slow
def test_model_on_the_example_profile_beside_the_parabola(capsys, example):
    status, out, err = run(capsys, "model", "--scar-profile", EXAMPLE)
    assert status == 0 and err == ""
    assert str(EXAMPLE) in out and "1351 samples, levelled" in out
    assert values(out, "wear scar depth") == [f"{float(example.depth) * 1e6:.6g}"]
    assert values(out, "wear scar half-width (detected)") == [
        f"{float(example.half_width) * 1e6:.6g}"
    ]
    ratio = float(example.aspect_ratio)
    assert values(out, "scar aspect ratio") == [f"{ratio:.6g}"]
    assert "parabola of the same D/W" in out
    for label, name in [
        ("slip amplitude", "slip_amplitude"),
        ("peak tangential force", "max_force"),
        ("dissipated energy", "dissipated_energy"),
        ("energy coefficient of friction", "energy_cof"),
    ]:
        function = getattr(ecofmaps, name)
        expected = [
            float(function(**POINT, mu=0.8, profile=example)),
            float(function(**POINT, mu=0.8, aspect_ratio=ratio)),
        ]
        shown = [float(v) for v in values(out, label)]
        scale = {"slip_amplitude": 1e6, "dissipated_energy": 1e3}.get(name, 1.0)
        assert shown == pytest.approx(np.array(expected) * scale, rel=5e-6)  # 6 digits
    ecof_profile, ecof_parabola = (float(v) for v in values(out, "energy coefficient"))
    # The shipped scar (a flat bottom with a hump) gives half the parabola's bias.
    assert ecof_profile == pytest.approx(0.810531, abs=2e-6)
    assert ecof_parabola == pytest.approx(0.821158, abs=2e-6)
    assert out.count("gross slip") == 2


@pytest.mark.slow
def test_model_reading_options_reach_the_reader(capsys, tmp_path):
    x, z = scar_example_trace()  # metres
    path = write_trace(tmp_path / "scar_mm.csv", x * 1e3, z * 1e3, header="pos,height")
    argv = ["model", "--scar-profile", path, "--x-column", "pos", "--z-column", "height",
            "--x-unit", "mm", "--z-unit", "mm", "--smoothing", "4um",
            "--profile-half-width", "480um", "--mapping", "physical",
            "--amplitude", "30um"]  # fmt: skip
    status, out, err = run(capsys, *argv)
    assert status == 0, err
    profile = ecofmaps.scar_profile(x, z, half_width=480e-6, smoothing=4e-6, level=True)
    mu_e = ecofmaps.energy_cof(30e-6, 450.0, 35e6, 0.8, profile=profile, mapping="physical")
    assert float(values(out, "energy coefficient")[0]) == pytest.approx(float(mu_e), rel=5e-6)
    assert "480 µm" in out and "(given)" in out and "smoothed over 4 µm" in out
    assert "X = x (physical)" in out


def test_model_on_an_unlevelled_profile(capsys, example):
    status, out, _ = run(capsys, "model", "--scar-profile", EXAMPLE, "--no-level")
    assert status == 0 and "as given" in out
    tilted = ecofmaps.read_scar_profile(EXAMPLE, level=False)
    mu_e = float(ecofmaps.energy_cof(**POINT, mu=0.8, profile=tilted))
    assert float(values(out, "energy coefficient")[0]) == pytest.approx(mu_e, rel=5e-6)
    assert mu_e != pytest.approx(float(ecofmaps.energy_cof(**POINT, mu=0.8, profile=example)))


def test_model_beyond_gross_slip_on_a_profile(capsys):
    status, out, _ = run(capsys, "model", "--scar-profile", EXAMPLE, "--stiffness", "5MN/m")
    assert status == 0
    assert values(out, "slip amplitude") == ["0", "0"]
    assert out.count("no gross slip") == 2 and "undefined" in out


# --- ecofmaps correct ---------------------------------------------------------------------


@pytest.mark.slow
def test_correct_one_point_on_the_profile(capsys, example):
    status, out, err = run(capsys, "correct", "--ecof", "0.85", *RIG, "--scar-profile", EXAMPLE)
    assert status == 0 and err == ""
    mu = float(ecofmaps.correct_ecof(0.85, **POINT, profile=example))
    shortcut = float(ecofmaps.correct_ecof(0.85, **POINT, aspect_ratio=float(example.aspect_ratio)))
    shown = [float(v) for v in values(out, "contact coefficient")]
    assert shown == pytest.approx([mu, shortcut], rel=5e-6)
    assert shown == pytest.approx([0.839814, 0.828079], abs=2e-6)
    factors = [float(v) for v in values(out, "contact CoF over energy CoF")]
    assert factors == pytest.approx([mu / 0.85, shortcut / 0.85], rel=5e-6)
    assert "D/W" in out and str(EXAMPLE) in out


def test_correct_beyond_gross_slip_on_the_profile(capsys):
    # μ_E ≥ μ, and gross slip needs μ < SΔ*/P = 35e6 · 50e-6 / 450 = 3.889
    status, out, err = run(capsys, "correct", "--ecof", "4", *RIG, "--scar-profile", EXAMPLE)
    assert status == 2 and out == ""
    assert "ecof = 4 cannot be corrected on this profile: it is at or above" in err
    assert "3.88889" in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_correct_a_table_on_the_profile(capsys, tmp_path, example):
    table = tmp_path / "tests.csv"
    table.write_text(
        "test,ecof,amplitude_um,load_N,stiffness_MN_per_m\nA,0.85,50,450,35\n\nB,0.83,25,450,50\n",
        encoding="utf-8",
    )
    status, out, err = run(capsys, "correct", table, "--scar-profile", EXAMPLE)
    assert status == 0 and err == ""
    rows = list(csv.DictReader(io.StringIO(out)))
    assert list(rows[0]) == [
        "test", "ecof", "amplitude_um", "load_N", "stiffness_MN_per_m", "mu",
        "correction_factor", "mu_parabolic",
    ]  # fmt: skip
    ecof = np.array([0.85, 0.83])
    rig = dict(amplitude=np.array([50e-6, 25e-6]), load=450.0, stiffness=np.array([35e6, 50e6]))
    mu = ecofmaps.correct_ecof(ecof, **rig, profile=example)
    shortcut = ecofmaps.correct_ecof(ecof, **rig, aspect_ratio=float(example.aspect_ratio))
    assert [float(r["mu"]) for r in rows] == pytest.approx(np.asarray(mu), rel=1e-9)
    assert [float(r["mu_parabolic"]) for r in rows] == pytest.approx(np.asarray(shortcut), rel=1e-9)
    assert [float(r["correction_factor"]) for r in rows] == pytest.approx(mu / ecof, rel=1e-9)

    out_file = tmp_path / "corrected.csv"
    status, out, _ = run(capsys, "correct", table, "--scar-profile", EXAMPLE, "--out", out_file)
    assert status == 0 and "2 rows corrected on the scar profile" in out
    assert list(csv.DictReader(out_file.open()))[1]["mu"] == rows[1]["mu"]


def test_correct_refuses_to_overwrite_the_profile(capsys, tmp_path):
    table = tmp_path / "tests.csv"
    table.write_text("ecof,amplitude_um,load_N,stiffness_MN_per_m\n0.85,50,450,35\n")
    profile = write_trace(tmp_path / "scar.csv", *(v * 1e6 for v in scar_example_trace()))
    before = profile.read_bytes()
    status, out, err = run(capsys, "correct", table, "--scar-profile", profile, "--out", profile)
    assert status == 2 and out == ""
    assert f"--out {profile} would write over the input file" in err
    assert profile.read_bytes() == before


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ("ecof,amplitude_um,load_N,stiffness_MN_per_m,aspect_ratio\n0.85,50,450,35,0.2\n",
         "line 1: column(s) aspect_ratio give the scar, but so does the profile"),
        ("ecof,amplitude_um,load_N,stiffness_MN_per_m,mu_parabolic\n0.85,50,450,35,1\n",
         "line 1: column(s) mu_parabolic would be overwritten"),
    ],
)  # fmt: skip
def test_correct_table_errors_on_a_profile(capsys, tmp_path, table, message):
    path = tmp_path / "tests.csv"
    path.write_text(table, encoding="utf-8")
    out_file = tmp_path / "out.csv"
    status, out, err = run(capsys, "correct", path, "--scar-profile", EXAMPLE, "--out", out_file)
    assert status == 2 and out == ""
    assert err.startswith(f"ecofmaps: error: {path}, ") and message in err
    assert len(err.strip().splitlines()) == 1 and not out_file.exists()


def test_a_row_the_profile_cannot_correct_gets_nan_and_the_others_are_written(capsys, tmp_path):
    path = tmp_path / "tests.csv"
    path.write_text("ecof,amplitude_um,load_N,stiffness_MN_per_m\n0.85,50,450,35\n4.0,50,450,35\n")
    status, out, err = run(capsys, "correct", path, "--scar-profile", EXAMPLE)
    assert status == 1
    assert err.startswith(f"ecofmaps correct: error: {path}, line 3: ecof = 4 cannot be corrected")
    assert "on this profile" in err and len(err.splitlines()) == 1
    rows = list(csv.DictReader(io.StringIO(out)))
    assert [r["status"] for r in rows] == ["corrected", "no gross slip"]
    assert rows[1]["mu"] == rows[1]["mu_parabolic"] == "nan" and float(rows[0]["mu"]) > 0


# --- errors --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["model", "--scar-profile", EXAMPLE, "--aspect-ratio", "0.2"],
         "give --scar-profile or --aspect-ratio, not both"),
        (["correct", "--ecof", "0.85", *RIG, "--scar-profile", EXAMPLE, "--scar-depth", "8um",
          "--scar-half-width", "40um"],
         "give --scar-profile or --scar-depth, --scar-half-width, not both"),
        (["model", "--x-unit", "mm"], "--x-unit reads a --scar-profile: give the FILE too"),
        (["correct", "--ecof", "0.85", *RIG, "--aspect-ratio", "0.2", "--no-level"],
         "--no-level reads a --scar-profile"),
        (["model", "--scar-profile", EXAMPLE, "--x-unit", "N"],
         "argument --x-unit: 'N' is not a length"),
        (["model", "--scar-profile", EXAMPLE, "--smoothing=-1um"],
         "argument --smoothing: '-1um' is out of range"),
        (["model", "--scar-profile", EXAMPLE, "--mapping", "physical", "--groove-half-width",
          "40um"], "mapping"),
        (["model", "--scar-profile", "no/such/file.csv"], "no/such/file.csv"),
    ],
)  # fmt: skip
def test_option_errors_are_one_line(capsys, argv, message):
    status, out, err = run(capsys, *argv)
    assert status == 2 and out == ""
    assert err.startswith("ecofmaps: error: ") and message in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def _damaged(kind: str) -> str:
    """The example trace as text (µm), damaged as ``kind`` says."""
    x, z = (v * 1e6 for v in scar_example_trace())
    lines = ["x,z", *(f"{a:.4f},{b:.5f}" for a, b in zip(x, z, strict=True))]
    if kind == "unsorted":
        lines[101], lines[102] = lines[102], lines[101]
    elif kind == "repeated":
        lines[201] = lines[200]
    elif kind == "text":
        lines[301] = "600.0,abc"
    elif kind == "fields":
        lines[401] = "800.0,1.0,2.0"
    elif kind == "nan":
        lines[501] = "1000.0,nan"
    elif kind == "column":
        lines[0] = "x,height"
    elif kind == "flat":
        lines = ["x,z", *(f"{a:.4f},{0.001 * np.sin(a):.5f}" for a in x)]
    elif kind == "edge":  # the scar runs off the end of the trace
        lines = lines[:700]
    elif kind == "sparse":  # 12 samples across the scar
        lines = ["x,z", *lines[1::90]]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    ("kind", "line", "message"),
    [
        ("unsorted", 103, "goes back from"),
        ("repeated", 202, "repeats"),
        ("text", 302, "abc"),
        ("fields", 402, "3 fields"),
        ("nan", 502, "nan"),
        ("column", 1, "z"),
        ("flat", 2, "no"),
        ("edge", 2, "trace"),
        ("sparse", 2, "samples"),
    ],
)
def test_damaged_profiles_name_file_and_line(capsys, tmp_path, kind, line, message):
    path = tmp_path / f"{kind}.csv"
    path.write_text(_damaged(kind), encoding="utf-8")
    for argv in (["model", "--scar-profile", path],
                 ["correct", "--ecof", "0.85", *RIG, "--scar-profile", path]):  # fmt: skip
        status, out, err = run(capsys, *argv)
        assert status == 2 and out == "", err
        assert err.startswith(f"ecofmaps: error: {path}, line {line}: "), err
        assert message in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_correct_with_the_physical_mapping(capsys, example):
    status, out, _ = run(capsys, "correct", "--ecof", "0.85", *RIG, "--scar-profile", EXAMPLE,
                         "--mapping", "physical")  # fmt: skip
    assert status == 0 and "(X = x)" in out.splitlines()[0]
    mu = float(ecofmaps.correct_ecof(0.85, **POINT, profile=example, mapping="physical"))
    assert float(values(out, "contact coefficient")[0]) == pytest.approx(mu, rel=5e-6)


# --- what the reading decided, on the command line ---------------------


def groove_in_band(path, dropout_line=None):
    """A groove 31 µm in half-width, 3 µm deep, in a band 170 µm wide between pile-up
    ridges (the floor 0.35 µm above the surface, rough), in µm; a dropout 5 µm down on
    ``dropout_line`` (x = -50 µm on line 702)."""
    x = np.arange(-400.0, 400.01, 0.5)
    z = np.where(np.abs(x) < 31, -3 * (1 - (x / 31) ** 2), 0.0)
    z += np.where((np.abs(x) >= 31) & (np.abs(x) < 70), 0.35 + 0.15 * np.sin(x / 1.75), 0.0)
    v = (np.abs(x) - 70) / 30  # ridges cresting at ±85 µm
    z += np.where((v > 0) & (v < 1), 1.5 * np.sin(np.pi * v) ** 2, 0.0)
    if dropout_line is not None:
        z[dropout_line - 2] -= 5.0
    return write_trace(path, x, z)


@pytest.mark.slow
def test_model_prints_each_finding_on_one_line_naming_the_file(capsys, tmp_path):
    path = groove_in_band(tmp_path / "track.csv", dropout_line=702)
    status, out, err = run(capsys, "model", "--scar-profile", path)
    assert status == 0
    lines = err.strip().splitlines()
    assert len(lines) == 2, err
    assert lines[0].startswith(f"ecofmaps model: warning: {path}: 1 outlier(s) ")
    assert lines[0].endswith("line 702 (x = -50 µm, 5 µm below its neighbours)")
    with pytest.warns(ScarProfileWarning):
        profile = ecofmaps.read_scar_profile(path)
    band = float(profile.half_width) * 1e6
    groove = float(profile.alternative_half_width) * 1e6
    assert band == pytest.approx(85.0, abs=1.0) and groove == pytest.approx(31.0, abs=1.0)
    assert lines[1].startswith(f"ecofmaps model: warning: {path}: ambiguous scar edges: ")
    assert f"half-width {band:.6g} µm for the band between its pile-up ridges" in lines[1]
    assert lines[1].endswith(f"; --profile-half-width {groove:.6g}um takes the groove")
    assert "(1601 samples, levelled, 1 outlier(s) replaced)" in out
    assert values(out, "wear scar half-width (band)") == [f"{band:.6g}"]
    assert values(out, "wear scar half-width (or groove)") == [f"{groove:.6g}"]
    mu_e = float(ecofmaps.energy_cof(**POINT, mu=0.8, profile=profile))
    assert float(values(out, "energy coefficient")[0]) == pytest.approx(mu_e, rel=5e-6)


@pytest.mark.slow
def test_correct_prints_the_findings_and_the_half_width_taken_stops_them(capsys, tmp_path):
    path = groove_in_band(tmp_path / "track.csv")
    argv = ["correct", "--ecof", "0.85", *RIG, "--scar-profile", path]
    status, out, err = run(capsys, *argv)
    assert status == 0
    assert err.startswith(f"ecofmaps correct: warning: {path}: ambiguous scar edges: ")
    assert len(err.strip().splitlines()) == 1
    groove = err.strip().rsplit("--profile-half-width ", 1)[1].split()[0]
    status, out, err = run(capsys, *argv, "--profile-half-width", groove)
    assert status == 0 and err == ""
    assert values(out, "wear scar half-width (given)") == [groove.removesuffix("um")]


@pytest.mark.slow
def test_model_on_a_profile_in_a_fresh_process_prints_no_warning():
    """In a process of its own (without the suite's global float64 switch), the command
    prints nothing on stderr: no JAX value is compared or computed outside float64, where JAX
    would truncate it to float32 with a warning."""
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-m", "ecofmaps.cli", "model", "--scar-profile", str(EXAMPLE)],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert "energy coefficient of friction" in done.stdout


def test_uncertain_edges_on_a_rough_surface_are_named_as_such(capsys, tmp_path):
    """A groove 31 µm in half-width, 3 µm deep, in a surface rough by 7 % of its depth: the
    warning says the edges are uncertain, and the table calls the half-widths what they are
    (the detected one, and the one of the edges read within the roughness), not the band's
    and the groove's of pile-up ridges."""
    x = np.arange(-400.0, 400.01, 0.5)
    kernel = np.exp(-0.5 * (np.arange(-20, 21) * 0.5 / 2.0) ** 2)
    noise = np.random.default_rng(0).normal(size=x.size)
    rough = np.convolve(noise, kernel / np.linalg.norm(kernel), "same")
    z = np.where(np.abs(x) < 31, -3 * (1 - (x / 31) ** 2), 0.0) + 0.2 * rough
    path = write_trace(tmp_path / "rough.csv", x, z)
    status, out, err = run(capsys, "model", "--scar-profile", path)
    assert status == 0
    (line,) = err.strip().splitlines()
    assert "uncertain groove edges on a rough surface" in line
    assert "takes the edges read within the roughness" in line
    with pytest.warns(ScarProfileWarning):
        profile = ecofmaps.read_scar_profile(path)
    detected = float(profile.half_width) * 1e6
    other = float(profile.alternative_half_width) * 1e6
    assert values(out, "wear scar half-width (detected)") == [f"{detected:.6g}"]
    assert values(out, "wear scar half-width (or edges read within the roughness)") == [
        f"{other:.6g}"
    ]
    assert "(band)" not in out and "groove)" not in out
