"""``ecofmaps loops``: recorded loops analysed cycle by cycle by :mod:`ecofmaps.measured.pipeline`
(out of core: :mod:`.loops_long`), the table written as it comes, then summaries (docs/loops.md)."""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import sys
import warnings
from pathlib import Path

import numpy as np

from ecofmaps._interrupts import interrupts_deferred
from ecofmaps._nomenclature import QUANTITIES, texts_with_se, transition_texts, with_se
from ecofmaps._parallel import worker_limit
from ecofmaps.cli import common
from ecofmaps.cli.main import CommandError, option_names
from ecofmaps.io.files import FileLineError, atomic_path, record_written
from ecofmaps.web import INSTALL_WEB, missing_web_packages

_HELP = {
    "files": "recording files (CSV, TSV or other text, TDMS, HDF5/netCDF-4, zarr)",
    "--example": "analyse the shipped synthetic example (load 450N) instead of FILEs",
    "--load": "normal load P, e.g. 450N, or a load column (e.g. Fz); required unless --example",
    "--out": "CSV file to write (its directory must exist); default: print the table",
    "--plots": "also write into DIR per file: loops with Q = SΔ (<name>_loops.png), ECoF and "
    "GICoF over the cycles (<name>_evolution.png), loops along the stroke (<name>_resolved.png)",
    "--resolved": "also write one FILE's loops along the stroke (netCDF): μ(ξ), slope g(ξ), h(ξ)",
    "--report": 'also write one recording as an offline HTML page (pip install "ecofmaps[web]")',
    "--no-resolve": "skip the reading along the stroke (ten times faster; no mu_resolved, ...)",
    "--flip-force": "read the force with the other sign (loops that run anticlockwise)",
    "--rig-stiffness": "the rig's own stiffness, e.g. 35MN/m: the contact's ratios, regime, δ_t",
    "--scar-profile": "the scar's profile after the test (x, z columns): the loop-scar closure of "
    "its last loop (with --plots <name>_closure.png); with --length or --sphere, its energy wear",
    "--nan-policy": "skip (default) and count cycles missing a sample, or raise naming its line",
    "--workers": "analyse out of core on a local dask cluster of N processes",
    "--scheduler": "analyse out of core on the dask cluster at ADDRESS (tcp://host:8786), whose "
    "workers have ecofmaps and see the files at the same paths",
    "--resume": "continue a stopped run from <out>.partial/ (the same --out, files and options)",
}


def add(subparsers) -> None:
    parser = common.command_parser(
        subparsers,
        "loops",
        help="analyse recorded fretting loops cycle by cycle: ECoF, GICoF, stiffness, ...",
        description="Cut recordings of fretting loops (text: a header line, any dialect) into "
        "cycles at the displacement reversals or by a cycle column, and write a row per cycle: "
        "cycle, amplitude_um, slip_amplitude_um, normal_load_N (with --load COLUMN), max_force_N, "
        "dissipated_energy_mJ, ecof, cof_max, energy_ratio (with --rig-stiffness also "
        "opening_ratio, contact_amplitude_um, contact_energy_ratio, contact_opening_ratio), "
        "stiffness_MN_per_m, gicof, regime, mu_resolved, mu_resolved_se, aspect_ratio (read along "
        "the stroke), quality ('ok', or why values are NaN); first a file column for several "
        "files. Columns are found by rigs' names (disp, Fx, cycle, ...), units by their names or "
        "the file, else um and N. A file that fails is an error line, the others are written "
        "(exit status 1), atomically, never over an input or a file ecofmaps did not write.",
        epilog="examples:\n  ecofmaps loops test.csv --load 450N --out results.csv --plots plots\n"
        "  ecofmaps loops --example --out results.csv --plots plots",
    )
    option = common.option_adder(parser, _HELP)
    option("files", nargs="*", metavar="FILE")
    option("--example", action="store_true")
    option("--load", type=_load_or_column, metavar="P")
    option("--out", metavar="FILE.csv")
    option("--plots", metavar="DIR")
    option("--overwrite", action="store_true")
    option("--resolved", metavar="FILE.nc")
    option("--report", metavar="FILE.html")
    option("--no-resolve", action="store_true")
    option("--flip-force", action="store_true")
    stiffness = common.quantity("stiffness", option="--rig-stiffness")
    option("--rig-stiffness", type=stiffness, metavar="S")
    option("--scar-profile", metavar="FILE")
    common.add_contact_options(parser, required=False)
    option("--nan-policy", choices=("skip", "raise"), default="skip")
    common.add_recording_options(parser)
    long_tests = parser.add_argument_group(
        "long tests",
        "past 2**24 samples a file is analysed out of core, by blocks (the same numbers)",
    )
    option = common.option_adder(long_tests, _HELP)
    option("--workers", type=_workers, metavar="N")
    option("--scheduler", metavar="ADDRESS")
    option("--resume", action="store_true")
    option("--quiet", action="store_true")


