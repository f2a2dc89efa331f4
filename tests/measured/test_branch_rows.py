"""The branch rows copied as stretches of the samples are those gathered point by point."""

import numpy as np
import pytest

from ecofmaps.measured.measure import LoopBlock, branch_rows


def _block(count):
    """A block of consecutive cycles of ``count`` samples each, with random values."""
    count = np.asarray(count, dtype=np.int64)
    offset = np.concatenate([[0], np.cumsum(count[:-1])])
    size = int(count.sum())
    rng = np.random.default_rng(1)
    return LoopBlock(
        rows=slice(0, count.size),
        displacement=rng.normal(size=size),
        force=rng.normal(size=size),
        offset=offset,
        count=count,
        rotation=np.zeros_like(count),
        continuous=True,
        displacement_centre=np.zeros(count.size),
        force_centre=np.zeros(count.size),
        force_swing=np.ones(count.size),
        force_drift_se=np.zeros(count.size),
    )


def _gathered(block, top):
    """The rows by their definition: point j of a branch is the loop's point first + j,
    up to its last one (the loop's point ``count`` is its first sample again)."""
    first = np.concatenate([np.zeros_like(top), top])
    last = np.concatenate([top, block.count])
    j = np.arange(int((last - first).max()) + 1)
    point = np.minimum(first[:, None] + j, last[:, None])
    index = block.samples(point, np.tile(np.arange(top.size), 2))
    return block.displacement[index], block.force[index], j <= (last - first)[:, None]


@pytest.mark.parametrize(
    ("count", "top"),
    [
        ([200, 198, 203, 200], [101, 0, 150, 199]),  # the last rows run past the samples
        ([7], [0]),  # a falling branch longer than the block's samples
        ([5, 9], [4, 1]),
    ],
)
def test_rows_are_the_loops_points(count, top):
    block = _block(count)
    top = np.asarray(top, dtype=np.int64)
    x, y, length = branch_rows(block, top)
    expected_x, expected_y, expected_valid = _gathered(block, top)
    np.testing.assert_array_equal(x, expected_x)
    np.testing.assert_array_equal(y, expected_y)
    np.testing.assert_array_equal(length, expected_valid.sum(axis=1))
