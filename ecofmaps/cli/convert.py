"""``ecofmaps convert``: a recording into a chunked store (zarr, HDF5/netCDF, TDMS) or CSV."""

from __future__ import annotations

from pathlib import Path

from ecofmaps.cli import common
from ecofmaps.cli.main import CommandError
from ecofmaps.io.files import CHUNK_BYTES, record_written

_HELP = {
    "source": "the recording to read",
    "destination": "the file or store to write",
    "--chunk-samples": "samples per block read, and per chunk of the store (at most "
    f"{CHUNK_BYTES // 8}, and no more than the recording) (default %(default)s)",
    "--overwrite": "replace DST if ecofmaps wrote it, once the new one is complete (no other)",
}


def add(subparsers) -> None:
    parser = common.command_parser(
        subparsers,
        "convert",
        help="copy a recording (e.g. a large CSV file) into a chunked zarr, HDF5 or TDMS file",
        description="Copy the displacement, force (and cycle) columns of a recording 'ecofmaps "
        "loops' reads into a file of the format its suffix names (.zarr, .h5/.nc, .tdms, .csv), "
        "in SI units (m, N), missing samples NaN, a block at a time, DST appearing once "
        "complete: 'ecofmaps loops' reads a large text file so converted lazily, in parallel.",
        epilog="example:\n  ecofmaps convert test.csv test.zarr --displacement-unit um",
    )
    option = common.option_adder(parser, _HELP)
    option("source", metavar="SRC")
    option("destination", metavar="DST")
    common.add_recording_options(parser)
    option("--chunk-samples", type=common.count("samples"), default=1 << 20, metavar="N")
    option("--overwrite", action="store_true")


def run(args) -> int:
    from ecofmaps.io.recordings import read_recording
    from ecofmaps.io.writers import WRITE_FORMATS, convert_recording

    source, out = Path(args.source), Path(args.destination)
    if out.suffix.lower() not in WRITE_FORMATS:
        formats = ", ".join(WRITE_FORMATS)
        raise CommandError(f"cannot tell the format of {out} from its suffix: use one of {formats}")
    common.refuse_to_overwrite([("the destination", out)], [source], overwrite=args.overwrite)
    options = common.recording_options(args) | {"chunk_samples": args.chunk_samples}
    convert_recording(source, out, overwrite=args.overwrite, **options)
    record_written([out])
    with read_recording(out, lazy=True) as written:
        print(f"wrote {out}: {written.size} samples of {', '.join(written.columns)} (SI)")
    return 0
