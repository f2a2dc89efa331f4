"""Arrays handed to the analysis that NumPy would read silently wrong: a masked array's mask,
cycle numbers that are not whole or come again, ragged or too large values."""

import numpy as np
import pytest

from ecofmaps.io import read_recording
from ecofmaps.measured import analyze_loops
from ecofmaps.measured.synthetic import EXAMPLE, example_path


@pytest.fixture(scope="module")
def example():
    recording = read_recording(example_path())
    return recording.displacement, recording.force, np.asarray(recording.cycle).astype(np.int64)


def _masked(values, lazy=False):
    """``values`` with samples 5000 to 5099 masked (and, under the mask, absurd)."""
    mask = np.zeros(values.size, bool)
    mask[5000:5100] = True
    hidden = np.where(mask, 10**6, values).astype(values.dtype)
    if lazy:
        import dask.array as da

        return da.ma.masked_array(da.from_array(hidden, 1700), da.from_array(mask, 1700))
    return np.ma.masked_array(hidden, mask)


def _nan(values):
    values = values.astype(np.float64)
    values[5000:5100] = np.nan
    return values


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("argument", ["displacement", "force", "load", "cycle", "missing", "lazy"])
def test_masked_samples_are_missing_samples(example, argument):
    x, q, cycle = example
    load = np.full(x.size, EXAMPLE["load"])
    given = dict(displacement=x, force=q, load=load, cycle=cycle)
    expected = dict(given)
    if argument == "missing":
        given["missing"] = _masked(np.zeros(x.size, bool))
        expected["displacement"] = _nan(x)
    elif argument == "lazy":
        import dask.array as da

        given["displacement"] = _masked(x, lazy=True)
        expected["displacement"] = da.from_array(_nan(x), 1700)
    else:
        given[argument] = _masked(given[argument])
        expected[argument] = _nan(expected[argument])
    assert analyze_loops(**given, resolve=False).equals(analyze_loops(**expected, resolve=False))


@pytest.mark.parametrize("chunks", [None, 1700])
@pytest.mark.parametrize(
    ("labels", "message"),
    [
        (lambda n: np.arange(n) // 200 + 0.5, "the cycle number 0.5 of sample 0 is not a whole"),
        (lambda n: (np.arange(n) // 200) % 50, "the cycle number 0 comes again at sample 10000"),
        (lambda n: np.where(np.arange(n) < 3000, np.arange(n) // 200, 7.25), "7.25 of sample 3000"),
    ],
)
def test_cycle_numbers_that_cycles_would_share_are_refused(example, labels, message, chunks):
    """In memory and out of core (dask blocks that cut the runs) alike."""
    x, q, _ = example
    arrays = (x, q, labels(x.size))
    if chunks is not None:
        import dask.array as da

        arrays = [da.from_array(a, chunks=chunks) for a in arrays]
    with pytest.raises(ValueError, match=message) as raised:
        analyze_loops(arrays[0], arrays[1], EXAMPLE["load"], arrays[2])
    assert "--cycle-col none, or cycle=None, cuts the cycles at the reversals" in str(raised.value)


def test_values_numpy_cannot_read_name_the_argument(example):
    x, q, _ = example
    with pytest.raises(ValueError, match=r"^displacement cannot be read as numbers"):
        analyze_loops([[1.0, 2.0], [3.0]], q[:2], EXAMPLE["load"])
    with pytest.raises(ValueError, match=r"^cycle must hold numbers of at most 64 bits"):
        analyze_loops(x, q, EXAMPLE["load"], [2**70] * x.size)
