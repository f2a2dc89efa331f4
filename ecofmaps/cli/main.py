"""The ``ecofmaps`` command.

Each subcommand is a pair of functions: ``_add_<name>(subparsers)`` declares its options
and ``_run_<name>(args)`` does the work through the public API. Quantities are read with
units (``50um``, ``35MN/m``); a bare number is SI. Errors in the input end the command
with exit status 2 and a one-line message, never a traceback.
"""

from __future__ import annotations

import argparse
import math
import sys
import textwrap
import time
import warnings
from pathlib import Path

from ecofmaps import RegimeWarning, __version__, model
from ecofmaps.units import parse_quantity, parse_values

__all__ = ["main"]

# The paper's Example 2 (Section 3 and Figure 5): the defaults of `ecofmaps model`.
EXAMPLE_2 = {
    "amplitude": 50e-6,
    "load": 450.0,
    "stiffness": 35e6,
    "mu": 0.8,
    "aspect_ratio": 0.2,
}


class CommandError(Exception):
    """A user error found after parsing (bad file, bad value): reported in one line."""


def quantity(kind: str):
    """An argparse ``type`` reading one quantity of ``kind`` with units (see ecofmaps.units)."""

    def parse(text: str) -> float:
        try:
            return parse_quantity(text, kind)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None

    parse.__name__ = kind
    return parse


def quantities(kind: str):
    """An argparse ``type`` reading a list ``a,b,c`` or a range ``start:stop:num``."""

    def parse(text: str):
        try:
            return parse_values(text, kind)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None

    parse.__name__ = kind
    return parse


# --- ecofmaps model ----------------------------------------------------------------------


def _add_model(subparsers) -> None:
    parser = subparsers.add_parser(
        "model",
        help="evaluate the model at one point (default: the paper's Example 2)",
        description=(
            "Evaluate the compliant wear-scar interaction model at one point and print "
            "the slip amplitude, peak force, dissipated energy, energy CoF and regime. "
            "Defaults are the paper's Example 2: amplitude 50um, load 450N, stiffness "
            "35MN/m, mu 0.8, aspect ratio 0.2."
        ),
    )
    parser.add_argument(
        "--amplitude", type=quantity("length"), default=EXAMPLE_2["amplitude"],
        help="displacement amplitude Δ* (default 50um)",
    )  # fmt: skip
    parser.add_argument(
        "--load", type=quantity("force"), default=EXAMPLE_2["load"],
        help="normal load P (default 450N)",
    )  # fmt: skip
    parser.add_argument(
        "--stiffness", type=quantity("stiffness"), default=EXAMPLE_2["stiffness"],
        help="rig stiffness S, 'inf' for a rigid rig (default 35MN/m)",
    )  # fmt: skip
    parser.add_argument(
        "--mu", type=quantity("dimensionless"), default=EXAMPLE_2["mu"],
        help="contact coefficient of friction μ (default 0.8)",
    )  # fmt: skip
    parser.add_argument(
        "--aspect-ratio", type=quantity("dimensionless"), default=EXAMPLE_2["aspect_ratio"],
        help="groove depth over half-width z_o/x_o (default 0.2)",
    )  # fmt: skip
    parser.add_argument(
        "--groove-half-width", type=quantity("length"), default=None,
        help="groove half-width x_o (default: the amplitude, as in the paper)",
    )  # fmt: skip
    parser.set_defaults(handler=_run_model)


