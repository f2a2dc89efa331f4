"""``ecofmaps convert``: a recording into a chunked store (zarr, HDF5/netCDF, TDMS) or CSV."""

from __future__ import annotations

import argparse
import textwrap

from ecofmaps.cli._common import unit

__all__ = ["add"]


def _samples(text: str) -> int:
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if not (value >= 1 and value.is_integer()):
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number of samples >= 1")
    return int(value)


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "convert",
        help="copy a recording (e.g. a large CSV file) into a chunked zarr, HDF5 or TDMS file",
        description=textwrap.fill(
            "Copy the displacement, force (and cycle) columns of a recording that 'ecofmaps "
            "loops' reads (text, TDMS, HDF5/netCDF-4, zarr) into a new file whose format is "
            "given by its suffix: .zarr, .h5/.nc, .tdms or .csv. The samples are stored in SI "
            "units (m, N) with their units, missing ones as NaN, a block at a time (memory "
            "stays near a few blocks whatever the size), and DST appears only once complete. "
            "A large text file converted once is read lazily, in parallel, by 'ecofmaps loops'.",
            width=80,
        ),
        epilog="example:\n  ecofmaps convert test.csv test.zarr --displacement-unit um",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("source", metavar="SRC", help="the recording to read")
    parser.add_argument("destination", metavar="DST", help="the file or store to write")
    parser.add_argument("--displacement-col", default="displacement", metavar="NAME")
    parser.add_argument("--force-col", default="force", metavar="NAME")
    parser.add_argument("--cycle-col", default=None, metavar="NAME")
    parser.add_argument(
        "--skip-rows", type=int, default=None, metavar="N",
        help="lines of a text file to skip before its header (default: found)",
    )  # fmt: skip
    parser.add_argument(
        "--displacement-unit", type=unit("length"), default=None, metavar="UNIT",
        help="unit of the displacement column (default: from its name or the file, else um)",
    )  # fmt: skip
    parser.add_argument(
        "--force-unit", type=unit("force"), default=None, metavar="UNIT",
        help="unit of the force column (default: from its name or the file, else N)",
    )  # fmt: skip
    parser.add_argument("--group", default=None, metavar="NAME", help="TDMS/HDF5/zarr group")
    parser.add_argument(
        "--chunk-samples", type=_samples, default=1 << 20, metavar="N",
        help="samples per chunk of the store, and per block read (default 1048576)",
    )  # fmt: skip
    parser.add_argument(
        "--overwrite", action="store_true",
        help="replace DST if ecofmaps wrote it (once the new one is complete); a file or "
        "folder ecofmaps did not write is never replaced",
    )  # fmt: skip
    parser.set_defaults(handler="ecofmaps.cli.convert_run:run")  # imported when it runs
