"""Grid evaluation in tiles (in memory, on every core) and in blocks of tiles (dask), so that
both give the same values to the bit: docs/performance.md, "Maps"."""

from __future__ import annotations

import concurrent.futures
import functools
import itertools
import math
import operator
import os
import threading
from collections.abc import Mapping

import jax
import numpy as np

from ecofmaps._inputs import available_memory
from ecofmaps._interrupts import check_interrupted

#: Default bound on the grid points evaluated in one call of a kernel (a tile; its working
#: arrays stay in the processor's cache: docs/performance.md, "Maps").
MAX_CHUNK = 2**14

#: Grid points in one block of a chunked map with ``chunks='auto'``.
BLOCK_POINTS = 2**22

#: Prefix of the dask keys of the tasks that evaluate the blocks of a chunked map.
BLOCK_TASK = "ecofmaps-block"


def _dtypes(kernel, axes, extra) -> dict:
    """The type of each of ``kernel``'s results, by name (traced on one grid point)."""
    with jax.enable_x64(True):
        outputs = jax.eval_shape(kernel, *(axis[:1] for axis in axes), *extra)
    return {name: spec.dtype for name, spec in outputs.items()}


def _empty(kernel, axes, extra, region) -> dict[str, np.ndarray]:
    """Arrays for ``kernel``'s results over ``region`` of the grid, by name."""
    shape = tuple(stop - start for start, stop in region)
    return {name: np.empty(shape, dtype) for name, dtype in _dtypes(kernel, axes, extra).items()}


def _check_memory(kernel, axes, extra, max_chunk: int) -> None:
    """Refuse, before allocating, a grid whose results would not fit in the free memory."""
    per_point = sum(dtype.itemsize for dtype in _dtypes(kernel, axes, extra).values())
    points = math.prod(axis.size for axis in axes)
    needed = per_point * (points + 2 * tile_workers() * min(points, max_chunk))
    free = available_memory()
    if free is not None and needed > free:
        raise ValueError(
            f"the grid of {points:.3g} points needs about {needed / 1e9:.3g} GB of memory for "
            f"its results, more than the {free / 1e9:.3g} GB available: use a smaller grid, "
            "or compute it block by block with chunks='auto' and write it with "
            "ecofmaps.maps.write_map (ecofmaps map does so above --chunk-points points, "
            "e.g. into --out FILE.zarr)"
        )


