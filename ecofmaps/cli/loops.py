"""``ecofmaps loops``: analyse recorded fretting loops cycle by cycle."""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np

from ecofmaps.cli import loops_long
from ecofmaps.cli._common import (
    CommandError,
    quantity,
    recording_options,
    refuse_to_overwrite,
    unit,
)

__all__ = ["add", "run"]


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "loops",
        help="analyse recorded fretting loops cycle by cycle: ECoF, GICoF, stiffness, ...",
        description=textwrap.fill(
            "Read recordings of fretting loops (text with a header line in any common "
            "dialect, TDMS, HDF5/netCDF-4 or zarr), cut them into cycles at the displacement "
            "reversals or by a cycle column, check every loop, and write one row per cycle: "
            "cycle, amplitude_um, slip_amplitude_um, max_force_N, dissipated_energy_mJ, ecof, "
            "cof_max, energy_ratio, stiffness_MN_per_m, gicof, regime, then mu_resolved, "
            "mu_resolved_se and aspect_ratio (friction and groove read along the whole "
            "stroke) and quality ('ok', or why values are NaN); first a file column when "
            "several files are given. By default the columns are 'displacement' and 'force' "
            "(units from their names or the file, else um and N), with an optional 'cycle'. "
            "A damaged file stops the command with its name and line number, and nothing is "
            "written; files are written atomically and never over an input. --example "
            "analyses the synthetic recording shipped with ecofmaps.",
            width=80,
        ),
        epilog=(
            "examples:\n  ecofmaps loops test.csv --load 450N --out results.csv --plots plots\n"
            "  ecofmaps loops --example --out results.csv --plots plots"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "files", nargs="*", metavar="FILE",
        help="recording files (CSV, TSV or other text, TDMS, HDF5/netCDF-4, zarr)",
    )  # fmt: skip
    parser.add_argument(
        "--example", action="store_true",
        help="analyse the shipped synthetic example (load 450N) instead of FILEs",
    )  # fmt: skip
    parser.add_argument(
        "--load", type=quantity("load"), default=None, metavar="P",
        help="normal load P, e.g. 450N (required unless --example)",
    )  # fmt: skip
    parser.add_argument(
        "--out", default=None, metavar="FILE.csv",
        help="CSV file to write (its directory must exist); default: print the table",
    )  # fmt: skip
    parser.add_argument(
        "--plots", default=None, metavar="DIR",
        help="also write, per file, its loops with the line Q = SΔ (<name>_loops.png), "
        "the ECoF and GICoF over the cycles (<name>_evolution.png) and the loops read along "
        "the stroke (<name>_resolved.png) into DIR",
    )  # fmt: skip
    parser.add_argument(
        "--resolved", default=None, metavar="FILE.nc",
        help="also write the loops read along the stroke (one FILE): μ(ξ), the groove slope "
        "g(ξ) and the felt profile h(ξ) over (cycle, position), a netCDF file",
    )  # fmt: skip
    parser.add_argument(
        "--no-resolve", action="store_true",
        help="skip the reading along the stroke (about ten times faster; no mu_resolved, "
        "mu_resolved_se, aspect_ratio)",
    )  # fmt: skip
    parser.add_argument(
        "--flip-force", action="store_true",
        help="read the force with the other sign (a rig recording it positive against the "
        "displacement: its loops run anticlockwise)",
    )  # fmt: skip
    parser.add_argument(
        "--displacement-col", default="displacement", metavar="NAME",
        help="name of the displacement column (default: displacement)",
    )  # fmt: skip
    parser.add_argument(
        "--force-col", default="force", metavar="NAME",
        help="name of the tangential force column (default: force)",
    )  # fmt: skip
    parser.add_argument(
        "--cycle-col", default=None, metavar="NAME",
        help="name of a column of cycle numbers, which must exist "
        "(default: 'cycle' if the file has it; else cycles are cut at the reversals)",
    )  # fmt: skip
    parser.add_argument(
        "--displacement-unit", type=unit("length"), default=None, metavar="UNIT",
        help="unit of the displacement column (default: the one its name or the file gives, "
        "as in 'displacement [mm]' or a channel's unit, else um)",
    )  # fmt: skip
    parser.add_argument(
        "--force-unit", type=unit("force"), default=None, metavar="UNIT",
        help="unit of the force column (default: from its name or the file, else N)",
    )  # fmt: skip
    parser.add_argument(
        "--group", default=None, metavar="NAME",
        help="TDMS group, or HDF5/netCDF/zarr group, holding the channels (default: any)",
    )  # fmt: skip
    loops_long.add_options(parser)
    parser.set_defaults(handler=run)


def _plot_names(paths) -> list[str]:
    """A distinct file-name stem for each recording's plots."""
    stems = [path.stem for path in paths]
    return [
        stem if stems.count(stem) == 1 else f"{stem}_{index}"
        for index, stem in enumerate(stems, start=1)
    ]


