"""``ecofmaps figures``: the paper's figures, by groups sharing one Dataset (costliest first,
:func:`ecofmaps.figures.figure_groups`) on ``--jobs`` processes, the parts of a costly Dataset
(:func:`ecofmaps.figures.figure_parts`) computed in parallel before it; JAX's kernels kept in
``<cache>/jax``."""

from __future__ import annotations

import argparse
import multiprocessing
import os
import signal
import sys
import time
from collections import deque
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from pathlib import Path

from ecofmaps._interrupts import check_interrupted, interrupts_stop_writes
from ecofmaps._parallel import start_resource_tracker_quietly
from ecofmaps.cli import common
from ecofmaps.io.files import record_written

_FORMATS = ("png", "pdf", "svg")

_HELP = {
    "--out": "directory to write into, created if missing (default: figures)",
    "--only": "write only these figures (NAME: one of those listed below)",
    "--format": "comma-separated file formats among png, pdf, svg (default: png)",
    "--overwrite": "replace figures ecofmaps wrote in DIR (needed if it is not empty; no others)",
    "--jobs": "processes drawing (default: one per core, at most one per figure group; 1: this)",
}


def _figure_formats(text: str) -> tuple[str, ...]:
    """An argparse ``type``: comma-separated figure file formats."""
    formats = tuple(dict.fromkeys(item.strip().lower() for item in text.split(",")))
    unknown = [item for item in formats if item not in _FORMATS]
    if unknown:
        raise argparse.ArgumentTypeError(
            f"unknown figure format {', '.join(map(repr, unknown))} in {text!r}; "
            f"give one or more of {', '.join(_FORMATS)}, comma-separated"
        )
    return formats


def add(subparsers) -> None:
    from ecofmaps.figures.recipes import FIGURES  # the names for the parser (no JAX)

    listing = "\n".join(f"  {name:<10} {recipe.description}" for name, recipe in FIGURES.items())
    parser = common.command_parser(
        subparsers,
        "figures",
        help="write the paper's Figures 5-8 and 11, the universal map and the scar shapes",
        description="Write the paper's figures listed below, a file per format (fig5.png, ...), "
        "at the paper's parameters: amplitude 50um (= groove half-width), load 450N, stiffness "
        "35MN/m, mu 0.8. Maps, loops and JAX's kernels (jax/) are read from the cache "
        "(ECOFMAPS_CACHE), else stored there; files are written atomically, progress to stderr.",
        epilog=f"figures:\n{listing}",
    )
    option = common.option_adder(parser, _HELP)
    option("--out", type=Path, default="figures", metavar="DIR")
    option("--only", nargs="+", choices=list(FIGURES), metavar="NAME")
    option("--format", type=_figure_formats, default=("png",), metavar="FORMATS")
    option("--overwrite", action="store_true")
    option("--jobs", type=common.count("processes"), metavar="N")


def _set_jax_options(options: dict | None = None) -> dict:
    """Set JAX's ``options`` (default: cache every kernel, however quick); their values before."""
    import jax

    if options is None:
        from ecofmaps.maps.cache import JAX_CACHE_FOLDER, cache_directory

        options = {
            "jax_compilation_cache_dir": str(cache_directory() / JAX_CACHE_FOLDER),
            "jax_persistent_cache_min_compile_time_secs": 0.0,
            "jax_persistent_cache_min_entry_size_bytes": 0,
        }
    previous = {name: getattr(jax.config, name) for name in options}
    for name, value in options.items():
        jax.config.update(name, value)
    return previous


def _write_figure_group(names, directory, formats) -> list[tuple[str, list[Path], float]]:
    """Each figure of the group ``names`` drawn into ``directory``: its name, files, time [s]."""
    from ecofmaps.figures import make_figures, save_figure

    written, start = [], time.perf_counter()
    for name, figure in make_figures(names):
        paths = [save_figure(figure, Path(directory) / f"{name}.{suffix}") for suffix in formats]
        written.append((name, paths, time.perf_counter() - start))
        start = time.perf_counter()
    return written