def _workers(text: str) -> int:
    value = common.count("workers")(text)
    limit, why = worker_limit(processes=True)
    if value > limit:
        raise argparse.ArgumentTypeError(f"{value} is more than this machine can run: {why}")
    return value


def _load_or_column(text: str):
    """``--load``: a load [N] (a float), or the name of a column (a str)."""
    try:
        return common.quantity("load")(text)
    except argparse.ArgumentTypeError:
        name = text.strip()
        try:
            float(name.split()[0] if name else "x")
        except ValueError:  # not a number at all (inf and nan are numbers): a column's name
            if name and not name[0].isdigit() and not name.startswith(("-", "+", ".")):
                return name  # a column of the recording, e.g. Fz
        raise


def _plot_names(paths) -> list[str]:
    """A distinct file-name stem for each recording's plots."""
    stems = [path.stem for path in paths]
    return [s if stems.count(s) == 1 else f"{s}_{i}" for i, s in enumerate(stems, start=1)]


#: The options that need what a long recording analysed out of core does not keep.
_NOT_KEPT = (
    ("--resolved", "reads every loop along the stroke", ""),
    ("--report", "draws loops and the whole table", ""),
    ("--scar-profile", "closes the last loops on the scar", ""),
    ("--plots", "draws every loop", " (or --workers, --scheduler, --resume)"),
)


def _analysed(index, path, recording, load, args, long_run, write):
    """One recording's results and reading along the stroke; its warnings one line each."""
    from ecofmaps.measured.quality import ImplausibleScaleError, ImplausibleScaleWarning

    for option, does, others in _NOT_KEPT:
        if recording.lazy and getattr(args, option[2:].replace("-", "_")) is not None:
            raise CommandError(
                f"{option} {does}, which a long recording ({path}) analysed out of core does "
                f"not keep: leave out {option}{others}"
            )
    columns = SUMMARY_VARIABLES if recording.lazy else None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            analysed = long_run.analyse(index, path, recording, load, write, columns)
        except ImplausibleScaleError as error:
            raise recording.error(_with_assumptions(str(error), recording)) from None
        except FileLineError:  # names its file and line already
            raise
        except ValueError as error:
            raise recording.error(str(error)) from None
    for warning in caught:  # one line each, naming the file, not a Python source line
        message = str(warning.message)
        if issubclass(warning.category, ImplausibleScaleWarning):
            message = _with_assumptions(message, recording)
        print(f"ecofmaps loops: warning: {path.name}: {message}", file=sys.stderr)
    return analysed


def _with_assumptions(message: str, recording) -> str:
    """``message`` (of an implausible scale) with the units assumed for columns without one."""
    said = [
        f"the {role} column {recording.columns[role]!r} has no unit and was read in "
        f"{recording.units[role]} (--{role}-unit gives it)"
        for role in ("displacement", "force")
        if role in recording.assumed_units
    ]
    return message if not said else f"{message} Here {'; '.join(said)}."


#: The variables the summary lines read: all that is kept of a long recording's results.
SUMMARY_VARIABLES = (
    *("regime", "gicof", "mu_resolved", "ecof", "quality", "amplitude"),
    *("max_force", "dissipated_energy", "normal_load"),
)


