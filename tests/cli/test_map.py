"""The `ecofmaps map` and `ecofmaps cache` commands: units, ranges, lists, errors, round trip."""

import sys
import types

import numpy as np
import pytest
import xarray as xr

from ecofmaps import Regime, compute_map
from ecofmaps.io.files import MANIFEST
from ecofmaps.maps.cache import cache_entries
from ecofmaps.units import parse_values
from tests.cli.commands import run

FIG11 = [
    "--stiffness-ratio", "0.02/um:0.2/um:10",
    "--aspect-ratio", "0:0.3:7",
    "--amplitude", "25um,50um",
    "--mu", "0.8",
]  # fmt: skip


def test_map_round_trip_is_identical(tmp_path, capsys):
    """The netCDF file holds exactly what compute_map returns for the parsed values."""
    out = tmp_path / "fig11.nc"
    status, stdout, _ = run(capsys, "map", *FIG11, "--load", "450 N", "--out", str(out))
    assert status == 0
    assert f"wrote {out}: 10 stiffness_ratio x 7 aspect_ratio x 2 amplitude" in stdout
    assert "regimes: gross slip" in stdout and "ECoF / contact CoF: 1 to 1.1" in stdout
    stiffness_ratio = parse_values("0.02/um:0.2/um:10", "stiffness_ratio")
    np.testing.assert_allclose(stiffness_ratio, np.linspace(2e4, 2e5, 10), rtol=1e-15)
    expected = compute_map(
        stiffness_ratio=stiffness_ratio,
        aspect_ratio=np.linspace(0.0, 0.3, 7),
        amplitude=parse_values("25um,50um", "length"),  # pint: 25um -> 2.4999999999999998e-05
        mu=0.8,
        load=450.0,
        cache=False,
    )
    with xr.open_dataset(out, engine="h5netcdf") as written:
        xr.testing.assert_identical(written.load(), expected)


def test_map_parses_units_lists_and_ranges(tmp_path, capsys):
    out = tmp_path / "map.nc"
    argv = ["--stiffness-ratio", "0.08/um,inf", "--aspect-ratio", "0.2,0.7",
            "--amplitude", "50e-6", "--mu", "0.5:1:3", "--out", str(out)]  # fmt: skip
    assert run(capsys, "map", *argv)[0] == 0
    with xr.open_dataset(out, engine="h5netcdf") as written:
        written = written.load()
    assert written.ecof_ratio.dims == ("stiffness_ratio", "aspect_ratio", "mu")
    np.testing.assert_array_equal(written.stiffness_ratio, [8e4, np.inf])
    np.testing.assert_array_equal(written.aspect_ratio, [0.2, 0.7])
    np.testing.assert_array_equal(written.mu, [0.5, 0.75, 1.0])
    assert written.amplitude.dims == () and float(written.amplitude) == 50e-6  # bare: SI
    assert "dissipated_energy" not in written  # no --load


def test_map_replaces_only_a_file_it_wrote_and_only_with_overwrite(tmp_path, capsys):
    out = tmp_path / "map.nc"
    out.write_text("a user's file")
    for extra in ([], ["--overwrite"]):  # never replaced, even with --overwrite
        status, stdout, stderr = run(capsys, "map", *FIG11, "--out", str(out), *extra)
        assert status == 2 and stdout == ""
        assert stderr == (
            f"ecofmaps: error: --out {out} is a file that ecofmaps did not write (or that "
            f"changed since; see {MANIFEST} in its folder): it is not replaced; choose "
            "another name\n"
        )
        assert out.read_text() == "a user's file"
    out.unlink()
    assert run(capsys, "map", *FIG11, "--out", str(out))[0] == 0
    status, _, stderr = run(capsys, "map", *FIG11, "--load", "450N", "--out", str(out))
    assert status == 2
    assert stderr == f"ecofmaps: error: --out {out} exists already: --overwrite replaces it\n"
    assert run(capsys, "map", *FIG11, "--load", "450N", "--out", str(out), "--overwrite")[0] == 0
    with xr.open_dataset(out, engine="h5netcdf") as written:
        assert written.sizes == {"stiffness_ratio": 10, "aspect_ratio": 7, "amplitude": 2}
        assert "dissipated_energy" in written
    assert sorted(p.name for p in tmp_path.iterdir()) == [MANIFEST, "map.nc"]


