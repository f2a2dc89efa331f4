"""Files: atomic writers, file-and-line errors, recordings of fretting loops (text, TDMS,
HDF5/netCDF, zarr) read whole, in blocks, lazily or as one Dataset (:func:`open_recording`),
written block by block; scar profiles. TDMS and text recordings also open in xarray itself:
``xr.open_dataset(path, engine="ecofmaps-tdms")`` (or ``"ecofmaps-text"``)."""

from ecofmaps._lazy import lazy_names

#: Each public name, by the module that defines it (imported on first use).
_PUBLIC = {
    "ecofmaps.io.files": ("FileLineError", "atomic_path", "atomic_store"),
    "ecofmaps.io.recording_types": ("Recording", "RecordingError", "RecordingWarning"),
    "ecofmaps.io.recordings": (
        "open_recording",
        "read_recording",
        "recording_blocks",
        "recording_format",
    ),
    "ecofmaps.io.scar_profiles": ("ScarProfileError", "read_scar_profile"),
    "ecofmaps.io.writers": ("RecordingWriter", "convert_recording"),
}

__getattr__, __dir__, __all__ = lazy_names(__name__, _PUBLIC)