class _Table:
    """The table, written to ``stream`` as each block of lines comes (its header line once)."""

    def __init__(self, stream):
        self.stream, self.started = stream, False

    def write(self, text: str) -> None:
        header, _, lines = text.partition("\n")
        self.stream.write(lines if self.started else f"{header}\n{lines}")
        self.started = True
        self.stream.flush()  # on disk as it comes: a block is a few MB


#: Why cycles are incomplete, by how they were cut (the results' ``cycles_from``).
_WHY_INCOMPLETE = {
    "displacement reversals": ": partial, where the recording starts or ends mid-cycle",
    "cycle numbers": ": too few samples, too short a stroke or not closed",
}


def _summary(path, results, recording) -> str:
    """One line on a recording's cycles: counts, the quality, the friction over the test."""
    from ecofmaps.lab.regime import sliding_condition_line
    from ecofmaps.model.regimes import GROSS_SLIP

    gross = results.isel(cycle=np.flatnonzero(results.regime.values == GROSS_SLIP))
    summary = f"{path.name}: {results.attrs['quality_summary']}"
    if results.attrs.get("motion") == "reciprocating sliding":
        amplitude = float(np.nanmedian(results.amplitude)) if "amplitude" in results else np.nan
        stroke = f" (amplitude {amplitude * 1e3:.3g} mm)" if np.isfinite(amplitude) else ""
        summary += f"; reciprocating sliding{stroke}, not fretting: analysed the same way"
    if results.attrs["incomplete_cycles"]:
        why = _WHY_INCOMPLETE.get(results.attrs.get("cycles_from"), "")
        summary += f" ({results.attrs['incomplete_cycles']} incomplete dropped{why})"
    if skipped := results.attrs.get("skipped_cycles", 0):
        first = recording.position(results.attrs["first_missing_sample"])
        where = f"line {first}" if isinstance(first, int) else first
        summary += f"; {skipped} skipped for missing samples (the first at {where})"
    summary += f"; {sliding_condition_line(results)}"
    if gross.gicof.notnull().any():
        summary += f"; GICoF median {float(gross.gicof.median()):.4f}"
    if "mu_resolved" in gross and gross.mu_resolved.notnull().any():
        summary += f", μ read along the stroke median {float(gross.mu_resolved.median()):.4f}"
    if (ecof := gross.ecof.dropna("cycle")).size:
        summary += f"; ECoF {float(ecof[0]):.4f} (first) to {float(ecof[-1]):.4f} (last)"
    return summary


def _scar_numbers(args, each, profile) -> tuple[dict, object]:
    """Rows of text of the energy wear and loop-scar closure on ``profile``; the closure."""
    from ecofmaps.lab import energy_wear, loop_scar_closure

    rows, closure = {}, None
    if (kind := common.contact(args)) is not None:
        try:
            wear = energy_wear(each.results, profile, args.length, kind)
        except ValueError as error:
            shown = f"none: {error}"
        else:
            names = ("wear_volume", "energy_wear_coefficient", "archard_slip", "archard_nominal")
            texts = texts_with_se(wear, names)
            shown = ", ".join(f"{QUANTITIES[q].symbol} = {text}" for q, text in texts)
        rows[f"energy wear ({kind}, {args.scar_profile})"] = shown
    try:
        closure = loop_scar_closure(each.results, each.resolved, profile, args.rig_stiffness)
    except ValueError as error:
        shown = f"none: {error}"
    else:
        shown = (
            f"cycle {int(closure.cycle)}, μ = GICoF {float(closure.mu):.4f}: the loop "
            f"{float(closure.loop_residual):.2%} of Q* off the model's, the scar "
            f"{float(closure.scar_residual) * 1e6:.3g} µm "
            f"({float(closure.scar_relative_residual):.2%} of its depth) off the profile's"
        )
    rows[f"loop-scar closure ({args.scar_profile})"] = shown
    return rows, closure


