"""``ecofmaps loops``: analyse recorded fretting loops cycle by cycle."""

from __future__ import annotations

import argparse
import textwrap

from ecofmaps._parallel import worker_limit
from ecofmaps.cli._common import quantity, unit

__all__ = ["add"]


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "loops",
        help="analyse recorded fretting loops cycle by cycle: ECoF, GICoF, stiffness, ...",
        description=textwrap.fill(
            "Read recordings of fretting loops (text with a header line in any common "
            "dialect, TDMS, HDF5/netCDF-4 or zarr), cut them into cycles at the displacement "
            "reversals or by a cycle column, check every loop, and write one row per cycle: "
            "cycle, amplitude_um, slip_amplitude_um, normal_load_N (with a recorded load, "
            "--load COLUMN), max_force_N, dissipated_energy_mJ, ecof, "
            "cof_max, energy_ratio, stiffness_MN_per_m, gicof, regime, then mu_resolved, "
            "mu_resolved_se and aspect_ratio (friction and groove read along the whole "
            "stroke) and quality ('ok', or why values are NaN); first a file column when "
            "several files are given. The columns are found by name as rigs write them "
            "(displacement, disp, delta, stroke, ...; force, Fx, Ft, Q, friction, ...) with "
            "units from their names or the file, else um and N, and an optional 'cycle'. "
            "With several files, one that cannot be analysed is one error line naming it and "
            "the others are written (exit status 1); files are written atomically and never "
            "over an input or a file ecofmaps did not write. --example "
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
        "--load", type=_load_or_column, default=None, metavar="P",
        help="normal load P, e.g. 450N; or the name of the recording's normal-load column "
        "(e.g. Fz), used sample by sample (required unless --example)",
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
        "--overwrite", action="store_true",
        help="replace the outputs ecofmaps wrote before (--out, --resolved, the plots in "
        "--plots); a file or folder ecofmaps did not write is never replaced",
    )  # fmt: skip
    parser.add_argument(
        "--resolved", default=None, metavar="FILE.nc",
        help="also write the loops read along the stroke (one FILE): μ(ξ), the groove slope "
        "g(ξ) and the felt profile h(ξ) over (cycle, position), a netCDF file",
    )  # fmt: skip
    parser.add_argument(
        "--report", default=None, metavar="FILE.html",
        help="also write the results of one recording as one HTML page that opens offline: "
        "the friction over the cycles with the quality flags, picked loops with the model's, "
        'the table (needs pip install "ecofmaps[web]")',
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
    _add_column_options(parser)
    add_long_options(parser)
    parser.set_defaults(handler="ecofmaps.cli.loops_run:run")  # imported when it runs


def _add_column_options(parser) -> None:
    """The options that say where the recording's columns are and in which units."""
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
        "--skip-rows", type=int, default=None, metavar="N",
        help="lines of a text file to skip before its header line (default: metadata "
        "lines before the header are found)",
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


def _workers(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number of workers >= 1")
    limit, why = worker_limit(processes=True)
    if value > limit:
        raise argparse.ArgumentTypeError(f"{value} is more than this machine can run: {why}")
    return value


def add_long_options(parser) -> None:
    """The options of long runs, for ``ecofmaps loops``."""
    group = parser.add_argument_group(
        "long tests",
        "a rig file of more than 2**24 samples is analysed out of core, a block of whole "
        "cycles at a time (the numbers are those of the analysis in memory)",
    )
    group.add_argument(
        "--nan-policy", choices=("skip", "raise"), default="skip",
        help="a cycle with a missing sample (NaN or an empty cell) is skipped and counted "
        "(skip, the default), or any missing sample stops the command naming its line",
    )  # fmt: skip
    group.add_argument(
        "--workers", type=_workers, default=None, metavar="N",
        help="analyse out of core on a local dask cluster of N processes",
    )  # fmt: skip
    group.add_argument(
        "--scheduler", default=None, metavar="ADDRESS",
        help="analyse out of core on the dask cluster at ADDRESS (tcp://host:8786); its "
        "workers must have ecofmaps and see the files at the same paths",
    )  # fmt: skip
    group.add_argument(
        "--resume", action="store_true",
        help="continue an interrupted run from the blocks kept in <out>.partial/ (needs "
        "--out and the same files and options)",
    )  # fmt: skip
    group.add_argument(
        "--quiet", action="store_true", help="no progress bar (none is shown off a terminal)",
    )  # fmt: skip


def _load_or_column(text: str):
    """``--load``: a load with its unit (a float, [N]), or the name of a column (a str)."""
    try:
        return quantity("load")(text)
    except argparse.ArgumentTypeError:
        name = text.strip()
        try:
            float(name.split()[0] if name else "x")
        except ValueError:  # not a number at all (inf and nan are numbers): a column's name
            if name and not name[0].isdigit() and not name.startswith(("-", "+", ".")):
                return name  # a column of the recording, e.g. Fz
        raise
