"""The work of ``ecofmaps convert`` (its options are in :mod:`ecofmaps.cli.convert`): a
recording rewritten in a chunked format."""

from __future__ import annotations

from pathlib import Path

from ecofmaps.cli._common import CommandError, recording_options, refuse_to_overwrite
from ecofmaps.io.files import record_written
from ecofmaps.io.recordings import read_recording
from ecofmaps.io.writers import WRITE_FORMATS, convert_recording

__all__ = ["run"]


def run(args) -> int:
    """Run ``ecofmaps convert`` with the parsed ``args``; the exit status."""
    source, destination = Path(args.source), Path(args.destination)
    if destination.suffix.lower() not in WRITE_FORMATS:
        raise CommandError(
            f"cannot tell the format of {destination} from its suffix: use one of "
            f"{', '.join(WRITE_FORMATS)}"
        )
    if not destination.parent.is_dir():
        raise CommandError(f"cannot write {destination}: its directory does not exist")
    refuse_to_overwrite([("DST", destination)], [source], overwrite=args.overwrite)
    convert_recording(
        source,
        destination,
        chunk_samples=args.chunk_samples,
        overwrite=args.overwrite,
        **recording_options(args),
    )
    record_written([destination])
    written = read_recording(destination, lazy=True)
    print(f"wrote {destination}: {written.size} samples of {', '.join(written.columns)} (SI)")
    return 0
