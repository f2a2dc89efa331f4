r"""The per-cycle analysis of a long recording held as dask arrays, a block of cycles at a time.

:class:`LongAnalysis` is what :func:`ecofmaps.analyze_loops` does with a dask recording, in
steps that a caller can follow (the command line writes each block's results as it comes):

1. The cycles are found by passes over the recording a block of samples at a time
   (:func:`ecofmaps.measured.cycles.find_cycles` on :class:`~ecofmaps.measured.samples.Samples`):
   the straight line through the displacement, its percentiles, the reversals (or the
   runs of cycle numbers), and the runs of missing samples. Only their results, a few
   numbers per cycle, are held.
2. The cycles are cut into tasks of whole cycles, about ``samples`` samples each, so no
   cycle is cut at a task's edge. Each task reads the stretch of its cycles and of two
   whole cycles on either side (a *halo*: the centring interpolates each cycle's centre
   from its neighbours', :mod:`ecofmaps.measured.centring`) and measures its cycles with
   :func:`ecofmaps.measured.per_cycle.measure_cycles`, with the sample indices of the whole
   recording. So every number is computed from the same samples, with the same arithmetic,
   as in memory; only sums over a loop's padded rows may be grouped differently (to the
   last bits).
3. :meth:`LongAnalysis.finish` checks the whole recording (every cycle refused, units) and
   gives the joined results their attributes, as :func:`~ecofmaps.analyze_loops` does.

The tasks run on a :class:`ecofmaps._parallel.Runner` (threads, a local cluster of
processes, or a dask cluster), a few at a time, so memory holds a few blocks whatever the
length of the recording.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np
import xarray as xr

from ecofmaps._parallel import stretch
from ecofmaps.measured.analysis import MissingSampleError, _missing_error, no_cycle_error
from ecofmaps.measured.cycles import Cycles, find_cycles
from ecofmaps.measured.per_cycle import measure_cycles
from ecofmaps.measured.quality import quality_summary
from ecofmaps.measured.resolved import REPORTED
from ecofmaps.measured.resolved import _attrs as _read_attrs
from ecofmaps.measured.results import (
    Tally,
    cycle_results,
    strip,
    with_loops,
    with_read_along_stroke,
)

__all__ = ["HALO", "TASK_SAMPLES", "LongAnalysis", "MissingSampleError", "only"]

#: Samples of the recording measured by one task (about; whole cycles).
TASK_SAMPLES = 1 << 22

#: Whole cycles on either side of a task's cycles that it reads for the centring.
HALO = 2


class _Stretch:
    """A stretch of a recording (samples ``low`` on) indexed like the whole recording."""

    def __init__(self, values, low: int):
        self.values, self.low = values, low

    def __getitem__(self, key):
        if isinstance(key, slice):
            return self.values[key.start - self.low : key.stop - self.low]
        return self.values[np.asarray(key) - self.low]


#: The prefix of the names under which a task's values hold its reading along the stroke.
READ = "read:"


def _measure(
    cycles: Cycles,
    low: int,
    rows: slice,
    load: float,
    options: dict,
    x,
    q,
    resolve: bool,
    then=None,
    keep=False,
    columns=None,
):
    """One task: the cycles ``rows`` of the table ``cycles`` measured on the stretch of the
    recording that begins at sample ``low``; with ``resolve``, also read along the stroke
    (the values :data:`~ecofmaps.measured.resolved.REPORTED` and the reading's quality), so
    the loops never leave the task.

    Returns the task's results (as :meth:`LongAnalysis.part` makes them) and a
    :class:`~ecofmaps.measured.results.Tally` of them, made where the task runs; with
    ``keep=True``, what :func:`~ecofmaps.measured.per_cycle.measure_cycles` measured too
    (with the reading along the stroke named with the prefix :data:`READ`), else None for
    both (a callable ``keep`` is given them here instead, ``keep(values, flags)``); and
    ``then(results)``, or None without ``then``, so that work on the results is done where
    the task runs too. With ``columns``, the results handed back hold only those variables
    (those of them there are); ``then`` is given them all."""
    values, flags, loops = measure_cycles(
        cycles, _Stretch(x, low), _Stretch(q, low), load, rows=rows, keep_loops=resolve, **options
    )
    counted = cycle_results(values, flags, cycles.label[rows], load, options)
    if resolve:
        read = with_read_along_stroke(with_loops(strip(counted), loops))
        values = values | {f"{READ}{name}": read[name].values for name in (*REPORTED, "quality")}
    part = _part(counted, values)
    tally = Tally()
    tally.add(counted)
    if callable(keep):
        keep(values, flags)
    if keep is not True:
        values = flags = None
    made = None if then is None else then(part)
    return only(part, columns), tally, values, flags, made


def only(part: xr.Dataset, columns=None) -> xr.Dataset:
    """``part`` with only the variables ``columns`` that it holds (all of them if None)."""
    if columns is None:
        return part
    return part[[name for name in columns if name in part.data_vars]]


def _part(counted: xr.Dataset, values: dict) -> xr.Dataset:
    """The results of a task: ``counted`` (from
    :func:`~ecofmaps.measured.results.cycle_results`) without its riders, with the reading
    along the stroke in ``values`` (named with the prefix :data:`READ`) where the task read
    it."""
    part = strip(counted)
    read = {k[len(READ) :]: v for k, v in values.items() if k.startswith(READ)}
    if read:  # as ecofmaps.measured.resolved.with_resolved adds them
        part = part.assign({k: ("cycle", read[k], _read_attrs(k)) for k in REPORTED})
        part["quality"] = part["quality"].copy(data=read["quality"])
    return part


class LongAnalysis:
    """:func:`ecofmaps.analyze_loops` of a dask recording, in steps (module notes).

    Parameters
    ----------
    displacement, force : dask.array.Array
        [m], [N]
    load : float
        Normal load. [N]
    cycle : dask.array.Array, optional
        Cycle numbers. [1]
    missing : dask.array.Array of bool, optional
        Samples to treat as missing.
    runner : ecofmaps._parallel.Runner
        Where the passes and the tasks run (entered).
    nan_policy : {'skip', 'raise'}
    resolve : bool
        Also read each loop along the stroke, as :func:`ecofmaps.analyze_loops` does.
    cycles : Cycles, optional
        The cycles, if found before (a resumed run); else they are found here.
    samples : int, optional
        Samples per task (about; default :data:`TASK_SAMPLES`).
    **options
        The checked options of :func:`ecofmaps.measured.analysis.check_options`.

    Attributes
    ----------
    cycles : Cycles
    tasks : list of slice
        The rows (cycles) of each task, in order.
    tally : ecofmaps.measured.results.Tally
        What the parts given out so far add up to.

    Raises
    ------
    MissingSampleError
        With ``nan_policy='raise'``, naming the first missing sample.
    ValueError
        If the recording holds no complete cycle.
    """

    def __init__(
        self,
        displacement,
        force,
        load,
        cycle=None,
        *,
        missing=None,
        runner,
        nan_policy="skip",
        resolve=False,
        cycles=None,
        samples=None,
        **options,
    ):
        self.arrays = (displacement, force)
        self.resolve = bool(resolve)
        self.load, self.options, self.runner = float(load), options, runner
        self.cycles_from = "displacement reversals" if cycle is None else "cycle numbers"
        if cycles is None:
            cycles = find_cycles(
                displacement,
                cycle,
                options["hysteresis"],
                force=force,
                missing=missing,
                runner=runner,
            )
        self.cycles = cycles
        if nan_policy == "raise" and cycles.first_missing >= 0:
            raise _missing_error(cycles.first_missing)
        if cycles.label.size == 0:
            raise no_cycle_error(int(displacement.shape[0]))
        self.tasks = _tasks(cycles.count, samples or TASK_SAMPLES)
        self.tally = Tally()
        self._whole = np.flatnonzero(cycles.whole)  # the cycles a halo may hold

    def _task(self, index: int, then, keep, columns=None):
        """The arguments of the task ``index`` (see :func:`_measure`)."""
        cycles, rows = self.cycles, self.tasks[index]
        first, stop = rows.start, rows.stop
        if cycles.continuous:  # a halo of whole cycles on either side
            kept = self._whole
            begin, end = np.searchsorted(kept, [first, stop])
            if begin > 0:
                first = min(first, int(kept[max(begin - HALO, 0)]))
            if end < kept.size:
                stop = max(stop, int(kept[min(end + HALO, kept.size) - 1]) + 1)
        table = cycles.rows(slice(first, stop))
        low = int(table.start[0])
        high = int(table.start[-1] + table.count[-1])
        x, q = (stretch(array, low, high) for array in self.arrays)
        inner = slice(rows.start - first, rows.stop - first)
        if callable(keep):
            keep = functools.partial(keep, index)
        return (table, low, inner, self.load, self.options, x, q, self.resolve, then, keep, columns)

    def measured(self, skip=(), then=None, keep=False, columns=None):
        """The results of each task, in order, as they come; counted in :attr:`tally`.

        Parameters
        ----------
        skip : collection of int
            Tasks not to run (done before, in a run that is resumed).
        then : callable, optional
            A function of a task's results (the Dataset :meth:`part` gives), called where
            the task runs: a module-level function, or a :func:`functools.partial` of one,
            for tasks in other processes. The command line formats its table rows so, in
            parallel.
        keep : bool or callable
            True: also hand back what each task measured (to be kept, and made into its
            results again by :meth:`part` when a run is resumed). A callable
            ``keep(index, values, flags)`` is called with it where the task runs instead
            (picklable as ``then`` is), so that what is kept does not travel: for a runner
            whose workers share this machine's files.
        columns : sequence of str, optional
            The variables of each task's results to hand back (those of them there are;
            default all): what the caller keeps of them, so the rest does not travel.
            ``then`` is given them all.

        Yields
        ------
        index : int
            The task (index into :attr:`tasks`).
        part : xarray.Dataset
            Its cycles' results, made where it ran (see :meth:`part`).
        values, flags : dict of str to numpy.ndarray, or None
            With ``keep=True``, its cycles' quantities and checks, from
            :func:`~ecofmaps.measured.per_cycle.measure_cycles`.
        made
            What ``then`` returned for the task's results (None without ``then``).
        """
        skip = set(skip)
        wanted = [k for k in range(len(self.tasks)) if k not in skip]
        tasks = (self._task(k, then, keep, columns) for k in wanted)
        results = self.runner.map(_measure, tasks)
        try:
            for index, (part, tally, values, flags, made) in zip(wanted, results, strict=False):
                self.tally.merge(tally)
                yield index, part, values, flags, made
        finally:  # closed with this generator: the tasks left are cancelled now, not later
            results.close()

    def part(self, index: int, values: dict, flags: dict) -> xr.Dataset:
        """The per-cycle results of task ``index`` from what it measured (kept by
        :meth:`measured`), as in :func:`ecofmaps.analyze_loops`'s Dataset (without the
        recording's attributes); counted in :attr:`tally`."""
        labels = self.cycles.label[self.tasks[index]]
        measured = {k: v for k, v in values.items() if not k.startswith(READ)}
        counted = cycle_results(measured, flags, labels, self.load, self.options)
        self.tally.add(counted)
        return _part(counted, values)

    def parts(self):
        """The results of each task, in order, as they come (see :meth:`part`)."""
        for index, part, *_ in self.measured():
            yield index, part

    def finish(self, parts) -> xr.Dataset:
        """The parts (all of them, in order) joined, with the recording's attributes, after
        the checks of the whole recording (see :meth:`ecofmaps.measured.results.Tally.finish`).

        The parts share their variables and the load: they are joined along ``cycle``
        without comparing the rest (six times faster than comparing it, which copied every
        quality string)."""
        results = xr.concat(list(parts), "cycle", coords="minimal", compat="override")
        results = self.tally.finish(results, self.cycles, self.cycles_from, self.options)
        if self.resolve:  # the summary of the reading's quality, as with_resolved gives it
            results.attrs["quality_summary"] = quality_summary(results["quality"].values)
        return results


def _tasks(count, samples: int) -> list[slice]:
    """Consecutive rows of cycles of about ``samples`` samples in all (at least one)."""
    ends = np.cumsum(count)
    targets = np.arange(samples, int(ends[-1]), samples)
    bounds = np.unique(np.concatenate([[0], np.searchsorted(ends, targets), [count.size]]))
    return [slice(int(a), int(b)) for a, b in itertools.pairwise(bounds)]
