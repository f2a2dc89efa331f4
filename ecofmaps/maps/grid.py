r"""Parameter maps: the model over whole grids, as labelled xarray Datasets.

Each function takes one value or one 1-D array per parameter; the arrays become the
Dataset's dimensions (in the order of the arguments), the single values its scalar
coordinates. The grid is evaluated with the dimensionless core of :mod:`ecofmaps.model`
by a ``jax.jit``-compiled kernel (broadcasting, float64, no Python loop over points), in
tiles of at most ``max_chunk`` points small enough for the processor's cache, on every
core, so the cost grows linearly with the grid and the memory needed is that of the results.
With ``chunks=`` the map is instead a dask-backed Dataset: each block is evaluated from the
same tiles when it is computed or written (:func:`ecofmaps.maps.write_map`), so a grid far
beyond memory can be written to disk, and its values equal the in-memory map's to the bit.
:func:`compute_map` and :func:`compute_universal_map` keep their in-memory results in the
disk cache (:mod:`ecofmaps.maps.cache`).

As in the paper, the groove half-width is the displacement amplitude, :math:`x_o = \Delta^*`,
so the curvature number is :math:`\kappa = 2 z_o/x_o` and the compliance ratio is
:math:`\lambda = P/(S\Delta^*)`.
"""

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
import jax.numpy as jnp
import numpy as np
import pandas as pd
import xarray as xr
from xarray.core.indexes import PandasIndex

from ecofmaps import _nomenclature as nomenclature
from ecofmaps import model, paper
from ecofmaps._inputs import check, float64
from ecofmaps._interrupts import check_interrupted
from ecofmaps._version import __version__
from ecofmaps.maps.cache import cached_dataset
from ecofmaps.model.simulation import fretting_loop
from ecofmaps.model.steady_state import dimensionless

__all__ = [
    "BLOCK_POINTS",
    "BLOCK_TASK",
    "MAX_CHUNK",
    "compute_loops",
    "compute_map",
    "compute_profile_map",
    "compute_universal_map",
]

#: Default bound on the number of grid points evaluated in one call of a kernel (a tile):
#: its working arrays (about 1.4 MB) stay in the processor's cache.
MAX_CHUNK = 2**14
#: Grid points in one block of a chunked map with ``chunks='auto'`` (results of about
#: 220 MB for :func:`compute_map` with a load).
BLOCK_POINTS = 2**22
#: Prefix of the dask keys of the tasks that evaluate the blocks of a chunked map.
BLOCK_TASK = "ecofmaps-block"

# The order of the variables in a Dataset (xarray orders the dimensions as they first appear).
_VARIABLES = (
    "displacement",
    "force",
    "slip_amplitude",
    "slip_ratio",
    "ecof",
    "ecof_ratio",
    "compliance_ratio",
    "regime",
    "dissipated_energy",
    "max_force",
)


def _attrs(name: str) -> dict:
    attrs = nomenclature.attrs(name)
    if name == "regime":
        attrs.update(model.Regime.flag_attrs())
    return attrs


def _global_attrs(title: str) -> dict:
    return {
        "title": title,
        "model": paper.MODEL,
        "references": paper.CITATION,
        "source": f"ecofmaps {__version__}",
        "ecofmaps_version": __version__,
    }


def _axis(name: str, value, rule: str, unit: str) -> np.ndarray:
    """``value`` checked (``ValueError`` naming ``name``) as a float64 scalar or 1-D array.

    A 1-D array is a grid axis: it must hold each value once.
    """
    check(name, value, rule, unit)
    array = np.asarray(value, dtype=np.float64)
    if array.ndim > 1:
        raise ValueError(f"{name} must be a single value or a 1-D array, got shape {array.shape}")
    if array.size == 0:
        raise ValueError(f"{name} must hold at least one value, got an empty array")
    ordered = np.sort(array, axis=None)
    if np.any(ordered[1:] == ordered[:-1]):
        unique, counts = np.unique(array, return_counts=True)
        repeated = unique[counts > 1][0]
        where = np.flatnonzero(array == repeated)
        raise ValueError(
            f"{name} repeats the value {repeated!r} (at indices {where.tolist()}): a grid axis "
            "takes each value once"
        )
    return array


def available_memory() -> int | None:
    """Memory the system can give this process now, or None where it cannot tell. [byte]"""
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


@functools.lru_cache(maxsize=64)
def _bytes_per_point(kernel, axes: int, extra: tuple) -> int:
    """Bytes of ``kernel``'s results per grid point, from ``jax.eval_shape`` on one point.

    ``extra`` holds the shapes and dtypes of the extra arguments (``None`` for ``None``).
    """
    point = [jax.ShapeDtypeStruct((1,), np.float64)] * axes
    arguments = [None if e is None else jax.ShapeDtypeStruct(*e) for e in extra]
    with jax.enable_x64(True):
        outputs = jax.eval_shape(kernel, *point, *arguments)
    return sum(out.dtype.itemsize * out.size for out in jax.tree_util.tree_leaves(outputs))


