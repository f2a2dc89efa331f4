r"""A long synthetic fretting test (10⁵–10⁶ cycles, 10⁸ samples and more), made and written
block by block with bounded memory.

:func:`long_recording` generates it with the example's rig, a deepening groove, noise,
offsets and drift (:func:`ecofmaps.measured.synthetic.synthetic_recording`, one block of
cycles at a time), and :func:`write_long_recording` streams it into a TDMS, HDF5/netCDF,
zarr or CSV file, for testing the reading and the out-of-core analysis of rig files.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ecofmaps.io.writers import RecordingWriter
from ecofmaps.measured.synthetic import synthetic_recording

__all__ = ["LONG_TEST", "long_recording", "write_long_recording"]


#: The default parameters of :func:`long_recording`: the example's rig (the paper's Example 2,
#: Section 3) and sensors, a groove deepening to z_o/x_o = 0.2 over the test, and a
#: displacement drift of 2 um over the whole test.
LONG_TEST = {
    "amplitude": 50e-6,
    "load": 450.0,
    "stiffness": 35e6,
    "mu": 0.8,
    "final_aspect_ratio": 0.2,
    "displacement_noise": 0.25e-6,
    "force_noise": 4.0,
    "displacement_offset": 3.0e-6,
    "force_offset": 6.0,
    "displacement_drift": 2.0e-6,
}


def long_recording(cycles, samples_per_cycle=200, *, block_cycles=4096, seed=0, **parameters):
    r"""A long fretting test, generated block by block with bounded memory.

    Parameters
    ----------
    cycles : int
        Number of cycles of the test (every one recorded). [1]
    samples_per_cycle : int
        Samples per cycle (>= 8). [1]
    block_cycles : int
        Cycles simulated at a time: the memory used is a few arrays of
        ``block_cycles * samples_per_cycle`` samples. [1]
    seed : int
        Seed of the noise: block ``k`` uses its own stream derived from ``(seed, k)``, so the
        recording depends on ``seed`` and ``block_cycles`` only.
    **parameters
        Any of :data:`LONG_TEST`: ``amplitude`` [m], ``load`` [N], ``stiffness`` [N/m],
        ``mu``, ``final_aspect_ratio`` (the groove's z_o/x_o at the end of the test),
        ``displacement_noise`` [m] and ``force_noise`` [N] (standard deviations),
        ``displacement_offset`` [m], ``force_offset`` [N], ``displacement_drift`` (over the
        whole test) [m].

    Yields
    ------
    cycle : numpy.ndarray of int64
        The 1-based test cycle of each sample of the block. [1]
    displacement, force : numpy.ndarray
        The recorded signals of the block. [m], [N]

    Notes
    -----
    Cycle :math:`N` (1-based) has the groove :math:`z_o/x_o = r_f \sqrt{N / N_{total}}`
    with the groove half-width equal to the amplitude (the paper's :math:`x_o = \Delta^*`),
    as in :func:`ecofmaps.measured.synthetic.example_recording`; each block is
    :func:`synthetic_recording`'s steady loops (eq. 9, 10) from zero displacement on the
    rise, with its offset advanced by the drift so far, so the drift runs on without a step
    from block to block.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 10.
    """
    unknown = set(parameters) - set(LONG_TEST)
    if unknown:
        raise TypeError(f"unknown parameters: {', '.join(sorted(unknown))}")
    p = {**LONG_TEST, **parameters}
    for name, value in (("cycles", cycles), ("block_cycles", block_cycles)):
        if isinstance(value, bool) or not int(value) == value >= 1:
            raise ValueError(f"{name} must be an integer >= 1; got {value!r}")
    cycles, block_cycles, n = int(cycles), int(block_cycles), int(samples_per_cycle)
    drift = p["displacement_drift"] / cycles  # per cycle
    for index, first in enumerate(range(0, cycles, block_cycles)):
        count = min(block_cycles, cycles - first)
        # Every block is simulated at the full size (one compilation), then cut.
        number = np.arange(first + 1, first + block_cycles + 1)
        ratio = p["final_aspect_ratio"] * np.sqrt(np.minimum(number, cycles) / cycles)
        displacement, force = synthetic_recording(
            p["amplitude"],
            p["load"],
            p["stiffness"],
            p["mu"],
            ratio,
            samples_per_cycle=n,
            start_phase=0.25,
            displacement_noise=p["displacement_noise"],
            force_noise=p["force_noise"],
            displacement_offset=p["displacement_offset"] + drift * first,
            force_offset=p["force_offset"],
            displacement_drift=drift,
            seed=int(np.random.SeedSequence([seed, index]).generate_state(1)[0]),
        )
        yield np.repeat(number[:count], n), displacement[: count * n], force[: count * n]


def write_long_recording(
    path,
    cycles,
    samples_per_cycle=200,
    *,
    format=None,
    cycle_numbers=False,
    chunk_samples=1 << 20,
    overwrite=False,
    block_cycles=4096,
    seed=0,
    **parameters,
):
    """Write :func:`long_recording` to a file or store, block by block.

    Parameters
    ----------
    path : str or os.PathLike
        ``.tdms``, ``.h5``/``.nc``, ``.zarr`` or ``.csv`` (the format from the suffix, or
        ``format``).
    cycles, samples_per_cycle, block_cycles, seed, **parameters
        As for :func:`long_recording`.
    format : str, optional
        See :class:`ecofmaps.io.writers.RecordingWriter`.
    cycle_numbers : bool
        Also write the cycle number of each sample (a ``cycle`` column).
    chunk_samples : int
        Samples per chunk (zarr, HDF5) or per TDMS segment.
    overwrite : bool
        Replace an existing file (only once the new one is complete).

    Returns
    -------
    path : pathlib.Path
        The file, written atomically: displacement [m] and force [N] (SI, float64, with
        their units), in the TDMS group ``recording`` or at the store's root.

    Examples
    --------
    >>> import tempfile, pathlib, ecofmaps
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "test.zarr"
    >>> _ = write_long_recording(path, cycles=20, samples_per_cycle=50)
    >>> ecofmaps.read_recording(path).size
    1000
    """
    blocks = long_recording(
        cycles, samples_per_cycle, block_cycles=block_cycles, seed=seed, **parameters
    )
    attrs = {
        "title": "SYNTHETIC DATA, not a measurement: ecofmaps.measured.synthetic.long_recording",
        "cycles": int(cycles),
        "samples_per_cycle": int(samples_per_cycle),
        "block_cycles": int(block_cycles),
        "seed": int(seed),
        **{name: float(value) for name, value in {**LONG_TEST, **parameters}.items()},
    }
    with RecordingWriter(
        path,
        format=format,
        cycle=cycle_numbers,
        chunk_samples=chunk_samples,
        overwrite=overwrite,
        attrs=attrs,
    ) as writer:
        for cycle, displacement, force in blocks:
            writer.write(displacement, force, cycle if cycle_numbers else None)
    return Path(path)
