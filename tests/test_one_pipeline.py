"""One pipeline behind every way in: the same table, byte for byte.

A small recording with drift, noise and a NaN dropout is analysed through the Python API
(``analyze_loops`` and ``resolve_loops`` on the arrays), and through ``ecofmaps loops`` from
CSV, TDMS, HDF5/netCDF, zarr format 2 and zarr format 3 files, with ``--workers 1`` and
``--workers 2``, and in a run stopped by SIGTERM and continued with ``--resume``. Every file
holds the same float64 samples in metres and newtons, so every way must write the same
text, every column as written.
"""

import os
import signal

import numpy as np
import pytest
import xarray as xr
from nptdms import ChannelObject, TdmsWriter

import ecofmaps
from ecofmaps.io.tables import results_csv
from ecofmaps.measured import LoopQualityWarning, pipeline
from ecofmaps.paper import EXAMPLE_2 as POINT
from ecofmaps.paper import LOAD
from tests.cli.commands import run_loops as run

CYCLES = 12
SKIPPED = r"11 ok, 1 skipped \(missing samples\)"
# The zarr format 3 store is written as xarray writes one by default, which zarr warns about.
pytestmark = pytest.mark.filterwarnings("ignore:Consolidated metadata:UserWarning")
SAMPLES_PER_CYCLE = 160


@pytest.fixture(scope="module")
def samples():
    """Twelve cycles of Example 2 with noise, offsets, drift and a dropout of 5 samples."""
    displacement, force = ecofmaps.synthetic_recording(
        **POINT,
        cycles=CYCLES,
        samples_per_cycle=SAMPLES_PER_CYCLE,
        displacement_noise=0.2e-6,
        force_noise=2.0,
        displacement_offset=3e-6,
        force_offset=5.0,
        displacement_drift=0.3e-6,
        seed=22,
    )
    displacement[700:705] = np.nan  # a dropout inside the fifth cycle
    return displacement, force


@pytest.fixture(scope="module")
def files(samples, tmp_path_factory):
    """The recording as CSV, TDMS, netCDF-4 and zarr format 2 and 3, in m and N."""
    folder = tmp_path_factory.mktemp("ways-in")
    displacement, force = samples
    written = {}
    csv = folder / "test.csv"
    lines = ["displacement [m],force [N]"]
    lines += [
        f"{float(d)!r},{float(q)!r}".replace("nan", "")
        for d, q in zip(displacement, force, strict=True)
    ]
    csv.write_text("\n".join(lines) + "\n")
    written["csv"] = csv
    tdms = folder / "test.tdms"
    with TdmsWriter(tdms) as writer:
        writer.write_segment(
            [
                ChannelObject("rig", "displacement", displacement, properties={"unit_string": "m"}),
                ChannelObject("rig", "force", force, properties={"unit_string": "N"}),
            ]
        )
    written["tdms"] = tdms
    dataset = xr.Dataset(
        {
            "displacement": ("sample", displacement, {"units": "m"}),
            "force": ("sample", force, {"units": "N"}),
        }
    )
    written["netcdf"] = folder / "test.nc"
    dataset.to_netcdf(written["netcdf"], engine="h5netcdf")
    written["zarr2"] = folder / "test2.zarr"
    dataset.to_zarr(written["zarr2"], zarr_format=2, consolidated=True)
    written["zarr3"] = folder / "test3.zarr"
    dataset.to_zarr(written["zarr3"])  # as xarray writes a store by default today
    return written


@pytest.fixture(scope="module")
def expected(samples):
    """The table of the arrays through the Python API."""
    with pytest.warns(LoopQualityWarning, match=SKIPPED):
        results = ecofmaps.analyze_loops(*samples, LOAD, resolve=True)
    return results_csv(results)


