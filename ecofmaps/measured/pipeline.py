r"""The driver of the loop pipeline, whatever the way in: chunks of whole cycles (with a halo for
the centring), each measured, read along the stroke and judged where it runs (this process or a
dask runner), the parts joined; a recorded load is converted to the mean load and back here.
``docs/method-loops.md`` ("One pipeline, in memory and out of core")."""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
import os
import types
from pathlib import Path

import numpy as np
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps._inputs import check
from ecofmaps._parallel import Runner, stretch
from ecofmaps.measured import quality, resolve
from ecofmaps.measured.cycles import Cycles, find_cycles
from ecofmaps.measured.measure import GROSS_SLIP_THRESHOLD, NEIGHBOURS, Stretch, measure_cycles
from ecofmaps.measured.samples import MissingSampleError

#: Samples of the recording measured by one chunk of a long recording (about; whole cycles).
TASK_SAMPLES = 1 << 22
#: The reading along the stroke of the per-cycle values alone (no grid of positions).
_PER_CYCLE = resolve.ReadingOptions(positions=None)


@dataclasses.dataclass(frozen=True)
class LoopOptions:
    """The load and the options of :func:`ecofmaps.analyze_loops`, checked (a ValueError)."""

    load: float
    hysteresis: float = 0.5
    stick_window: tuple = (0.05, 0.45)
    crossing_window: float = 0.7
    gross_slip_threshold: float = GROSS_SLIP_THRESHOLD
    flip_force: bool = False
    rig_stiffness: float | None = None

    def __post_init__(self):
        load = resolve.single_value("load", self.load, "positive", "N")
        hysteresis = resolve.within("hysteresis", self.hysteresis, 1.0)
        window = resolve.checked_stick_window(self.stick_window)
        crossing = resolve.within("crossing_window", self.crossing_window)
        threshold = resolve.within("gross_slip_threshold", self.gross_slip_threshold, 1.0)
        if not isinstance(self.flip_force, bool | np.bool_):
            raise ValueError(f"flip_force must be True or False; got {self.flip_force!r}")
        flip, rig = bool(self.flip_force), self.rig_stiffness
        if rig is not None:
            check("rig_stiffness", rig, "positive_or_inf", "N/m")
            rig = float(rig)
        resolve.settle(self, load, hysteresis, window, crossing, threshold, flip, rig)


def _in_order(function, tasks):
    """Each chunk run in this process, one after the other (a recording in memory)."""
    yield from itertools.starmap(function, tasks)


#: The runner of a recording in memory (as :class:`ecofmaps._parallel.Runner` is used).
IN_PROCESS = types.SimpleNamespace(local=True, map=_in_order)


def runner_for(scheduler=None, workers=None):
    """The runner of :func:`ecofmaps.analyze_loops`' ``scheduler`` and ``workers``."""
    if scheduler is None:
        with contextlib.suppress(ImportError, ValueError):  # no client: threads
            from distributed import default_client  # only where dask's cluster is used

            return Runner(client=default_client())
    if scheduler in (None, "threads"):
        return Runner(workers)
    if scheduler == "processes":
        return Runner(workers or 2, cluster=True)
    if isinstance(scheduler, str):
        return Runner(scheduler=scheduler)
    return Runner(client=scheduler)


@dataclasses.dataclass(frozen=True)
class Reading:
    """What each chunk reads besides the per-cycle values, and what it hands back."""

    resolve: bool = False
    keep_loops: bool = False
    along_stroke: resolve.ReadingOptions = _PER_CYCLE
    hand_back: bool = False


@dataclasses.dataclass(frozen=True)
class Task:
    """One chunk's work besides its samples; ``keep``: its values' file, or True: hand them back."""

    cycles: Cycles
    rows: slice
    low: int
    options: LoopOptions
    reading: Reading
    then: object = None
    keep: Path | bool = False
    columns: tuple | None = None


@dataclasses.dataclass
class Chunk:
    """What :func:`measure_chunk` hands back."""

    part: xr.Dataset
    tally: quality.Tally
    values: dict | None = None
    flags: dict | None = None
    made: object = None
    resolved: xr.Dataset | None = None