def _start_worker() -> None:
    """Set up a drawing process: Ctrl-C is the parent's to handle; JAX's compilation cache."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _set_jax_options()


def _in_worker(task, out: Path, formats):
    """A :class:`TaskQueue` task done in a drawing process, which ends when told to stop."""
    kind, _, work = task
    try:
        with interrupts_stop_writes():  # SIGTERM from the parent: stop at a safe point
            return work() if kind == "part" else _write_figure_group(work, out, formats)
    except KeyboardInterrupt:  # its file removed; end without JAX's teardown, as console does
        os._exit(128 + signal.SIGTERM)


class TaskQueue:
    """The order of the parallel work, ``jobs`` tasks at once: parts, then the groups whose parts
    are done. A task is ``('part', index, callable)`` or ``('group', index, names)``."""

    def __init__(self, groups, parts, jobs: int):
        self.groups, self.jobs, self.running = groups, jobs, 0
        self.missing = [len(group_parts) for group_parts in parts]
        self.ready = deque(("part", i, part) for i, group in enumerate(parts) for part in group)
        self.ready.extend(("group", i, group) for i, group in enumerate(groups) if not parts[i])

    def started(self) -> list:
        """The tasks to start now, as many as there are idle processes."""
        idle = min(len(self.ready), self.jobs - self.running)
        self.running += idle
        return [self.ready.popleft() for _ in range(idle)]

    def finished(self, task) -> list:
        """The tasks to start once ``task`` has finished."""
        self.running -= 1
        kind, index, _ = task
        if kind == "part":
            self.missing[index] -= 1
            if not self.missing[index]:
                self.ready.appendleft(("group", index, self.groups[index]))
        return self.started()


def _written_in_parallel(groups, parts, out: Path, formats, jobs: int):
    """Each group's :func:`_write_figure_group` from ``jobs`` processes (:class:`TaskQueue`)."""
    others = set(multiprocessing.active_children())
    start_resource_tracker_quietly()
    spawn = multiprocessing.get_context("spawn")  # JAX's threads do not survive a fork
    executor = ProcessPoolExecutor(jobs, mp_context=spawn, initializer=_start_worker)
    queue = TaskQueue(groups, parts, jobs)

    def submitted(tasks) -> dict:  # each future: its task
        return {executor.submit(_in_worker, task, out, formats): task for task in tasks}

    try:
        pending = submitted(queue.started())
        while pending:  # waits of a quarter second, so Ctrl-C is seen at once
            done, _ = wait(pending, timeout=0.25, return_when=FIRST_COMPLETED)
            check_interrupted()
            for future in done:
                task = pending.pop(future)
                written = future.result()
                pending.update(submitted(queue.finished(task)))
                if task[0] == "group":
                    yield written
    finally:
        # stopped, not left to tear JAX down; a busy one stops at a safe point, writing nothing
        executor.shutdown(wait=False, cancel_futures=True)
        ours = set(multiprocessing.active_children()) - others
        for process in ours:
            process.terminate()
        for process in ours:
            process.join()
        executor.shutdown(wait=True)
        executor = None  # an interrupt's traceback keeps the frame: its semaphores released now


def _written_here(groups, out: Path, formats):
    """Each group's :func:`_write_figure_group`, drawn in this process."""
    previous = _set_jax_options()
    try:
        for group in groups:
            yield _write_figure_group(group, out, formats)
    finally:
        _set_jax_options(previous)


def run(args) -> int:
    from ecofmaps.figures.recipes import figure_groups, figure_parts

    names = list(dict.fromkeys(args.only or ())) or None
    groups, parts = figure_groups(names), figure_parts(names)
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    jobs = min(args.jobs or cores or 1, max(len(groups), *map(len, parts)))
    drawn = [name for group in groups for name in group]
    planned = [("--out", args.out / f"{name}.{suffix}") for name in drawn for suffix in args.format]
    common.refuse_to_overwrite(planned, [], overwrite=args.overwrite, folders=[("--out", args.out)])
    with common.made_folder(args.out):
        print(
            f"ecofmaps figures: {len(drawn)} figure(s) as {', '.join(args.format)} into {args.out}"
            + (f", {jobs} processes" if jobs > 1 else ""),
            file=sys.stderr,
        )
        begin = time.perf_counter()
        if jobs > 1:
            results = _written_in_parallel(groups, parts, args.out, args.format, jobs)
        else:
            results = _written_here(groups, args.out, args.format)
        written = (figure for group in results for figure in group)
        for index, (name, paths, seconds) in enumerate(written, start=1):
            record_written(paths)
            files = ", ".join(str(path) for path in paths)
            print(f"  [{index}/{len(drawn)}] {name:<10} {seconds:5.1f} s  {files}", file=sys.stderr)
    print(f"done in {time.perf_counter() - begin:.1f} s", file=sys.stderr)
    return 0