def _analysed(path, recording, load, args, resolved_file: bool):
    """The analysis of one recording, its reading along the stroke, and its warnings."""
    from ecofmaps.measured.analysis import MissingSampleError, analyze_loops
    from ecofmaps.measured.resolved import resolve_analyzed_loops, with_resolved

    plots = args.plots is not None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            results = analyze_loops(
                recording.displacement,
                recording.force,
                load,
                cycle=recording.cycle,
                flip_force=args.flip_force,
                keep_loops=plots or not args.no_resolve,
                nan_policy=args.nan_policy,
            )
        except MissingSampleError as error:
            raise recording.error(loops_long.MISSING, error.sample) from None
        except ValueError as error:
            raise recording.error(str(error)) from None
        resolved = None
        if not args.no_resolve:
            positions = 201 if plots or resolved_file else None
            resolved = resolve_analyzed_loops(results, positions=positions)
            results = with_resolved(results, resolved)
    for warning in caught:  # one line each, naming the file, not a Python source line
        print(f"ecofmaps loops: warning: {path.name}: {warning.message}", file=sys.stderr)
    return results, resolved


#: The variables of a recording's results that its summary line reads (:func:`_summary`):
#: all that is kept of a long recording's results once their lines are written.
SUMMARY_VARIABLES = ("regime", "gicof", "mu_resolved", "ecof", "quality")


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
    from ecofmaps.model.regimes import GROSS_SLIP

    gross = results.isel(cycle=np.flatnonzero(results.regime.values == GROSS_SLIP))
    summary = f"  {path.name}: {results.attrs['quality_summary']}"
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


def run(args) -> int:
    from ecofmaps.io.files import atomic_path
    from ecofmaps.io.recordings import read_recording
    from ecofmaps.io.tables import results_csv
    from ecofmaps.maps.cache import write_netcdf
    from ecofmaps.measured.synthetic import EXAMPLE, example_path

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
    for option, target in (("--out", args.out), ("--resolved", args.resolved)):
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
    refuse_to_overwrite([("--out", args.out), ("--resolved", args.resolved), *plots], paths)
    long_run = loops_long.LongRun(args, paths)
    analyses, recordings = [], []
    many = len(paths) > 1
    with contextlib.ExitStack() as stack:  # the table is written as it comes, renamed at the end
        if args.out is None:  # held, and printed once every file is analysed
            stream = io.StringIO()
        else:
            temporary = stack.enter_context(atomic_path(args.out))
            stream = stack.enter_context(open(temporary, "w", encoding="utf-8", newline=""))
        table = _Table(stream)
        for index, path in enumerate(paths):
            recording = read_recording(path, lazy=long_run.lazy, **recording_options(args))
            if recording.lazy:
                if args.resolved is not None:
                    raise CommandError(
                        f"--resolved reads every loop along the stroke, which a long recording "
                        f"({path}) analysed out of core does not keep: leave out --resolved"
                    )
                results = long_run.analyse(
                    index, path, recording, load, many=many, write=table.write,
                    columns=SUMMARY_VARIABLES,
                )  # fmt: skip
                analyses.append((results, None))
            else:
                analyses.append(_analysed(path, recording, load, args, args.resolved is not None))
                table.write(results_csv(analyses[-1][0], file=str(path) if many else None))
            recordings.append(recording)
        if args.plots is not None:
            from ecofmaps.figures import cof_evolution, measured_loops, resolved_loops, save_figure

            folder = Path(args.plots)
            folder.mkdir(parents=True, exist_ok=True)
            for name, (results, resolved) in zip(_plot_names(paths), analyses, strict=True):
                save_figure(
                    measured_loops(results, resolved=resolved), folder / f"{name}_loops.png"
                )
                save_figure(cof_evolution(results), folder / f"{name}_evolution.png")
                if resolved is not None:
                    save_figure(resolved_loops(resolved, results), folder / f"{name}_resolved.png")
        if args.resolved is not None:
            write_netcdf(analyses[0][1], args.resolved)
    if args.out is None:
        sys.stdout.write(table.stream.getvalue())
        for path, (results, _), recording in zip(paths, analyses, recordings, strict=True):
            print(_summary(path, results, recording).strip(), file=sys.stderr)
        return 0
    long_run.finish()
    print(f"wrote {args.out}: {sum(r.cycle.size for r, _ in analyses)} cycles")
    for path, (results, _), recording in zip(paths, analyses, recordings, strict=True):
        print(_summary(path, results, recording))
    if args.resolved is not None:
        print(f"  the loops read along the stroke in {args.resolved}")
    if args.plots is not None:
        print(f"  plots in {args.plots}")
    return 0