def _lab_lines(results, rig_stiffness) -> list[str]:
    """ΣE_d over a recording's cycles, and its transition to gross slip if it crosses one."""
    from ecofmaps.lab import transition
    from ecofmaps.lab.wear import cumulated_energy

    try:
        energy = with_se("cumulated_energy", *cumulated_energy(results))
        lines = [f"ΣE_d = {energy} over cycles 1 to {float(results['cycle'][-1]):.0f}"]
    except ValueError as error:
        lines = [f"ΣE_d: {error}"]
    try:
        found = transition(results, rig_stiffness=rig_stiffness)
    except ValueError:  # never crosses: nothing to say
        return lines
    shown = ", ".join(f"{QUANTITIES[q].symbol} = {text}" for q, text in transition_texts(found))
    return [*lines, f"transition to gross slip: {shown}"]


def _checked(args) -> tuple[list[Path], float | str, list]:
    """The recordings, load and outputs ``(option, path)`` of the command, its options checked."""
    from ecofmaps.measured.synthetic import EXAMPLE, example_path

    if args.example == bool(args.files):
        raise CommandError("give one or more recording FILEs, or --example (not both)")
    paths = [example_path()] if args.example else [Path(name) for name in args.files]
    load = EXAMPLE["load"] if args.example and args.load is None else args.load
    if load is None:
        raise CommandError("--load is required: the normal load, e.g. --load 450N")
    named = {}  # a column's name: the first option naming it
    for option in ("--displacement-col", "--force-col", "--cycle-col"):
        if value := getattr(args, option[2:].replace("-", "_")):
            name = value.strip().lower()
            if named.setdefault(name, option) != option:
                raise CommandError(f"{named[name]} and {option} name the same column {name!r}")
    if args.resolved is not None and args.no_resolve:
        raise CommandError("--resolved writes the reading along the stroke; not --no-resolve")
    for option, what in (("--resolved", "the reading"), ("--report", "the page")):
        if getattr(args, option[2:]) is not None and len(paths) > 1:
            raise CommandError(f"{option} writes {what} of one recording: give one FILE")
    if args.scar_profile is not None and (len(paths) > 1 or args.no_resolve):
        raise CommandError(
            "--scar-profile is the scar of one recording, closed on its loops read along the "
            "stroke: give one FILE, without --no-resolve"
        )
    if args.scar_profile is None and common.contact(args) is not None:
        raise CommandError("--length or --sphere reads the wear on a --scar-profile: give it")
    if args.report is not None and missing_web_packages():
        raise CommandError(INSTALL_WEB)
    outputs = [("--out", args.out), ("--resolved", args.resolved), ("--report", args.report)]
    if args.plots is not None:
        kinds = ("loops", "evolution") + (() if args.no_resolve else ("resolved",))
        kinds += ("closure",) if args.scar_profile is not None else ()
        names = _plot_names(paths)
        outputs += [("--plots", Path(args.plots, f"{n}_{k}.png")) for n in names for k in kinds]
    inputs = [path for path in (*paths, args.scar_profile) if path is not None]
    folders = [("--plots", args.plots)]
    common.refuse_to_overwrite(outputs, inputs, overwrite=args.overwrite, folders=folders)
    return paths, load, outputs


class _NothingAnalysed(Exception):
    """No recording of a batch could be analysed."""


#: A recording analysed: its results and reading along the stroke, and the name of its plots.
_Analysed = collections.namedtuple("_Analysed", "path recording results resolved plot_name")


def _analyse_each(args, paths, load, long_run, table) -> tuple[list[_Analysed], list[Path]]:
    """Every recording analysed into ``table``; of several, one that fails is an error line."""
    from ecofmaps.io.recordings import read_recording

    done, failed = [], []
    for index, (path, plot_name) in enumerate(zip(paths, _plot_names(paths), strict=True)):
        held = []  # a recording in memory: its lines once its analysis has succeeded
        try:
            options = common.recording_options(args)
            options["load_column"] = load if isinstance(load, str) else None  # --load COLUMN
            # closed once analysed: the report reads only its names and units
            with read_recording(path, lazy=long_run.lazy, **options) as recording:
                write = table.write if recording.lazy else held.append
                results, resolved = _analysed(index, path, recording, load, args, long_run, write)
        except (ValueError, OSError, CommandError) as error:
            if len(paths) == 1:
                raise
            failed.append(path)
            named = option_names(str(error) if str(path) in str(error) else f"{path}: {error}")
            print(f"ecofmaps loops: error: {named}", file=sys.stderr)
            continue
        for text in held:
            table.write(text)
        done.append(_Analysed(path, recording, results, resolved, plot_name))
    return done, failed