def _signature(extra) -> tuple:
    return tuple(None if e is None else (np.shape(e), np.result_type(e)) for e in extra)


def _check_memory(kernel, axes, extra, max_chunk: int) -> None:
    """Refuse, before allocating, a grid whose results would not fit in the free memory.

    The results' sizes come from ``jax.eval_shape`` (no computation); the working arrays
    of the blocks evaluated at once (each taken as twice its results) come on top. The
    way out is named: a chunked map (``chunks=``) is computed block by block and never
    needs more than a few blocks in memory.
    """
    per_point = _bytes_per_point(kernel, len(axes), _signature(extra))
    points = math.prod(axis.size for axis in axes)
    needed = per_point * (points + 2 * _workers() * min(points, max_chunk))
    free = available_memory()
    if free is not None and needed > free:
        raise ValueError(
            f"the grid of {points:.3g} points needs about {needed / 1e9:.3g} GB of memory for "
            f"its results, more than the {free / 1e9:.3g} GB available: use a smaller grid, "
            "or compute it block by block with chunks='auto' and write it with "
            "ecofmaps.maps.write_map (ecofmaps map does so above --chunk-points points, "
            "e.g. into --out FILE.zarr)"
        )


# ---------------------------------------------------------------------------------------
# Grid evaluation in tiles (in memory) and blocks of tiles (dask)
# ---------------------------------------------------------------------------------------


def _mesh(*axes):
    """The 1-D ``axes`` reshaped to broadcast against each other, axis ``i`` along dim ``i``."""
    count = len(axes)
    return [
        jnp.reshape(axis, tuple(-1 if j == i else 1 for j in range(count)))
        for i, axis in enumerate(axes)
    ]


