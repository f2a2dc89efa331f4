"""A recording held as dask arrays, analysed block by block: the numbers of the same
recording in memory; and recordings with missing samples.

Chunks of the passes over the recording, dask blocks and the tasks of cycles are made small
and awkward here (1000, 1700 and 777 samples), so that runs, cycles, percentile brackets,
halos and missing samples straddle every edge. Every per-cycle quantity must equal the
analysis in memory to 1e-12 of its natural scale (tests/measured/test_equivalence.py), the
quality and regime strings and the attributes exactly.
"""

import warnings

import dask.array as da
import numpy as np
import pytest
import xarray as xr

import ecofmaps
from ecofmaps.measured import cycles, pipeline
from ecofmaps.measured import samples as passes
from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.pipeline import LoopOptions
from ecofmaps.measured.quality import LoopQualityWarning
from ecofmaps.measured.samples import MissingSampleError
from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.paper import EXAMPLE_2, LOAD
from tests.measured.compare import COEFFICIENTS, DISPLACEMENTS, FORCES, TOLERANCE
from tests.recordings import mindlin_recording, noisy

READ = ("mu_resolved", "mu_resolved_se", "aspect_ratio")


@pytest.fixture
def small_blocks(monkeypatch):
    """Passes a chunk of 1000 samples at a time, tasks of about 777 samples."""
    monkeypatch.setattr(passes, "_CHUNK", 1000)
    monkeypatch.setattr(passes, "_SAMPLE", 256)
    monkeypatch.setattr(pipeline, "TASK_SAMPLES", 777)


def analysed(displacement, force, cycle=None, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LoopQualityWarning)
        return analyze_loops(displacement, force, LOAD, cycle, **options)


def lazily(*arrays, chunks=1700):
    return [None if a is None else da.from_array(a, chunks=chunks) for a in arrays]


def assert_equal_results(lazy, memory):
    """Every per-cycle number within 1e-12 of its natural scale; the rest exactly."""
    assert lazy.attrs.keys() == memory.attrs.keys()
    for name, value in memory.attrs.items():  # regime_changes_at is an array
        np.testing.assert_array_equal(lazy.attrs[name], value, err_msg=name)
    np.testing.assert_array_equal(lazy.cycle, memory.cycle)
    for name in ("regime", "quality"):
        np.testing.assert_array_equal(lazy[name].values, memory[name].values)
    amplitude = np.abs(memory.amplitude.values)
    scale = dict.fromkeys(DISPLACEMENTS, amplitude) | {"stick_residual": amplitude}
    scale |= dict.fromkeys((*FORCES, "force_drift_se"), np.abs(memory.max_force.values))
    scale |= dict.fromkeys(COEFFICIENTS, np.abs(memory.cof_max.values))
    scale |= {"dissipated_energy": 4 * amplitude * np.abs(memory.max_force.values)}
    scale |= {"stiffness": np.abs(memory.stiffness.values)}
    if "mu_resolved" in memory:  # read along the stroke: coefficients and slopes
        scale |= dict.fromkeys(READ, np.abs(memory.cof_max.values))
    assert set(scale) == {n for n in memory.data_vars if memory[n].dtype.kind == "f"}
    for name, natural in scale.items():
        a, b = lazy[name].values, memory[name].values
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=name)
        both = ~np.isnan(b)
        allowed = TOLERANCE * np.maximum(np.abs(b[both]), natural[both])
        assert np.all(np.abs(a[both] - b[both]) <= allowed), name


def with_gaps(displacement, force, where):
    """A copy with NaN displacement or force at the samples ``where`` (alternately)."""
    x, q = displacement.copy(), force.copy()
    for k, index in enumerate(where):
        (x if k % 2 == 0 else q)[index] = np.nan
    return x, q


def labelled_with_offsets():
    displacement, force = noisy(EXAMPLE_2, 12, 7, start_phase=0.3)
    jumps = np.repeat(np.arange(12) * 1e-6, 200)  # a new offset for each loop
    return displacement + jumps, force + 3e3 * jumps, np.repeat(np.arange(1, 13) * 100, 200)


