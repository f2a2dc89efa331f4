"""``ecofmaps cache``: list or clear the cache of computed maps."""

from __future__ import annotations

import textwrap

__all__ = ["add"]


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
        ("list", "ecofmaps.cli.cache_run:list_cache", "list the cached maps with their sizes"),
        ("clear", "ecofmaps.cli.cache_run:clear", "remove every cached map"),
    ):
        action = actions.add_parser(name, help=text, description=text + ".")
        action.add_argument(
            "--cache-dir", default=None, metavar="DIR",
            help="cache directory (default: $ECOFMAPS_CACHE, else the per-user cache directory)",
        )  # fmt: skip
        action.set_defaults(handler=handler)  # imported when it runs