def force_at_mean_load(force, load):
    r"""The force as at the mean load, :math:`Q(t)\,\bar P/P(t)` [N] (NaN where the ``load`` is
    not positive), and :math:`\bar P`, the mean of the positive loads [N]; ``docs/loops.md``."""
    if isinstance(load, np.ndarray):
        finite = load[np.isfinite(load)]
        usable = np.where(np.isfinite(load) & (load > 0.0), load, np.nan)
        positive = finite[finite > 0.0]
        mean = positive.mean() if positive.size else np.nan
        lowest, highest = (finite.min(), finite.max()) if finite.size else (np.nan, np.nan)
    else:
        import dask.array as da  # only for a lazy recording, read out of core

        finite = da.where(da.isfinite(load), load, np.nan)  # as in memory: inf is missing
        usable = da.where(finite > 0.0, finite, np.nan)
        mean, lowest, highest = da.compute(da.nanmean(usable), da.nanmin(finite), da.nanmax(finite))
    mean, lowest, highest = float(mean), float(lowest), float(highest)
    if np.isnan(lowest):
        raise ValueError("the recorded normal load holds no value")
    if np.isnan(mean):
        hint = quality.COMPRESSION if lowest < 0.0 else "is it the normal load?"
        raise ValueError(
            f"the recorded normal load is nowhere positive (from {lowest:g} N to "
            f"{highest + 0.0:g} N): {hint}"
        )
    return force * (mean / usable), mean


def _with_loops(results: xr.Dataset, loops) -> xr.Dataset:
    """``results`` with the centred loops of :func:`measure_cycles` (``keep_loops=True``)."""
    for name, values in zip(("loop_displacement", "loop_force"), loops[:2], strict=True):
        results[name] = (("cycle", "point"), values, nomenclature.attrs(name))
    results.coords["point"] = ("point", np.arange(loops[0].shape[1]), nomenclature.attrs("point"))
    return results


def _at_own_load(dataset: xr.Dataset, ratio) -> xr.Dataset:
    """``dataset`` with the variables that scale with the load times ``ratio`` (own / mean)."""
    scaled = (*quality.LOAD_SCALED, "loop_force", "force_forward", "force_backward")
    return dataset.assign(
        {k: dataset[k].copy(data=(dataset[k].values.T * ratio).T) for k in scaled if k in dataset}
    )


def _cycle_loads(load, task: Task) -> tuple:
    """The mean, lowest and highest finite ``load`` [N] over each of the task's own cycles."""
    start, count = task.cycles.start[task.rows], task.cycles.count[task.rows]
    low = int(start.min())
    values = np.asarray(Stretch(load, task.low)[low : int((start + count).max())], dtype=np.float64)
    finite = np.isfinite(values)
    sums, counts = (
        np.concatenate([[0.0], np.cumsum(a)]) for a in (np.where(finite, values, 0.0), finite)
    )
    ends, begins = start + count - low, start - low
    with np.errstate(invalid="ignore"):  # a cycle without a finite value: NaN
        mean = (sums[ends] - sums[begins]) / (counts[ends] - counts[begins])
    padded = np.append(np.where(finite, values, np.nan), np.nan)  # an end may be the last
    bounds = np.ravel([begins, ends], order="F")
    return mean, *(f.reduceat(padded, bounds)[::2] for f in (np.fmin, np.fmax))


def measure_chunk(task: Task, x, q, recorded_load=None) -> Chunk:
    """One chunk's cycles measured on its stretch ``x``, ``q`` (and load), read and judged."""
    options, reading, rows = task.options, task.reading, task.rows
    x, q, kept = Stretch(x, task.low), Stretch(q, task.low), reading.resolve or reading.keep_loops
    values, flags, loops = measure_cycles(task.cycles, x, q, options, rows=rows, keep_loops=kept)
    labels, tally = task.cycles.label[rows], quality.Tally()
    if recorded_load is not None:
        mean, lowest, highest = _cycle_loads(recorded_load, task)
        values["normal_load"] = mean
        flags |= quality.load_flags(flags["missing-samples"], mean, lowest, highest)
    flags |= quality.scale_flags(values, options)
    resolved = None
    if reading.resolve:
        judged = _with_loops(quality.cycle_results(values, flags, labels, options), loops)
        resolved, read = resolve.read_along_stroke(judged, reading.along_stroke)
        values = values | {name: resolved[name].values for name in quality.RESOLVED}
        flags = flags | read
    part = _part(values, flags, labels, options, tally, loops if reading.keep_loops else None)
    handed = resolved if reading.hand_back else None
    if handed is not None and "normal_load" in values:  # as the part: at each cycle's load
        handed = _at_own_load(handed, values["normal_load"] / options.load)
    if isinstance(task.keep, Path):
        _keep_block(task.keep, values, flags)
    if task.keep is not True:
        values = flags = None
    made = None if task.then is None else task.then(part)
    return Chunk(only(part, task.columns), tally, values, flags, made, handed)