def test_map_follows_the_library_and_does_not_cache_a_closed_form_map(tmp_path, capsys):
    cache_dir = tmp_path / "cache"
    argv = ["map", *FIG11, "--cache-dir", str(cache_dir), "--out", str(tmp_path / "a.nc")]
    assert run(capsys, *argv, "--no-cache")[0] == 0
    assert run(capsys, *argv, "--overwrite")[0] == 0
    assert cache_entries(cache_dir) == []


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--amplitude", "35MN/m", "argument --amplitude: '35MN/m' is not a length"),
        ("--amplitude", "fifty", "argument --amplitude: cannot read 'fifty' as a length"),
        ("--stiffness-ratio", "35MN/m", "'35MN/m' is not a stiffness_ratio"),
        ("--aspect-ratio", "0:0.3:x", "the number of points in '0:0.3:x' must be an integer"),
        ("--aspect-ratio", "0:0.3", "a range is start:stop:num"),
        ("--mu", "nan", "'nan' holds a NaN"),
        ("--mu", "0.8um", "'0.8um' is not a dimensionless"),
        ("--load", "450N,500N", "argument --load: cannot read '450N,500N' as a force"),
    ],
)
def test_bad_values_are_rejected_by_the_parser(tmp_path, capsys, option, value, message):
    argv = dict(zip(FIG11[::2], FIG11[1::2], strict=True)) | {option: value}
    flat = [item for pair in argv.items() for item in pair]
    status, stdout, stderr = run(capsys, "map", *flat, "--out", str(tmp_path / "x.nc"))
    assert status == 2 and stdout == ""
    assert stderr.count("\n") == 1 and stderr.startswith("ecofmaps: error: ")
    assert message in stderr.splitlines()[-1]
    assert "Traceback" not in stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        (
            "--stiffness-ratio",
            "0",
            "argument --stiffness-ratio: '0' is out of range: the rig "
            "stiffness over normal load must satisfy 0 < S/P <= inf [m-1]",
        ),
        (
            "--aspect-ratio",
            "-0.1,0.2",
            "argument --aspect-ratio: '-0.1,0.2' is out of range: "
            "the groove aspect ratio must satisfy 0 <= z_o/x_o < inf",
        ),
        (
            "--amplitude",
            "inf",
            "argument --amplitude: 'inf' is out of range: the displacement "
            "amplitude must satisfy 0 < Δ* < inf [m]",
        ),
        ("--mu", "0", "argument --mu: '0' is out of range"),
        ("--load", "0N", "argument --load: '0N' is out of range"),
        (
            "--aspect-ratio",
            "0.1,0.2,0.1",
            "argument --aspect-ratio: '0.1,0.2,0.1' repeats the "
            "value 0.1: a grid axis takes each value once",
        ),
    ],
)
def test_values_out_of_range_end_with_one_line(tmp_path, capsys, option, value, message):
    argv = dict(zip(FIG11[::2], FIG11[1::2], strict=True)) | {option: value}
    flat = [f"{key}={item}" for key, item in argv.items()]
    status, stdout, stderr = run(capsys, "map", *flat, "--out", str(tmp_path / "x.nc"))
    assert status == 2 and stdout == ""
    assert stderr.count("\n") == 1 and stderr.startswith("ecofmaps: error: ")
    assert message in stderr
    assert list(tmp_path.iterdir()) == []


def test_missing_directory_ends_with_one_line(tmp_path, capsys):
    out = tmp_path / "missing" / "x.nc"
    status, _, stderr = run(capsys, "map", *FIG11, "--out", str(out))
    assert status == 2
    message = f"cannot write {out} (--out): its directory does not exist"
    assert stderr == f"ecofmaps: error: {message}\n"


def test_required_options(capsys):
    status, _, stderr = run(capsys, "map", "--mu", "0.8")
    assert status == 2
    assert "the following arguments are required: --stiffness-ratio, --aspect-ratio" in stderr