def _run_model(args) -> int:
    point = dict(
        amplitude=args.amplitude,
        load=args.load,
        stiffness=args.stiffness,
        mu=args.mu,
        aspect_ratio=args.aspect_ratio,
        groove_half_width=args.groove_half_width,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RegimeWarning)
        code = model.Regime(int(model.regime(**point)))
        slip = float(model.slip_amplitude(**point))
        peak = float(model.max_force(**point))
        energy = float(model.dissipated_energy(**point))
        ecof = float(model.energy_cof(**point))
    half_width = args.amplitude if args.groove_half_width is None else args.groove_half_width
    stiffness = "inf (rigid)" if math.isinf(args.stiffness) else f"{args.stiffness / 1e6:.6g} MN/m"
    rows = [
        ("displacement amplitude", "Δ*", f"{args.amplitude * 1e6:.6g} µm"),
        ("normal load", "P", f"{args.load:.6g} N"),
        ("rig stiffness", "S", stiffness),
        ("contact CoF", "μ", f"{args.mu:.6g}"),
        ("groove aspect ratio", "z_o/x_o", f"{args.aspect_ratio:.6g}"),
        ("groove half-width", "x_o", f"{half_width * 1e6:.6g} µm"),
        None,
        ("regime", "", code.name.lower().replace("_", " ")),
        ("slip amplitude", "δ*", f"{slip * 1e6:.6g} µm"),
        ("peak tangential force", "Q*", f"{peak:.6g} N"),
        ("dissipated energy", "E_d", f"{energy * 1e3:.6g} mJ"),
        ("energy CoF", "μ_E", f"{ecof:.6g}" if math.isfinite(ecof) else "undefined"),
        ("ECoF / contact CoF", "μ_E/μ", f"{ecof / args.mu:.6g}" if math.isfinite(ecof) else ""),
    ]
    print(f"ecofmaps {__version__}: compliant wear-scar interaction model")
    for row in rows:
        print("" if row is None else f"  {row[0]:<24} {row[1]:<8} {row[2]}")
    return 0


# --- ecofmaps figures --------------------------------------------------------------------

FIGURE_FORMATS = ("png", "pdf", "svg")


def figure_formats(text: str) -> tuple[str, ...]:
    """An argparse ``type`` reading a comma-separated list of figure file formats."""
    formats = tuple(dict.fromkeys(item.strip().lower() for item in text.split(",")))
    unknown = [item for item in formats if item not in FIGURE_FORMATS]
    if unknown or not formats:
        raise argparse.ArgumentTypeError(
            f"unknown figure format {', '.join(map(repr, unknown))} in {text!r}; "
            f"give one or more of {', '.join(FIGURE_FORMATS)}, comma-separated"
        )
    return formats


def _add_figures(subparsers) -> None:
    from ecofmaps.figures import FIGURES

    listing = "\n".join(f"  {name:<10} {recipe.description}" for name, recipe in FIGURES.items())
    parser = subparsers.add_parser(
        "figures",
        help="write the paper's Figures 5-8 and 11 and the universal map (default: figures/)",
        description=textwrap.fill(
            "Write the paper's Figures 5, 6, 7a, 7b, 8, 11a, 11b and the universal map of "
            "the ECoF ratio, one file per figure and format (fig5.png, ...). Parameters are "
            "the paper's: amplitude 50um (= groove half-width), load 450N, stiffness 35MN/m, "
            "mu 0.8. Maps are read from the cache when there (see ECOFMAPS_CACHE) and stored "
            "there otherwise; files are written atomically. Progress goes to stderr.",
            width=80,
        ),
        epilog=f"figures:\n{listing}",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--out", default="figures", metavar="DIR",
        help="directory to write into, created if missing (default: figures)",
    )  # fmt: skip
    parser.add_argument(
        "--only", nargs="+", choices=list(FIGURES), metavar="NAME",
        help=f"write only these figures; NAME is one of: {', '.join(FIGURES)}",
    )  # fmt: skip
    parser.add_argument(
        "--format", type=figure_formats, default=("png",), metavar="FORMATS",
        help="comma-separated file formats among png, pdf, svg (default: png)",
    )  # fmt: skip
    parser.set_defaults(handler=_run_figures)


def _run_figures(args) -> int:
    from ecofmaps.figures import FIGURES, make_figures, save_figure

    names = list(dict.fromkeys(args.only or FIGURES))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(
        f"ecofmaps figures: {len(names)} figure(s) as {', '.join(args.format)} into {out}",
        file=sys.stderr,
    )
    begin = start = time.perf_counter()
    for index, (name, figure) in enumerate(make_figures(names), start=1):
        paths = [save_figure(figure, out / f"{name}.{suffix}") for suffix in args.format]
        now = time.perf_counter()
        print(
            f"  [{index}/{len(names)}] {name:<10} {now - start:5.1f} s  "
            + ", ".join(str(path) for path in paths),
            file=sys.stderr,
        )
        start = now
    print(f"done in {time.perf_counter() - begin:.1f} s", file=sys.stderr)
    return 0


