"""``ecofmaps cache``: list or clear the cache of computed maps."""

from __future__ import annotations

from ecofmaps.cli import common


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "cache",
        help="list or clear the cache of computed maps",
        description="Computed maps are netCDF files, one per grid and package version, in "
        "--cache-dir, else $ECOFMAPS_CACHE, else the per-user cache directory. 'list' shows "
        "them; 'clear' removes them, JAX's kernels (jax/) and temporaries (no other file).",
    )
    actions = parser.add_subparsers(title="actions", metavar="ACTION", required=True)
    for name, text in (
        ("list", "list the cached maps with their sizes"),
        ("clear", "remove every cached map"),
    ):
        action = actions.add_parser(name, help=text, description=text + ".")
        action.add_argument("--cache-dir", metavar="DIR", help=common.OPTION_HELP["--cache-dir"])
        action.set_defaults(action=name)


def run(args) -> int:
    from ecofmaps.maps.cache import cache_directory, cache_entries, clear_cache

    directory = cache_directory(args.cache_dir)
    if args.action == "clear":
        files, size = clear_cache(directory)
        print(f"removed {files} file(s), {common.byte_size(size)}, from {directory}")
        return 0
    entries = cache_entries(directory)
    if not entries:
        print(f"no cached maps in {directory}")
        return 0
    print(f"cached maps in {directory}:")
    for entry in entries:
        modified = entry.modified.astimezone().strftime("%Y-%m-%d %H:%M:%S")
        print(f"  {common.byte_size(entry.size):>9}  {modified}  {entry.path.name}")
    print(f"{len(entries)} file(s), {common.byte_size(sum(entry.size for entry in entries))}")
    return 0
