"""The offset between a loop's branches that the drift correction leaves, and its standard
error ``force_drift_se`` (ecofmaps.measured.measure), against a brute force.

The drift subtracted from the force is the centres of the cycles interpolated linearly
between their middle samples (extended beyond the first and last); an error of the centres
offsets the mean drift over a loop's second half against its first. The brute force reads
that offset off ``np.interp`` of each unit vector of centres, and the centres' noise off a
plain median of their second differences; the standard error is then checked against the
scatter of the offset actually subtracted, over many noise draws.
"""

import numpy as np
import pytest
from scipy.stats import norm

from ecofmaps.measured.cycles import find_cycles
from ecofmaps.measured.measure import loop_blocks
from ecofmaps.paper import LOAD, MU, STIFFNESS
from tests.return_map import return_map

#: Half-width of the window of second differences of the centres (cycles either side).
REACH = 3


def slider(phase, amplitude=50e-6):
    """A Coulomb slider's displacement and force (tests/return_map.py) at drive ``phase``."""
    displacement = -amplitude * np.cos(2 * np.pi * phase)
    force, _ = return_map(displacement, LOAD, STIFFNESS, MU, np.zeros_like)
    return displacement, force


@pytest.fixture(scope="module")
def chirp():
    """14 cycles whose period grows from 300 to 420 samples (no two cycles alike)."""
    period = np.linspace(300.0, 420.0, 14 * 360)
    phase = np.cumsum(1.0 / period)
    return slider(phase[phase < 14.0])


def centred(displacement, force, gap=None):
    """The cycles, and every whole cycle's middle, period, centre, drift se and the offset
    of the drift subtracted over its second half against its first (by samples)."""
    if gap is not None:
        displacement = displacement.copy()
        displacement[gap] = np.nan
    cycles = find_cycles(displacement, force=force)
    blocks = list(loop_blocks(cycles, displacement, force))
    kept = np.flatnonzero(cycles.whole)
    start, count = cycles.start[kept], cycles.count[kept]
    middle = np.array(
        [(np.arange(s, s + n).sum() + s) / (n + 1) for s, n in zip(start, count, strict=True)]
    )
    offset = []
    for block in blocks:
        for row, (first, size) in enumerate(zip(block.offset, block.count, strict=True)):
            cycle = block.rows.start + row
            recorded = force[cycles.start[cycle] : cycles.start[cycle] + size]
            drift = recorded - block.force[first : first + size]
            half = size // 2
            offset.append(drift[half:].mean() - drift[:half].mean())
    joined = {
        name: np.concatenate([getattr(block, name) for block in blocks])
        for name in ("force_centre", "force_drift_se")
    }
    return middle, count, joined["force_centre"], joined["force_drift_se"], np.array(offset)


def interpolated(points, values, at):
    """``values`` at ``points`` interpolated linearly at ``at``, extended beyond the ends."""
    inside = np.interp(at, points, values)
    below = values[0] + (at - points[0]) * (values[1] - values[0]) / (points[1] - points[0])
    above = values[-1] + (at - points[-1]) * (values[-1] - values[-2]) / (points[-1] - points[-2])
    return np.where(at < points[0], below, np.where(at > points[-1], above, inside))


def brute_force_se(middle, count, centre):
    """σ_c (Σ_j a_j²)^½ with a_j the offset of unit centre j, over continuous halves."""
    size = centre.size
    second = np.abs(centre[:-2] - 2 * centre[1:-1] + centre[2:])  # at cycles 1 .. size - 2
    result = []
    for i in range(size):
        window = second[max(i - REACH - 1, 0) : max(i + REACH, 0)]
        sigma = np.median(window) / (norm.ppf(0.75) * np.sqrt(6.0))
        weights = [
            interpolated(middle, unit, middle[i] + count[i] / 4)
            - interpolated(middle, unit, middle[i] - count[i] / 4)
            for unit in np.eye(size)
        ]
        result.append(sigma * np.sqrt(np.sum(np.square(weights))))
    return np.array(result)


@pytest.mark.parametrize("gap", [None, slice(2600, 3000)], ids=["whole", "one cycle missing"])
def test_drift_se_is_the_brute_force(chirp, gap):
    """force_drift_se equals the brute force to rounding (1e-9), gaps and ends included."""
    rng = np.random.default_rng(3)
    displacement = chirp[0] + rng.normal(0.0, 0.1e-6, chirp[0].size)
    force = chirp[1] + rng.normal(0.0, 1.0, chirp[1].size)
    middle, count, centre, drift_se, _ = centred(displacement, force, gap)
    assert centre.size >= 11
    expected = brute_force_se(middle, count, centre)
    np.testing.assert_allclose(drift_se, expected, rtol=1e-9)
    # The ends, extrapolated, are about twice as uncertain as the inner cycles.
    assert drift_se[0] > 1.5 * np.median(drift_se[2:-2])


def test_drift_se_is_the_scatter_of_the_offset(chirp):
    """Over 300 noise draws, the offset subtracted between each loop's branches scatters as
    force_drift_se says, never more: the ratio of its standard deviation to the root mean
    square of the se is 0.7 to 1.1 inside, 0.5 to 1.1 at the ends. The se errs on the safe
    side: the median of 7 absolute second differences (3 at the ends) over 0.6745 has a root
    mean square 1.12 (1.25) times the noise's standard deviation."""
    rng = np.random.default_rng(5)
    offsets, ses = [], []
    for _ in range(300):
        displacement = chirp[0] + rng.normal(0.0, 0.1e-6, chirp[0].size)
        force = chirp[1] + rng.normal(0.0, 1.0, chirp[1].size)
        _, _, _, drift_se, offset = centred(displacement, force)
        offsets.append(offset)
        ses.append(drift_se)
    ratio = np.std(offsets, axis=0) / np.sqrt(np.mean(np.square(ses), axis=0))
    assert np.all((ratio[1:-1] > 0.7) & (ratio[1:-1] < 1.1)), ratio
    assert np.all((ratio[[0, -1]] > 0.5) & (ratio[[0, -1]] < 1.1)), ratio


def test_short_recordings_and_labelled_cycles():
    """One whole cycle: no offset (0). Two: the first difference of their centres. Cycles
    with their own numbers are each moved by their own centre: 0."""
    displacement, force = slider(np.arange(2 * 400 + 1) / 400)
    force = force + np.random.default_rng(1).normal(0.0, 1.0, force.size)
    for size in (1, 2):
        cut = slice(0, size * 400 + 1)
        cycles = find_cycles(displacement[cut], force=force[cut])
        (block,) = loop_blocks(cycles, displacement[cut], force[cut])
        assert block.force_drift_se.size == size
        if size == 1:
            assert block.force_drift_se[0] == 0.0
        else:
            jump = abs(block.force_centre[1] - block.force_centre[0])
            # a = ±1/(2k) for middles k periods apart, noise |c1 - c0|/√2: |c1 - c0|/(2k).
            start, count = cycles.start, cycles.count
            middle = (count * (2 * start + count - 1) / 2 + start) / (count + 1)
            periods = (middle[1] - middle[0]) / count
            np.testing.assert_allclose(block.force_drift_se, jump / (2 * periods), rtol=1e-9)
    label = np.repeat([1, 2], 401)[: displacement.size]
    cycles = find_cycles(displacement, label)
    for block in loop_blocks(cycles, displacement, force):
        np.testing.assert_array_equal(block.force_drift_se, 0.0)
