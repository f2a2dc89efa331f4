"""The work of ``ecofmaps map`` (its options are in :mod:`ecofmaps.cli.map`): the grid's
size stated and checked, the map computed and written."""

from __future__ import annotations

import contextlib
import math
import shutil
import sys
from pathlib import Path

import numpy as np
from dask.callbacks import Callback
from tqdm import tqdm

from ecofmaps.cli._common import CommandError, refuse_to_overwrite
from ecofmaps.io.files import record_written
from ecofmaps.maps.files import (
    ZARR_SUFFIX,
    write_map,
)
from ecofmaps.maps.grid import compute_map
from ecofmaps.maps.tiles import BLOCK_TASK
from ecofmaps.model import Regime

__all__ = ["map_bytes", "run"]


def run(args) -> int:
    """Run ``ecofmaps map`` with the parsed ``args``; the exit status."""
    out = Path(args.out)
    if not out.parent.is_dir():
        raise CommandError(f"cannot write {out}: the directory {out.parent} does not exist")
    refuse_to_overwrite([("--out", out)], [], overwrite=args.overwrite)
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
    size = map_bytes(grid, args.load)
    free = shutil.disk_usage(out.parent).free
    print(
        f"ecofmaps map: {points:,} points, {_bytes(size)} into {out} ({_bytes(free)} free there)",
        file=sys.stderr,
        flush=True,
    )
    if size > free:
        raise CommandError(
            f"--out {out}: the map of {points:.3g} points needs up to {_bytes(size)} on disk, "
            f"more than the {_bytes(free)} free in {out.parent.resolve()}: use a smaller grid "
            "or another disk"
        )
    chunked = out.suffix == ZARR_SUFFIX or points > args.chunk_points
    if chunked:
        dataset = compute_map(**grid, load=args.load, chunks=args.chunk_points)
    else:  # refused there if it would not fit in memory
        dataset = compute_map(
            **grid, load=args.load, cache=False if args.no_cache else None, cache_dir=args.cache_dir
        )
    return _write(dataset, out, shown=chunked and not args.quiet and sys.stderr.isatty())


def map_bytes(grid: dict, load) -> int:
    """Bytes of the map of ``grid`` with its coordinates, uncompressed, before computing it.

    The variables' types and dimensions come from the map of at most two values along
    each axis of ``grid``, chunked (its blocks are not computed).

    Parameters
    ----------
    grid : dict
        ``compute_map``'s keywords ``stiffness_ratio``, ``aspect_ratio``, ``amplitude``,
        ``mu``: each a value [SI] or a 1-D array of values.
    load : float or None
        Normal load. [N]

    Returns
    -------
    size : int
        The map's size in memory, and at most on disk (netCDF and zarr may compress it).
        [byte]
    """
    small = {name: values[:2] if np.ndim(values) else values for name, values in grid.items()}
    sample = compute_map(**small, load=load, chunks=1)  # lazy: nothing computed
    sizes = {name: np.size(values) for name, values in grid.items() if np.ndim(values)}
    return sum(
        variable.dtype.itemsize * math.prod(sizes[dim] for dim in variable.dims)
        for variable in sample.variables.values()
    )


def _bytes(size: float) -> str:
    """``size`` [byte] in words: ``'88 TB'``, ``'512 kB'`` (decimal units)."""
    power = min(int(math.log10(max(size, 1)) // 3), 5)
    return f"{size / 1000**power:.3g} {('B', 'kB', 'MB', 'GB', 'TB', 'PB')[power]}"


def _write(dataset, out: Path, shown: bool) -> int:
    """Write ``dataset`` to ``out`` (a progress bar if ``shown``), record it as written by
    ecofmaps, and print what was written."""
    summary = [(dataset.regime == code).sum().data for code in Regime]
    summary += [dataset.ecof_ratio.min().data, dataset.ecof_ratio.max().data]
    with _progress(dataset, shown=shown):
        *counts, low, high = write_map(dataset, out, also=summary)
    record_written([out])
    shape = " x ".join(f"{size} {dim}" for dim, size in dataset.sizes.items()) or "1 point"
    regimes = ", ".join(
        f"{code.label} {int(count)}" for code, count in zip(Regime, counts, strict=True) if count
    )
    print(f"wrote {out}: {shape}")
    print(f"  regimes: {regimes}")
    if math.isfinite(low := float(low)):  # NaN-skipping
        print(f"  ECoF / contact CoF: {low:.6g} to {float(high):.6g}")
    return 0


@contextlib.contextmanager
def _progress(dataset, shown: bool):
    """A progress bar on standard error (points and blocks done, rate, ETA) while in the block.

    It counts the blocks of a chunked map as their dask tasks finish; on an error or
    Ctrl-C it is cleared, so the error is the last line.
    """
    if not shown:
        yield
        return
    blocks = math.prod(len(c) for c in dataset.regime.chunks)
    bar = tqdm(
        total=dataset.regime.size, unit="pt", unit_scale=True, desc="ecofmaps map",
        file=sys.stderr, dynamic_ncols=True, postfix=f"0/{blocks} blocks",
    )  # fmt: skip
    done = 0

    class Blocks(Callback):
        def _posttask(self, key, result, dsk, state, worker_id):
            nonlocal done
            if isinstance(key, tuple) and str(key[0]).startswith(BLOCK_TASK):
                done += 1
                bar.set_postfix_str(f"{done}/{blocks} blocks", refresh=False)
                bar.update(next(iter(result.values())).size)

    try:
        with Blocks():
            yield
    except BaseException:
        bar.leave = False
        raise
    finally:
        bar.close()
