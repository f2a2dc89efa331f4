"""The model over whole grids, as labelled xarray Datasets kept in a disk cache."""

from ecofmaps.maps.cache import CacheWarning, cache_entries, clear_cache
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
]