def dead_channel():
    """The force channel dies in the 7th of ten cycles: flagged cycles beside good ones."""
    displacement, force = noisy(EXAMPLE_2, 10, 3)
    force[1300:] = 7.25
    return displacement, force, None


def missing_everywhere():
    """NaN in the middle of cycles, a run of empty samples, at a reversal, at both ends."""
    displacement, force = noisy(EXAMPLE_2, 14, 5)
    bottom = 5 * 200  # a bottom reversal of the sinusoid
    x, q = with_gaps(displacement, force, [0, 450, bottom, 2101, *range(2400, 2440), -1])
    return x, q, None


RECORDINGS = {
    "noise, offsets, drift": lambda: (*noisy(EXAMPLE_2, 30, 1), None),
    "jittered clock, mid-stroke start": lambda: (
        *noisy(EXAMPLE_2, 25, 2, sampling_jitter=0.4, samples_per_cycle=139, start_phase=0.37),
        None,
    ),
    "labelled, new offset each loop": labelled_with_offsets,
    "partial slip (Mindlin)": lambda: (*mindlin_recording(0.9, cycles=8), None),
    "flagged cycles (dead force channel)": dead_channel,
    "missing samples": missing_everywhere,
    "missing samples, labelled": lambda: (
        *with_gaps(*labelled_with_offsets()[:2], [10, 777, 2300, 2399]),
        labelled_with_offsets()[2].astype(np.float64),
    ),
}


@pytest.mark.parametrize("name", RECORDINGS)
@pytest.mark.parametrize("chunks", [1700, 3000])
def test_same_numbers_as_in_memory(small_blocks, name, chunks, monkeypatch):
    displacement, force, cycle = RECORDINGS[name]()
    memory = analysed(displacement, force, cycle)
    tasks = []
    original = pipeline._tasks
    monkeypatch.setattr(pipeline, "_tasks", lambda *a: tasks.append(original(*a)) or tasks[-1])
    lazy = analysed(*lazily(displacement, force, cycle, chunks=chunks), scheduler="threads")
    assert len(tasks[0]) >= 3  # several tasks, each with its halo
    assert_equal_results(lazy, memory)


@pytest.mark.parametrize(
    "name", ["noise, offsets, drift", "labelled, new offset each loop", "missing samples"]
)
def test_read_along_the_stroke_as_in_memory(small_blocks, name):
    """resolve=True: each task reads its own loops along the stroke, which never leave it;
    the values and the reading's quality as in memory."""
    displacement, force, cycle = RECORDINGS[name]()
    memory = analysed(displacement, force, cycle, resolve=True)
    lazy = analysed(*lazily(displacement, force, cycle), scheduler="threads", resolve=True)
    assert memory.mu_resolved.notnull().sum() >= 8
    assert_equal_results(lazy, memory)


def test_xarray_and_a_missing_mask(small_blocks):
    """DataArrays backed by dask, and samples marked missing by a mask."""
    displacement, force = noisy(EXAMPLE_2, 12, 11)
    mask = np.zeros(displacement.size, dtype=bool)
    mask[[650, 1999]] = True
    data = xr.Dataset(
        {"x": ("sample", displacement), "q": ("sample", force), "m": ("sample", mask)}
    ).chunk(sample=1300)
    lazy = analysed(data.x, data.q, missing=data.m, scheduler="threads", workers=2)
    memory = analysed(displacement, force, missing=mask)
    assert lazy.attrs["skipped_cycles"] == 2
    assert_equal_results(lazy, memory)


@pytest.mark.slow
def test_a_local_cluster_of_two_processes(small_blocks):
    """The blocks run in two worker processes: the same numbers (the passes' chunk and the
    tasks' cycles travel with the tasks, not as settings of this process)."""
    displacement, force, _ = missing_everywhere()
    memory = analysed(displacement, force)
    lazy = analysed(*lazily(displacement, force), scheduler="processes", workers=2)
    assert_equal_results(lazy, memory)