def _workers() -> int:
    """Threads that evaluate tiles at once: the cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _split(shape: tuple[int, ...], points: int) -> tuple[int, int]:
    """How blocks of at most ``points`` points tile ``shape``: split axis ``k`` and ``rows``.

    The split axis is the first one whose trailing axes hold at most ``points`` points
    together; a block takes one index along the axes before ``k``, ``rows`` consecutive
    indices along ``k`` and all of the axes after it. The blocks along ``k`` are as even as
    can be, so the last one (padded up to ``rows`` in a tile) wastes little.
    """
    k = next(i for i in range(len(shape)) if math.prod(shape[i + 1 :]) <= points)
    count = -(-shape[k] // max(1, points // math.prod(shape[k + 1 :])))  # blocks along k
    return k, -(-shape[k] // count)


def _tiles(split: tuple[int, int], region):
    """The tiles (``index``, ``start``) of a grid split by ``split`` that overlap ``region``.

    ``region`` holds a ``(start, stop)`` pair per axis. A tile is the block of
    :func:`_split` at ``index`` along the axes before the split axis and at rows
    ``start:start + rows`` along it (the tiles' starts are multiples of ``rows``).
    """
    k, rows = split
    first = region[k][0] // rows * rows
    for index in itertools.product(*(range(start, stop) for start, stop in region[:k])):
        for start in range(first, region[k][1], rows):
            yield index, start


def _fill(out, kernel, axes, extra, split, region, tiles, stop=None) -> None:
    """Evaluate ``tiles`` and copy their part inside ``region`` into the arrays ``out``.

    Every tile has the same shape (the last one along the split axis is padded by
    repeating its last value, and the padding is dropped), so the kernel compiles once
    and each point's value does not depend on how the grid is cut into blocks: the
    in-memory and chunked maps are equal to the bit. ``out`` maps each result's name to
    an array of the region's shape (allocated here on the first tile when empty).
    ``stop``, a ``threading.Event``, ends the loop at the next tile once it is set; after
    Ctrl-C on the command line the loop raises ``KeyboardInterrupt`` at the next tile.
    """
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
            target = (
                *(i - o for i, o in zip(index, offset, strict=False)),
                slice(low - offset[k], high - offset[k]),
            )
            for name, value in values.items():
                if name not in out:
                    shape = tuple(stop - start for start, stop in region)
                    out[name] = np.empty(shape, dtype=value.dtype)
                out[name][target] = np.asarray(value)[source]


def _evaluate_grid(kernel, axes, extra, max_chunk: int) -> dict[str, np.ndarray]:
    """Evaluate ``kernel(*block_axes, *extra)`` over the grid spanned by 1-D ``axes``.

    ``kernel`` is jit-compiled and returns a dict of arrays of the block's full shape. A
    grid of at most ``max_chunk`` points is one call, and its arrays are XLA's own
    buffers, read-only, without a copy. A larger grid is cut into tiles of at most
    ``max_chunk`` points (:func:`_split`), which threads (one per core) evaluate and copy
    into the result arrays: a tile's working arrays stay in the processor's cache, and
    the cost grows linearly with the number of points.
    """
    if not (isinstance(max_chunk, int) and not isinstance(max_chunk, bool) and max_chunk >= 1):
        raise ValueError(f"max_chunk must be an integer >= 1, got {max_chunk!r}")
    _check_memory(kernel, axes, extra, max_chunk)
    shape = tuple(axis.size for axis in axes)
    if math.prod(shape) <= max_chunk:
        return {name: np.asarray(value) for name, value in kernel(*axes, *extra).items()}
    split = _split(shape, max_chunk)
    region = tuple((0, size) for size in shape)
    tiles = list(_tiles(split, region))
    with jax.enable_x64(True):
        first = [axis[:1] for axis in axes]
        first[split[0]] = axes[split[0]][: split[1]]
        outputs = jax.eval_shape(kernel, *first, *extra)
    out = {name: np.empty(shape, dtype=spec.dtype) for name, spec in outputs.items()}
    workers = min(_workers(), len(tiles))
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
    usage = (
        "chunks must be 'auto', an integer >= 1 (grid points per block) or a dict of block "
        "lengths by dimension name"
    )
    if isinstance(chunks, str):
        if chunks != "auto":
            raise ValueError(f"{usage}, got {chunks!r}")
        chunks = BLOCK_POINTS
    if isinstance(chunks, bool) or not isinstance(chunks, (int, np.integer, Mapping)):
        raise ValueError(f"{usage}, got {chunks!r}")
    if not isinstance(chunks, Mapping):
        if chunks < 1:
            raise ValueError(f"{usage}, got {chunks!r}")
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
    """The results of :func:`_evaluate_grid` as dask arrays, one task per block.

    Each block's task evaluates the tiles that overlap it (the same tiles as in memory,
    so the values are equal to the bit) and returns its arrays by name; the variables'
    chunks are taken from it, so a block is evaluated once for all of them. Keys of the
    block tasks start with :data:`BLOCK_TASK`.
    """
    import dask.array as da
    from dask.base import tokenize
    from dask.highlevelgraph import HighLevelGraph

    if not (isinstance(max_chunk, int) and not isinstance(max_chunk, bool) and max_chunk >= 1):
        raise ValueError(f"max_chunk must be an integer >= 1, got {max_chunk!r}")
    shape = tuple(axis.size for axis in axes)
    split = _split(shape, max_chunk)
    lengths = _block_lengths(chunks, shape, dims, split)
    block_chunks = tuple(
        (length,) * (size // length) + ((size % length,) if size % length else ())
        for size, length in zip(shape, lengths, strict=True)
    )
    starts = [np.cumsum((0, *c)) for c in block_chunks]
    with jax.enable_x64(True):
        outputs = jax.eval_shape(kernel, *(axis[:1] for axis in axes), *extra)
    token = tokenize(kernel.__name__, *axes, *extra, max_chunk, block_chunks)
    name = f"{BLOCK_TASK}-{token}"
    blocks = {}
    for index in itertools.product(*(range(len(c)) for c in block_chunks)):
        region = tuple((int(s[i]), int(s[i + 1])) for s, i in zip(starts, index, strict=True))
        tiles = functools.partial(_tiles, split, region)
        blocks[(name, *index)] = (
            functools.partial(_block, kernel, axes, extra, split, region, tiles),
        )
    arrays = {}
    for variable, spec in outputs.items():
        layer = f"{variable}-{token}"
        getters = {(layer, *key[1:]): (operator.getitem, key, variable) for key in blocks}
        graph = HighLevelGraph({name: blocks, layer: getters}, {name: set(), layer: {name}})
        arrays[variable] = da.Array(graph, layer, chunks=block_chunks, dtype=spec.dtype)
    return arrays


def _block(kernel, axes, extra, split, region, tiles) -> dict[str, np.ndarray]:
    """One block of a chunked map: its arrays by name (a dask task)."""
    out: dict[str, np.ndarray] = {}
    _fill(out, kernel, axes, extra, split, region, tiles())
    return out


def _dataset(axes: dict, values: dict, title: str, extra=None) -> xr.Dataset:
    """A Dataset of grid ``values`` over ``axes`` (scalars become scalar coordinates).

    A value is an array over the whole grid (with a length-1 axis for each scalar
    coordinate), or a ``(dims, array)`` pair for one that depends on fewer parameters.
    ``extra`` coordinates are not grid axes: 0-d ones are scalar coordinates, 1-D ones
    trailing dimensions of the values that have more axes than the grid.
    """
    dims = [name for name, axis in axes.items() if axis.ndim == 1]
    squeeze = tuple(i for i, axis in enumerate(axes.values()) if axis.ndim == 0)
    extra = extra or {}
    trailing = [name for name, coordinate in extra.items() if coordinate.ndim == 1]
    coords = {
        name: ((name,) if axis.ndim == 1 else (), axis, _attrs(name))
        for name, axis in {**axes, **extra}.items()
    }
    variables, indexes = {}, {}
    for name, (dim, value, attrs) in coords.items():
        if dim:  # a dimension coordinate, indexed as xarray.Dataset would index it
            indexes[name] = PandasIndex(pd.Index(value), name)
            variables.update(indexes[name].create_variables({name: xr.Variable(dim, value, attrs)}))
        else:
            variables[name] = xr.Variable(dim, value, attrs)
    for name in sorted(values, key=_VARIABLES.index):
        if isinstance(values[name], tuple):
            variables[name] = xr.Variable(*values[name], _attrs(name))
            continue
        value = np.squeeze(values[name], axis=squeeze)
        variables[name] = xr.Variable(
            dims + trailing[: value.ndim - len(dims)], value, _attrs(name)
        )
    # What xarray.Dataset(data_vars, coords, attrs) builds, without its merging and alignment
    # of variables that are consistent by construction (a third of a small map's time).
    return xr.Dataset._construct_direct(
        variables, set(coords), attrs=_global_attrs(title), indexes=indexes
    )


# ---------------------------------------------------------------------------------------
# Kernels
# ---------------------------------------------------------------------------------------


def _steady_state(mu, kappa, lam, amplitude=None, load=None) -> dict:
    """The steady-loop quantities of the core numbers, by variable name (eq. 1, 9, 12, 16)."""
    values = {
        "slip_ratio": model.slip_ratio(mu, kappa, lam),
        "ecof_ratio": model.ecof_ratio(mu, kappa, lam),
        "regime": model.regime_code(mu, kappa, lam),
    }
    if amplitude is not None:
        values["slip_amplitude"] = amplitude * values["slip_ratio"]
        values["ecof"] = mu * values["ecof_ratio"]
    if load is not None:
        values["dissipated_energy"] = load * amplitude * model.normalized_energy(mu, kappa, lam)
        values["max_force"] = load * model.normalized_max_force(mu, kappa, lam)
    return values


def _broadcast(values: dict, shape) -> dict:
    return {name: jnp.broadcast_to(value, shape) for name, value in values.items()}


@jax.jit
def _map_kernel(stiffness_ratio, aspect_ratio, amplitude, mu, load):
    stiffness_ratio, aspect_ratio, amplitude, mu = _mesh(
        stiffness_ratio, aspect_ratio, amplitude, mu
    )
    kappa = model.curvature_number(1.0, aspect_ratio, 1.0)  # x_o = Δ*: κ = 2 z_o/x_o
    lam = model.compliance_ratio(amplitude, 1.0, stiffness_ratio)  # 1/((S/P) Δ*)
    values = _steady_state(mu, kappa, lam, amplitude, load)
    shape = jnp.broadcast_shapes(stiffness_ratio.shape, aspect_ratio.shape, amplitude.shape)
    return _broadcast(values, jnp.broadcast_shapes(shape, mu.shape))


@jax.jit
def _universal_kernel(compliance_ratio, aspect_ratio, mu):
    lam, aspect_ratio, mu = _mesh(compliance_ratio, aspect_ratio, mu)
    kappa = model.curvature_number(1.0, aspect_ratio, 1.0)
    values = _steady_state(mu, kappa, lam)
    return _broadcast(values, (lam.size, aspect_ratio.size, mu.size))


def _check_cache(cache, chunks) -> None:
    """Refuse ``cache=True`` for a chunked map (it is never cached)."""
    if cache not in (None, True, False):
        raise ValueError(f"cache must be True, False or None, got {cache!r}")
    if cache and chunks is not None:
        raise ValueError(
            "cache=True with chunks: a chunked map is not cached (it is evaluated block by "
            "block where it is written); leave cache out"
        )


def _grid_values(kernel, axes: dict, extra: tuple, max_chunk: int, chunks) -> dict:
    """The kernel's results over the grid of ``axes`` (name -> 0-d or 1-D array)."""
    grid = [np.atleast_1d(axis) for axis in axes.values()]
    if chunks is None:
        return _evaluate_grid(kernel, grid, extra, max_chunk)
    dims = [name if axis.ndim else None for name, axis in axes.items()]
    return _chunked_grid(kernel, grid, extra, max_chunk, chunks, dims)


