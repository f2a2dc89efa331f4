"""The ``ecofmaps`` command: its parser, and the run of one subcommand.

Each subcommand is a module of :mod:`ecofmaps.cli` with ``add(subparsers)``, which declares
its options, and a ``run(args)`` it sets as the handler, which does the work through the
public API. Quantities are read with units (``50um``, ``35MN/m``); a bare number is SI.
Errors in the input end the command with exit status 2 and a one-line message, never a
traceback.
"""

from __future__ import annotations

import argparse
import sys

from ecofmaps._version import __version__
from ecofmaps.cli import cache, correct, figures, loops, model
from ecofmaps.cli import map as grid_map
from ecofmaps.cli._common import CommandError

__all__ = ["build_parser", "main"]

_SUBCOMMANDS = (model, figures, grid_map, cache, loops, correct)


def build_parser() -> argparse.ArgumentParser:
    """The ``ecofmaps`` argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="ecofmaps",
        description=(
            "Fretting friction maps: how far the energy coefficient of friction drifts "
            "from the contact one with rig stiffness and wear-scar shape, the paper's "
            "figures, corrections of reported ECoF values, and the per-cycle analysis of "
            "measured loops (ECoF, GICoF, rig stiffness). Quantities take units: 50um, "
            "450N, 35MN/m."
        ),
    )
    parser.add_argument("--version", action="version", version=f"ecofmaps {__version__}")
    subparsers = parser.add_subparsers(title="commands", metavar="COMMAND", required=True)
    for subcommand in _SUBCOMMANDS:
        subcommand.add(subparsers)
    return parser


def main(argv=None) -> int:
    """Run the ``ecofmaps`` command; return its exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.handler(args)
    except (CommandError, ValueError, OSError) as error:
        print(f"{parser.prog}: error: {error}", file=sys.stderr)
        return 2
