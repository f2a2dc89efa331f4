"""Files: atomic writers, file-and-line errors, recordings of fretting loops."""

from ecofmaps.io.files import FileLineError, atomic_path
from ecofmaps.io.recordings import Recording, RecordingError, read_recording

__all__ = ["FileLineError", "Recording", "RecordingError", "atomic_path", "read_recording"]