# ---------------------------------------------------------------------------------------
# Public functions
# ---------------------------------------------------------------------------------------


@float64
def compute_map(
    stiffness_ratio,
    aspect_ratio=None,
    amplitude=None,
    mu=None,
    load=None,
    *,
    chunks=None,
    profile=None,
    mapping="scaled",
    cache=None,
    cache_dir=None,
    max_chunk=MAX_CHUNK,
) -> xr.Dataset:
    r"""The steady-loop quantities of the model over a grid of test conditions.

    Parameters
    ----------
    stiffness_ratio : float or 1-D array_like
        Rig stiffness over normal load :math:`S/P`; ``numpy.inf`` for a rigid rig. [1/m]
    aspect_ratio : float or 1-D array_like
        Groove depth over half-width :math:`z_o/x_o`, >= 0. [1]
    amplitude : float or 1-D array_like
        Displacement amplitude :math:`\Delta^*` (also the groove half-width :math:`x_o`). [m]
    mu : float or 1-D array_like
        Contact coefficient of friction :math:`\mu`. [1]
    load : float, optional
        Normal load :math:`P`; when given, the map also holds ``dissipated_energy`` and
        ``max_force`` and a scalar coordinate ``load``. [N]
    chunks : 'auto', int or dict, optional
        Return a chunked map: its variables are dask arrays, evaluated block by block
        when they are computed or written (:func:`ecofmaps.maps.write_map`), so the grid
        need not fit in memory. An int is the largest number of grid points in a block
        (blocks then take whole trailing dimensions, like the tiles below); ``'auto'`` is
        :data:`BLOCK_POINTS`; a dict gives the block length by dimension name (-1 or
        None: the whole dimension; dimensions not named are whole). By default the map
        is computed at once, in memory.
    profile : ScarProfile, optional
        A wear-scar profile of any shape instead of ``aspect_ratio``: see
        :func:`compute_profile_map`.
    mapping : {'scaled', 'physical'}
        With a profile: :math:`X = xW/\Delta^*` (eq. 11) or :math:`X = x`.
    cache : bool, optional
        Read the result from the disk cache, and store it there after computing it.
        Default: yes for a map in memory; a chunked map is never cached (see Notes), so
        ``cache=True`` with ``chunks`` is an error.
    cache_dir : str or os.PathLike, optional
        Cache directory; default ``$ECOFMAPS_CACHE`` or the per-user cache directory.
    max_chunk : int
        Largest number of grid points evaluated in one call of the jit-compiled kernel (a
        tile); a bigger grid is evaluated tile by tile, on every core, and copied into
        place. The default keeps a tile's working arrays in the processor's cache. [1]

    Returns
    -------
    map : xarray.Dataset
        Dimensions ``stiffness_ratio``, ``aspect_ratio``, ``amplitude``, ``mu`` (in this
        order; only those given as arrays, the others are scalar coordinates). Variables:
        ``slip_amplitude`` [m], ``slip_ratio`` [1], ``ecof`` [1], ``ecof_ratio`` [1],
        ``regime`` (:class:`ecofmaps.Regime` codes, int32), ``compliance_ratio`` [1] (over
        ``stiffness_ratio`` and ``amplitude`` only) and, with a load, ``dissipated_energy``
        [J] and ``max_force`` [N]. Every variable and coordinate has ``long_name`` and
        ``units``. ECoF values are NaN where there is no gross slip; every value but the
        regime is NaN when self-locking (rigid rig, :math:`\mu\kappa \ge 1`). Freshly
        computed arrays of a grid of at most ``max_chunk`` points are read-only (they are
        the computation's buffers, not copies): ``.copy()`` the Dataset to write into them.
        With ``chunks``, the variables over the whole grid are dask arrays; computed,
        they equal the map in memory to the bit (``xarray.testing.assert_identical``).

    Raises
    ------
    ValueError
        If a parameter is not a scalar or a non-empty 1-D array, or is out of range:
        stiffness_ratio > 0 (inf allowed); aspect_ratio >= 0; amplitude, mu, load > 0;
        all finite except stiffness_ratio, none NaN. If ``chunks`` is not one of its
        forms, or names a parameter that is not a dimension. If a map in memory would
        not fit in the memory available (before allocating it; a chunked map is not
        refused).

    Warns
    -----
    ecofmaps.maps.cache.CacheWarning
        When a cache file is unusable (it is removed and the map recomputed).

    Notes
    -----
    The map depends on :math:`S`, :math:`P` and :math:`\Delta^*` only through
    :math:`\lambda = P/(S\Delta^*)` (eq. 16): the Figure 11 maps at :math:`\Delta^* = 25` and
    50 µm are one surface read on two scales of :math:`S/P`. Values come from the closed
    forms of eq. 16 (slip amplitude), the corrected eq. 13-15 (:math:`\mu_E`), eq. 12
    (:math:`E_d = 4P\delta^*\mu_E`) and eq. 9 (:math:`Q^*`).

    A chunked map is not cached: it is meant for grids beyond memory, which the cache
    would have to compute at once (and read back whole to verify its checksum); it would
    double the disk space of the user's own store; and evaluating a block costs about as
    much as reading it back from disk.

    Examples
    --------
    >>> import numpy as np
    >>> m = compute_map(np.geomspace(2e4, 2e5, 5), np.linspace(0, 0.3, 4), 50e-6, 0.8)
    >>> m.ecof_ratio.dims
    ('stiffness_ratio', 'aspect_ratio')

    The same map in blocks of 2 values of S/P, evaluated when it is computed or written:

    >>> lazy = compute_map(
    ...     np.geomspace(2e4, 2e5, 5), np.linspace(0, 0.3, 4), 50e-6, 0.8,
    ...     chunks={"stiffness_ratio": 2},
    ... )
    >>> lazy.ecof_ratio.chunks
    ((2, 2, 1), (4,))
    >>> lazy.compute().identical(m)
    True
    """
    if profile is not None or aspect_ratio is None:
        if aspect_ratio is not None:
            raise ValueError("give aspect_ratio or profile, not both")
        if chunks is not None:
            raise ValueError("chunks is for maps of the parabolic groove; a map on a profile "
                             "is computed in memory")  # fmt: skip
        return compute_profile_map(
            stiffness_ratio, amplitude, mu, load, profile=profile, mapping=mapping,
            cache=cache is not False, cache_dir=cache_dir, max_chunk=max_chunk,
        )  # fmt: skip
    if mapping != "scaled":
        raise ValueError("mapping applies to a profile only (profile=...)")
    if amplitude is None or mu is None:
        raise ValueError("compute_map needs amplitude and mu")
    axes = {
        "stiffness_ratio": _axis("stiffness_ratio", stiffness_ratio, "positive_or_inf", "1/m"),
        "aspect_ratio": _axis("aspect_ratio", aspect_ratio, "non_negative", "1"),
        "amplitude": _axis("amplitude", amplitude, "positive", "m"),
        "mu": _axis("mu", mu, "positive", "1"),
    }
    if load is not None:
        load = _axis("load", load, "positive", "N")
        if load.ndim:
            raise ValueError(f"load must be a single value, got shape {load.shape}")

    _check_cache(cache, chunks)

    def compute() -> xr.Dataset:
        values = _grid_values(_map_kernel, axes, (load,), max_chunk, chunks)
        # λ depends on S/P and Δ* only: a variable over those two (eq. 16).
        stiffness, amplitude = axes["stiffness_ratio"], axes["amplitude"]
        lam = model.compliance_ratio(
            np.atleast_1d(amplitude), 1.0, np.atleast_1d(stiffness)[:, None]
        )
        scalars = tuple(i for i, axis in enumerate((stiffness, amplitude)) if axis.ndim == 0)
        dims = tuple(n for n in ("stiffness_ratio", "amplitude") if axes[n].ndim == 1)
        values["compliance_ratio"] = (dims, np.squeeze(lam, axis=scalars))
        extra = {} if load is None else {"load": load}
        return _dataset(axes, values, "ECoF map of the compliant wear-scar model", extra)

    if chunks is not None or cache is False:
        return compute()
    return cached_dataset("compute_map", {**axes, "load": load}, compute, cache_dir)


