"""The work of ``ecofmaps cache`` (its options are in :mod:`ecofmaps.cli.cache`)."""

from __future__ import annotations

from ecofmaps.maps.cache import cache_directory, cache_entries, clear_cache

__all__ = ["clear", "list_cache"]


def _size(count: int) -> str:
    """A byte count for people: 512 B, 12.3 kB, 4.5 MB."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if count >= scale:
            return f"{count / scale:.1f} {unit}"
    return f"{count} B"


def list_cache(args) -> int:
    """``ecofmaps cache list``: the cached maps with their sizes; the exit status."""
    directory = cache_directory(args.cache_dir)
    entries = cache_entries(directory)
    if not entries:
        print(f"no cached maps in {directory}")
        return 0
    print(f"cached maps in {directory}:")
    for entry in entries:
        modified = entry.modified.astimezone().strftime("%Y-%m-%d %H:%M:%S")
        print(f"  {_size(entry.size):>9}  {modified}  {entry.path.name}")
    total = sum(entry.size for entry in entries)
    print(f"{len(entries)} file(s), {_size(total)}")
    return 0


def clear(args) -> int:
    """``ecofmaps cache clear``: every cached map removed; the exit status."""
    directory = cache_directory(args.cache_dir)
    count, size = clear_cache(directory)
    print(f"removed {count} file(s), {_size(size)}, from {directory}")
    return 0
