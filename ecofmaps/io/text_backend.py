"""Text recordings as the xarray engine ``ecofmaps-text`` (parsed whole when opened): the
Dataset of :func:`~ecofmaps.io.recordings.open_recording`, variables named as its columns."""

from __future__ import annotations

import xarray as xr
from xarray.backends import BackendEntrypoint

from ecofmaps.io.recording_types import RecordingError
from ecofmaps.io.recordings import open_recording, recording_format
from ecofmaps.io.tdms import engine_path, has_suffix

#: The options of :func:`ecofmaps.io.read_recording` the engine takes.
_OPTIONS = ("displacement_column", "force_column", "cycle_column", "displacement_unit")
_OPTIONS += ("force_unit", "nan_policy", "block_bytes")


class TextBackendEntrypoint(BackendEntrypoint):
    """xarray's engine ``ecofmaps-text``: a text recording (CSV, TSV, whitespace columns
    under a header line) as a Dataset over ``sample``, variables named as its columns."""

    description = "Text recordings of fretting loops (CSV, TSV), in SI units (ecofmaps)"
    open_dataset_parameters = ("filename_or_obj", "drop_variables", *_OPTIONS)

    def open_dataset(self, filename_or_obj, *, drop_variables=None, **options) -> xr.Dataset:
        """The recording's columns (``options``: those of ``open_dataset_parameters``, as in
        :func:`ecofmaps.io.read_recording`); a RecordingError for a file that is not text."""
        if unknown := sorted(set(options) - set(_OPTIONS)):
            raise TypeError(f"the ecofmaps-text engine takes no option {unknown[0]!r}")
        path = engine_path(filename_or_obj, "ecofmaps-text")
        kind = recording_format(path)
        if kind != "text":
            engine = "ecofmaps-tdms" if kind == "tdms" else {"hdf5": "h5netcdf"}.get(kind, kind)
            raise RecordingError(path, None, f"a {kind} file, not text: use engine={engine!r}")
        dataset = open_recording(path, **options)
        dataset = dataset.rename_vars({k: v.attrs["source_column"] for k, v in dataset.items()})
        return dataset.drop_vars(drop_variables or [], errors="ignore")

    def guess_can_open(self, filename_or_obj) -> bool:
        """A path ending in ``.csv`` or ``.tsv``."""
        return has_suffix(filename_or_obj, (".csv", ".tsv"))
