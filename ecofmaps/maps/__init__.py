"""The model over whole grids, as labelled xarray Datasets: in memory (kept in a disk cache)
or chunked (dask), written to netCDF or zarr."""

from ecofmaps.maps.cache import CacheWarning, cache_entries, clear_cache
from ecofmaps.maps.files import write_map
from ecofmaps.maps.grid import (
    compute_loops,
    compute_map,
    compute_profile_map,
    compute_universal_map,
)

__all__ = [
    "CacheWarning",
    "cache_entries",
    "clear_cache",
    "compute_loops",
    "compute_map",
    "compute_profile_map",
    "compute_universal_map",
    "write_map",
]
