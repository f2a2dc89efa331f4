"""``ecofmaps loops``: analyse recorded fretting loops cycle by cycle."""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

from ecofmaps.cli import loops_long
from ecofmaps.cli._common import CommandError, quantity, refuse_to_overwrite, unit

__all__ = ["add", "run"]


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "loops",
        help="analyse recorded fretting loops cycle by cycle: ECoF, GICoF, stiffness, ...",
        description=textwrap.fill(
            "Read recordings of fretting loops (CSV, TSV or whitespace-separated text with a "
            "header line; lines starting with # are skipped), cut them into cycles at the "
            "displacement reversals or by a cycle column, and write one row per cycle: "
            "cycle, amplitude_um, slip_amplitude_um, max_force_N, dissipated_energy_mJ, ecof, "
            "cof_max, energy_ratio, stiffness_MN_per_m, gicof, regime (and first a file "
            "column when several files are given). By default the columns are "
            "'displacement' in um and 'force' in N, with an optional 'cycle'. A damaged file "
            "stops the command with its name and line number, and nothing is written; files "
            "are written atomically. --example analyses the synthetic recording shipped with "
            "ecofmaps.",
            width=80,
        ),
        epilog=(
            "examples:\n  ecofmaps loops test.csv --load 450N --out results.csv --plots plots\n"
            "  ecofmaps loops --example --out results.csv --plots plots"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "files", nargs="*", metavar="FILE", help="recording files (CSV, TSV or text)",
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
        help="also write, per file, its loops with the line Q = SΔ (<name>_loops.png) and "
        "the ECoF and GICoF over the cycles (<name>_evolution.png) into DIR",
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


def run(args) -> int:
    import pandas as pd

    from ecofmaps.io.files import write_text
    from ecofmaps.io.recordings import RecordingError, read_recording
    from ecofmaps.io.tables import results_table
    from ecofmaps.measured.analysis import MissingSampleError, analyze_loops
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
    if args.out is not None and not Path(args.out).parent.is_dir():
        raise CommandError(f"cannot write {args.out}: its directory does not exist")
    plots = (
        []
        if args.plots is None
        else [
            ("--plots", Path(args.plots) / f"{name}_{kind}.png")
            for name in _plot_names(paths)
            for kind in ("loops", "evolution")
        ]
    )
    refuse_to_overwrite([("--out", args.out), *plots], paths)
    long_run = loops_long.LongRun(args, paths)
    analyses, recordings = [], []
    for index, path in enumerate(paths):
        recording = read_recording(
            path,
            displacement_column=args.displacement_col,
            force_column=args.force_col,
            cycle_column=args.cycle_col,
            displacement_unit=args.displacement_unit,
            force_unit=args.force_unit,
            group=args.group,
            lazy=long_run.lazy,
        )
        try:
            if recording.lazy:
                results = long_run.analyse(index, path, recording, load)
            else:
                results = analyze_loops(
                    recording.displacement,
                    recording.force,
                    load,
                    cycle=recording.cycle,
                    keep_loops=args.plots is not None,
                    nan_policy=args.nan_policy,
                )
        except MissingSampleError as error:
            raise recording.error(loops_long.MISSING, error.sample) from None
        except RecordingError:  # a block of a long recording that cannot be read
            raise
        except ValueError as error:
            raise recording.error(str(error)) from None
        analyses.append(results)
        recordings.append(recording)
    tables = [results_table(results) for results in analyses]
    if len(paths) > 1:
        for path, table in zip(paths, tables, strict=True):
            table.insert(0, "file", str(path))
    text = pd.concat(tables).to_csv(index=False, float_format="%.6g", lineterminator="\n")
    if args.plots is not None:
        from ecofmaps.figures import cof_evolution, measured_loops, save_figure

        folder = Path(args.plots)
        folder.mkdir(parents=True, exist_ok=True)
        for name, results in zip(_plot_names(paths), analyses, strict=True):
            save_figure(measured_loops(results), folder / f"{name}_loops.png")
            save_figure(cof_evolution(results), folder / f"{name}_evolution.png")
    if args.out is None:
        sys.stdout.write(text)
        return 0
    write_text(args.out, text)
    long_run.finish()
    print(f"wrote {args.out}: {sum(len(table) for table in tables)} cycles")
    for path, results, recording in zip(paths, analyses, recordings, strict=True):
        gross = results.where(results.regime == "gross slip", drop=True)
        summary = f"  {path.name}: {results.cycle.size} cycles"
        if results.attrs["incomplete_cycles"]:
            summary += f" ({results.attrs['incomplete_cycles']} incomplete dropped)"
        summary += loops_long.skipped(results, recording)
        if gross.cycle.size:
            summary += (
                f"; GICoF median {float(gross.gicof.median()):.4f}, ECoF "
                f"{float(gross.ecof[0]):.4f} (first) to {float(gross.ecof[-1]):.4f} (last)"
            )
        if gross.cycle.size < results.cycle.size:
            summary += f"; {results.cycle.size - gross.cycle.size} in partial slip"
        print(summary)
    if args.plots is not None:
        print(f"  plots in {args.plots}")
    return 0
