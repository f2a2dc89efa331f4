"""``ecofmaps loops`` on long tests: out of core, in parallel, resumable, with progress.

A recording read lazily (past :data:`ecofmaps.io.recording_types.LAZY_SAMPLES` samples, or with
``--workers``, ``--scheduler``, ``--resume``) is analysed on threads, processes or a cluster, its
lines written in order; with ``--out`` each block is kept in ``<out>.partial/`` (docs/parallel.md).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import json
import sys
import zlib
from pathlib import Path

import numpy as np

from ecofmaps._interrupts import INTERRUPTED, Interrupted, add_stop_note
from ecofmaps.cli.common import CommandError, progress_bar
from ecofmaps.io.tables import results_csv
from ecofmaps.measured import pipeline
from ecofmaps.measured.cycles import Cycles
from ecofmaps.measured.resolve import ReadingOptions
from ecofmaps.measured.samples import MissingSampleError

#: Suffix of the folder that holds an unfinished run's blocks beside ``--out``.
PARTIAL_SUFFIX = ".partial"

#: The files of a ``.partial`` folder holding work (cycles, blocks), and all it keeps there.
_WORK = "file*.npz"
_KEPT = (_WORK, "run.json", "kept.jsonl")

#: Options that change how a run goes, not what it computes (left out of its fingerprint).
_RUNTIME = ("workers", "scheduler", "resume", "quiet", "out", "plots", "handler", "files")


def _checksums(path: Path) -> list:
    """[name, size, CRC-32] of a recording's file, or of every file of a store by its name."""
    files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    sums = []
    for file in files:
        crc = 0
        with open(file, "rb") as stream:
            while block := stream.read(1 << 22):
                crc = zlib.crc32(block, crc)
        name = file.relative_to(path).as_posix() if file != path else ""
        sums.append([name, file.stat().st_size, crc])
    return sums


def _fingerprint(args, paths) -> dict:
    """What the run computes: the files' content as it is now and the options that matter."""
    files = [[str(path.resolve()), _checksums(path)] for path in paths]
    options = {
        key: value
        for key, value in sorted(vars(args).items())
        if key not in _RUNTIME and isinstance(value, str | int | float | bool | type(None))
    }
    return {"format": 4, "files": files, "options": options}


def _sha256(path: Path) -> str:
    with open(path, "rb") as stream:
        return hashlib.file_digest(stream, "sha256").hexdigest()