def test_cache_list_and_clear(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("ECOFMAPS_CACHE", str(tmp_path / "cache"))
    status, stdout, _ = run(capsys, "cache", "list")
    assert status == 0 and stdout == f"no cached maps in {tmp_path / 'cache'}\n"
    compute_map(1e5, 0.2, 50e-6, 0.8, cache=True)
    compute_map(1e5, 0.2, 50e-6, np.array([0.5, 0.8]), cache=True)
    entries = cache_entries()
    status, stdout, _ = run(capsys, "cache", "list")
    assert status == 0
    lines = stdout.splitlines()
    assert lines[0] == f"cached maps in {tmp_path / 'cache'}:"
    assert all(entry.path.name in stdout for entry in entries) and len(lines) == 4
    assert lines[-1].startswith("2 file(s), ") and lines[-1].endswith(" kB")
    status, stdout, _ = run(capsys, "cache", "clear")
    assert status == 0 and stdout.startswith("removed 2 file(s), ")
    assert cache_entries() == []
    other = tmp_path / "other"
    assert run(capsys, "cache", "list", "--cache-dir", str(other))[1].endswith(f"{other}\n")


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["map", "--help"], ["--stiffness-ratio", "--aspect-ratio", "--amplitude", "--mu",
                             "--load", "--out", "--no-cache", "--cache-dir", "start:stop:num",
                             "atomically", "[1/m]", "zarr", "--chunk-points", "--quiet",
                             "block by block", "progress bar"]),
        (["cache", "--help"], ["list", "clear", "ECOFMAPS_CACHE"]),
        (["cache", "clear", "--help"], ["--cache-dir"]),
        (["--help"], ["map", "cache"]),
    ],
)  # fmt: skip
def test_help_is_complete(capsys, argv, expected):
    status, stdout, _ = run(capsys, *argv)
    assert status == 0
    for word in expected:
        assert word in stdout


# --- zarr, block by block, progress -----------------------------------------------------------


def fig11_map(load=None):
    """compute_map of the FIG11 options, in memory."""
    return compute_map(
        stiffness_ratio=parse_values("0.02/um:0.2/um:10", "stiffness_ratio"),
        aspect_ratio=np.linspace(0.0, 0.3, 7),
        amplitude=parse_values("25um,50um", "length"),
        mu=0.8,
        load=load,
        cache=False,
    )


@pytest.mark.parametrize("name", ["fig11.zarr", "fig11.nc"])
def test_map_block_by_block_round_trip_is_identical(tmp_path, capsys, name):
    """A zarr store, or a grid above --chunk-points: block by block, identical, not cached."""
    out, cache_dir = tmp_path / name, tmp_path / "cache"
    argv = ["map", *FIG11, "--load", "450N", "--chunk-points", "30", "--out", str(out)]
    status, stdout, stderr = run(capsys, *argv, "--cache-dir", str(cache_dir))
    assert status == 0
    expected = fig11_map(450.0)
    stated = f"ecofmaps map: 140 points, {expected.nbytes / 1e3:.3g} kB into {out} ("
    assert stdout.startswith(stated) and stderr == ""  # no progress bar
    assert stdout.splitlines()[0].endswith(" free there)")  # the size first, then the summary
    regimes = ", ".join(
        f"{code.label} {n}" for code in Regime if (n := int((expected.regime == code).sum()))
    )
    assert f"wrote {out}: 10 stiffness_ratio x 7 aspect_ratio x 2 amplitude" in stdout
    assert f"  regimes: {regimes}\n" in stdout and "ECoF / contact CoF: 1 to 1.1" in stdout
    if name.endswith(".zarr"):
        with xr.open_zarr(out) as written:
            assert written.ecof_ratio.encoding["chunks"] == (2, 7, 2)  # 30 points: 2 rows
            written = written.compute()
    else:
        with xr.open_dataset(out, engine="h5netcdf") as written:
            written = written.load()
    xr.testing.assert_identical(written, expected)
    assert sorted(p.name for p in tmp_path.iterdir()) == [MANIFEST, name]  # nothing cached


