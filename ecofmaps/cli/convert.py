"""``ecofmaps convert``: a recording into a chunked store (zarr, HDF5/netCDF, TDMS) or CSV."""

from __future__ import annotations

from pathlib import Path

from ecofmaps.cli._common import (
    CommandError,
    add_recording_options,
    command_parser,
    count,
    option_adder,
    recording_options,
    refuse_to_overwrite,
)
from ecofmaps.io.files import CHUNK_BYTES, record_written

__all__ = ["add", "run"]

_HELP = {
    "source": "the recording to read",
    "destination": "the file or store to write",
    "--chunk-samples": "samples per block read, and per chunk of the store (at most "
    f"{CHUNK_BYTES // 8}, and no more than the recording) (default %(default)s)",
    "--overwrite": "replace DST if ecofmaps wrote it, once the new one is complete (no other)",
}


def add(subparsers) -> None:
    parser = command_parser(
        subparsers,
        "convert",
        help="copy a recording (e.g. a large CSV file) into a chunked zarr, HDF5 or TDMS file",
        description="Copy the displacement, force (and cycle) columns of a recording 'ecofmaps "
        "loops' reads (text, TDMS, HDF5/netCDF-4, zarr) into a file of the format its suffix "
        "names: .zarr, .h5/.nc, .tdms or .csv; in SI units (m, N), missing samples NaN, a block "
        "at a time (memory stays a few blocks), DST appearing once complete. A large text file "
        "converted once is read lazily, in parallel, by 'ecofmaps loops'.",
        epilog="example:\n  ecofmaps convert test.csv test.zarr --displacement-unit um",
    )
    option = option_adder(parser, _HELP)
    option("source", metavar="SRC")
    option("destination", metavar="DST")
    add_recording_options(parser)
    option("--chunk-samples", type=count("samples"), default=1 << 20, metavar="N")
    option("--overwrite", action="store_true")


def run(args) -> int:
    from ecofmaps.io.recordings import read_recording
    from ecofmaps.io.writers import WRITE_FORMATS, convert_recording

    source, destination = Path(args.source), Path(args.destination)
    if destination.suffix.lower() not in WRITE_FORMATS:
        raise CommandError(
            f"cannot tell the format of {destination} from its suffix: use one of "
            f"{', '.join(WRITE_FORMATS)}"
        )
    refuse_to_overwrite([("the destination", destination)], [source], overwrite=args.overwrite)
    options = recording_options(args)
    convert_recording(
        source, destination, chunk_samples=args.chunk_samples, overwrite=args.overwrite, **options
    )
    record_written([destination])
    with read_recording(destination, lazy=True) as written:
        print(f"wrote {destination}: {written.size} samples of {', '.join(written.columns)} (SI)")
    return 0