def block_file(prefix: Path, index: int) -> Path:
    """The file of chunk ``index`` kept at ``prefix`` (:func:`_keep_block`)."""
    return prefix.with_name(f"{prefix.name}{index:06d}.npz")


def temporary_file(path: Path) -> Path:
    """The temporary that :func:`write_whole` writes before renaming it onto ``path``."""
    return path.with_name(f".{path.name}.tmp")


def write_whole(path: Path, content) -> None:
    """Write ``content`` (text, or arrays by name: ``.npz``) to ``path``, whole or nothing."""
    temporary = temporary_file(path)
    try:
        if isinstance(content, str):
            temporary.write_text(content, "utf-8")
        else:
            with open(temporary, "wb") as stream:
                np.savez(stream, **content)
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


def _keep_block(path: Path, values: dict, flags: dict) -> None:
    """Keep a chunk's measured ``values`` and ``flags`` in ``path`` (``.npz``)."""
    kept = {f"v:{k}": v for k, v in values.items()}
    write_whole(path, kept | {f"f:{k}": v for k, v in flags.items()})


def kept_block(path: Path) -> tuple[dict, dict]:
    """The values and flags :func:`_keep_block` kept in ``path``."""
    with np.load(path) as stored:
        values = {k[2:]: stored[k] for k in stored.files if k.startswith("v:")}
        return values, {k[2:]: stored[k] for k in stored.files if k.startswith("f:")}


def only(part: xr.Dataset, columns=None) -> xr.Dataset:
    """``part`` with only the variables ``columns`` that it holds (all of them if None)."""
    return part if columns is None else part[[k for k in columns if k in part.data_vars]]


def _part(values: dict, flags: dict, labels, options, tally, loops=None) -> xr.Dataset:
    """A chunk's results from what it measured, judged (counted in ``tally``), at own load."""
    measured = {k: v for k, v in values.items() if k not in quality.RESOLVED}
    part = quality.cycle_results(measured, flags, labels, options)
    read = [name for name in quality.RESOLVED if name in values]
    part = part.assign({k: ("cycle", values[k], resolve.resolved_attrs(k)) for k in read})
    if loops is not None:
        part = _with_loops(part, loops)
    if "normal_load" in part:
        part = _at_own_load(part, part["normal_load"].values / options.load)
    tally.add(part["quality"].values, flags, values["amplitude"])
    return part