def _worker_settings():
    import os

    import dask

    return (
        os.environ.get("MALLOC_TRIM_THRESHOLD_"),
        dask.config.get("distributed.worker.profile.enabled"),
    )


@pytest.mark.slow
def test_the_workers_of_a_local_cluster_run_lean():
    """A local cluster's workers keep glibc's own mmap threshold and do not sample their
    tasks' stacks (module notes of ecofmaps._parallel); this process's settings are left as
    they were."""
    import copy

    import dask
    import distributed  # noqa: F401 - its settings are read

    from ecofmaps._parallel import Runner

    before = copy.deepcopy(dask.config.get("distributed"))
    with Runner(1, cluster=True) as runner:
        settings = runner._client.run(_worker_settings)
    assert list(settings.values()) == [(None, False)]
    assert dask.config.get("distributed") == before


def test_a_scheduler_that_does_not_answer():
    from ecofmaps._parallel import Runner, SchedulerError

    with (
        pytest.raises(
            SchedulerError, match=r"no dask scheduler at tcp://127\.0\.0\.1:9: .* after 1 s"
        ),
        Runner(scheduler="tcp://127.0.0.1:9", timeout=1.0),
    ):
        pass


# --- missing samples, in memory ----------------------------------------------------------------


def test_a_few_missing_samples_skip_their_cycles_only():
    """Each NaN skips the one cycle that holds it; cycles three or more away from a skipped
    one are measured as in the recording without gaps (to rounding): the centring reaches no
    further (a neighbour's displacement drift is interpolated across the gap, which moves
    its force centre, which the next cycle's force drift uses). Those nearer move by less
    than the rig's noise moves them (1 % of the force here; Δ* and Q*, read through the
    noise round the extremes, by 2 %: the fit follows the extreme sample when another
    takes its place)."""
    displacement, force = noisy(EXAMPLE_2, 20, 4)
    clean = analysed(displacement, force)
    gaps = [430, 2250, 2251, 3615]
    result = analysed(*with_gaps(displacement, force, gaps))
    found = cycles.find_cycles(displacement)
    skipped = np.unique(np.searchsorted(found.start, gaps, side="right") - 1)
    np.testing.assert_array_equal(skipped, [2, 11, 18])  # of 20 cycles
    assert (result.quality.values[skipped] == "missing-samples").all()
    assert (result.regime.values[skipped] == ecofmaps.INVALID).all()
    assert result[["gicof", "ecof", "amplitude"]].isel(cycle=skipped).isnull().all()
    assert result.attrs["quality_summary"] == "20 cycles: 17 ok, 3 skipped (missing samples)"
    assert result.attrs["skipped_cycles"] == 3
    assert result.attrs["missing_samples"] == 4
    assert result.attrs["first_missing_sample"] == 430
    rows = np.arange(clean.cycle.size)
    distance = np.min(np.abs(rows[:, None] - skipped[None, :]), axis=1)
    far, near = distance >= 3, (distance > 0) & (distance < 3)
    for name in ("gicof", "ecof", "stiffness", "displacement_offset", "force_offset"):
        np.testing.assert_allclose(result[name].values[far], clean[name].values[far], rtol=1e-12)
    for name in ("gicof", "ecof", "stiffness", "amplitude", "max_force"):
        rtol = 2e-2 if name in ("amplitude", "max_force") else 1e-2
        np.testing.assert_allclose(result[name].values[near], clean[name].values[near], rtol=rtol)