def _write_extras(args, done: list[_Analysed], lab: dict, closure) -> None:
    """The plots, the reading along the stroke and the report the options ask for."""
    if args.plots is not None:
        from ecofmaps import figures  # matplotlib only when plots are asked for

        with common.made_folder(Path(args.plots)) as folder:  # none left empty behind
            for each in done:
                results, resolved, source = each.results, each.resolved, each.path.name
                drawn = {
                    "loops": figures.measured_loops(results, resolved=resolved, source=source),
                    "evolution": figures.cof_evolution(results, source=source),
                }
                if resolved is not None:
                    drawn["resolved"] = figures.resolved_loops(resolved, results, source=source)
                if closure is not None:
                    drawn["closure"] = figures.loop_scar_closure_figure(closure)
                for kind, figure in drawn.items():
                    path = folder / f"{each.plot_name}_{kind}.png"
                    figures.save_figure(figure, path, dpi=figures.RECORDING_DPI)
    if args.resolved is not None:
        from ecofmaps.maps.cache import write_netcdf

        write_netcdf(done[0].resolved, args.resolved)
    if args.report is not None:  # Bokeh loads only when a report is asked for
        from ecofmaps.web.report import recording_inputs, write_report

        mean_load = float(done[0].results["load"])  # the load given, or a channel's mean
        inputs = recording_inputs(done[0].recording, mean_load, flip_force=args.flip_force)
        write_report(args.report, done[0].results, inputs=inputs, lab=lab)


def run(args) -> int:
    """Run ``ecofmaps loops``: 0, or 1 when some of several recordings could not be analysed."""
    from ecofmaps.cli.loops_long import LongRun

    paths, load, outputs = _checked(args)
    scar = None if args.scar_profile is None else common.read_scar_file(args.scar_profile, "loops")
    long_run = LongRun(args, paths)
    try:
        with contextlib.ExitStack() as stack:  # the table is written as it comes, renamed last
            if args.out is None:  # held, and printed once every file is analysed
                stream = io.StringIO()
            else:
                temporary = stack.enter_context(atomic_path(args.out))
                stream = stack.enter_context(open(temporary, "w", encoding="utf-8", newline=""))
            done, failed = _analyse_each(args, paths, load, long_run, _Table(stream))
            if not done:  # nothing to write: the temporary goes
                raise _NothingAnalysed
            lab, closure = ({}, None) if scar is None else _scar_numbers(args, done[0], scar)
            _write_extras(args, done, lab, closure)
    except _NothingAnalysed:
        none = f"none of the {len(paths)} recordings could be analysed; nothing written"
        print(f"ecofmaps loops: {none}", file=sys.stderr)
        return 1
    with interrupts_deferred():  # the table is in place: a stop now would leave it unrecorded
        record_written(path for _, path in outputs if path is not None)
    if args.out is None:  # the table on standard output, the summaries on standard error
        sys.stdout.write(stream.getvalue())
        told, indent = sys.stderr, ""
    else:
        long_run.finish()
        written = sum(each.results.cycle.size for each in done)
        print(f"wrote {args.out}: {written} cycle{'' if written == 1 else 's'}")
        told, indent = sys.stdout, "  "
    said = [f"{name}: {text}" for name, text in lab.items()]
    for each in done:
        print(indent + _summary(each.path, each.results, each.recording), file=told)
        for line in [*_lab_lines(each.results, args.rig_stiffness), *said]:
            print(f"{indent}  {line}", file=told)
    if args.out is not None:
        if failed:
            print(f"  not analysed ({len(failed)}): " + ", ".join(str(path) for path in failed))
        extras = (("the loops read along the stroke", args.resolved), ("the report", args.report))
        for what, where in (*extras, ("plots", args.plots)):
            if where is not None:
                print(f"  {what} in {where}")
    return 1 if failed else 0
