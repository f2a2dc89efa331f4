"""The work of ``ecofmaps loops`` (its options are in :mod:`ecofmaps.cli.loops`): every
recording through the one pipeline of :mod:`ecofmaps.measured.pipeline`, in memory as one
chunk, a long one out of core (:mod:`ecofmaps.cli.loops_long`); the table written as the
chunks come, the summary lines, the plots and the reading along the stroke."""

from __future__ import annotations

import contextlib
import io
import sys
import warnings
from pathlib import Path

import numpy as np

from ecofmaps._interrupts import interrupts_deferred
from ecofmaps.cli import loops_long
from ecofmaps.cli._common import CommandError, recording_options, refuse_to_overwrite
from ecofmaps.io.files import atomic_path, record_written
from ecofmaps.io.recordings import read_recording
from ecofmaps.maps.cache import write_netcdf
from ecofmaps.measured.pipeline import Reading
from ecofmaps.measured.quality import ImplausibleScaleError, ImplausibleScaleWarning
from ecofmaps.measured.resolve import ReadingOptions
from ecofmaps.measured.synthetic import EXAMPLE, example_path
from ecofmaps.model.regimes import GROSS_SLIP
from ecofmaps.web import INSTALL_WEB, missing_web_packages

__all__ = ["SUMMARY_VARIABLES", "run"]


def _plot_names(paths) -> list[str]:
    """A distinct file-name stem for each recording's plots."""
    stems = [path.stem for path in paths]
    return [
        stem if stems.count(stem) == 1 else f"{stem}_{index}"
        for index, stem in enumerate(stems, start=1)
    ]


