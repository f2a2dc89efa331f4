"""The ``ecofmaps`` command."""

from ecofmaps.cli.main import build_parser, main

__all__ = ["build_parser", "main"]