def test_the_api_reads_a_dropout_and_resolves_as_analyze_loops(samples, expected):
    """The table has one row per cycle of the drive, the dropout's cycle skipped with its
    reason, and resolve_loops reads the same values along the stroke."""
    with pytest.warns(LoopQualityWarning, match=SKIPPED):
        results = ecofmaps.analyze_loops(*samples, LOAD, resolve=True)
    assert "missing-samples" in results.quality.values.tolist()
    assert (results.quality == "ok").sum() >= CYCLES - 3
    with pytest.warns(LoopQualityWarning, match=SKIPPED):
        resolved = ecofmaps.resolve_loops(*samples, LOAD, positions=None)
    for name in ("mu_resolved", "mu_resolved_se", "aspect_ratio", "quality"):
        np.testing.assert_array_equal(resolved[name].values, results[name].values)
    assert expected.count("\n") == results.cycle.size + 1


@pytest.mark.parametrize("way", ["csv", "tdms", "netcdf", "zarr2", "zarr3"])
def test_every_format_writes_the_table_of_the_arrays(files, expected, way, tmp_path, capsys):
    out = tmp_path / "out.csv"
    status, _, err = run(capsys, files[way], "--load", "450N", "--out", out)
    assert status == 0, err
    assert out.read_text() == expected


@pytest.fixture
def small_chunks(monkeypatch):
    """Chunks of about 500 samples: the recording is four of them."""
    monkeypatch.setattr(pipeline, "TASK_SAMPLES", 500)


@pytest.mark.slow
@pytest.mark.parametrize("workers", ["1", "2"])
def test_workers_write_the_table_of_the_arrays(
    files, expected, workers, tmp_path, capsys, small_chunks
):
    out = tmp_path / "out.csv"
    status, _, err = run(
        capsys, files["zarr2"], "--load", "450N", "--out", out, "--workers", workers
    )
    assert status == 0, err
    assert out.read_text() == expected


@pytest.mark.slow
def test_a_run_stopped_by_sigterm_and_resumed_writes_the_table_of_the_arrays(
    files, expected, tmp_path, capsys, small_chunks, on_each_block
):
    """SIGTERM after the first chunk has come back: nothing at --out, the chunks done kept;
    ``--resume`` finishes the table, the same as an uninterrupted run."""
    out = tmp_path / "out.csv"

    def terminate_after_first(received):
        if len(received) == 1:
            os.kill(os.getpid(), signal.SIGTERM)

    on_each_block(terminate_after_first)
    status, _, err = run(capsys, files["tdms"], "--load", "450N", "--out", out, "--workers", "1")
    assert status in (130, 143), err
    assert not out.exists() and "--resume" in err
    assert list((tmp_path / "out.csv.partial").glob("file0-block*.npz"))
    on_each_block(None)
    status, _, err = run(capsys, files["tdms"], "--load", "450N", "--out", out, "--resume")
    assert status == 0, err
    assert out.read_text() == expected


@pytest.mark.parametrize("workers", [[], ["--workers", "2"]])
def test_a_recorded_load_not_positive_refuses_its_cycles_alone(
    samples, tmp_path, capsys, small_chunks, workers
):
    """``--load Fz`` zero at a sample of one cycle and negative at one of another: those two
    cycles ``load-not-positive``, the others analysed; the table of the arrays."""
    displacement, force = samples
    load = np.full(displacement.size, LOAD)
    load[400], load[1400] = 0.0, -5.0
    with pytest.warns(LoopQualityWarning, match="load-not-positive 2"):
        results = ecofmaps.analyze_loops(displacement, force, load, resolve=True)
    lines = [
        ",".join(repr(float(value)) for value in row).replace("nan", "")
        for row in zip(displacement, force, load, strict=True)
    ]
    recording = tmp_path / "fz.csv"
    recording.write_text("\n".join(["displacement [m],force [N],Fz [N]", *lines]) + "\n")
    out = tmp_path / "out.csv"
    status, _, err = run(capsys, recording, "--load", "Fz", "--out", out, *workers)
    assert status == 0, err
    assert out.read_text() == results_csv(results)
    assert out.read_text().count(",load-not-positive\n") == 2