class _Partial:
    """The folder ``<out>.partial`` of an unfinished run: its record, cycles, blocks, sums."""

    def __init__(self, out, fingerprint: dict):
        self.folder = Path(f"{out}{PARTIAL_SUFFIX}")
        record, self.manifest = self.folder / "run.json", self.folder / "kept.jsonl"
        self.made = not self.folder.exists()  # else --resume: LongRun checked it
        if self.made:
            self.folder.mkdir()
            pipeline.write_whole(record, json.dumps(fingerprint))
            return
        try:
            found = json.loads(record.read_text(encoding="utf-8"))
        except (OSError, ValueError, RecursionError) as error:  # deep nesting: RecursionError
            raise CommandError(
                f"{record} is missing or damaged ({type(error).__name__}): the run kept in "
                f"{self.folder} cannot be resumed; delete the folder to start again"
            ) from None
        if found != fingerprint:
            raise CommandError(
                f"{self.folder} holds a run of other files or options (or of these files "
                "before they changed, or of another ecofmaps): delete it to start again with these"
            )

    def _manifest(self) -> dict:
        """(file, block or 'cycles') -> its line in ``kept.jsonl`` (one cut short passed over)."""
        found = {}
        with contextlib.suppress(OSError), open(self.manifest, encoding="utf-8") as lines:
            for line in lines:
                with contextlib.suppress(ValueError, TypeError, KeyError, RecursionError):
                    entry = json.loads(line)
                    found[(int(entry["file"]), entry["block"])] = entry
        return found

    def _record(self, path: Path, **entry) -> None:
        """Add the checksum of ``path`` just kept, with ``entry``, to the manifest."""
        entry["sha256"] = _sha256(path)
        with open(self.manifest, "a", encoding="utf-8") as lines:
            lines.write(json.dumps(entry) + "\n")

    def _refused(self, path: Path, reason: str) -> None:
        print(f"ecofmaps loops: warning: {path} {reason}: it is measured again", file=sys.stderr)
        path.unlink(missing_ok=True)

    def _checked(self, path: Path, entry, rows=None) -> bool:
        """Whether the kept ``path`` is as recorded (checksum, a block's ``rows``); else refused."""
        if entry is None:
            reason = "is not in the run's record (kept.jsonl)"
        elif rows is not None and entry.get("rows") != rows:
            reason = f"holds cycles {entry.get('rows')}, not this block's {rows}"
        elif _sha256(path) != entry.get("sha256"):
            reason = "changed since it was kept (its checksum is not the one recorded)"
        else:
            return True
        self._refused(path, reason)
        return False

    def cycles(self, index: int):
        """The cycles of file ``index`` found before, or None (its blocks dropped if they fail)."""
        path = self.folder / f"file{index}-cycles.npz"
        if not path.exists():
            return None
        if not self._checked(path, self._manifest().get((index, "cycles"))):
            for block in self.kept(index).values():
                self._refused(block, "was measured on the cycles refused")
            return None
        with np.load(path) as stored:  # the scalars as Python's
            fields = {f.name: stored[f.name] for f in dataclasses.fields(Cycles)}
        return Cycles(**{name: v.item() if v.ndim == 0 else v for name, v in fields.items()})

    def keep_cycles(self, index: int, cycles) -> None:
        path = self.folder / f"file{index}-cycles.npz"
        pipeline.write_whole(path, dataclasses.asdict(cycles))
        self._record(path, file=index, block="cycles")

    def blocks(self, index: int) -> Path:
        """Where the blocks of file ``index`` are kept (:func:`block_file`)."""
        return self.folder / f"file{index}-block"

    def record_block(self, index: int, block: int, rows: slice) -> None:
        path = pipeline.block_file(self.blocks(index), block)
        self._record(path, file=index, block=block, rows=[rows.start, rows.stop])

    def record_late(self, index: int, tasks) -> None:
        """Record the blocks of file ``index`` kept by tasks that had not come back at a stop."""
        recorded = self._manifest()
        for block in self.kept(index):
            if (index, block) not in recorded and block < len(tasks):
                self.record_block(index, block, tasks[block])

    def kept(self, index: int) -> dict:
        """The blocks of file ``index`` kept: block -> its file."""
        name = self.blocks(index).name  # and the block's number
        found = {file.stem.removeprefix(name): file for file in self.folder.glob(f"{name}*.npz")}
        return {int(block): path for block, path in found.items() if block.isdigit()}

    def done(self, index: int, tasks) -> dict:
        """The blocks of file ``index`` kept and checked: block -> (values, flags) measured."""
        kept = {}
        manifest = self._manifest()
        for block, path in self.kept(index).items():
            if block >= len(tasks):
                self._refused(path, f"is beyond the run's {len(tasks)} blocks")
                continue
            rows = [tasks[block].start, tasks[block].stop]
            if self._checked(path, manifest.get((index, block)), rows):
                kept[block] = pipeline.kept_block(path)
        return kept

    def remove_temporaries(self, *kept) -> None:
        """Remove the files ``kept`` (patterns) then the temporaries of files being written."""
        for pattern in (*kept, *(pipeline.temporary_file(Path(pattern)).name for pattern in _KEPT)):
            for path in self.folder.glob(pattern):
                path.unlink(missing_ok=True)

    def remove(self) -> None:
        """Remove the files the run kept, then the folder if nothing else is in it."""
        self.remove_temporaries(*_KEPT)
        with contextlib.suppress(OSError):  # not empty: left as it is
            self.folder.rmdir()


