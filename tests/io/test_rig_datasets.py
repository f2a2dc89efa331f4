"""Rig files opened through xarray (zarr formats 2 and 3, netCDF) and npTDMS: fill values and
CF packing decoded by the libraries, the same numbers whatever the format; open_recording's
Dataset; the engines ecofmaps-tdms and ecofmaps-text in xarray."""

import subprocess
import sys

import numpy as np
import pytest
import xarray as xr
from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

from ecofmaps._parallel import Slice, stretch
from ecofmaps.cli import main
from ecofmaps.io import open_recording
from ecofmaps.io.recordings import read_recording, recording_blocks
from ecofmaps.io.tdms import TdmsReader
from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.paper import EXAMPLE_2 as POINT

# Zarr format 3 stores are written as xarray writes them by default, which zarr warns about.
pytestmark = pytest.mark.filterwarnings("ignore:Consolidated metadata:UserWarning")

SIZE = 801
DROPPED = (100, 433)  # the displacement's and the force's missing sample


@pytest.fixture(scope="module")
def samples():
    """Four cycles of the model: displacement in µm that int32 counts of 0.001 µm plus an
    offset of 0.5 µm hold exactly (as xarray decodes them: count * 0.001 + 0.5), force in N;
    one sample of each missing."""
    displacement, force = synthetic_recording(**POINT, cycles=5)
    counts = np.round((displacement[:SIZE] * 1e6 - 0.5) / 0.001).astype(np.int32)
    micrometres = counts * 0.001 + 0.5
    micrometres[DROPPED[0]] = np.nan
    newtons = force[:SIZE].copy()
    newtons[DROPPED[1]] = np.nan
    return micrometres, newtons


def dataset_of(samples) -> xr.Dataset:
    micrometres, newtons = samples
    return xr.Dataset(
        {
            "displacement": ("time", micrometres, {"units": "um"}),
            "force": ("time", newtons, {"units": "N"}),
        }
    )


#: The displacement packed as int32 counts, a fill value for the missing sample.
PACKED = {
    "displacement": {
        "dtype": "int32",
        "scale_factor": 0.001,
        "add_offset": 0.5,
        "_FillValue": np.int32(-(2**31) + 1),
    }
}


def write_file(folder, samples, kind):
    """The same samples as a zarr store of format 3 (xarray's default) or 2, netCDF-4 or
    TDMS; float64 force with NaN for its missing sample (a NaN ``_FillValue`` in zarr)."""
    dataset = dataset_of(samples)
    path = folder / {"zarr3": "v3.zarr", "zarr2": "v2.zarr", "nc": "r.nc", "tdms": "r.tdms"}[kind]
    if kind == "zarr3":
        dataset.to_zarr(path, encoding=PACKED)
    elif kind == "zarr2":
        dataset.to_zarr(path, encoding=PACKED, zarr_format=2)
    elif kind == "nc":
        dataset.to_netcdf(path, engine="h5netcdf", encoding=PACKED)
    else:
        with TdmsWriter(path) as writer:
            writer.write_segment(
                [
                    RootObject({"rig": "B3"}),
                    GroupObject("Rig"),
                    ChannelObject("Rig", "Displacement", samples[0], {"unit_string": "um"}),
                    ChannelObject("Rig", "Force", samples[1], {"NI_UnitDescription": "N"}),
                ]
            )
    return path


KINDS = ("zarr3", "zarr2", "nc", "tdms")


def test_default_zarr_stores_have_fill_values_in_their_attributes(tmp_path, samples):
    """What made the hand-written reading fail: xarray keeps a format-3 store's _FillValue
    base64-encoded in the attributes, a format-2 store's in the array's fill_value."""
    import json

    v3 = write_file(tmp_path, samples, "zarr3")
    metadata = json.loads((v3 / "force" / "zarr.json").read_text())
    assert isinstance(metadata["attributes"]["_FillValue"], str)  # "AAAAAAAA+H8="
    v2 = write_file(tmp_path, samples, "zarr2")
    assert "_FillValue" not in json.loads((v2 / "force" / ".zattrs").read_text())


@pytest.mark.parametrize("kind", KINDS)
def test_every_format_reads_the_same_numbers(tmp_path, samples, kind):
    """Unpacked, fill values as NaN, in SI: the same bits from zarr 3 and 2, netCDF and
    TDMS, whole, lazily and through open_recording."""
    path = write_file(tmp_path, samples, kind)
    read = read_recording(path)
    np.testing.assert_array_equal(read.displacement, samples[0] / 1e6)
    np.testing.assert_array_equal(read.force, samples[1])
    assert np.flatnonzero(read.missing).tolist() == list(DROPPED)
    assert read.format == ("hdf5" if kind == "nc" else kind.rstrip("23"))
    lazy = read_recording(path, lazy=True, chunks=300)
    assert lazy.lazy
    np.testing.assert_array_equal(lazy.displacement.compute(), read.displacement)
    dataset = open_recording(path, lazy=True, chunks=300)
    assert dataset.displacement.chunks == ((300, 300, 201),)
    part = stretch(dataset.force.data, 250, 520)  # a task's range, read by its column
    assert isinstance(part, Slice)
    np.testing.assert_array_equal(part.read(), samples[1][250:520])
    np.testing.assert_array_equal(dataset.force.values, samples[1])
    np.testing.assert_array_equal(dataset.displacement.values, samples[0] / 1e6)


