"""Write the golden outputs of the frozen padded implementation (run once, then removed).

PYTHONPATH=$PWD python tests/measured/golden/make.py
"""

from pathlib import Path

import numpy as np

from tests.measured.golden import (
    CHUNKED,
    DRIFT_CASES,
    LABELLED_CASES,
    PLOTTED,
    RECORDINGS,
    SPLIT_CASES,
    drift_inputs,
    fingerprint,
    labelled_input,
    signal,
)
from tests.measured.reference import cycles as reference
from tests.measured.reference.analysis import analyze_loops as reference_analysis

HERE = Path(__file__).parent
LOAD = 450.0


def dataset_arrays(prefix, result, recording):
    """The arrays of one analysis result under ``prefix``, with its attributes and inputs."""
    arrays = {f"{prefix}/{name}": result[name].values for name in result.variables}
    for name in ("incomplete_cycles", "dropped_samples", "cycles_from"):
        arrays[f"{prefix}/attrs/{name}"] = np.array(result.attrs[name])
    arrays[f"{prefix}/fingerprint"] = fingerprint(*recording)
    return arrays


def analyses():
    arrays = {}
    for name, make in RECORDINGS.items():
        displacement, force, cycle = make()
        result = reference_analysis(displacement, force, LOAD, cycle)
        arrays |= dataset_arrays(name, result, (displacement, force))
    for name, (make, options) in (PLOTTED | CHUNKED).items():
        displacement, force, cycle = make()
        result = reference_analysis(displacement, force, LOAD, cycle, **options)
        arrays |= dataset_arrays(name, result, (displacement, force))
    np.savez_compressed(HERE / "analysis.npz", **arrays)


def cycles_found(prefix, found):
    """What the tests compare of a reference ``Cycles``: sample numbers as differences."""
    taken = found.samples[found.valid]
    points = np.count_nonzero(found.valid, axis=1)
    assert np.array_equal(found.valid, np.arange(found.samples.shape[1]) < points[:, None])
    return {
        f"{prefix}/samples": np.diff(taken, prepend=0),
        f"{prefix}/points": points,
        f"{prefix}/width": np.array(found.samples.shape[1]),
        f"{prefix}/label": found.label,
        f"{prefix}/incomplete_cycles": np.array(found.incomplete_cycles),
        f"{prefix}/dropped_samples": np.array(found.dropped_samples),
    }


def cycles():
    arrays = {}
    for number, (kind, size, seed) in enumerate(SPLIT_CASES):
        found = reference.split_cycles(signal(kind, size, seed))
        arrays |= cycles_found(f"split/{number}", found)
    for number, case in enumerate(LABELLED_CASES):
        x, label = labelled_input(*case)
        arrays |= cycles_found(f"labelled/{number}", reference.labelled_cycles(x, label))
    for number, case in enumerate(DRIFT_CASES):
        low, high, middle, centre, _ = drift_inputs(*case)
        drift = reference._interpolate(np.arange(low, high, dtype=float), middle, centre)
        arrays[f"drift/{number}"] = drift
    np.savez_compressed(HERE / "cycles.npz", **arrays)


if __name__ == "__main__":
    analyses()
    cycles()