def _analysed(index, path, recording, load, args, long_run, write, *, many, resolved_file):
    """One recording through the pipeline: its results (all of them in memory, those the
    summary reads of a long one), its reading along the stroke over positions (for the
    plots and ``--resolved``, in memory only) and its warnings, printed one line each."""
    in_memory = not recording.lazy
    if not in_memory and resolved_file:
        raise CommandError(
            f"--resolved reads every loop along the stroke, which a long recording "
            f"({path}) analysed out of core does not keep: leave out --resolved"
        )
    if not in_memory and args.report is not None:
        raise CommandError(
            f"--report draws loops and the whole table, which a long recording ({path}) "
            "analysed out of core does not keep: leave out --report"
        )
    plots = args.plots is not None and in_memory
    positions = 201 if plots or resolved_file else None
    reading = Reading(
        resolve=not args.no_resolve,
        keep_loops=plots or args.report is not None,
        along_stroke=ReadingOptions(positions=positions),
        hand_back=positions is not None,
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            results, resolved = long_run.analyse(
                index, path, recording, load, many=many, write=write,
                columns=None if in_memory else SUMMARY_VARIABLES, reading=reading,
            )  # fmt: skip
        except ImplausibleScaleError as error:
            raise recording.error(_with_assumptions(str(error), recording)) from None
        except ValueError as error:
            raise recording.error(str(error)) from None
    for warning in caught:  # one line each, naming the file, not a Python source line
        message = str(warning.message)
        if issubclass(warning.category, ImplausibleScaleWarning):
            message = _with_assumptions(message, recording)
        print(f"ecofmaps loops: warning: {path.name}: {message}", file=sys.stderr)
    return results, resolved


def _with_assumptions(message: str, recording) -> str:
    """``message`` (of an implausible scale: an assumed unit is the likely culprit) with the
    units the recording's columns without one were assumed to be in."""
    said = [
        f"the {role} column {recording.columns[role]!r} has no unit and was read in "
        f"{recording.units[role]} (--{role}-unit gives it)"
        for role in ("displacement", "force")
        if role in recording.assumed_units
    ]
    return message if not said else f"{message} Here {'; '.join(said)}."


#: The variables of a recording's results that its summary line reads (:func:`_summary`):
#: all that is kept of a long recording's results once their lines are written.
SUMMARY_VARIABLES = ("regime", "gicof", "mu_resolved", "ecof", "quality", "amplitude")


class _Table:
    """The table of results, written to ``stream`` as each block of lines comes. Each block
    begins with the header line, written once."""

    def __init__(self, stream):
        self.stream, self.started = stream, False

    def write(self, text: str) -> None:
        header, _, lines = text.partition("\n")
        if not self.started:
            self.stream.write(f"{header}\n")
            self.started = True
        self.stream.write(lines)
        self.stream.flush()  # on disk as it comes: a block is a few MB


def _summary(path, results, recording) -> str:
    """One line on a recording's cycles: counts, the quality, the friction over the test."""
    gross = results.isel(cycle=np.flatnonzero(results.regime.values == GROSS_SLIP))
    summary = f"  {path.name}: {results.attrs['quality_summary']}"
    if results.attrs.get("motion") == "reciprocating sliding":
        amplitude = float(np.nanmedian(results.amplitude)) if "amplitude" in results else np.nan
        stroke = f" (amplitude {amplitude * 1e3:.3g} mm)" if np.isfinite(amplitude) else ""
        summary += f"; reciprocating sliding{stroke}, not fretting: analysed the same way"
    if results.attrs["incomplete_cycles"]:
        summary += f" ({results.attrs['incomplete_cycles']} incomplete dropped)"
    summary += loops_long.skipped(results, recording)
    if gross.cycle.size and gross.gicof.notnull().any():
        summary += f"; GICoF median {float(gross.gicof.median()):.4f}"
    if "mu_resolved" in gross and gross.mu_resolved.notnull().any():
        summary += f", μ read along the stroke median {float(gross.mu_resolved.median()):.4f}"
    ecof = gross.ecof.dropna("cycle") if gross.cycle.size else gross.ecof
    if ecof.size:
        summary += f"; ECoF {float(ecof[0]):.4f} (first) to {float(ecof[-1]):.4f} (last)"
    return summary


def _checked_inputs(args) -> tuple[list[Path], float]:
    """The recordings and the load of the command, its options checked against each other."""
    if args.example == bool(args.files):
        raise CommandError("give one or more recording FILEs, or --example (not both)")
    paths = [example_path()] if args.example else [Path(name) for name in args.files]
    load = EXAMPLE["load"] if args.example and args.load is None else args.load
    if load is None:
        raise CommandError("--load is required: the normal load, e.g. --load 450N")
    columns = {
        "--displacement-col": args.displacement_col,
        "--force-col": args.force_col,
        "--cycle-col": args.cycle_col,
    }
    named = [(option, name.strip().lower()) for option, name in columns.items() if name]
    for index, (option, name) in enumerate(named):
        for other, other_name in named[:index]:
            if name == other_name:
                raise CommandError(f"{other} and {option} name the same column {name!r}")
    if args.resolved is not None:
        if args.no_resolve:
            raise CommandError("--resolved writes the reading along the stroke; not --no-resolve")
        if len(paths) > 1:
            raise CommandError("--resolved writes the reading of one recording: give one FILE")
    if args.report is not None:
        if len(paths) > 1:
            raise CommandError("--report writes the page of one recording: give one FILE")
        if missing_web_packages():
            raise CommandError(INSTALL_WEB)
    return paths, load


def _checked_outputs(args, paths) -> list:
    """The command's outputs as ``(option, path)``, refused where they would overwrite a
    file that ecofmaps did not write (or an input)."""
    for option, target in (
        ("--out", args.out),
        ("--resolved", args.resolved),
        ("--report", args.report),
    ):
        if target is not None and not Path(target).parent.is_dir():
            raise CommandError(f"cannot write {target} ({option}): its directory does not exist")
    kinds = ("loops", "evolution") + (() if args.no_resolve else ("resolved",))
    plots = (
        []
        if args.plots is None
        else [
            ("--plots", Path(args.plots) / f"{name}_{kind}.png")
            for name in _plot_names(paths)
            for kind in kinds
        ]
    )
    outputs = [("--out", args.out), ("--resolved", args.resolved), ("--report", args.report)]
    outputs += plots
    refuse_to_overwrite(outputs, paths, overwrite=args.overwrite, folders=[("--plots", args.plots)])
    return outputs


class _NothingAnalysed(Exception):
    """No recording of a batch could be analysed."""


class _Analysed:
    """A recording analysed: its path, the recording, its results and reading along the
    stroke, and the name of its plots."""

    def __init__(self, path, recording, results, resolved, plot_name):
        self.path, self.recording, self.plot_name = path, recording, plot_name
        self.results, self.resolved = results, resolved


def _analyse_each(args, paths, load, long_run, table) -> tuple[list[_Analysed], list[Path]]:
    """Every recording through the pipeline, its lines written to ``table``. With several
    recordings, one that cannot be analysed is one error line naming it, and the others go
    on (a batch); a single recording's error ends the command."""
    done, failed = [], []
    many = len(paths) > 1
    for index, (path, plot_name) in enumerate(zip(paths, _plot_names(paths), strict=True)):
        held = []  # a recording in memory: its lines once its analysis has succeeded
        try:
            options = recording_options(args)
            if isinstance(load, str):  # --load names the recording's normal-load column
                options["load_column"] = load
            recording = read_recording(path, lazy=long_run.lazy, **options)
            write = table.write if recording.lazy else held.append
            results, resolved = _analysed(
                index, path, recording, load, args, long_run, write, many=many,
                resolved_file=args.resolved is not None,
            )  # fmt: skip
        except (ValueError, OSError, CommandError) as error:
            if not many:
                raise
            failed.append(path)
            named = str(error) if str(path) in str(error) else f"{path}: {error}"
            print(f"ecofmaps loops: error: {named}", file=sys.stderr)
            continue
        for text in held:
            table.write(text)
        done.append(_Analysed(path, recording, results, resolved, plot_name))
    return done, failed


def _write_extras(args, done: list[_Analysed], load) -> None:
    """The plots, the reading along the stroke and the report the options ask for."""
    if args.plots is not None and done:
        # matplotlib only when plots are asked for
        from ecofmaps.figures import cof_evolution, measured_loops, resolved_loops, save_figure

        folder = Path(args.plots)
        folder.mkdir(parents=True, exist_ok=True)
        for each in done:
            name, results, resolved = each.plot_name, each.results, each.resolved
            save_figure(measured_loops(results, resolved=resolved), folder / f"{name}_loops.png")
            save_figure(cof_evolution(results), folder / f"{name}_evolution.png")
            if resolved is not None:
                save_figure(resolved_loops(resolved, results), folder / f"{name}_resolved.png")
    if args.resolved is not None and done:
        write_netcdf(done[0].resolved, args.resolved)
    if args.report is not None and done:
        # Bokeh loads only when a report is asked for (the extra web is optional)
        from ecofmaps.web.report import recording_inputs, write_report

        mean_load = float(done[0].results["load"])  # the load given, or a channel's mean
        inputs = recording_inputs(done[0].recording, mean_load, flip_force=args.flip_force)
        write_report(args.report, done[0].results, inputs=inputs)


def run(args) -> int:
    """Run ``ecofmaps loops`` with the parsed ``args``: 0 when every recording was
    analysed, 1 when some of several could not be (each named in an error line; the others'
    rows are written)."""
    paths, load = _checked_inputs(args)
    outputs = _checked_outputs(args, paths)
    long_run = loops_long.LongRun(args, paths)
    try:
        with contextlib.ExitStack() as stack:  # the table is written as it comes, renamed last
            if args.out is None:  # held, and printed once every file is analysed
                stream = io.StringIO()
            else:
                temporary = stack.enter_context(atomic_path(args.out))
                stream = stack.enter_context(open(temporary, "w", encoding="utf-8", newline=""))
            table = _Table(stream)
            done, failed = _analyse_each(args, paths, load, long_run, table)
            if not done:  # nothing to write: the temporary goes
                raise _NothingAnalysed
            _write_extras(args, done, load)
    except _NothingAnalysed:
        print(f"ecofmaps loops: none of the {len(paths)} recordings could be analysed; "
              "nothing written", file=sys.stderr)  # fmt: skip
        return 1
    with interrupts_deferred():  # the table is in place: a stop now would leave it unrecorded
        record_written(path for _, path in outputs if path is not None)
    status = 1 if failed else 0
    if args.out is None:
        sys.stdout.write(table.stream.getvalue())
        for each in done:
            print(_summary(each.path, each.results, each.recording).strip(), file=sys.stderr)
        return status
    long_run.finish()
    written = sum(each.results.cycle.size for each in done)
    print(f"wrote {args.out}: {written} cycle{'' if written == 1 else 's'}")
    for each in done:
        print(_summary(each.path, each.results, each.recording))
    if failed:
        print(f"  not analysed ({len(failed)}): " + ", ".join(str(path) for path in failed))
    if args.resolved is not None:
        print(f"  the loops read along the stroke in {args.resolved}")
    if args.report is not None:
        print(f"  the report in {args.report}")
    if args.plots is not None:
        print(f"  plots in {args.plots}")
    return status
