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
    return recording.displacement, recording.force


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_masked_samples_are_missing_samples(example):
    x, q = example
    masked = np.ma.masked_array(q.copy(), mask=np.zeros(q.size, bool))
    masked[5000:5100] = 1e6  # what the mask hides
    masked[5000:5100] = np.ma.masked
    nan = q.copy()
    nan[5000:5100] = np.nan
    expected = analyze_loops(x, nan, EXAMPLE["load"], resolve=False)
    assert analyze_loops(x, masked, EXAMPLE["load"], resolve=False).equals(expected)


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
    x, q = example
    arrays = (x, q, labels(x.size))
    if chunks is not None:
        import dask.array as da

        arrays = [da.from_array(a, chunks=chunks) for a in arrays]
    with pytest.raises(ValueError, match=message) as raised:
        analyze_loops(arrays[0], arrays[1], EXAMPLE["load"], arrays[2])
    assert "--cycle-col none, or cycle=None, cuts the cycles at the reversals" in str(raised.value)


def test_values_numpy_cannot_read_name_the_argument(example):
    x, q = example
    with pytest.raises(ValueError, match=r"^displacement cannot be read as numbers"):
        analyze_loops([[1.0, 2.0], [3.0]], q[:2], EXAMPLE["load"])
    with pytest.raises(ValueError, match=r"^cycle must hold numbers of at most 64 bits"):
        analyze_loops(x, q, EXAMPLE["load"], [2**70] * x.size)
