"""analyze_loops, rewritten to work block by block, against the outputs of its former padded
implementation (tests/measured/golden).

On each recording every per-cycle quantity must agree to 1e-12 of its natural scale
(tests/measured/compare.py); the cycles found, their labels, the regimes and the counts of
dropped samples must be the same. The plausibility checks (ecofmaps.measured.quality) came
after: a value the padded implementation gave may now be NaN, but only where the cycle's
``quality`` says why, and every cycle of the gross-slip recordings here must be ``'ok'``.
"""

import warnings

import numpy as np
import pytest

from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.quality import LoopQualityWarning
from ecofmaps.paper import AMPLITUDE, LOAD
from tests.measured import golden
from tests.measured.compare import TOLERANCE, assert_same

PARTIAL_SLIP = ("partial slip (Mindlin)", "no gross slip")


@pytest.mark.parametrize("name", golden.RECORDINGS)
def test_same_numbers_as_the_padded_implementation(name):
    displacement, force, cycle = golden.RECORDINGS[name]()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LoopQualityWarning)  # partial slip, flagged
        new = analyze_loops(displacement, force, LOAD, cycle)
    assert_same(new, golden.analysis(name, displacement, force))
    if name not in PARTIAL_SLIP:  # clean recordings of gross slip: every cycle plausible
        assert (new.quality == "ok").all(), new.attrs["quality_summary"]


@pytest.mark.parametrize("name", golden.PLOTTED)
def test_same_loops_for_plotting(name):
    """``keep_loops=True``: the same centred (cycle, point) loops, NaN-padded alike."""
    make, options = golden.PLOTTED[name]
    displacement, force, cycle = make()
    new = analyze_loops(displacement, force, LOAD, cycle, **options)
    old = golden.analysis(name, displacement, force)
    for variable, scale in (("loop_displacement", AMPLITUDE), ("loop_force", LOAD)):
        np.testing.assert_array_equal(new[variable].isnull(), old[variable].isnull())
        np.testing.assert_allclose(new[variable], old[variable], rtol=0, atol=TOLERANCE * scale)
    np.testing.assert_array_equal(new.point, old.point)
