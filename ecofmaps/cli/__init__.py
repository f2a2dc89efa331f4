"""The ``ecofmaps`` command."""

from ecofmaps.cli.main import build_parser, console, main

__all__ = ["build_parser", "console", "main"]
