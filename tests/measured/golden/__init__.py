"""The outputs of the padded implementation of the loop analysis, kept to compare against.

The recordings and signals of each case are made here; what the padded implementation
returned for them is in ``analysis.npz`` (``analyze_loops``: per-cycle quantities, regimes,
counts) and ``cycles.npz`` (``find_cycles`` without and with cycle numbers, and the centres'
drift).
README.md says how they were made.
"""

from functools import cache
from pathlib import Path

import numpy as np
import xarray as xr

from ecofmaps.measured.synthetic import example_recording, synthetic_recording
from ecofmaps.paper import EXAMPLE_2, LOAD
from tests.recordings import mindlin_recording, noisy, ploughing_recording

HERE = Path(__file__).parent


def _recordings():
    """Name and maker of (displacement, force, cycle) of each recording of ``analysis.npz``."""

    def labelled():
        displacement, force = noisy(EXAMPLE_2, 12, 7, start_phase=0.3)
        jumps = np.repeat(np.arange(12) * 1e-6, 200)  # a new offset for each loop
        cycle = np.repeat(np.arange(1, 13) * 100, 200)
        return displacement + jumps, force + 3e3 * jumps, cycle

    def shipped():
        cycle, displacement, force = example_recording()
        return displacement, force, cycle

    flat = dict(EXAMPLE_2, aspect_ratio=0.0)
    return {
        "Example 2, noise, offsets, drift": lambda: (*noisy(EXAMPLE_2, 40, 1), None),
        "jittered clock": lambda: (*noisy(EXAMPLE_2, 30, 2, sampling_jitter=0.4), None),
        "flat groove": lambda: (*noisy(flat, 20, 3), None),
        "stiff rig, low friction": lambda: (
            *noisy(dict(EXAMPLE_2, stiffness=80e6, mu=0.4, aspect_ratio=0.3), 20, 4),
            None,
        ),
        "139 samples per cycle, starting mid-stroke": lambda: (
            *noisy(EXAMPLE_2, 25, 5, samples_per_cycle=139, start_phase=0.37),
            None,
        ),
        "noise-free": lambda: (*synthetic_recording(**EXAMPLE_2, cycles=6), None),
        "sparse: 16 samples per cycle": lambda: (
            *synthetic_recording(**flat, cycles=5, samples_per_cycle=16),
            None,
        ),
        "ploughing peaks": lambda: (*ploughing_recording(0.3 * 0.8 * LOAD, 20, noise=True), None),
        "partial slip (Mindlin)": lambda: (*mindlin_recording(0.9), None),
        "no gross slip": lambda: (*noisy(dict(EXAMPLE_2, stiffness=5e6), 8, 6), None),
        "a single loop": lambda: (
            *synthetic_recording(**EXAMPLE_2, cycles=1, start_phase=0.25),
            None,
        ),
        "shipped example (labelled)": shipped,
        "labelled, new offset each loop": labelled,
    }


#: The recordings analysed as they come.
RECORDINGS = _recordings()


def _chunked(labelled):
    displacement, force = noisy(EXAMPLE_2, 12, 9, sampling_jitter=0.3, start_phase=0.2)
    return displacement, force, np.repeat(np.arange(12), 200) if labelled else None


#: Recordings analysed with options: name -> (maker, keyword arguments of analyze_loops).
PLOTTED = {
    "loops kept for plotting": (
        lambda: (*noisy(EXAMPLE_2, 8, 8, sampling_jitter=0.3), None),
        {"keep_loops": True},
    )
}
CHUNKED = {
    "in small chunks": (lambda: _chunked(False), {}),
    "in small chunks, labelled": (lambda: _chunked(True), {}),
}

