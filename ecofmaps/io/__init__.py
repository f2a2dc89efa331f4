"""Files: atomic writers, file-and-line errors, recordings of fretting loops, scar profiles."""

from ecofmaps.io.files import FileLineError, atomic_path
from ecofmaps.io.recordings import Recording, RecordingError, read_recording
from ecofmaps.io.scar_profiles import ScarProfileError, read_scar_profile

__all__ = [
    "FileLineError",
    "Recording",
    "RecordingError",
    "ScarProfileError",
    "atomic_path",
    "read_recording",
    "read_scar_profile",
]