class LongRun:
    """The recordings ``paths`` of one ``ecofmaps loops`` through the pipeline."""

    def __init__(self, args, paths):
        if args.workers and args.scheduler:
            raise CommandError("give --workers or --scheduler, not both")
        if args.resume and args.out is None:
            raise CommandError("--resume continues the run kept beside --out: give --out")
        folder = Path(f"{args.out}{PARTIAL_SUFFIX}")
        if args.out is not None and folder.exists() and not args.resume:
            raise CommandError(f"{folder} holds an unfinished run: add --resume, or delete it")
        self.args, self.paths, self.partial = args, paths, None
        self.lazy = True if (args.workers or args.scheduler or args.resume) else None  # or by size
        self.analysed = None  # (index, path, blocks or None) of the recording analysed last
        scar = args.scar_profile is not None
        handed = args.plots is not None or args.resolved is not None or scar  # on 201 positions
        self.reading = pipeline.Reading(
            resolve=not args.no_resolve,
            keep_loops=args.plots is not None or args.report is not None or scar,
            along_stroke=ReadingOptions(positions=201 if handed else None),
            hand_back=handed,
        )

    def analyse(self, index, path, recording, load, write, columns):
        """Results (of ``columns``) and reading along the stroke of recording ``index``."""
        args, runner = self.args, contextlib.nullcontext(pipeline.IN_PROCESS)
        if recording.lazy:
            cluster = "processes" if args.workers else args.scheduler
            runner = pipeline.runner_for(cluster, args.workers)
        self.analysed = (index, path, None)
        try:
            with runner as runner:  # a cluster that does not answer: nothing written
                if recording.lazy and args.out is not None and self.partial is None:
                    self.partial = _Partial(args.out, _fingerprint(args, self.paths))
                    add_stop_note(self.stop_note)  # asked when the line is written
                analysis, parts, resolved = _analyse(
                    self, index, path, recording, load, runner, write, columns
                )
        except KeyboardInterrupt as stop:  # counted once the runner is closed: no task runs
            if isinstance(stop, _Interrupted):
                self.analysed = (index, path, len(stop.tasks))
                if self.partial is not None and self.partial.folder.exists():
                    self.partial.record_late(index, stop.tasks)
            note = self.stop_note()
            raise (stop if note is None else Interrupted(note)) from None
        except MissingSampleError as error:
            what = f"{error.what or 'missing sample (an empty cell or NaN)'}; --nan-policy skip"
            raise recording.error(f"{what} {error.skips}", error.sample) from None
        self.analysed = (index, path, len(analysis.tasks))
        return analysis.finish([parts.pop(k) for k in sorted(parts)]), resolved

    def stop_note(self) -> str | None:
        """The sentence naming the folder a stop leaves beside ``--out`` (None: none kept)."""
        partial = self.partial
        if partial is None or not partial.folder.exists():
            return None
        if partial.made and not any(partial.folder.glob(_WORK)):
            self.finish()  # nothing worth keeping
            return None
        partial.remove_temporaries()
        index, path, blocks = self.analysed
        kept, of = len(partial.kept(index)), "" if blocks is None else f" of {blocks}"
        what = f"{kept}{of} blocks of {path} are" if kept else f"the cycles found in {path} are"
        return f"{what} kept in {partial.folder}: run the same command with --resume to continue"

    def finish(self) -> None:
        """Remove the kept blocks (the table is written, or nothing was kept yet)."""
        if self.partial is not None:
            self.partial.remove()
            self.partial = None


def _analyse(run, index, path, recording, load, runner, write, columns):
    """One recording chunk by chunk (:meth:`LongRun.analyse`): analysis, parts, reading."""
    args, partial = run.args, run.partial if recording.lazy else None
    force, recorded = recording.force, None
    if isinstance(load, str):  # the load recorded sample by sample (--load COLUMN)
        force, load = pipeline.force_at_mean_load(force, recording.load)
        recorded = recording.load
    shown = recording.lazy and not args.quiet and sys.stderr.isatty()
    if shown:
        print(f"{path.name}: finding the cycles of {recording.size} samples", file=sys.stderr)
    keywords = {"flip_force": args.flip_force, "rig_stiffness": args.rig_stiffness}
    analysis = pipeline.Analysis(
        recording.displacement,
        force,
        recording.cycle,
        options=pipeline.LoopOptions(load, **keywords),
        recorded_load=recorded,
        runner=runner,
        nan_policy=args.nan_policy,
        reading=run.reading,
        cycles=None if partial is None else partial.cycles(index),
        one_chunk=not recording.lazy,
    )
    done = {}
    if partial is not None:
        partial.keep_cycles(index, analysis.cycles)
        done = partial.done(index, analysis.tasks)
    lines = functools.partial(results_csv, file=str(path) if len(run.paths) > 1 else None)
    parts, texts = {}, {}  # texts: the lines of chunks that came before an earlier one
    for block, measured in done.items():
        part = analysis.part(block, *measured)
        parts[block], texts[block] = pipeline.only(part, columns), lines(part)
    written = _in_order(texts, write)
    bar = _bar(analysis, path, shown, sum(parts[b].cycle.size for b in parts))
    keep = False if partial is None else partial.blocks(index)
    resolved = []
    try:
        measured = analysis.measured(skip=done, then=lines, keep=keep, columns=columns)
        with contextlib.closing(measured) as kept:
            for block, chunk in kept:
                if partial is not None:
                    partial.record_block(index, block, analysis.tasks[block])
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
        raise _Interrupted(analysis.tasks) from (None if stopped else error)
    finally:
        bar.close()
    return analysis, parts, resolved[0] if resolved else None


def _in_order(texts: dict, write, written: int = 0) -> int:
    """Write the next blocks' ``texts`` that have come, in order; the blocks written so far."""
    while written in texts:
        write(texts.pop(written))
        written += 1
    return written


class _Interrupted(KeyboardInterrupt):
    """Ctrl-C while the blocks of a recording, its cycle rows ``tasks``, were measured."""

    def __init__(self, tasks):
        super().__init__(len(tasks))
        self.tasks = tasks


def _bar(analysis, path, shown: bool, initial: int):
    total, options = int(analysis.cycles.label.size), {"disable": not shown, "smoothing": 0.1}
    return progress_bar(total, path.name, initial=initial, unit=" cycles", **options)