def test_the_formats_give_one_dataset(tmp_path, samples):
    """open_recording's Datasets of the four files are equal (the attributes aside: the
    source columns are named as in each file)."""
    datasets = {kind: open_recording(write_file(tmp_path, samples, kind)) for kind in KINDS}
    for kind in KINDS[1:]:
        xr.testing.assert_equal(datasets[kind], datasets["zarr3"])
    assert datasets["tdms"].force.attrs["source_column"] == "Rig/Force"
    assert datasets["zarr3"].force.attrs["source_column"] == "force"


def test_open_recording_attributes(tmp_path):
    """Units in SI, the column and unit as read, and whether the unit was assumed."""
    path = tmp_path / "rig.csv"
    path.write_text("time,displacement,Force [kN],cycle,Fz\n0,1.5,0.25,1,450\n1,2.5,0.5,1,451\n")
    recording = read_recording(path)
    assert recording.assumed_units == ("displacement",)
    loaded = open_recording(path, load_column="Fz")
    assert (loaded["load"].attrs["unit_assumed"], loaded["load"].attrs["units"]) == (1, "N")
    np.testing.assert_array_equal(loaded["load"].values, [450.0, 451.0])
    dataset = open_recording(path)
    assert dataset.attrs["source"] == str(path) and dataset.attrs["format"] == "text"
    assert dataset.displacement.attrs == {
        "long_name": "applied displacement Δ",
        "units": "m",
        "source_column": "displacement",
        "source_units": "um",
        "unit_assumed": 1,
    }
    assert dataset.force.attrs["source_column"] == "Force [kN]"
    assert (dataset.force.attrs["source_units"], dataset.force.attrs["unit_assumed"]) == ("kN", 0)
    np.testing.assert_array_equal(dataset.force.values, [250.0, 500.0])
    np.testing.assert_array_equal(dataset.displacement.values, [1.5e-6, 2.5e-6])
    np.testing.assert_array_equal(dataset.cycle.values, [1, 1])
    given = open_recording(path, displacement_unit="um")
    assert given.displacement.attrs["unit_assumed"] == 0
    blocks = list(recording_blocks(path, samples=1))
    assert [b.assumed_units for b in blocks] == [("displacement",)] * 2


def test_rig_file_units_assumed_or_read(tmp_path, samples):
    """A variable with a units attribute has its unit read; one without, assumed."""
    dataset = dataset_of(samples)
    del dataset.displacement.attrs["units"]
    path = tmp_path / "bare.zarr"
    dataset.to_zarr(path)
    read = read_recording(path)
    assert read.assumed_units == ("displacement",)
    assert read.units == {"displacement": "um", "force": "N"}
    assert open_recording(path).displacement.attrs["unit_assumed"] == 1


# --- xarray's engines ------------------------------------------------------------------------


def test_tdms_engine(tmp_path, samples, monkeypatch):
    """xr.open_dataset(engine='ecofmaps-tdms'): channels named as in the file, units in
    attrs, lazily indexed (a slice reads its samples, steps and reversals too); every group
    with open_datatree."""
    path = write_file(tmp_path, samples, "tdms")
    with TdmsWriter(path, mode="a") as writer:
        writer.write_segment([ChannelObject("Other", "Temperature [°C]", np.arange(5.0))])
    reads = []
    samples_of = TdmsReader.samples
    monkeypatch.setattr(
        TdmsReader, "samples", lambda self, *a: reads.append(a[2:]) or samples_of(self, *a)
    )
    with xr.open_dataset(path, engine="ecofmaps-tdms") as dataset:
        assert list(dataset.data_vars) == ["Displacement", "Force"]
        assert dataset.Displacement.attrs["units"] == "um"
        assert dataset.Force.attrs["units"] == "N" and dataset.sizes == {"sample": SIZE}
        assert reads == []
        np.testing.assert_array_equal(dataset.Force[40:45].values, samples[1][40:45])
        assert reads == [(40, 5)]  # those samples only
        for key in (slice(5, 50), slice(10, 300, 7), slice(None, None, -3), 17):
            np.testing.assert_array_equal(dataset.Force[key].values, samples[1][key])
    tree = xr.open_datatree(path, engine="ecofmaps-tdms")
    assert tree.attrs["rig"] == "B3" and set(tree.children) == {"Rig", "Other"}
    np.testing.assert_array_equal(tree["Other"]["Temperature [°C]"].values, np.arange(5.0))
    other = xr.open_dataset(path, engine="ecofmaps-tdms", group="/Other")
    assert list(other.data_vars) == ["Temperature [°C]"]
    with pytest.raises(ValueError, match=r"no group 'Rog' \(groups: 'Rig', 'Other'\)"):
        xr.open_dataset(path, engine="ecofmaps-tdms", group="Rog")


