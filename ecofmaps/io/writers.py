"""Writing recordings block by block (zarr, HDF5 / netCDF-4, TDMS, CSV), atomically, and
converting any recording into a chunked store with bounded memory (``docs/formats.md``)."""

from __future__ import annotations

import contextlib
import itertools
import sys
import warnings
from pathlib import Path

import numpy as np

from ecofmaps import _nomenclature as nomenclature
from ecofmaps.io.files import CHUNK_BYTES, atomic_store, check_room
from ecofmaps.io.recordings import recording_blocks

#: The format written for each suffix.
WRITE_FORMATS = {".zarr": "zarr", **dict.fromkeys((".h5", ".hdf5", ".nc"), "hdf5")}
WRITE_FORMATS |= {".tdms": "tdms", ".csv": "text"}

#: The attributes of each role's channel (SI units).
ATTRS = {role: nomenclature.attrs(role) for role in ("displacement", "force", "cycle")}

#: The TDMS group that holds the channels written.
TDMS_GROUP = "recording"


class RecordingWriter:
    """Append blocks of samples to a new recording file or store; complete it atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The file or store to create (its directory must exist).
    format : {'zarr', 'hdf5', 'tdms', 'text'}, optional
        By default from the suffix (:data:`WRITE_FORMATS`).
    cycle : bool
        Whether a ``cycle`` column (int64) is written too.
    chunk_samples : int
        Samples per chunk (zarr, HDF5; at most :data:`CHUNK_BYTES`) or segment (TDMS).
    overwrite : bool
        Replace an existing ``path`` (only once the new one is complete).
    attrs : dict, optional
        Attributes (text or numbers) of the file (zarr, HDF5) or the TDMS root.

    Examples
    --------
    >>> import numpy as np, tempfile, pathlib
    >>> from ecofmaps.io import read_recording
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> with RecordingWriter(folder / "a.zarr", chunk_samples=4) as writer:
    ...     writer.write(np.arange(10.0) * 1e-6, np.arange(10.0))
    >>> read_recording(folder / "a.zarr").displacement[:3] * 1e6
    array([0., 1., 2.])
    """

    def __init__(
        self,
        path,
        *,
        format=None,
        cycle: bool = False,
        chunk_samples: int = 1 << 20,
        overwrite: bool = False,
        attrs=None,
    ):
        self.path = Path(path)
        self.format = format or WRITE_FORMATS.get(self.path.suffix.lower())
        if self.format not in WRITE_FORMATS.values():
            raise ValueError(
                f"format must be one of {sorted(set(WRITE_FORMATS.values()))} or given by "
                f"the suffix ({', '.join(WRITE_FORMATS)}); got {format!r} for {self.path.name}"
            )
        if isinstance(chunk_samples, bool) or not int(chunk_samples) == chunk_samples > 0:
            raise ValueError(f"chunk_samples must be a positive integer; got {chunk_samples!r}")
        self.chunk = int(chunk_samples)
        if self.format in ("zarr", "hdf5"):
            self.chunk = min(self.chunk, CHUNK_BYTES // 8)  # float64 and int64
        self.roles = ["displacement", "force"] + (["cycle"] if cycle else [])
        self.attrs = dict(attrs or {})
        self.overwrite = overwrite
        self.size = self._held = 0
        self._pending: dict[str, list] = {role: [] for role in self.roles}

    def __enter__(self) -> RecordingWriter:
        with contextlib.ExitStack() as stack:
            self._temporary = stack.enter_context(atomic_store(self.path, overwrite=self.overwrite))
            getattr(self, f"_open_{self.format}")(stack)
            self._stack = stack.pop_all()
        return self

    def __exit__(self, kind, value, traceback):
        if kind is None:
            try:
                self._flush(everything=True)
                self._finish()
            except BaseException:
                self._stack.__exit__(*sys.exc_info())
                raise
        return self._stack.__exit__(kind, value, traceback)

    def write(self, displacement, force, cycle=None) -> None:
        """Append samples: ``displacement`` [m], ``force`` [N] and, if the writer was made with
        ``cycle=True``, ``cycle`` numbers [1] (array_like, of one length)."""
        given = {"displacement": displacement, "force": force}
        arrays = {role: np.asarray(a, dtype=np.float64).reshape(-1) for role, a in given.items()}
        if "cycle" in self.roles:
            if cycle is None:
                raise ValueError("cycle numbers are required: the writer has a cycle column")
            if not np.all(np.isfinite(cycle := np.asarray(cycle).reshape(-1))):
                raise ValueError("cycle numbers must be finite")
            arrays["cycle"] = cycle.astype(np.int64)
        sizes = {role: array.size for role, array in arrays.items()}
        if len(set(sizes.values())) != 1:
            raise ValueError(f"the blocks must have one length; got {sizes}")
        for role in self.roles:
            self._pending[role].append(arrays[role])
        self._held += sizes["displacement"]
        self._flush(everything=False)

    def _flush(self, everything: bool) -> None:
        count = self._held if everything else self._held // self.chunk * self.chunk
        if count == 0:
            return
        joined = {role: np.concatenate(parts) for role, parts in self._pending.items()}
        if self.format == "hdf5":
            check_room(self._temporary, count * 8 * len(self.roles))
        getattr(self, f"_append_{self.format}")({role: a[:count] for role, a in joined.items()})
        self._pending = {role: [array[count:]] for role, array in joined.items()}
        self._held -= count
        self.size += count

    def _first_chunks(self, arrays) -> tuple[int]:
        """The chunks, chosen at the first write: fewer samples if the recording has fewer."""
        return (max(1, min(self.chunk, next(iter(arrays.values())).size)),)

    def _open_zarr(self, stack) -> None:
        import zarr

        self._handle = zarr.open_group(str(self._temporary), mode="w-")
        self._handle.attrs.update(self.attrs)

    def _append_zarr(self, arrays) -> None:
        if self.size == 0:
            self._arrays = {
                role: self._handle.create_array(
                    role,
                    shape=(0,),
                    chunks=self._first_chunks(arrays),
                    dtype=np.int64 if role == "cycle" else np.float64,
                    fill_value=-1 if role == "cycle" else np.nan,
                    dimension_names=["sample"],
                    compressors=None,
                    attributes=ATTRS[role],
                    config={"write_empty_chunks": True},
                )
                for role in self.roles
            }
        for role, array in arrays.items():
            self._arrays[role].append(array)

    def _open_hdf5(self, stack) -> None:
        import h5netcdf

        self._handle = stack.enter_context(h5netcdf.File(self._temporary, "w"))
        self._handle.dimensions = {"sample": None}
        self._handle.attrs.update(self.attrs)

    def _append_hdf5(self, arrays) -> None:
        if self.size == 0:
            self._arrays = {}
            for role in self.roles:
                dtype = np.int64 if role == "cycle" else np.float64
                self._arrays[role] = self._handle.create_variable(
                    role, ("sample",), dtype, chunks=self._first_chunks(arrays)
                )
                self._arrays[role].attrs.update(ATTRS[role])
        count = next(iter(arrays.values())).size
        self._handle.resize_dimension("sample", self.size + count)
        for role, array in arrays.items():
            self._arrays[role][self.size : self.size + count] = array

    def _open_tdms(self, stack) -> None:
        from nptdms import TdmsWriter

        self._handle = stack.enter_context(TdmsWriter(str(self._temporary)))

    def _append_tdms(self, arrays) -> None:
        from nptdms import ChannelObject, GroupObject, RootObject

        first = self.size == 0
        root = {k: v if isinstance(v, int | float | str) else str(v) for k, v in self.attrs.items()}
        objects = [RootObject(properties=root if first else {}), GroupObject(TDMS_GROUP)]
        for role, array in arrays.items():
            units, name = ATTRS[role]["units"], ATTRS[role]["long_name"]
            properties = {"unit_string": units, "description": name} if first else {}
            objects.append(ChannelObject(TDMS_GROUP, role, array, properties=properties))
        self._handle.write_segment(objects)

    def _open_text(self, stack) -> None:
        self._handle = stack.enter_context(
            open(self._temporary, "w", encoding="utf-8", newline="\n")  # noqa: SIM115
        )
        self._handle.writelines(f"# {key}: {value}\n" for key, value in self.attrs.items())
        names = (
            role if role == "cycle" else f"{role} [{ATTRS[role]['units']}]" for role in self.roles
        )
        self._handle.write(",".join(names) + "\n")

    def _append_text(self, arrays) -> None:
        # Each float as its shortest repr, which reads back bit for bit (as to_csv, faster).
        cells = [map(repr, arrays[role].tolist()) for role in self.roles]
        self._handle.write("\n".join(map(",".join, zip(*cells, strict=True))) + "\n")

    def _finish(self) -> None:
        if self.size == 0 and self.format != "text":  # the variables or channels, empty
            getattr(self, f"_append_{self.format}")({role: np.zeros(0) for role in self.roles})
        if self.format == "zarr":
            import zarr

            # xarray opens a consolidated store without a warning (zarr's: not in format 3 yet)
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", "Consolidated metadata", UserWarning)
                zarr.consolidate_metadata(str(self._temporary))


def convert_recording(
    source, destination, *, format=None, chunk_samples: int = 1 << 20, overwrite=False, **options
) -> Path:
    """Copy a recording into a chunked store (or another format), block by block.

    Parameters
    ----------
    source : str or os.PathLike
        Any recording :func:`ecofmaps.io.read_recording` reads.
    destination : str or os.PathLike
        The file or store to create: ``.zarr``, ``.h5``/``.nc``, ``.tdms`` or ``.csv``.
    format, chunk_samples, overwrite
        As in :class:`RecordingWriter`; ``chunk_samples`` is also the block read.
    **options
        As in :func:`ecofmaps.io.read_recording` (columns, units, group, nan_policy).

    Returns
    -------
    destination : pathlib.Path
        Samples in SI units (m, N), missing ones NaN; its attributes name the source, its
        columns and their units.

    Raises
    ------
    RecordingError
        For a damaged source (nothing is left at ``destination``).
    ValueError
        If ``destination`` is ``source``, or for bad options.
    """
    source, destination = Path(source), Path(destination)
    if destination.resolve() == source.resolve():
        raise ValueError(f"convert_recording would write over its source {source}")
    blocks = recording_blocks(source, samples=chunk_samples, **options)
    first = next(blocks)
    attrs = {
        "source": str(source),
        "source_columns": ", ".join(f"{k}: {v}" for k, v in first.columns.items()),
        "source_units": ", ".join(f"{k}: {v}" for k, v in first.units.items()),
    }
    with RecordingWriter(
        destination,
        format=format,
        cycle=first.cycle is not None,
        chunk_samples=chunk_samples,
        overwrite=overwrite,
        attrs=attrs,
    ) as writer:
        for block in itertools.chain([first], blocks):
            writer.write(block.displacement, block.force, block.cycle)
    return destination
