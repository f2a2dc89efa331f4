"""``ecofmaps cache``: list or clear the cache of computed maps."""

from __future__ import annotations

import textwrap

__all__ = ["add"]


def _size(count: int) -> str:
    """A byte count for people: 512 B, 12.3 kB, 4.5 MB."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if count >= scale:
            return f"{count / scale:.1f} {unit}"
    return f"{count} B"


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "cache",
        help="list or clear the cache of computed maps",
        description=textwrap.fill(
            "Computed maps are kept as netCDF files, one per grid and package version, in the "
            "directory given by --cache-dir, else the ECOFMAPS_CACHE environment variable, "
            "else the per-user cache directory. 'list' shows them with their sizes; 'clear' "
            "removes them (and temporary files of interrupted writes; other files are left "
            "alone).",
            width=80,
        ),
    )
    actions = parser.add_subparsers(title="actions", metavar="ACTION", required=True)
    for name, handler, text in (
        ("list", _run_cache_list, "list the cached maps with their sizes"),
        ("clear", _run_cache_clear, "remove every cached map"),
    ):
        action = actions.add_parser(name, help=text, description=text + ".")
        action.add_argument(
            "--cache-dir", default=None, metavar="DIR",
            help="cache directory (default: $ECOFMAPS_CACHE, else the per-user cache directory)",
        )  # fmt: skip
        action.set_defaults(handler=handler)


def _run_cache_list(args) -> int:
    from ecofmaps.maps.cache import cache_directory, cache_entries

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


def _run_cache_clear(args) -> int:
    from ecofmaps.maps.cache import cache_directory, clear_cache

    directory = cache_directory(args.cache_dir)
    count, size = clear_cache(directory)
    print(f"removed {count} file(s), {_size(size)}, from {directory}")
    return 0