@float64
def compute_universal_map(
    compliance_ratio,
    aspect_ratio,
    mu,
    *,
    chunks=None,
    cache=None,
    cache_dir=None,
    max_chunk=MAX_CHUNK,
) -> xr.Dataset:
    r"""The dimensionless map: :math:`\mu_E/\mu` and :math:`\delta^*/\Delta^*` over :math:`\lambda`.

    Parameters
    ----------
    compliance_ratio : float or 1-D array_like
        :math:`\lambda = P/(S\Delta^*)`, the rig's deflection at :math:`Q = P` over the
        displacement amplitude, >= 0 (0 for a rigid rig). [1]
    aspect_ratio : float or 1-D array_like
        Groove depth over half-width :math:`z_o/x_o` with :math:`x_o = \Delta^*`, >= 0. [1]
    mu : float or 1-D array_like
        Contact coefficient of friction, > 0. [1]
    chunks, cache, cache_dir, max_chunk
        As for :func:`compute_map`.

    Returns
    -------
    map : xarray.Dataset
        Dimensions ``compliance_ratio``, ``aspect_ratio``, ``mu`` (those given as arrays).
        Variables ``ecof_ratio`` [1], ``slip_ratio`` [1], ``regime``.

    Raises
    ------
    ValueError
        If a parameter is not a scalar or a non-empty 1-D array, or out of range; for
        ``chunks``, ``cache`` and memory, as :func:`compute_map`.

    Notes
    -----
    With :math:`x_o = \Delta^*` the curvature number is :math:`\kappa = 2 z_o/x_o`, and
    :math:`\mu_E/\mu` depends on :math:`(\mu, z_o/x_o, \lambda)` only (eq. 13-16): this one
    chart holds both panels of Figure 11, whose axes :math:`S/P` map onto
    :math:`\lambda = 1/((S/P)\Delta^*)`.
    """
    axes = {
        "compliance_ratio": _axis("compliance_ratio", compliance_ratio, "non_negative", "1"),
        "aspect_ratio": _axis("aspect_ratio", aspect_ratio, "non_negative", "1"),
        "mu": _axis("mu", mu, "positive", "1"),
    }

    _check_cache(cache, chunks)

    def compute() -> xr.Dataset:
        values = _grid_values(_universal_kernel, axes, (), max_chunk, chunks)
        return _dataset(axes, values, "Universal ECoF map of the compliant wear-scar model")

    if chunks is not None or cache is False:
        return compute()
    return cached_dataset("compute_universal_map", axes, compute, cache_dir)


