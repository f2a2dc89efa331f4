"""Files: atomic writers, file-and-line errors, recordings of fretting loops (text, TDMS,
HDF5/netCDF, zarr), read whole, in blocks or lazily, written block by block; scar profiles."""

from ecofmaps.io.files import FileLineError, atomic_path, atomic_store
from ecofmaps.io.recording_types import Recording, RecordingError, RecordingWarning
from ecofmaps.io.recordings import read_recording, recording_blocks, recording_format
from ecofmaps.io.scar_profiles import ScarProfileError, read_scar_profile
from ecofmaps.io.writers import RecordingWriter, convert_recording

__all__ = [
    "FileLineError",
    "Recording",
    "RecordingError",
    "RecordingWarning",
    "RecordingWriter",
    "ScarProfileError",
    "atomic_path",
    "atomic_store",
    "convert_recording",
    "read_recording",
    "read_scar_profile",
    "recording_blocks",
    "recording_format",
]
