"""``ecofmaps map``: the model over a grid of test conditions, into a netCDF file."""

from __future__ import annotations

import argparse
import math
import sys
import textwrap
from pathlib import Path

import numpy as np

from ecofmaps.cli._common import CommandError, quantities, quantity

__all__ = ["add", "run"]

_GRID_HELP = "; one value, a list or a range start:stop:num"


def add(subparsers) -> None:
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
    parser.set_defaults(handler=run)


def run(args) -> int:
    from ecofmaps.maps.cache import write_netcdf
    from ecofmaps.maps.grid import compute_map
    from ecofmaps.model import Regime

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
    points = math.prod(values.size for values in grid.values() if np.ndim(values))
    print(f"ecofmaps map: {points:,} points into {out}", file=sys.stderr, flush=True)
    dataset = compute_map(**grid, load=args.load, cache=not args.no_cache, cache_dir=args.cache_dir)
    write_netcdf(dataset, out)
    shape = " x ".join(f"{size} {dim}" for dim, size in dataset.sizes.items()) or "1 point"
    regimes = ", ".join(
        f"{code.label} {count}" for code in Regime if (count := int((dataset.regime == code).sum()))
    )
    print(f"wrote {out}: {shape}")
    print(f"  regimes: {regimes}")
    if math.isfinite(low := float(dataset.ecof_ratio.min())):  # NaN-skipping
        print(f"  ECoF / contact CoF: {low:.6g} to {float(dataset.ecof_ratio.max()):.6g}")
    return 0