@jax.jit
def _loop_kernel(stiffness, aspect_ratio, amplitude, load, mu):
    mu, kappa, lam, code = dimensionless(amplitude, load, stiffness, mu, aspect_ratio, amplitude)
    values = _steady_state(mu, kappa, lam, amplitude, load)
    values = {n: values[n] for n in ("slip_amplitude", "max_force", "dissipated_energy")}
    values["regime"] = code
    return values


@float64
def compute_loops(stiffness, aspect_ratio, amplitude, load, mu, num=201) -> xr.Dataset:
    r"""Steady fretting loops over a grid of test conditions (Figures 5 and 6).

    Parameters
    ----------
    stiffness : float or 1-D array_like
        Rig stiffness :math:`S`; ``numpy.inf`` for a rigid rig. [N/m]
    aspect_ratio : float or 1-D array_like
        Groove depth over half-width :math:`z_o/x_o`. [1]
    amplitude : float or 1-D array_like
        Displacement amplitude :math:`\Delta^*` (also the groove half-width). [m]
    load : float or 1-D array_like
        Normal load :math:`P`. [N]
    mu : float or 1-D array_like
        Contact coefficient of friction. [1]
    num : int
        Points on each slip branch (>= 2); each loop has ``2 * num + 1`` points. [1]

    Returns
    -------
    loops : xarray.Dataset
        Dimensions: those of the parameters given as arrays (in the order of the
        arguments), then ``point``. Variables ``displacement`` [m] and ``force`` [N] around
        each loop (see :func:`ecofmaps.fretting_loop`: it starts and ends at the reversal
        :math:`(-\Delta^*, -Q^*)` and runs clockwise), and per loop ``slip_amplitude`` [m],
        ``max_force`` [N], ``dissipated_energy`` [J] (the loop's area) and ``regime``.
        Self-locking loops are NaN.

    Raises
    ------
    ValueError
        If a parameter is not a scalar or a non-empty 1-D array, or out of range (see
        :func:`ecofmaps.slip_amplitude`), or ``num < 2``.

    Notes
    -----
    Slip branches from eq. 9 with eq. 10, stick segments of slope :math:`S`; the per-loop
    quantities from eq. 16 (:math:`\delta^*`), eq. 9 (:math:`Q^*`) and eq. 12 (:math:`E_d`).
    """
    axes = {
        "stiffness": _axis("stiffness", stiffness, "positive_or_inf", "N/m"),
        "aspect_ratio": _axis("aspect_ratio", aspect_ratio, "non_negative", "1"),
        "amplitude": _axis("amplitude", amplitude, "positive", "m"),
        "load": _axis("load", load, "positive", "N"),
        "mu": _axis("mu", mu, "positive", "1"),
    }
    grid = jnp.broadcast_arrays(*_mesh(*(np.atleast_1d(a) for a in axes.values())))
    displacement, force = fretting_loop(
        amplitude=grid[2], load=grid[3], stiffness=grid[0], mu=grid[4], aspect_ratio=grid[1],
        num=num,
    )  # fmt: skip
    values = jax.device_get(_loop_kernel(*grid))
    values["displacement"] = displacement
    values["force"] = force
    values = {name: np.asarray(value) for name, value in values.items()}
    point = np.arange(2 * num + 1)
    return _dataset(axes, values, "Steady fretting loops", extra={"point": point})