#: (kind of signal, samples, seed) of ``find_cycles`` at the reversals.
SPLIT_CASES = [
    (kind, size, 1000 * kind + number)
    for kind in range(5)
    for number, size in enumerate((8, 40, 333, 1000, 1001, 2500, 5000, 12_000))
]
#: (kind of signal, samples, samples per label, seed) of ``find_cycles`` by cycle numbers.
LABELLED_CASES = [
    (kind, size, length, 2000 + 100 * kind + number)
    for kind in range(5)
    for number, (size, length) in enumerate(
        ((8, 5), (200, 7), (1000, 300), (3001, 64), (8000, 150))
    )
]
#: (cycles, seed, power of ten of the centres) of the centres' drift.
DRIFT_CASES = [
    (count, 3000 + number, scale)
    for number, (count, scale) in enumerate(
        ((1, 0), (2, -9), (2, 3), (3, -6), (5, 0), (7, -3), (12, 1), (20, -7), (30, 2), (30, -9))
    )
]


def signal(kind: int, size: int, seed: int):
    """Noise, a random walk, a clipped noisy sine, rounded noise (ties) or a drifting sine."""
    rng = np.random.default_rng(seed)
    period = rng.integers(8, 400)
    sine = np.sin(2 * np.pi * np.arange(size) / period)
    return [
        rng.normal(size=size),
        np.cumsum(rng.normal(size=size)),
        np.clip(sine, -0.7, 0.7) + 0.01 * rng.normal(size=size),
        np.round(rng.normal(size=size), 1),
        sine + 3.0 * np.arange(size) / size + 0.02 * rng.normal(size=size),
    ][kind]


def labelled_input(kind, size, length, seed):
    """A signal and its labels, a new one every ``length`` samples."""
    return signal(kind, size, seed), np.arange(size) // length * 10


def drift_inputs(count, seed, scale):
    """Cycles' middles and centres, the samples a block spans (``low`` to ``high``) and the
    rows of the cycles it needs."""
    rng = np.random.default_rng(seed)
    starts = np.cumsum(rng.integers(5, 300, count + 1))
    start, size = starts[:-1], np.diff(starts) + 1
    middle = ((size * (2 * start + size - 1)) // 2 + start) / (size + 1)
    centre = rng.normal(size=count) * 10.0**scale
    first = int(rng.integers(0, count))
    stop = int(rng.integers(first, count)) + 1
    low, high = int(start[first]), int(start[stop - 1] + size[stop - 1])
    return low, high, middle, centre, slice(max(first - 1, 0), stop + 1)


def fingerprint(displacement, force):
    """The sizes and 16 evenly spaced samples of a recording: enough to tell it changed."""
    at = np.linspace(0, displacement.size - 1, 16).astype(int)
    return np.concatenate([[displacement.size, force.size], displacement[at], force[at]])


@cache
def _stored(name):
    with np.load(HERE / name) as stored:
        return dict(stored)


def _under(arrays, prefix):
    return {key[len(prefix) :]: value for key, value in arrays.items() if key.startswith(prefix)}


def analysis(name, displacement, force):
    """The padded implementation's analysis of recording ``name``, as a Dataset.

    ``displacement`` and ``force`` must be the recording it was made from.
    """
    arrays = _under(_stored("analysis.npz"), f"{name}/")
    np.testing.assert_allclose(
        fingerprint(displacement, force),
        arrays.pop("fingerprint"),
        rtol=1e-12,
        err_msg=f"{name!r} is not the recording the golden outputs were made from",
    )
    attrs = {key: value.item() for key, value in _under(arrays, "attrs/").items()}
    variables = {}
    for key, value in arrays.items():
        if not key.startswith("attrs/"):
            dims = ("cycle", "point")[: value.ndim] if key not in ("point", "load") else ()
            variables[key] = (("point",) if key == "point" else dims, value)
    return xr.Dataset(variables, attrs=attrs).set_coords(["cycle", "load"])


def found_cycles(kind, number):
    """What ``find_cycles`` at the reversals (``kind`` 'split') or by numbers ('labelled') found
    in case ``number``: the samples of the cycles one after the other, the count of each
    cycle's samples, the width of its rows, labels, incomplete cycles, dropped samples."""
    arrays = _under(_stored("cycles.npz"), f"{kind}/{number}/")
    found = {key: value.item() if value.ndim == 0 else value for key, value in arrays.items()}
    found["samples"] = np.cumsum(found["samples"])
    return found


def drift(number):
    """The padded implementation's drift on the samples of ``DRIFT_CASES[number]``."""
    return _stored("cycles.npz")[f"drift/{number}"]