def test_missing_at_a_reversal_and_at_the_ends():
    """A recording that begins and ends on a bottom reversal (samples 0 and 1999): with NaN
    there, the first and last cuts move to the lowest finite samples near them, and the
    missing samples are dropped with the incomplete ends; a NaN force at the reversal at
    1000 skips the cycle that holds it."""
    displacement, force = noisy(EXAMPLE_2, 10, 6)
    clean = cycles.find_cycles(displacement)
    assert (clean.start[0], clean.start[-1] + clean.count[-1]) == (0, 2000)
    x, q = with_gaps(displacement, force, [0, 1000, -1])
    found = cycles.find_cycles(x, force=q)
    first, last = found.start[0], found.start[-1] + found.count[-1] - 1
    assert 1 <= first <= 5 and 1993 <= last <= 1998
    assert found.dropped_samples == first + 1999 - last
    result = analysed(x, q)
    assert result.cycle.size == clean.label.size == 10
    assert result.attrs["skipped_cycles"] == 1
    assert list(result.quality.values).count("missing-samples") == 1
    assert (result.quality.values != "ok").sum() == 1


def test_missing_cycle_numbers_take_the_one_before():
    displacement, force, cycle = labelled_with_offsets()
    cycle = cycle.astype(np.float64)
    cycle[[450, 1800]] = np.nan  # inside the 3rd loop and on the 10th's first sample
    result = analysed(displacement, force, cycle)
    np.testing.assert_array_equal(result.cycle, np.arange(1, 13) * 100)
    # The sample without a number joins the 9th loop, which holds a missing sample then;
    # the 10th, one sample short, still closes.
    assert list(result.cycle.values[result.quality.values == "missing-samples"]) == [300, 900]


def test_nan_policy_raise_names_the_sample():
    displacement, force = noisy(EXAMPLE_2, 6, 1)
    x, q = with_gaps(displacement, force, [777, 900])
    with pytest.raises(MissingSampleError, match="sample 777 is missing") as caught:
        analyze_loops(x, q, LOAD, nan_policy="raise")
    assert caught.value.sample == 777
    with pytest.raises(MissingSampleError, match="sample 900 is missing"):
        analyze_loops(*lazily(displacement, q), LOAD, nan_policy="raise", scheduler="threads")
    mask = np.zeros(x.size, dtype=bool)
    mask[5] = True
    with pytest.raises(MissingSampleError, match="sample 5 is missing"):
        analyze_loops(displacement, force, LOAD, missing=mask, nan_policy="raise")
    with pytest.raises(ValueError, match="nan_policy must be one of"):
        analyze_loops(displacement, force, LOAD, nan_policy="omit")


def test_every_cycle_missing_is_an_error():
    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=4)
    force[100::200] = np.nan
    with pytest.raises(ValueError, match=r"no plausible cycle.*Every cycle holds a missing"):
        analyze_loops(displacement, force, LOAD)


def test_tallies_of_parts_merge_into_the_tally_of_the_whole():
    """Tasks count their parts where they run (Tally.add) and the counts are merged: the
    same summary, refusals, checks and amplitudes as counting the whole at once."""
    from ecofmaps.measured.measure import measure_cycles
    from ecofmaps.measured.quality import Tally, judged, scale_flags

    x, q = noisy(EXAMPLE_2, 12, 3)
    x, q = with_gaps(x, q, [700, 1900])  # skipped cycles besides the flagged ones
    options = LoopOptions(LOAD)
    found = cycles.find_cycles(x, None, 0.5, force=q)
    values, flags, _ = measure_cycles(found, x, q, options)
    flags |= scale_flags(values, options)
    whole = Tally()
    whole.add(judged(values, flags, options)[1], flags, values["amplitude"])
    merged = Tally()
    for rows in (slice(0, 5), slice(5, 6), slice(6, None)):
        part = Tally()
        take = {k: v[rows] for k, v in values.items()}
        checks = {k: v[rows] for k, v in flags.items()}
        part.add(judged(take, checks, options)[1], checks, take["amplitude"])
        merged.merge(part)
    assert whole.summary == merged.summary and "skipped" in whole.summary
    assert (whole.cycles, whole.refused, whole.flagged) == (
        merged.cycles,
        merged.refused,
        merged.flagged,
    )
    assert whole.every == merged.every and whole.counts == merged.counts
    assert whole.negative_stiffness == merged.negative_stiffness
    np.testing.assert_array_equal(
        np.concatenate(whole.amplitudes), np.concatenate(merged.amplitudes)
    )


