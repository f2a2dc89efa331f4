"""Maps written to a netCDF file or a zarr store, block by block when they are chunked
(docs/performance.md, "Maps")."""

from __future__ import annotations

import concurrent.futures
from collections.abc import Sequence
from pathlib import Path

import xarray as xr

from ecofmaps.io.files import atomic_store, check_room
from ecofmaps.maps.tiles import tile_workers

#: The suffix of the paths that :func:`write_map` writes as zarr stores.
ZARR_SUFFIX = ".zarr"


def write_map(dataset: xr.Dataset, path, *, also: Sequence = ()) -> tuple:
    """Write a map to a netCDF file, or to a zarr store if ``path`` ends in ``.zarr``.

    Parameters
    ----------
    dataset : xarray.Dataset
        A map, in memory or chunked (evaluated block by block as it is written).
    path : str or os.PathLike
        The file (netCDF 4, engine h5netcdf) or zarr store (format 2, consolidated, a
        directory) to create or replace, complete or not at all; its parent must exist.
    also : sequence of dask or NumPy arrays, optional
        Values computed in the same pass over the blocks (e.g. ``dataset.regime.max().data``).

    Returns
    -------
    values : tuple
        The computed values of ``also``, in order.

    Raises
    ------
    ValueError
        If ``path`` is a directory that is not a zarr store, or a directory where a
        netCDF file is asked for (nothing is replaced).
    OSError
        If the output cannot be written (the temporary output is removed).

    Examples
    --------
    >>> import numpy as np, tempfile, ecofmaps
    >>> lazy = ecofmaps.compute_map(np.geomspace(2e4, 2e5, 30), 0.3, 50e-6, 0.8, chunks=10)
    >>> with tempfile.TemporaryDirectory() as directory:
    ...     (top,) = write_map(lazy, f"{directory}/map.zarr", also=[lazy.ecof_ratio.max().data])
    >>> round(float(top), 4)
    1.1361
    """
    import dask

    path = Path(path)
    zarr = path.suffix == ZARR_SUFFIX
    if path.is_dir() and not zarr:
        raise ValueError(f"{path} is a directory: a netCDF file cannot replace it")
    if path.is_dir() and not any((path / n).is_file() for n in ("zarr.json", ".zgroup", ".zarray")):
        raise ValueError(f"{path} is a directory but not a zarr store: it is not replaced")
    with atomic_store(path, overwrite=True) as temporary:
        if zarr:
            written = dataset.to_zarr(temporary, compute=False, zarr_format=2, consolidated=True)
        else:
            check_room(temporary, dataset.nbytes)
            written = dataset.to_netcdf(temporary, engine="h5netcdf", compute=False)
        pool = concurrent.futures.ThreadPoolExecutor(tile_workers())
        try:
            _, *values = dask.compute(written, *also, scheduler="threads", pool=pool)
        finally:  # queued blocks are dropped, running ones end before the output is removed
            pool.shutdown(wait=True, cancel_futures=True)
    return tuple(values)