def test_map_replaces_a_store_it_wrote_and_refuses_other_directories(tmp_path, capsys):
    out = tmp_path / "m.zarr"
    assert run(capsys, "map", *FIG11, "--out", str(out))[0] == 0
    argv = ["map", *FIG11, "--load", "450N", "--out", str(out), "--overwrite"]
    assert run(capsys, *argv)[0] == 0
    with xr.open_zarr(out) as written:
        xr.testing.assert_identical(written.compute(), fig11_map(450.0))
    mine = tmp_path / "mine.zarr"
    mine.mkdir()
    (mine / "thesis.txt").write_text("chapter 1")
    status, stdout, stderr = run(capsys, "map", *FIG11, "--out", str(mine), "--overwrite")
    assert status == 2 and stdout == ""
    assert stderr.splitlines()[-1].startswith(
        f"ecofmaps: error: --out {mine} is a folder that ecofmaps did not write"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == [MANIFEST, "m.zarr", "mine.zarr"]
    assert (mine / "thesis.txt").read_text() == "chapter 1"


def test_map_states_its_size_and_refuses_one_the_disk_cannot_hold(tmp_path, capsys, monkeypatch):
    """2e12 points (tens of TB) against the free space of --out's folder: refused at once."""
    from ecofmaps.cli import map as command

    free = 10**12
    usage = types.SimpleNamespace(total=2 * free, used=free, free=free)
    monkeypatch.setattr(command.shutil, "disk_usage", lambda path: usage)
    out = tmp_path / "big.zarr"
    argv = [
        "--stiffness-ratio", "0.01/um:0.3/um:1000000", "--aspect-ratio", "0:0.4:1000000",
        "--amplitude", "25um,50um", "--mu", "0.8", "--load", "450N", "--out", str(out),
    ]  # fmt: skip
    status, stdout, stderr = run(capsys, "map", *argv)
    assert status == 2
    small = fig11_map(450.0)  # the same variables: bytes per point and per coordinate value
    per_point = sum(v.nbytes for v in small.data_vars.values() if v.ndim == 3) / small.regime.size
    size = per_point * 2e12  # the coordinates and compliance_ratio add less than 0.1 %
    (first,), (second,) = stdout.splitlines(), stderr.splitlines()
    assert first.startswith("ecofmaps map: 2,000,000,000,000 points, ")
    assert first.endswith(f" into {out} (1 TB free there)")
    stated = float(first.split(", ")[1].split()[0])
    assert stated == pytest.approx(size / 1e12, rel=5e-3)  # in TB, 3 digits
    assert second.startswith(f"ecofmaps: error: --out {out}: the map of 2e+12 points needs up to ")
    assert second.endswith(f"more than the 1 TB free in {tmp_path.resolve()}: use a smaller grid "
                           "or another disk")  # fmt: skip
    assert list(tmp_path.iterdir()) == []


def test_a_grid_block_by_block_is_not_refused_for_memory(tmp_path, capsys, monkeypatch):
    from ecofmaps.maps import tiles

    monkeypatch.setattr(tiles, "available_memory", lambda: 1000)  # 1 kB free
    out = tmp_path / "m.nc"
    status, _, stderr = run(capsys, "map", *FIG11, "--chunk-points", "100", "--out", str(out))
    assert status == 0, stderr
    argv = ["map", *FIG11, "--no-cache", "--out", str(out), "--overwrite"]
    status, _, stderr = run(capsys, *argv)
    assert status == 2 and "needs about" in stderr and "--chunk-points" in stderr


@pytest.mark.parametrize(
    ("argv", "bar"),
    [([], True), (["--quiet"], False), (["--chunk-points", "1000"], False)],  # in memory: no bar
)
def test_progress_bar_on_a_terminal_only(tmp_path, capsys, monkeypatch, argv, bar):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    out = tmp_path / "m.nc"
    status, stdout, stderr = run(
        capsys, "map", *FIG11, "--chunk-points", "30", *argv, "--out", str(out)
    )
    assert status == 0
    first = stdout.splitlines()[0]
    assert first.startswith("ecofmaps map: 140 points, ") and first.endswith(" free there)")
    if bar:
        assert "ecofmaps map: 100%" in stderr and "140/140" in stderr
        assert "5/5 blocks" in stderr and "pt/s" in stderr
    else:
        assert stderr == ""


@pytest.mark.parametrize("value", ["0", "-3", "1.5", "many", "inf"])
def test_bad_chunk_points_are_named(tmp_path, capsys, value):
    status, _, stderr = run(capsys, "map", *FIG11, f"--chunk-points={value}", "--out",
                            str(tmp_path / "m.nc"))  # fmt: skip
    assert status == 2 and stderr.count("\n") == 1
    assert f"argument --chunk-points: {value!r} is not a whole number of points >= 1" in stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_ctrl_c_during_a_zarr_write_leaves_no_store(tmp_path):
    """Ctrl-C while blocks are written: status 130, one line, no store and no temporary."""
    from tests.cli.commands import interrupted_run

    out = tmp_path / "big.zarr"
    command = [
        sys.executable, "-m", "ecofmaps.cli", "map", "--stiffness-ratio", "0.01/um:0.3/um:4000",
        "--aspect-ratio", "0:0.3:2500", "--amplitude", "25um,50um", "--mu", "0.8", "--load",
        "450N", "--chunk-points", "100000", "--out", str(out),
    ]  # fmt: skip
    status, stdout, stderr = interrupted_run(command, "ecofmaps map: 20,000,000 points", 1.5)
    assert status == 130, stderr
    assert stderr == "ecofmaps: interrupted; no output was left half written\n"
    assert stdout == "" and list(tmp_path.iterdir()) == []  # the size line read before
