"""The checks of scale speak through their own types: an API user filters
``ImplausibleScaleWarning`` or catches ``ImplausibleScaleError`` without reading messages."""

import warnings

import numpy as np
import pytest

import ecofmaps.measured
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.cycles import find_cycles
from ecofmaps.measured.quality import (
    ImplausibleScaleError,
    ImplausibleScaleWarning,
    LoopQualityWarning,
)
from ecofmaps.paper import EXAMPLE_2, LOAD
from tests.recordings import noisy


@pytest.fixture(scope="module")
def rig():
    """Ten cycles of Example 2 with noise, offsets and drift. [m], [N]"""
    return noisy(EXAMPLE_2, 10, 3)


def test_the_types_are_public():
    assert ecofmaps.measured.ImplausibleScaleWarning is ImplausibleScaleWarning
    assert ecofmaps.measured.ImplausibleScaleError is ImplausibleScaleError
    assert issubclass(ImplausibleScaleWarning, LoopQualityWarning)
    assert issubclass(ImplausibleScaleError, ValueError)


def test_a_wrong_load_warns_with_its_own_category(rig):
    displacement, force = rig
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        analyze_loops(displacement, force, 1.0)
    scale = [w for w in caught if w.category is ImplausibleScaleWarning]
    assert len(scale) == 1 and "load of 1 N: is the load right" in str(scale[0].message)
    others = [w for w in caught if w.category is not ImplausibleScaleWarning]
    assert others and all(w.category is LoopQualityWarning for w in others)


def test_the_scale_warning_is_filtered_by_category(rig):
    """Ignored by category, the scale warning goes and the summary stays; made an error by
    category, it stops the analysis."""
    displacement, force = rig
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.filterwarnings("ignore", category=ImplausibleScaleWarning)
        result = analyze_loops(displacement, force, 1.0)
    assert (result.quality == "implausible-cof").all()
    assert [w.category for w in caught] == [LoopQualityWarning]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        warnings.filterwarnings("error", category=ImplausibleScaleWarning)
        with pytest.raises(ImplausibleScaleWarning, match="is the load right"):
            analyze_loops(displacement, force, 1.0)
        analyze_loops(displacement, force, LOAD)  # a right load: nothing to raise


@pytest.mark.parametrize("scale", [1e-3, 1e6])
def test_a_displacement_in_another_unit_raises_the_scale_error(rig, scale):
    displacement, force = rig
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ImplausibleScaleError, match="--displacement-unit"):
            analyze_loops(displacement * scale, force, LOAD)


def test_other_refusals_are_plain_value_errors(rig):
    """Played backwards, the loops run anticlockwise: refused, but not for their scale."""
    displacement, force = rig
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match="anticlockwise") as raised:
            analyze_loops(displacement[::-1], force[::-1], LOAD)
    assert not isinstance(raised.value, ImplausibleScaleError)


def test_some_cycles_of_an_implausible_amplitude_warn_with_the_category(rig):
    """Numbered loops, two of them ten thousand times too large (an amplitude of 0.5 m):
    those two are refused, the others analysed, and the warning names the unit."""
    displacement, force = rig
    cut = find_cycles(displacement).start  # each loop from its bottom reversal
    cycle = np.searchsorted(cut, np.arange(displacement.size), side="right")
    shrunk = np.where(np.isin(cycle, (4, 7)), displacement * 1e4, displacement)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = analyze_loops(shrunk, force, LOAD, cycle=cycle)
    flagged = result.quality.sel(cycle=[4, 7]).values.tolist()
    assert all("implausible-amplitude" in text for text in flagged)
    scale = [w for w in caught if w.category is ImplausibleScaleWarning]
    assert len(scale) == 1
    assert "2 cycles have an amplitude outside 0.5 µm to 50 mm" in str(scale[0].message)
