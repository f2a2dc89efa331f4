"""``ecofmaps map``: the model over a grid of test conditions, into a netCDF file or zarr store.

A grid of more than ``--chunk-points`` points, and any grid written to a zarr store, is
computed block by block straight into the output (:func:`ecofmaps.maps.write_map`), with a
progress bar on a terminal; a smaller one is computed at once (not cached: it computes
faster than the cache would read it back).
Before any work the command states the map's size (points, bytes) and refuses one that
would not fit on the output's disk, or, computed at once, in memory
(:func:`ecofmaps.maps.compute_map` refuses that).
"""

from __future__ import annotations

import argparse
import math
import textwrap

from ecofmaps.cli._common import quantities, quantity

__all__ = ["add"]

_GRID_HELP = "; one value, a list or a range start:stop:num"
#: Default of --chunk-points: blocks of 2**22 points (about 220 MB of results with a load).
_CHUNK_POINTS = 2**22


def _points(text: str) -> int:
    """An argparse ``type``: a whole number of points >= 1 (``4194304``, ``4e6``)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value.is_integer() and value >= 1):
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number of points >= 1")
    return int(value)


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "map",
        help="compute the model over a grid of test conditions into a netCDF file or zarr store",
        description=textwrap.fill(
            "Compute the steady-loop quantities of the model (slip amplitude and slip ratio, "
            "energy CoF and its ratio to mu, compliance ratio P/(S*amplitude), regime, and "
            "with --load the dissipated energy and peak force) over a grid, and write them "
            "as an xarray Dataset to a netCDF file, or to a zarr store if --out ends in .zarr "
            "(atomically; an existing output is replaced only with --overwrite, if ecofmaps "
            "wrote it, and only once the new one is complete). The map's size is printed "
            "first, and a map that would not fit on the disk is refused. "
            "The groove half-width equals the amplitude, "
            "as in the paper. Each of --stiffness-ratio, --aspect-ratio, --amplitude and --mu "
            "takes one value (a scalar coordinate of the result), a comma-separated list or a "
            "range start:stop:num (num evenly spaced points, both ends included); each list or "
            "range is a dimension, in this order. Values take units (50um, 0.08/um, 450N); a "
            "bare number is SI. A grid of more than --chunk-points points, and any zarr "
            "store, is computed block by block straight into the output, with a few blocks "
            "in memory at a time (grids far beyond memory work), and a progress bar on a "
            "terminal. The map is not cached: it computes faster than the cache would read "
            "it back, and --out keeps it.",
            width=80,
        ),
        epilog=(
            "example (the grid of Figure 11):\n  ecofmaps map --stiffness-ratio 0.01/um:0.3/um:30 "
            "--aspect-ratio 0:0.3:31 \\\n      --amplitude 25um,50um --mu 0.8 --load 450N "
            "--out fig11.nc\n"
            "a billion points, block by block into a zarr store:\n"
            "  ecofmaps map --stiffness-ratio 0.01/um:0.3/um:25000 --aspect-ratio 0:0.4:20000 "
            "\\\n      --amplitude 25um,50um --mu 0.8 --out big.zarr"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--stiffness-ratio", type=quantities("stiffness_ratio"), required=True, metavar="S/P",
        help="rig stiffness over normal load S/P [1/m], 'inf' for a rigid rig" + _GRID_HELP,
    )  # fmt: skip
    parser.add_argument(
        "--aspect-ratio", type=quantities("aspect_ratio"), required=True, metavar="Z/X",
        help="groove depth over half-width z_o/x_o (>= 0)" + _GRID_HELP,
    )  # fmt: skip
    parser.add_argument(
        "--amplitude", type=quantities("amplitude"), required=True, metavar="DELTA",
        help="displacement amplitude Δ* [m], e.g. 25um,50um" + _GRID_HELP,
    )  # fmt: skip
    parser.add_argument(
        "--mu", type=quantities("mu"), required=True, metavar="MU",
        help="contact coefficient of friction μ (> 0)" + _GRID_HELP,
    )  # fmt: skip
    parser.add_argument(
        "--load", type=quantity("load"), default=None, metavar="P",
        help="normal load P [N], one value; adds dissipated_energy [J] and max_force [N]",
    )  # fmt: skip
    parser.add_argument(
        "--out", required=True, metavar="FILE.nc|FILE.zarr",
        help="netCDF file, or zarr store if the name ends in .zarr, to write (its directory "
        "must exist)",
    )  # fmt: skip
    parser.add_argument(
        "--overwrite", action="store_true",
        help="replace --out if it exists and ecofmaps wrote it (once the new map is complete)",
    )  # fmt: skip
    parser.add_argument(
        "--chunk-points", type=_points, default=_CHUNK_POINTS, metavar="N",
        help=f"grid points per block (default {_CHUNK_POINTS}); a larger grid is computed "
        "block by block into --out",
    )  # fmt: skip
    parser.add_argument(
        "--quiet", action="store_true",
        help="no progress bar (there is none either when standard error is not a terminal)",
    )  # fmt: skip
    parser.add_argument(
        "--no-cache", action="store_true",
        help="do not read or store the result in the cache (a map of the parabolic groove "
        "is not cached anyway: kept for scripts that give it)",
    )  # fmt: skip
    parser.add_argument(
        "--cache-dir", default=None, metavar="DIR",
        help="cache directory (default: $ECOFMAPS_CACHE, else the per-user cache directory)",
    )  # fmt: skip
    parser.set_defaults(handler="ecofmaps.cli.map_run:run")  # imported when it runs