class Analysis:
    """One recording through the pipeline chunk by chunk on ``runner`` (entered), from
    ``cycles`` found before if given; with a ``recorded_load``, ``force`` is at the mean load."""

    def __init__(
        self,
        displacement,
        force,
        cycle=None,
        *,
        options: LoopOptions,
        missing=None,
        recorded_load=None,
        runner=IN_PROCESS,
        nan_policy="skip",
        reading=None,
        cycles=None,
        samples=None,
        one_chunk=False,
    ):
        self.arrays = (displacement, force, recorded_load)
        self.options, self.runner, self.reading = options, runner, reading or Reading()
        self.cycles_from = "displacement reversals" if cycle is None else "cycle numbers"
        self.cycles = cycles = cycles or find_cycles(
            displacement, cycle, options.hysteresis, force=force, missing=missing, runner=runner
        )
        if nan_policy == "raise" and cycles.first_missing >= 0:
            first = cycles.first_missing
            load = np.nan if recorded_load is None else float(recorded_load[first])
            if load <= 0.0:
                row = np.searchsorted(cycles.start, first, side="right") - 1
                within = row >= 0 and first < cycles.start[row] + cycles.count[row]
                at = f"sample {first}" + (f" (cycle {cycles.label[row]})" if within else "")
                raise MissingSampleError(
                    first,
                    f"the recorded normal load at {at} is {load:g} N, not positive, and the "
                    "force is scaled by it",
                    "flags its cycle load-not-positive and analyses the others"
                    + (f": {quality.COMPRESSION}" if load < 0 else ""),
                )
            raise MissingSampleError(first)
        if cycles.label.size == 0:
            raise ValueError(
                f"too few samples for one cycle: no complete cycle in {displacement.shape[0]} "
                "samples (the loop does not close, or the recording does not oscillate)"
            )
        self.tasks = _tasks(cycles.count, None if one_chunk else samples or TASK_SAMPLES)
        grid = self.reading.resolve and isinstance(self.reading.along_stroke.positions, int)
        if grid and len(self.tasks) > 1:  # a grid made from all the cycles
            raise ValueError(
                "a count of positions needs the recording in memory: give the positions themselves"
            )
        self.tally = quality.Tally()
        self._whole = np.flatnonzero(cycles.whole)  # the cycles a halo may hold

    def _task(self, index: int, then, keep, columns=None) -> tuple:
        """The arguments of :func:`measure_chunk` for chunk ``index`` (see :meth:`measured`)."""
        cycles, rows = self.cycles, self.tasks[index]
        first, stop = rows.start, rows.stop
        if cycles.continuous:  # a halo of NEIGHBOURS whole cycles on either side
            kept = self._whole
            begin, end = np.searchsorted(kept, [first, stop])
            if begin > 0:
                first = min(first, int(kept[max(begin - NEIGHBOURS, 0)]))
            if end < kept.size:
                stop = max(stop, int(kept[min(end + NEIGHBOURS, kept.size) - 1]) + 1)
        table = cycles.rows(slice(first, stop))
        low, high = int(table.start[0]), int(table.start[-1] + table.count[-1])
        x, q, p = (None if a is None else stretch(a, low, high) for a in self.arrays)
        if isinstance(keep, Path):
            keep = block_file(keep, index) if self.runner.local else True
        inner = slice(rows.start - first, rows.stop - first)
        return Task(table, inner, low, self.options, self.reading, then, keep, columns), x, q, p

    def measured(self, skip=(), then=None, keep=False, columns=None):
        """Each chunk's :class:`Chunk`, in order, counted in :attr:`tally`; ``keep``: True to hand
        back its values and flags, or the prefix to keep them at (where it ran if local)."""
        wanted = sorted(set(range(len(self.tasks))) - set(skip))
        tasks = (self._task(k, then, keep, columns) for k in wanted)
        results = self.runner.map(measure_chunk, tasks)
        try:
            for index, chunk in zip(wanted, results, strict=False):
                self.tally.merge(chunk.tally)
                if isinstance(keep, Path) and chunk.values is not None:  # measured elsewhere
                    _keep_block(block_file(keep, index), chunk.values, chunk.flags)
                    chunk.values = chunk.flags = None
                yield index, chunk
        finally:  # closed with this generator: the chunks left are cancelled now, not later
            results.close()

    def part(self, index: int, values: dict, flags: dict) -> xr.Dataset:
        """Chunk ``index``'s results from what it measured (as kept), counted in :attr:`tally`."""
        labels = self.cycles.label[self.tasks[index]]
        return _part(values, flags, labels, self.options, self.tally)

    def finish(self, parts) -> xr.Dataset:
        """All the parts, in order, joined and checked as a whole (:meth:`quality.Tally.finish`)."""
        return self.tally.finish(_joined(list(parts)), self.cycles, self.cycles_from, self.options)

    def run(self):
        """Every chunk, joined; and the reading along the stroke if handed back (else None)."""
        chunks = [chunk for _, chunk in self.measured()]
        read = [chunk.resolved for chunk in chunks if chunk.resolved is not None]
        return self.finish(chunk.part for chunk in chunks), _joined(read) if read else None


def _joined(parts: list) -> xr.Dataset:
    """The parts of a recording, over ``cycle``, joined."""
    if len(parts) == 1:
        return parts[0]
    return xr.concat(parts, "cycle", coords="minimal", compat="override", join="outer")


def _tasks(count, samples) -> list[slice]:
    """Consecutive rows of cycles of about ``samples`` samples in all (all in one if None)."""
    ends = np.cumsum(count)
    targets = np.arange(samples, int(ends[-1]), samples) if samples else np.empty(0)
    bounds = np.unique(np.concatenate([[0], np.searchsorted(ends, targets), [count.size]]))
    return [slice(int(a), int(b)) for a, b in itertools.pairwise(bounds)]