def test_text_engine(tmp_path):
    """xr.open_dataset(engine='ecofmaps-text'): the columns named as in the file, in SI
    with their units in attrs; the reading options pass through."""
    path = tmp_path / "rig.tsv"
    path.write_text("Disp [mm]\tQ [kN]\tcycle\n0.001\t0.25\t1\n0.002\t-0.5\t1\n")
    dataset = xr.open_dataset(
        path, engine="ecofmaps-text", displacement_column="disp", force_column="q"
    )
    assert list(dataset.data_vars) == ["Disp [mm]", "Q [kN]", "cycle"]
    np.testing.assert_array_equal(dataset["Disp [mm]"].values, [1e-6, 2e-6])
    np.testing.assert_array_equal(dataset["Q [kN]"].values, [250.0, -500.0])
    assert dataset["Q [kN]"].attrs["units"] == "N"
    assert dataset["Q [kN]"].attrs["source_units"] == "kN"
    tdms = tmp_path / "r.tdms"
    with TdmsWriter(tdms) as writer:
        writer.write_segment([ChannelObject("Rig", "force", np.arange(3.0))])
    with pytest.raises(ValueError, match="a tdms file, not text: use engine='ecofmaps-tdms'"):
        xr.open_dataset(tdms, engine="ecofmaps-text")


def test_xarray_guesses_the_engines_from_the_suffix(tmp_path, samples):
    path = write_file(tmp_path, samples, "tdms")
    assert list(xr.open_dataset(path).data_vars) == ["Displacement", "Force"]


# --- the command line and the modules --------------------------------------------------------


def test_loops_on_a_format_3_store_writes_the_csv_table(tmp_path, capsys):
    """``ecofmaps loops store.zarr --load 450N`` on a store xarray wrote by default gives
    the table of the same samples in a CSV file (it failed on the store's fill value)."""
    displacement, force = synthetic_recording(**POINT, cycles=5)
    csv = tmp_path / "test.csv"
    lines = ["displacement,force"]
    lines += [
        f"{d * 1e6:.9f},{f:.9f}" for d, f in zip(displacement[:SIZE], force[:SIZE], strict=True)
    ]
    csv.write_text("\n".join(lines) + "\n")
    read = read_recording(csv)
    store = tmp_path / "store.zarr"
    xr.Dataset(
        {
            "displacement": ("sample", read.displacement, {"units": "m"}),
            "force": ("sample", read.force, {"units": "N"}),
        }
    ).to_zarr(store)
    tables = []
    for path in (csv, store):
        out = tmp_path / f"{path.stem}-results.csv"
        assert main(["loops", str(path), "--load", "450N", "--out", str(out)]) == 0
        tables.append(out.read_text())
    capsys.readouterr()
    assert tables[0] == tables[1] and len(tables[0].splitlines()) == 5


def test_binary_does_not_import_recordings():
    """The rig formats' reader and the dispatch in recordings import one way only."""
    code = (
        "import sys, ecofmaps.io.binary\n"
        "assert 'ecofmaps.io.recordings' not in sys.modules\n"
        "import ecofmaps.io.recordings\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


@pytest.mark.parametrize("zarr_format", [2, 3])
def test_stores_written_by_zarr_alone(tmp_path, zarr_format):
    """Arrays without dimension names (which xarray's engine needs) are read too, their CF
    attributes decoded by xarray; a store that is one array is its one variable."""
    import zarr

    from ecofmaps.io.binary import open_group, variables

    path = tmp_path / "plain.zarr"
    root = zarr.open_group(str(path), mode="w", zarr_format=zarr_format)
    counts = np.array([3, -999, 5, 7], dtype=np.int16)
    for name, attrs in (
        ("displacement", {"units": "mm", "scale_factor": 0.5, "_FillValue": -999}),
        ("force", {"units": "N"}),
    ):
        array = root.create_array(name, shape=(4,), chunks=(2,), dtype=np.int16)
        array[:] = counts
        array.attrs.update(attrs)
    read = read_recording(path)
    np.testing.assert_array_equal(read.displacement, [1.5e-3, np.nan, 2.5e-3, 3.5e-3])
    np.testing.assert_array_equal(read.force, counts)
    single = zarr.create_array(str(tmp_path / "one.zarr"), shape=(3,), chunks=(3,), dtype="f8")
    single[:] = [1.0, 2.0, 3.0]
    assert [v.name for v in variables(tmp_path / "one.zarr", "zarr")] == ["one"]
    np.testing.assert_array_equal(open_group(tmp_path / "one.zarr", "zarr", "")["one"], [1, 2, 3])