# ---------------------------------------------------------------------------------------
# Maps on a scar profile
# ---------------------------------------------------------------------------------------

MODEL_ON_PROFILE = (
    "compliant wear-scar interaction model on a measured or modelled scar profile: a rigid "
    "round-ended pad with Coulomb friction feels the profile's slope g(X) (eq. 9 pointwise), "
    "driven through a spring of stiffness S (the rig); steady loops of displacement amplitude "
    "Delta* by first passage of the quasi-static return map"
)


@float64
def compute_profile_map(stiffness_ratio, amplitude, mu, load=None, *, profile, mapping="scaled",
                        cache=True, cache_dir=None, max_chunk=MAX_CHUNK) -> xr.Dataset:  # fmt: skip
    r"""The steady-loop quantities on a scar profile over a grid of test conditions.

    Parameters
    ----------
    stiffness_ratio : float or 1-D array_like
        Rig stiffness over normal load :math:`S/P`; ``numpy.inf`` for a rigid rig. [1/m]
    amplitude : float or 1-D array_like
        Displacement amplitude :math:`\Delta^*`. [m]
    mu : float or 1-D array_like
        Contact coefficient of friction :math:`\mu`. [1]
    load : float, optional
        Normal load :math:`P`, for ``dissipated_energy`` and ``max_force``. [N]
    profile : ScarProfile
        The scar (:func:`ecofmaps.scar_profile`, :func:`ecofmaps.read_scar_profile`, a
        profile family).
    mapping : {'scaled', 'physical'}
        :math:`X = xW/x_o` with :math:`x_o = \Delta^*` (eq. 11), or :math:`X = x`.
    cache, cache_dir, max_chunk
        As for :func:`compute_map`; the cache key holds every array of the profile.

    Returns
    -------
    map : xarray.Dataset
        Dimensions ``stiffness_ratio``, ``amplitude``, ``mu`` (those given as arrays), the
        variables of :func:`compute_map`, and the profile's depth, half-width, aspect ratio,
        sample count and the mapping as global attributes. Points where the pad slips off
        the trace have the regime ``BEYOND_PROFILE`` and NaN values.

    Raises
    ------
    ValueError
        As for :func:`compute_map`, and for a missing or bad profile or mapping.

    Notes
    -----
    With the scaled mapping the map depends on :math:`S/P` and :math:`\Delta^*` only through
    :math:`\lambda = P/(S\Delta^*)`, as in eq. 16; the steady loop comes from
    :func:`ecofmaps.model.on_profile.steady_numbers` (one set of tables per :math:`\mu`).

    Examples
    --------
    >>> import numpy as np, ecofmaps
    >>> p = ecofmaps.flat_bottomed_profile(10e-6, 50e-6)
    >>> m = compute_map(np.geomspace(2e4, 2e5, 5), amplitude=50e-6, mu=0.8, profile=p)
    >>> m.ecof_ratio.dims
    ('stiffness_ratio',)
    """
    from ecofmaps.model.on_profile import as_profile, check_mapping, steady_numbers

    if profile is None:
        raise ValueError("compute_map needs aspect_ratio or profile")
    if amplitude is None or mu is None:
        raise ValueError("compute_map needs amplitude and mu")
    physical = check_mapping(mapping, None)
    profile = as_profile(profile)
    axes = {
        "stiffness_ratio": _axis("stiffness_ratio", stiffness_ratio, "positive_or_inf", "1/m"),
        "amplitude": _axis("amplitude", amplitude, "positive", "m"),
        "mu": _axis("mu", mu, "positive", "1"),
    }
    if load is not None:
        load = _axis("load", load, "positive", "N")
        if load.ndim:
            raise ValueError(f"load must be a single value, got shape {load.shape}")
    if not (isinstance(max_chunk, int) and max_chunk >= 1):
        raise ValueError(f"max_chunk must be an integer >= 1, got {max_chunk!r}")

    def compute() -> xr.Dataset:
        grid = [np.atleast_1d(a) for a in axes.values()]
        shape = tuple(a.size for a in grid)
        size = math.prod(shape)
        names = ("slip_ratio", "ecof_ratio", "regime", "normalized_energy", "normalized_max_force")
        flat = {name: np.empty(size, dtype=np.int32 if name == "regime" else np.float64)
                for name in names}  # fmt: skip
        for start in range(0, size, max_chunk):
            index = np.unravel_index(np.arange(start, min(start + max_chunk, size)), shape)
            stiffness, amplitude, mu = (axis[i] for axis, i in zip(grid, index, strict=True))
            # λ = P/(S Δ*) = 1/((S/P) Δ*): a unit load and the stiffness ratio.
            numbers = steady_numbers(profile, amplitude, 1.0, stiffness, mu, mapping=mapping)
            for name in names:
                flat[name][start : start + index[0].size] = np.asarray(numbers[name])
        values = {name: flat[name].reshape(shape) for name in names}
        amplitude = grid[1][None, :, None]
        values["slip_amplitude"] = amplitude * values["slip_ratio"]
        values["ecof"] = grid[2][None, None, :] * values["ecof_ratio"]
        if load is not None:
            values["dissipated_energy"] = load * amplitude * values["normalized_energy"]
            values["max_force"] = load * values["normalized_max_force"]
        del values["normalized_energy"], values["normalized_max_force"]
        stiffness, amplitude = axes["stiffness_ratio"], axes["amplitude"]
        lam = model.compliance_ratio(
            np.atleast_1d(amplitude), 1.0, np.atleast_1d(stiffness)[:, None]
        )
        scalars = tuple(i for i, axis in enumerate((stiffness, amplitude)) if axis.ndim == 0)
        dims = tuple(n for n in ("stiffness_ratio", "amplitude") if axes[n].ndim == 1)
        values["compliance_ratio"] = (dims, np.squeeze(lam, axis=scalars))
        extra = {} if load is None else {"load": load}
        dataset = _dataset(axes, values, "ECoF map of the compliant wear-scar model on a scar "
                           "profile", extra)  # fmt: skip
        dataset.attrs["model"] = MODEL_ON_PROFILE
        dataset.attrs.update(
            scar_depth=float(profile.depth),
            scar_half_width=float(profile.half_width),
            scar_aspect_ratio=float(profile.aspect_ratio),
            scar_samples=int(profile.position.shape[-1]),
            mapping=mapping,
        )
        return dataset

    if not cache:
        return compute()
    inputs = {**axes, "load": load, "mapping": float(physical)}
    inputs.update({f"profile_{name}": value for name, value in profile._asdict().items()})
    return cached_dataset("compute_profile_map", inputs, compute, cache_dir)