def tile_workers() -> int:
    """Threads that evaluate tiles at once: the cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _split(shape: tuple[int, ...], points: int) -> tuple[int, int]:
    """How blocks of at most ``points`` points tile ``shape``: split axis ``k`` and ``rows``."""
    k = next(i for i in range(len(shape)) if math.prod(shape[i + 1 :]) <= points)
    count = -(-shape[k] // max(1, points // math.prod(shape[k + 1 :])))  # blocks along k
    return k, -(-shape[k] // count)


def _tiles(split: tuple[int, int], region):
    """The tiles (``index``, ``start``) of a grid split by ``split`` that overlap ``region``."""
    k, rows = split
    first = region[k][0] // rows * rows
    for index in itertools.product(*(range(start, stop) for start, stop in region[:k])):
        for start in range(first, region[k][1], rows):
            yield index, start


def _fill(out, kernel, axes, extra, split, region, tiles, stop=None) -> None:
    """Evaluate ``tiles`` into ``out`` (their part inside ``region``) until ``stop`` is set."""
    k, rows = split
    offset = tuple(start for start, _ in region)
    trailing = tuple(slice(start, stop) for start, stop in region[k + 1 :])
    with jax.enable_x64(True):
        for index, start in tiles:
            check_interrupted()
            if stop is not None and stop.is_set():
                return
            along = axes[k][start : start + rows]
            if along.size < rows:
                along = np.pad(along, (0, rows - along.size), mode="edge")
            tile_axes = [axis[i : i + 1] for axis, i in zip(axes, index, strict=False)]
            values = kernel(*tile_axes, along, *axes[k + 1 :], *extra)
            low, high = max(start, region[k][0]), min(start + rows, region[k][1])
            source = (0,) * k + (slice(low - start, high - start), *trailing)
            target = (*np.subtract(index, offset[:k]), slice(low - offset[k], high - offset[k]))
            for name, value in values.items():
                out[name][target] = np.asarray(value)[source]


def _evaluate_grid(kernel, axes, extra, max_chunk: int) -> dict[str, np.ndarray]:
    _check_memory(kernel, axes, extra, max_chunk)
    shape = tuple(axis.size for axis in axes)
    if math.prod(shape) <= max_chunk:
        return {name: np.asarray(value) for name, value in kernel(*axes, *extra).items()}
    split = _split(shape, max_chunk)
    region = tuple((0, size) for size in shape)
    tiles = list(_tiles(split, region))
    out = _empty(kernel, axes, extra, region)
    workers = min(tile_workers(), len(tiles))
    stop = threading.Event()  # set on an error or Ctrl-C: the other threads end early
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        futures = [
            pool.submit(_fill, out, kernel, axes, extra, split, region, tiles[i::workers], stop)
            for i in range(workers)
        ]
        try:
            for future in futures:
                future.result()
        finally:
            stop.set()
    return out


def _block_lengths(chunks, shape, dims, split) -> list[int]:
    """The block length along each axis that ``chunks`` asks for (see :func:`compute_map`)."""
    if isinstance(chunks, str) and chunks == "auto":
        chunks = BLOCK_POINTS
    whole = isinstance(chunks, (int, np.integer)) and not isinstance(chunks, bool)
    if not ((whole and chunks >= 1) or isinstance(chunks, Mapping)):
        raise ValueError(
            "chunks must be 'auto', an integer >= 1 (grid points per block) or a dict of block "
            f"lengths by dimension name, got {chunks!r}"
        )
    if whole:
        k, rows = _split(shape, int(chunks))
        if k == split[0] and rows > split[1]:  # whole tiles: none is evaluated twice
            tiles = -(-shape[k] // split[1])
            blocks = -(-tiles // (rows // split[1]))
            rows = -(-tiles // blocks) * split[1]
        return [1] * k + [rows] + list(shape[k + 1 :])
    unknown = [name for name in chunks if name not in dims]
    if unknown:
        named = ", ".join(d for d in dims if d) or "none: every parameter is a single value"
        raise ValueError(
            f"chunks names {unknown[0]!r}, which is not a dimension of this map (its "
            f"dimensions: {named})"
        )
    lengths = []
    for name, size in zip(dims, shape, strict=True):
        length = chunks.get(name, -1) if name else 1
        if length is None or (not isinstance(length, bool) and length == -1):
            length = size
        if isinstance(length, bool) or not isinstance(length, (int, np.integer)) or length < 1:
            raise ValueError(
                f"chunks[{name!r}] must be an integer >= 1, or -1 or None for the whole "
                f"dimension; got {length!r}"
            )
        lengths.append(min(int(length), size))
    return lengths


def _chunked_grid(kernel, axes, extra, max_chunk: int, chunks, dims) -> dict:
    """The results of :func:`_evaluate_grid` as dask arrays, one task per block."""
    import dask.array as da
    from dask.base import tokenize
    from dask.highlevelgraph import HighLevelGraph

    shape = tuple(axis.size for axis in axes)
    split = _split(shape, max_chunk)
    block_chunks = da.core.normalize_chunks(_block_lengths(chunks, shape, dims, split), shape)
    starts = [np.cumsum((0, *c)) for c in block_chunks]
    token = tokenize(kernel.__name__, *axes, *extra, max_chunk, block_chunks)
    name = f"{BLOCK_TASK}-{token}"
    blocks = {}
    for index in itertools.product(*(range(len(c)) for c in block_chunks)):
        region = tuple((int(s[i]), int(s[i + 1])) for s, i in zip(starts, index, strict=True))
        blocks[(name, *index)] = (functools.partial(_block, kernel, axes, extra, split, region),)
    arrays = {}
    for variable, dtype in _dtypes(kernel, axes, extra).items():
        layer = f"{variable}-{token}"
        getters = {(layer, *key[1:]): (operator.getitem, key, variable) for key in blocks}
        graph = HighLevelGraph({name: blocks, layer: getters}, {name: set(), layer: {name}})
        arrays[variable] = da.Array(graph, layer, chunks=block_chunks, dtype=dtype)
    return arrays


def _block(kernel, axes, extra, split, region) -> dict[str, np.ndarray]:
    """One block of a chunked map: its arrays by name (a dask task)."""
    out = _empty(kernel, axes, extra, region)
    _fill(out, kernel, axes, extra, split, region, _tiles(split, region))
    return out


def check_max_chunk(max_chunk) -> None:
    if not (isinstance(max_chunk, int) and not isinstance(max_chunk, bool) and max_chunk >= 1):
        raise ValueError(f"max_chunk must be an integer >= 1, got {max_chunk!r}")


def grid_values(kernel, axes: dict, extra: tuple, max_chunk: int, chunks) -> dict:
    """The kernel's results over the grid of ``axes`` (name -> 0-d or 1-D array)."""
    check_max_chunk(max_chunk)
    grid = [np.atleast_1d(axis) for axis in axes.values()]
    if chunks is None:
        return _evaluate_grid(kernel, grid, extra, max_chunk)
    dims = [name if axis.ndim else None for name, axis in axes.items()]
    return _chunked_grid(kernel, grid, extra, max_chunk, chunks, dims)
