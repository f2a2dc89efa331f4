"""``ecofmaps map``: the model over a grid of test conditions, into a netCDF file or zarr store
(block by block through :func:`ecofmaps.maps.write_map` past ``--chunk-points`` or to zarr)."""

from __future__ import annotations

import contextlib
import itertools
import math
import shutil
import sys
from pathlib import Path

import numpy as np

from ecofmaps.cli import common
from ecofmaps.cli.main import CommandError
from ecofmaps.io.files import record_written

#: The grid's axes, in the order of the map's dimensions, and their metavars.
_AXES = {"stiffness_ratio": "S/P", "aspect_ratio": "Z/X", "amplitude": "DELTA", "mu": "MU"}
_HELP = {
    "--stiffness-ratio": "rig stiffness over normal load S/P [1/m], inf for a rigid rig",
    "--aspect-ratio": "groove depth over half-width z_o/x_o (>= 0)",
    "--amplitude": "displacement amplitude Δ* [m], e.g. 25um,50um",
    "--mu": "contact coefficient of friction μ (> 0)",
    "--load": "normal load P [N], one value; adds dissipated_energy [J] and max_force [N]",
    "--out": "netCDF file, or zarr store if it ends in .zarr, to write (its directory must exist)",
    "--chunk-points": "grid points per block computed into --out (default %(default)s)",
    "--no-cache": "do not use the cache (no map of the parabolic groove is cached: for scripts)",
}


def add(subparsers) -> None:
    parser = common.command_parser(
        subparsers,
        "map",
        help="compute the model over a grid of test conditions into a netCDF file or zarr store",
        description="Compute the model's steady-loop quantities (slip amplitude and ratio, energy "
        "CoF and its ratio to mu, compliance ratio P/(S*amplitude), regime; with --load the "
        "dissipated energy and peak force) over a grid into an xarray Dataset in --out, "
        "atomically, its size printed first (refused if the disk cannot hold it). The groove "
        "half-width is the amplitude. Each grid option takes one value (a scalar coordinate), a "
        "list a,b,c or a range start:stop:num (num points, ends included) (a dimension, in this "
        "order), with units (50um, 0.08/um); a bare number is SI. A zarr store, or more than "
        "--chunk-points points, is computed block by block, a few in memory. Maps are not cached.",
        epilog="example (the grid of Figure 11):\n  ecofmaps map "
        "--stiffness-ratio 0.01/um:0.3/um:30 --aspect-ratio 0:0.3:31 \\\n      --amplitude "
        "25um,50um --mu 0.8 --load 450N --out fig11.nc\n"
        "a billion points, block by block into a zarr store:\n"
        "  ecofmaps map --stiffness-ratio 0.01/um:0.3/um:25000 --aspect-ratio 0:0.4:20000 "
        "\\\n      --amplitude 25um,50um --mu 0.8 --out big.zarr",
    )
    option = common.option_adder(parser, _HELP)
    for name, metavar in _AXES.items():
        values = common.quantity(name, grid=True)
        option(f"--{name.replace('_', '-')}", type=values, required=True, metavar=metavar)
    option("--load", type=common.quantity("load"), metavar="P")
    option("--out", required=True, metavar="FILE.nc|FILE.zarr")
    option("--overwrite", action="store_true")
    # blocks of 2**22 points by default: about 220 MB of results with a load
    option("--chunk-points", type=common.count("points"), default=2**22, metavar="N")
    option("--quiet", action="store_true")
    option("--no-cache", action="store_true")
    option("--cache-dir", metavar="DIR")


def run(args) -> int:
    from ecofmaps.maps.files import ZARR_SUFFIX, write_map
    from ecofmaps.maps.grid import compute_map
    from ecofmaps.model import Regime

    out = Path(args.out)
    common.refuse_to_overwrite([("--out", out)], [], overwrite=args.overwrite)
    grid = {name: getattr(args, name) for name in _AXES}
    grid = {name: values[0] if values.size == 1 else values for name, values in grid.items()}
    points = math.prod(values.size for values in grid.values() if np.ndim(values))
    size = _map_bytes(grid, args.load)
    free = shutil.disk_usage(out.parent).free
    print(
        f"ecofmaps map: {points:,} points, {common.byte_size(size)} into {out} "
        f"({common.byte_size(free)} free there)",
        flush=True,  # before the summary, also when the two streams are read apart
    )
    if size > free:
        raise CommandError(
            f"--out {out}: the map of {points:.3g} points needs up to {common.byte_size(size)} on "
            f"disk, more than the {common.byte_size(free)} free in {out.parent.resolve()}: use a "
            "smaller grid or another disk"
        )
    chunked = out.suffix == ZARR_SUFFIX or points > args.chunk_points
    options = {"cache": False if args.no_cache else None, "cache_dir": args.cache_dir}
    if chunked:
        options = {"chunks": args.chunk_points}  # else refused if it would not fit in memory
    dataset = compute_map(**grid, load=args.load, **options)
    summary = [(dataset.regime == code).sum().data for code in Regime]
    summary += [dataset.ecof_ratio.min().data, dataset.ecof_ratio.max().data]
    shown = chunked and not args.quiet and sys.stderr.isatty()  # a progress bar
    with _progress(dataset) if shown else contextlib.nullcontext():
        *counts, low, high = write_map(dataset, out, also=summary)
    record_written([out])
    shape = " x ".join(f"{size} {dim}" for dim, size in dataset.sizes.items()) or "1 point"
    regimes = ", ".join(
        f"{code.label} {int(n)}" for code, n in zip(Regime, counts, strict=True) if n
    )
    print(f"wrote {out}: {shape}")
    print(f"  regimes: {regimes}")
    if math.isfinite(low := float(low)):  # NaN-skipping
        print(f"  ECoF / contact CoF: {low:.6g} to {float(high):.6g}")
    return 0


def _map_bytes(grid: dict, load) -> int:
    """Bytes [byte] of the map of ``grid``, uncompressed, from a lazy map (nothing computed)."""
    from ecofmaps.maps.grid import compute_map

    small = {name: values[:2] if np.ndim(values) else values for name, values in grid.items()}
    sample = compute_map(**small, load=load, chunks=1)
    sizes = {name: np.size(values) for name, values in grid.items() if np.ndim(values)}
    return sum(
        variable.dtype.itemsize * math.prod(sizes[dim] for dim in variable.dims)
        for variable in sample.variables.values()
    )


@contextlib.contextmanager
def _progress(dataset):
    """A progress bar of the map's blocks as their dask tasks finish; cleared on an error."""
    from dask.callbacks import Callback

    from ecofmaps.maps.tiles import BLOCK_TASK

    blocks, done = math.prod(len(c) for c in dataset.regime.chunks), itertools.count(1)
    options = {"unit": "pt", "unit_scale": True, "postfix": f"0/{blocks} blocks"}
    bar = common.progress_bar(dataset.regime.size, "ecofmaps map", **options)

    def on_task(key, result, dsk, state, worker_id) -> None:
        if isinstance(key, tuple) and str(key[0]).startswith(BLOCK_TASK):
            bar.set_postfix_str(f"{next(done)}/{blocks} blocks", refresh=False)
            bar.update(next(iter(result.values())).size)

    try:
        with Callback(posttask=on_task):
            yield
    except BaseException:
        bar.leave = False
        raise
    finally:
        bar.close()
