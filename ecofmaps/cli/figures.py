"""``ecofmaps figures``: write the paper's figures (default: into figures/)."""

from __future__ import annotations

import argparse
import sys
import textwrap
import time
from pathlib import Path

__all__ = ["FIGURE_FORMATS", "add", "figure_formats", "run"]

FIGURE_FORMATS = ("png", "pdf", "svg")


def figure_formats(text: str) -> tuple[str, ...]:
    """An argparse ``type`` reading a comma-separated list of figure file formats."""
    formats = tuple(dict.fromkeys(item.strip().lower() for item in text.split(",")))
    unknown = [item for item in formats if item not in FIGURE_FORMATS]
    if unknown or not formats:
        raise argparse.ArgumentTypeError(
            f"unknown figure format {', '.join(map(repr, unknown))} in {text!r}; "
            f"give one or more of {', '.join(FIGURE_FORMATS)}, comma-separated"
        )
    return formats


def add(subparsers) -> None:
    from ecofmaps.figures.recipes import FIGURES

    listing = "\n".join(f"  {name:<10} {recipe.description}" for name, recipe in FIGURES.items())
    parser = subparsers.add_parser(
        "figures",
        help="write the paper's Figures 5-8 and 11, the universal map and the scar shapes "
        "(default: figures/)",
        description=textwrap.fill(
            "Write the paper's Figures 5, 6, 7a, 7b, 8, 11a, 11b, the universal map of "
            "the ECoF ratio and the comparison of scar shapes at equal D/W (shapes), one file "
            "per figure and format (fig5.png, ...). Parameters are "
            "the paper's: amplitude 50um (= groove half-width), load 450N, stiffness 35MN/m, "
            "mu 0.8. Maps are read from the cache when there (see ECOFMAPS_CACHE) and stored "
            "there otherwise; files are written atomically. Progress goes to stderr.",
            width=80,
        ),
        epilog=f"figures:\n{listing}",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--out", default="figures", metavar="DIR",
        help="directory to write into, created if missing (default: figures)",
    )  # fmt: skip
    parser.add_argument(
        "--only", nargs="+", choices=list(FIGURES), metavar="NAME",
        help=f"write only these figures; NAME is one of: {', '.join(FIGURES)}",
    )  # fmt: skip
    parser.add_argument(
        "--format", type=figure_formats, default=("png",), metavar="FORMATS",
        help="comma-separated file formats among png, pdf, svg (default: png)",
    )  # fmt: skip
    parser.set_defaults(handler=run)


def run(args) -> int:
    from ecofmaps.figures import FIGURES, make_figures, save_figure

    names = list(dict.fromkeys(args.only or FIGURES))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(
        f"ecofmaps figures: {len(names)} figure(s) as {', '.join(args.format)} into {out}",
        file=sys.stderr,
    )
    begin = start = time.perf_counter()
    for index, (name, figure) in enumerate(make_figures(names), start=1):
        paths = [save_figure(figure, out / f"{name}.{suffix}") for suffix in args.format]
        now = time.perf_counter()
        print(
            f"  [{index}/{len(names)}] {name:<10} {now - start:5.1f} s  "
            + ", ".join(str(path) for path in paths),
            file=sys.stderr,
        )
        start = now
    print(f"done in {time.perf_counter() - begin:.1f} s", file=sys.stderr)
    return 0