def test_tasks_keep_what_they_measured_where_they_run(small_blocks, tmp_path):
    """``keep=True`` hands each task's values and flags back; a ``keep`` path has each task
    keep the same in its file there (:func:`pipeline.block_file`), and nothing comes back."""
    from ecofmaps._parallel import Runner

    x, q = noisy(EXAMPLE_2, 12, 3)
    options = LoopOptions(LOAD)
    x, q = lazily(x, q)
    prefix = tmp_path / "block"
    with Runner(2) as runner:
        analysis = pipeline.Analysis(x, q, options=options, runner=runner, samples=900)
        assert len(analysis.tasks) > 2
        handed = {k: (c.values, c.flags) for k, c in analysis.measured(keep=True)}
        nothing = [(c.values, c.flags) for _, c in analysis.measured()]
        returned = [(c.values, c.flags) for _, c in analysis.measured(keep=prefix)]
    assert all(v is None and f is None for v, f in nothing + returned)
    assert sorted(handed) == list(range(len(analysis.tasks)))
    assert sorted(tmp_path.iterdir()) == [pipeline.block_file(prefix, k) for k in handed]
    for index, (values, flags) in handed.items():
        kept = pipeline.kept_block(pipeline.block_file(prefix, index))
        assert kept[0].keys() == values.keys() and kept[1].keys() == flags.keys()
        for name in values:
            np.testing.assert_array_equal(kept[0][name], values[name])
        for name in flags:
            np.testing.assert_array_equal(kept[1][name], flags[name])


def _variables(part):
    """A ``then`` of :meth:`Analysis.measured`: the names of the results it is given."""
    return sorted(part.data_vars)


def test_tasks_hand_back_only_the_columns_asked_for(small_blocks):
    """With ``columns``, each task's results hold only those of them there are, with the
    same values; ``then`` is given them all."""
    from ecofmaps._parallel import Runner

    x, q = lazily(*noisy(EXAMPLE_2, 12, 3))
    columns = ("quality", "ecof", "no_such_variable")
    with Runner(2) as runner:
        reading = pipeline.Reading(resolve=True)
        analysis = pipeline.Analysis(
            x, q, options=LoopOptions(LOAD), runner=runner, samples=900, reading=reading
        )
        whole = [chunk.part for _, chunk in analysis.measured(then=_variables)]
        only = list(analysis.measured(then=_variables, columns=columns))
    assert len(only) == len(whole) == len(analysis.tasks) > 2
    for (_, chunk), full in zip(only, whole, strict=True):
        part, made = chunk.part, chunk.made
        assert sorted(part.data_vars) == ["ecof", "quality"]
        assert made == sorted(full.data_vars) and "mu_resolved" in made
        xr.testing.assert_identical(part, full[["quality", "ecof"]])


@pytest.mark.slow
def test_a_worker_reads_and_measures_without_jax_or_pint():
    """The modules a task of a long analysis loads (reading a rig file's column, the passes,
    measuring a block, formatting its rows) leave JAX, pint and SciPy unloaded: a worker
    process starts its first task without them. Names of the packages still import.

    numba (the measuring kernels) imports the ``scipy`` package itself to check its
    version (its ``__init__``, about 10 ms), none of SciPy's subpackages."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "import ecofmaps.io.binary, ecofmaps.measured.samples, ecofmaps.measured.pipeline\n"
        "import ecofmaps.io.tables, ecofmaps.cli.loops_long\n"
        "loaded = [m for m in ('jax', 'pint') if m in sys.modules]\n"
        "loaded += [m for m in sys.modules if m.startswith('scipy.')\n"
        "           and not m.startswith(('scipy._', 'scipy.version'))]\n"
        "assert not loaded, loaded\n"
        "from ecofmaps.measured import analyze_loops, fit_loop\n"
        "from ecofmaps.model import GROSS_SLIP, fretting_loop\n"
        "from ecofmaps.io import read_scar_profile\n"
        "assert 'jax' in sys.modules and callable(fit_loop) and callable(read_scar_profile)\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