# --- ecofmaps map ------------------------------------------------------------------------

_GRID_HELP = "; one value, a list or a range start:stop:num"


def _add_map(subparsers) -> None:
    parser = subparsers.add_parser(
        "map",
        help="compute the model over a grid of test conditions into a netCDF file",
        description=textwrap.fill(
            "Compute the steady-loop quantities of the model (slip amplitude and slip ratio, "
            "energy CoF and its ratio to mu, compliance ratio P/(S*amplitude), regime, and "
            "with --load the dissipated energy and peak force) over a grid, and write them "
            "as an xarray Dataset to a netCDF file (atomically: an existing file is replaced "
            "only once the new one is complete). The groove half-width equals the amplitude, "
            "as in the paper. Each of --stiffness-ratio, --aspect-ratio, --amplitude and --mu "
            "takes one value (a scalar coordinate of the result), a comma-separated list or a "
            "range start:stop:num (num evenly spaced points, both ends included); each list or "
            "range is a dimension, in this order. Values take units (50um, 0.08/um, 450N); a "
            "bare number is SI. Results are kept in the cache (see 'ecofmaps cache') unless "
            "--no-cache.",
            width=80,
        ),
        epilog=(
            "example (the grid of Figure 11):\n  ecofmaps map --stiffness-ratio 0.01/um:0.3/um:30 "
            "--aspect-ratio 0:0.3:31 \\\n      --amplitude 25um,50um --mu 0.8 --load 450N "
            "--out fig11.nc"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--stiffness-ratio", type=quantities("stiffness_ratio"), required=True, metavar="S/P",
        help="rig stiffness over normal load S/P [1/m], 'inf' for a rigid rig" + _GRID_HELP,
    )  # fmt: skip
    parser.add_argument(
        "--aspect-ratio", type=quantities("dimensionless"), required=True, metavar="Z/X",
        help="groove depth over half-width z_o/x_o (>= 0)" + _GRID_HELP,
    )  # fmt: skip
    parser.add_argument(
        "--amplitude", type=quantities("length"), required=True, metavar="DELTA",
        help="displacement amplitude Δ* [m], e.g. 25um,50um" + _GRID_HELP,
    )  # fmt: skip
    parser.add_argument(
        "--mu", type=quantities("dimensionless"), required=True, metavar="MU",
        help="contact coefficient of friction μ (> 0)" + _GRID_HELP,
    )  # fmt: skip
    parser.add_argument(
        "--load", type=quantity("force"), default=None, metavar="P",
        help="normal load P [N], one value; adds dissipated_energy [J] and max_force [N]",
    )  # fmt: skip
    parser.add_argument(
        "--out", required=True, metavar="FILE.nc",
        help="netCDF file to write (its directory must exist)",
    )  # fmt: skip
    parser.add_argument(
        "--no-cache", action="store_true",
        help="compute afresh and do not store the result in the cache",
    )  # fmt: skip
    parser.add_argument(
        "--cache-dir", default=None, metavar="DIR",
        help="cache directory (default: $ECOFMAPS_CACHE, else the per-user cache directory)",
    )  # fmt: skip
    parser.set_defaults(handler=_run_map)


def _run_map(args) -> int:
    from ecofmaps.maps.cache import write_netcdf
    from ecofmaps.maps.grid import compute_map

    out = Path(args.out)
    if not out.parent.is_dir():
        raise CommandError(f"cannot write {out}: the directory {out.parent} does not exist")
    grid = {
        name: values[0] if values.size == 1 else values
        for name, values in (
            ("stiffness_ratio", args.stiffness_ratio),
            ("aspect_ratio", args.aspect_ratio),
            ("amplitude", args.amplitude),
            ("mu", args.mu),
        )
    }
    dataset = compute_map(**grid, load=args.load, cache=not args.no_cache, cache_dir=args.cache_dir)
    write_netcdf(dataset, out)
    shape = " x ".join(f"{size} {dim}" for dim, size in dataset.sizes.items()) or "1 point"
    regimes = ", ".join(
        f"{code.name.lower().replace('_', ' ')} {count}"
        for code in model.Regime
        if (count := int((dataset.regime == code).sum()))
    )
    print(f"wrote {out}: {shape}")
    print(f"  regimes: {regimes}")
    if math.isfinite(low := float(dataset.ecof_ratio.min())):  # NaN-skipping
        print(f"  ECoF / contact CoF: {low:.6g} to {float(dataset.ecof_ratio.max()):.6g}")
    return 0


# --- ecofmaps cache ----------------------------------------------------------------------


def _size(count: int) -> str:
    """A byte count for people: 512 B, 12.3 kB, 4.5 MB."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if count >= scale:
            return f"{count / scale:.1f} {unit}"
    return f"{count} B"


def _add_cache(subparsers) -> None:
    parser = subparsers.add_parser(
        "cache",
        help="list or clear the cache of computed maps",
        description=textwrap.fill(
            "Computed maps are kept as netCDF files, one per grid and package version, in the "
            "directory given by --cache-dir, else the ECOFMAPS_CACHE environment variable, "
            "else the per-user cache directory. 'list' shows them with their sizes; 'clear' "
            "removes them (and temporary files of interrupted writes; other files are left "
            "alone).",
            width=80,
        ),
    )
    actions = parser.add_subparsers(title="actions", metavar="ACTION", required=True)
    for name, handler, text in (
        ("list", _run_cache_list, "list the cached maps with their sizes"),
        ("clear", _run_cache_clear, "remove every cached map"),
    ):
        action = actions.add_parser(name, help=text, description=text + ".")
        action.add_argument(
            "--cache-dir", default=None, metavar="DIR",
            help="cache directory (default: $ECOFMAPS_CACHE, else the per-user cache directory)",
        )  # fmt: skip
        action.set_defaults(handler=handler)


def _run_cache_list(args) -> int:
    from ecofmaps.maps.cache import cache_directory, cache_entries

    directory = cache_directory(args.cache_dir)
    entries = cache_entries(directory)
    if not entries:
        print(f"no cached maps in {directory}")
        return 0
    print(f"cached maps in {directory}:")
    for entry in entries:
        modified = entry.modified.astimezone().strftime("%Y-%m-%d %H:%M:%S")
        print(f"  {_size(entry.size):>9}  {modified}  {entry.path.name}")
    total = sum(entry.size for entry in entries)
    print(f"{len(entries)} file(s), {_size(total)}")
    return 0


def _run_cache_clear(args) -> int:
    from ecofmaps.maps.cache import cache_directory, clear_cache

    directory = cache_directory(args.cache_dir)
    count, size = clear_cache(directory)
    print(f"removed {count} file(s), {_size(size)}, from {directory}")
    return 0


# --- ecofmaps loops ----------------------------------------------------------------------


def _add_loops(subparsers) -> None:
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
        "--load", type=quantity("force"), default=None, metavar="P",
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
        "--displacement-unit", default="um", metavar="UNIT",
        help="unit of the displacement column (default: um)",
    )  # fmt: skip
    parser.add_argument(
        "--force-unit", default="N", metavar="UNIT",
        help="unit of the force column (default: N)",
    )  # fmt: skip
    parser.set_defaults(handler=_run_loops)


def _plot_names(paths) -> list[str]:
    """A distinct file-name stem for each recording's plots."""
    stems = [path.stem for path in paths]
    return [
        stem if stems.count(stem) == 1 else f"{stem}_{index}"
        for index, stem in enumerate(stems, start=1)
    ]


def _run_loops(args) -> int:
    import pandas as pd

    from ecofmaps.io.recordings import RecordingError, read_recording, results_table, write_text
    from ecofmaps.measured.analysis import analyze_loops
    from ecofmaps.measured.synthetic import EXAMPLE, example_path

    if args.example == bool(args.files):
        raise CommandError("give one or more recording FILEs, or --example (not both)")
    paths = [example_path()] if args.example else [Path(name) for name in args.files]
    load = EXAMPLE["load"] if args.example and args.load is None else args.load
    if load is None:
        raise CommandError("--load is required: the normal load, e.g. --load 450N")
    if not load > 0.0:
        raise CommandError(f"--load must be > 0 N; got {load:g} N")
    if args.out is not None and not Path(args.out).parent.is_dir():
        raise CommandError(f"cannot write {args.out}: its directory does not exist")
    analyses = []
    for path in paths:
        recording = read_recording(
            path,
            displacement_column=args.displacement_col,
            force_column=args.force_col,
            cycle_column=args.cycle_col,
            displacement_unit=args.displacement_unit,
            force_unit=args.force_unit,
        )
        try:
            results = analyze_loops(
                recording.displacement,
                recording.force,
                load,
                cycle=recording.cycle,
                keep_loops=args.plots is not None,
            )
        except ValueError as error:
            raise RecordingError(path, recording.last_line, str(error)) from None
        analyses.append(results)
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
    print(f"wrote {args.out}: {sum(len(table) for table in tables)} cycles")
    for path, results in zip(paths, analyses, strict=True):
        gross = results.where(results.regime == "gross slip", drop=True)
        summary = f"  {path.name}: {results.cycle.size} cycles"
        if results.attrs["incomplete_cycles"]:
            summary += f" ({results.attrs['incomplete_cycles']} incomplete dropped)"
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


# --- ecofmaps correct --------------------------------------------------------------------

_POINT_OPTIONS = ("ecof", "amplitude", "load", "stiffness")


def _add_correct(subparsers) -> None:
    parser = subparsers.add_parser(
        "correct",
        help="correct reported ECoF values to the contact CoF (one point or a CSV table)",
        description=(
            "Correct a reported energy coefficient of friction μ_E to the contact CoF μ the "
            "model puts behind it, given the test's amplitude, load and rig stiffness and the "
            "wear scar's depth over half-width z_o/x_o = D/W (eq. 11; x_o = Δ*). One point: "
            "--ecof --amplitude --load --stiffness and --aspect-ratio (or --scar-depth and "
            "--scar-half-width). A table: TABLE.csv with columns ecof, amplitude_um, load_N, "
            "stiffness_MN_per_m and aspect_ratio or scar_depth_um + scar_half_width_um; the "
            "output keeps every column and adds mu, correction_factor and regime. A bad row "
            "stops the run, naming the file and line (the header is line 1); nothing is "
            "written then."
        ),
    )
    parser.add_argument("table", nargs="?", metavar="TABLE", help="CSV table of reported ECoFs")
    parser.add_argument(
        "--out", metavar="OUT", default=None,
        help="write the corrected table here (CSV; default: standard output)",
    )  # fmt: skip
    parser.add_argument(
        "--ecof", type=quantity("dimensionless"), help="reported energy CoF μ_E, e.g. 0.83"
    )
    parser.add_argument(
        "--amplitude", type=quantity("length"), help="displacement amplitude Δ*, e.g. 50um"
    )
    parser.add_argument("--load", type=quantity("force"), help="normal load P, e.g. 450N")
    parser.add_argument(
        "--stiffness", type=quantity("stiffness"),
        help="rig stiffness S, e.g. 35MN/m ('inf' for a rigid rig)",
    )  # fmt: skip
    parser.add_argument(
        "--aspect-ratio", type=quantity("dimensionless"),
        help="wear scar depth over half-width z_o/x_o = D/W, e.g. 0.2",
    )  # fmt: skip
    parser.add_argument("--scar-depth", type=quantity("length"), help="scar depth D, e.g. 8um")
    parser.add_argument(
        "--scar-half-width", type=quantity("length"), help="scar half-width W, e.g. 40um"
    )
    parser.set_defaults(handler=_run_correct)


def _run_correct(args) -> int:
    from ecofmaps.correction.inversion import correct_ecof
    from ecofmaps.correction.tables import correct_table
    from ecofmaps.io.recordings import write_text

    given = [name for name in (*_POINT_OPTIONS, "aspect_ratio", "scar_depth", "scar_half_width")
             if getattr(args, name) is not None]  # fmt: skip
    if args.table is not None:
        if given:
            options = ", ".join("--" + name.replace("_", "-") for name in given)
            raise CommandError(f"give a TABLE or one point's options, not both ({options})")
        if args.out is not None and not Path(args.out).parent.is_dir():
            raise CommandError(f"cannot write {args.out}: its directory does not exist")
        text, rows = correct_table(args.table)
        if args.out is None:
            sys.stdout.write(text)
            return 0
        write_text(args.out, text)
        print(f"wrote {args.out}: {rows} rows corrected")
        return 0
    if args.out is not None:
        raise CommandError("--out writes a corrected TABLE; give the TABLE too")
    missing = ["--" + name for name in _POINT_OPTIONS if getattr(args, name) is None]
    if missing:
        raise CommandError(f"give {', '.join(missing)} (or a TABLE)")
    scar = [value is not None for value in (args.scar_depth, args.scar_half_width)]
    if (args.aspect_ratio is not None) == any(scar) or any(scar) != all(scar):
        raise CommandError("give --aspect-ratio, or both --scar-depth and --scar-half-width")
    point = dict(amplitude=args.amplitude, load=args.load, stiffness=args.stiffness)
    if args.aspect_ratio is not None:
        ratio = args.aspect_ratio
        ratio_text = f"{ratio:.6g}"
    else:
        ratio = args.scar_depth / args.scar_half_width
        ratio_text = (
            f"{ratio:.6g} (scar {args.scar_depth * 1e6:.6g} µm deep, "
            f"{args.scar_half_width * 1e6:.6g} µm half-width)"
        )
    mu = float(correct_ecof(args.ecof, **point, aspect_ratio=ratio))
    code = model.Regime(int(model.regime(**point, mu=mu, aspect_ratio=ratio)))
    stiffness = "inf (rigid)" if math.isinf(args.stiffness) else f"{args.stiffness / 1e6:.6g} MN/m"
    rows = [
        ("energy CoF (reported)", "μ_E", f"{args.ecof:.6g}"),
        ("displacement amplitude", "Δ*", f"{args.amplitude * 1e6:.6g} µm"),
        ("normal load", "P", f"{args.load:.6g} N"),
        ("rig stiffness", "S", stiffness),
        ("groove aspect ratio", "z_o/x_o", ratio_text),
        None,
        ("regime", "", code.name.lower().replace("_", " ")),
        ("contact CoF", "μ", f"{mu:.6g}"),
        ("correction factor", "μ/μ_E", f"{mu / args.ecof:.6g}"),
    ]
    print(f"ecofmaps {__version__}: reported ECoF corrected to the contact CoF (x_o = Δ*)")
    for row in rows:
        print("" if row is None else f"  {row[0]:<24} {row[1]:<8} {row[2]}")
    return 0


# --- the command -------------------------------------------------------------------------

_SUBCOMMANDS = (_add_model, _add_figures, _add_map, _add_cache, _add_loops, _add_correct)


def build_parser() -> argparse.ArgumentParser:
    """The ``ecofmaps`` argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="ecofmaps",
        description=(
            "Fretting friction maps: how far the energy coefficient of friction drifts "
            "from the contact one with rig stiffness and wear-scar shape, the paper's "
            "figures, corrections of reported ECoF values, and the per-cycle analysis of "
            "measured loops (ECoF, GICoF, rig stiffness). Quantities take units: 50um, "
            "450N, 35MN/m."
        ),
    )
    parser.add_argument("--version", action="version", version=f"ecofmaps {__version__}")
    subparsers = parser.add_subparsers(title="commands", metavar="COMMAND", required=True)
    for add in _SUBCOMMANDS:
        add(subparsers)
    return parser


def main(argv=None) -> int:
    """Run the ``ecofmaps`` command; return its exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.handler(args)
    except (CommandError, ValueError, OSError) as error:
        print(f"{parser.prog}: error: {error}", file=sys.stderr)
        return 2
