"""``ecofmaps loops`` on long tests: out of core, in parallel, resumable, with progress.

A recording read lazily (a rig file of more than :data:`ecofmaps.io.recordings.LAZY_SAMPLES`
samples, or any file with ``--workers``, ``--scheduler`` or ``--resume``) is analysed by
:class:`ecofmaps.measured.pipeline.Analysis` on local threads, ``--workers`` processes or the
cluster at ``--scheduler``. With ``--out``, what each block measured is kept as it completes
in ``<out>.partial/`` (one ``.npz`` per block, renamed into place when whole), so that a stop
keeps what was finished and ``--resume`` goes on from it; the table's lines are written in
order as the blocks come. A stop's line names the folder kept (:meth:`LongRun.stop_note`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import json
import os
import sys
from pathlib import Path

import numpy as np

from ecofmaps._interrupts import INTERRUPTED, Interrupted, add_stop_note
from ecofmaps._parallel import Runner
from ecofmaps.cli._common import CommandError
from ecofmaps.io.tables import results_csv
from ecofmaps.measured.cycles import Cycles
from ecofmaps.measured.options import MissingSampleError, default_options
from ecofmaps.measured.pipeline import IN_PROCESS, Analysis, force_at_mean_load, only

__all__ = ["MISSING", "PARTIAL_SUFFIX", "LongRun", "keep_block"]

#: The message for a missing sample with ``--nan-policy raise`` (the file and line before it).
MISSING = (
    "missing sample (an empty cell or NaN); --nan-policy skip analyses the cycles without "
    "missing samples and reports the others as skipped"
)

#: Suffix of the folder that holds an unfinished run's blocks beside ``--out``.
PARTIAL_SUFFIX = ".partial"

#: The files of a run's ``.partial`` folder that hold its work (each file's cycles and
#: finished blocks), and all the files it keeps there (with the run's record), as patterns.
_WORK = "file*.npz"
_KEPT = (_WORK, "run.json")

#: Options that change how a run goes, not what it computes (left out of its fingerprint).
_RUNTIME = ("workers", "scheduler", "resume", "quiet", "out", "plots", "handler", "files")


def _fingerprint(args, paths) -> dict:
    """What the run computes: the files as they are now and the options that matter."""
    files = []
    for path in paths:
        stat = Path(path).stat()
        files.append([str(Path(path).resolve()), stat.st_size, stat.st_mtime_ns])
    options = {
        key: value
        for key, value in sorted(vars(args).items())
        if key not in _RUNTIME and isinstance(value, str | int | float | bool | type(None))
    }
    return {"format": 1, "files": files, "options": options}


_UNFINISHED = (
    "{folder} holds an unfinished run: add --resume to continue it, or delete it to start again"
)


class _Partial:
    """The folder ``<out>.partial`` of an unfinished run (see the module notes)."""

    def __init__(self, out, fingerprint: dict, resume: bool):
        self.folder = Path(f"{out}{PARTIAL_SUFFIX}")
        record = self.folder / "run.json"
        self.made = not self.folder.exists()
        if self.folder.exists():
            if not resume:
                raise CommandError(_UNFINISHED.format(folder=self.folder))
            try:
                found = json.loads(record.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                found = None
            if found != fingerprint:
                raise CommandError(
                    f"{self.folder} holds a run of other files or options: delete it to start "
                    "again with these"
                )
        else:
            self.folder.mkdir()
            _write(record, lambda path: path.write_text(json.dumps(fingerprint), "utf-8"))

    def cycles(self, index: int):
        """The cycles of file ``index`` found before, or None."""
        path = self.folder / f"file{index}-cycles.npz"
        if not path.exists():
            return None
        with np.load(path) as stored:
            fields = {f.name: stored[f.name] for f in dataclasses.fields(Cycles)}
        fields["missing"] = None if fields["missing"].ndim == 0 else fields["missing"]
        for name in ("continuous",):
            fields[name] = bool(fields[name])
        for name in ("incomplete_cycles", "dropped_samples", "missing_samples", "first_missing"):
            fields[name] = int(fields[name])
        return Cycles(**fields)

    def keep_cycles(self, index: int, cycles) -> None:
        values = dataclasses.asdict(cycles)
        values["missing"] = np.asarray(False) if cycles.missing is None else cycles.missing
        _write(self.folder / f"file{index}-cycles.npz", lambda path: _savez(path, values))

    def kept(self, index: int) -> dict:
        """The blocks of file ``index`` kept: block -> its file."""
        prefix = f"file{index}-block"
        return {
            int(path.stem[len(prefix) :]): path
            for path in self.folder.glob(f"{prefix}*.npz")
            if path.stem[len(prefix) :].isdigit()
        }

    def done(self, index: int) -> dict:
        """The blocks of file ``index`` kept: block -> (values, flags) as measured."""
        kept = {}
        for block, path in self.kept(index).items():
            with np.load(path) as stored:
                values = {k[2:]: stored[k] for k in stored.files if k.startswith("v:")}
                flags = {k[2:]: stored[k] for k in stored.files if k.startswith("f:")}
            kept[block] = (values, flags)
        return kept

    def holds_work(self) -> bool:
        """Whether the folder holds anything a resumed run would use (cycles or blocks)."""
        return any(self.folder.glob(_WORK))

    def remove_temporaries(self) -> None:
        """Remove the temporaries of files being written (a worker stopped while it wrote
        a block leaves one): a folder kept to resume from holds only whole files."""
        for pattern in _KEPT:
            for path in self.folder.glob(_temporary_name(pattern)):
                path.unlink(missing_ok=True)

    def remove(self) -> None:
        """Remove the files the run kept, then the folder if nothing else is in it (a file
        someone put there is not removed)."""
        for pattern in _KEPT:
            for path in self.folder.glob(pattern):
                path.unlink(missing_ok=True)
        self.remove_temporaries()
        with contextlib.suppress(OSError):  # not empty: left as it is
            self.folder.rmdir()


def keep_block(folder: Path, index: int, block: int, values: dict, flags: dict) -> None:
    """Keep in ``folder`` what block ``block`` of file ``index`` measured (a function of the
    module, so a task can call it where it runs)."""
    stored = {f"v:{k}": v for k, v in values.items()} | {f"f:{k}": v for k, v in flags.items()}
    _write(folder / f"file{index}-block{block:06d}.npz", lambda p: _savez(p, stored))


def _savez(path: Path, values: dict) -> None:
    with open(path, "wb") as stream:
        np.savez(stream, **values)


def _temporary_name(name: str) -> str:
    """The name of the temporary that :func:`_write` writes ``name`` to (or a pattern of
    names, for a pattern)."""
    return f".{name}.tmp"


def _write(path: Path, write) -> None:
    """``write(temporary)``, then rename the temporary onto ``path`` (whole, or nothing)."""
    temporary = path.with_name(_temporary_name(path.name))
    try:
        write(temporary)
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


class LongRun:
    """The long recordings of one ``ecofmaps loops`` command with options ``args`` and
    recordings ``paths``. ``lazy`` is for :func:`ecofmaps.read_recording`: True when a long
    run was asked for (``--workers``, ``--scheduler``, ``--resume``), else None."""

    def __init__(self, args, paths):
        if args.workers and args.scheduler:
            raise CommandError("give --workers or --scheduler, not both")
        if args.resume and args.out is None:
            raise CommandError("--resume continues the run kept beside --out: give --out")
        self.args = args
        self.lazy = True if (args.workers or args.scheduler or args.resume) else None
        folder = Path(f"{args.out}{PARTIAL_SUFFIX}")
        if args.out is not None and folder.exists() and not args.resume:
            raise CommandError(_UNFINISHED.format(folder=folder))
        self.fingerprint = _fingerprint(args, paths) if args.out is not None else None
        self.partial = None
        self.analysed = None  # (index, path, blocks or None) of the recording analysed last

    def _runner(self):
        if self.args.scheduler:
            return Runner(scheduler=self.args.scheduler)
        if self.args.workers:
            return Runner(self.args.workers, cluster=True)
        return Runner()

    def analyse(self, index, path, recording, load, *, many: bool, write, columns=None, reading):
        """The results of recording ``index`` (only the variables ``columns``, if given) and
        its reading along the stroke when ``reading`` hands it back; the table's lines (a
        file column if ``many``) given to ``write`` in order, a string per chunk that begins
        with the header line. The results are joined once the cluster is closed."""
        runner = self._runner() if recording.lazy else contextlib.nullcontext(IN_PROCESS)
        self.analysed = (index, path, None)
        try:
            with runner as runner:  # a cluster that does not answer: nothing written
                partial = None
                if recording.lazy and self.fingerprint is not None:
                    if self.partial is None:
                        self.partial = _Partial(self.args.out, self.fingerprint, self.args.resume)
                        add_stop_note(self.stop_note)  # asked when the line is written
                    partial = self.partial
                analysis, parts, resolved = _analyse(
                    index,
                    path,
                    recording,
                    load,
                    self.args,
                    runner,
                    partial,
                    many,
                    write,
                    columns,
                    reading,
                )
        except KeyboardInterrupt as stop:  # counted once the runner is closed: no task runs
            if isinstance(stop, _Interrupted):
                self.analysed = (index, path, stop.blocks)
            note = self.stop_note()
            raise (stop if note is None else Interrupted(note)) from None
        except MissingSampleError as error:
            raise recording.error(MISSING, error.sample) from None
        self.analysed = (index, path, len(analysis.tasks))
        return analysis.finish([parts.pop(k) for k in sorted(parts)]), resolved

    def stop_note(self) -> str | None:
        """What a stop leaves beside ``--out``, as it is now: the sentence naming the folder
        kept and how to go on, or None. A folder this run made with nothing in it yet is
        removed; a folder kept loses the temporaries of blocks being written."""
        partial = self.partial
        if partial is None or not partial.folder.exists():
            return None
        if partial.made and not partial.holds_work():
            partial.remove()
            self.partial = None
            return None
        partial.remove_temporaries()
        index, path, blocks = self.analysed
        of = "" if blocks is None else f" of {blocks}"
        return (
            f"{len(partial.kept(index))}{of} blocks of {path} are kept in {partial.folder}: "
            "run the same command with --resume to continue"
        )

    def finish(self) -> None:
        """Remove the kept blocks: the table is written."""
        if self.partial is not None:
            self.partial.remove()
            self.partial = None


def _analyse(index, path, recording, load, args, runner, partial, many, write, columns, reading):
    """One recording through the pipeline, chunk by chunk: its analysis, each chunk's results
    (the variables ``columns``) and the reading along the stroke handed back (or None); each
    chunk's lines given to ``write`` in order."""
    if args.plots is not None and recording.lazy:
        raise CommandError(
            f"--plots draws every loop, which a long recording ({path}) analysed out of core "
            "does not keep: leave out --plots (or --workers, --scheduler, --resume)"
        )
    force, recorded = recording.force, None
    if isinstance(load, str):  # the load recorded sample by sample (--load COLUMN)
        force, load = force_at_mean_load(force, recording.load)
        recorded = recording.load
    options = default_options(load, getattr(args, "flip_force", False))
    shown = recording.lazy and not args.quiet and sys.stderr.isatty()
    if shown:
        print(f"{path.name}: finding the cycles of {recording.size} samples", file=sys.stderr)
    analysis = Analysis(
        recording.displacement,
        force,
        load,
        recording.cycle,
        recorded_load=recorded,
        runner=runner,
        nan_policy=args.nan_policy,
        reading=reading,
        cycles=None if partial is None else partial.cycles(index),
        one_chunk=not recording.lazy,
        **options,
    )
    done = {}
    if partial is not None:
        partial.keep_cycles(index, analysis.cycles)
        done = partial.done(index)
    lines = functools.partial(results_csv, file=str(path) if many else None)
    parts, texts = {}, {}  # texts: the lines of chunks that came before an earlier one
    for block, measured in done.items():
        part = analysis.part(block, *measured)
        parts[block], texts[block] = only(part, columns), lines(part)
    written = _in_order(texts, write)
    bar = _bar(analysis, path, shown, sum(parts[b].cycle.size for b in parts))
    keep = partial is not None
    if keep and runner.local:  # the chunks keep their blocks themselves, where they run
        keep = functools.partial(keep_block, partial.folder, index)
    resolved = []
    try:
        measured = analysis.measured(skip=done, then=lines, keep=keep, columns=columns)
        with contextlib.closing(measured) as kept:
            for block, chunk in kept:
                if chunk.values is not None:  # sent here: kept by this process
                    keep_block(partial.folder, index, block, chunk.values, chunk.flags)
                parts[block], texts[block] = chunk.part, chunk.made
                if chunk.resolved is not None:
                    resolved.append(chunk.resolved)
                written = _in_order(texts, write, written)
                bar.update(chunk.part.cycle.size)
    except (Exception, KeyboardInterrupt) as error:
        stopped = isinstance(error, KeyboardInterrupt)
        if not (stopped or INTERRUPTED.is_set()):  # not caused by a stop (a worker it stopped)
            raise
        bar.leave = False
        bar.close()
        raise _Interrupted(len(analysis.tasks)) from (None if stopped else error)
    bar.close()
    return analysis, parts, resolved[0] if resolved else None


def _in_order(texts: dict, write, written: int = 0) -> int:
    """Give ``write`` the texts of blocks ``written``, ``written + 1``, ... that ``texts``
    holds, in order, taking them out; the number of blocks written so far."""
    while written in texts:
        write(texts.pop(written))
        written += 1
    return written


class _Interrupted(KeyboardInterrupt):
    """Ctrl-C while the blocks of a recording of ``blocks`` blocks were measured."""

    def __init__(self, blocks: int):
        super().__init__(blocks)
        self.blocks = blocks


def _bar(analysis, path, shown: bool, initial: int):
    from tqdm import tqdm

    return tqdm(
        total=int(analysis.cycles.label.size),
        initial=initial,
        unit=" cycles",
        desc=path.name,
        file=sys.stderr,
        disable=not shown,
        dynamic_ncols=True,
        smoothing=0.1,
    )
