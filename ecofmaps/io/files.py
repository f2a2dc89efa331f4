"""Writing files safely (:func:`atomic_store`; a :data:`MANIFEST` of what the command line
wrote), and where a file is damaged (:class:`FileLineError`); ``docs/formats.md``."""

from __future__ import annotations

import contextlib
import errno
import glob
import hashlib
import json
import os
import re
import shutil
import uuid
from pathlib import Path

from ecofmaps._interrupts import check_interrupted

#: The most bytes of one chunk of a zarr or HDF5 variable: HDF5 keeps a chunk this size in
#: its cache (1 MiB per variable by default), so reads of parts of a chunk read it once.
CHUNK_BYTES = 1 << 20

#: Names of the temporary files :func:`atomic_path` writes (left behind only by a crash).
TEMPORARY_NAME = re.compile(r"^\..+\.[0-9a-f]{32}\.tmp$")

#: A temporary's name: the destination's name, and the process writing it.
_OURS = re.compile(r"^\.(?P<name>.+)\.(?P<pid>\d+)\.[0-9a-f]{32}\.tmp$")

#: The file, in each folder the command line writes into, that lists what it wrote there.
MANIFEST = ".ecofmaps-manifest.json"

#: Files whose presence makes a directory a zarr store (version 3, then version 2).
STORE_MARKERS = ("zarr.json", ".zgroup", ".zarray")


def atomic_path(path, *, exclusive: bool = True):
    """:func:`atomic_store` with ``overwrite=True`` (``exclusive=False``: a file any writer
    may replace with the same content, a cache entry).

    Parameters
    ----------
    path, exclusive
        As in :func:`atomic_store`.

    Returns
    -------
    context : contextlib.AbstractContextManager
    """
    return atomic_store(path, overwrite=True, exclusive=exclusive)


def write_text(path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    path = Path(path)
    with atomic_path(path) as temporary:
        temporary.write_text(text, encoding="utf-8", newline="")
    return path


def _temporary(path: Path) -> Path:
    return path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex}.tmp")


def _remove_dead_temporaries(path: Path) -> None:
    """Remove the temporaries of ``path`` that processes no longer running left."""
    for item in path.parent.glob(f".{glob.escape(path.name)}.*.tmp"):
        ours = _OURS.match(item.name)
        if ours is None or ours["name"] != path.name or int(ours["pid"]) == os.getpid():
            continue
        try:
            os.kill(int(ours["pid"]), 0)
        except ProcessLookupError:
            _remove(item)
        except (PermissionError, OverflowError):  # another user's process, or no process id
            continue


def _create(temporary: Path, path: Path) -> None:
    """Rename ``temporary`` to ``path``, or :class:`FileExistsError` if that exists by now."""
    try:
        try:
            os.link(temporary, path)  # fails if path exists, unlike a rename
        except FileExistsError:
            raise
        except OSError:  # a file system without hard links: claim the name, then rename
            open(path, "x").close()
            os.replace(temporary, path)
            return
    except FileExistsError:
        raise FileExistsError(errno.EEXIST, _RACED, str(path)) from None
    temporary.unlink()


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)


def _sync(path: Path) -> None:
    """Flush a file, or every file and folder of a directory, to disk."""
    paths = [path]
    for folder, _, names in os.walk(path):  # nothing for a file
        paths += [Path(folder)] + [Path(folder) / name for name in names]
    for item in paths:
        descriptor = os.open(item, os.O_RDONLY)
        try:
            os.fsync(descriptor)
        finally:
            os.close(descriptor)


@contextlib.contextmanager
def atomic_store(path, *, overwrite: bool = False, exclusive: bool = True):
    """A temporary path to write a file or a directory store (zarr) at, moved onto ``path``
    when the block succeeds (flushed to disk; an old ``path`` moved aside, then removed).

    Parameters
    ----------
    path : str or os.PathLike
        The file or directory to create; its directory must exist.
    overwrite : bool
        Replace an existing ``path``.
    exclusive : bool
        Whether a file ``path`` that did not exist when the block began is created exclusively.

    Yields
    ------
    temporary : pathlib.Path
        ``.<name>.<process id>.<32 hex digits>.tmp`` beside ``path``, removed if the block
        raises; one a crash left (:data:`TEMPORARY_NAME`) is removed by the next write.

    Raises
    ------
    FileExistsError
        If ``path`` exists and ``overwrite`` is false (before any writing), or (``exclusive``)
        another program created it meanwhile (this result is then not written).
    IsADirectoryError
        If ``path`` is a directory that is not a store (:func:`is_store`), or a store and
        a file was written: a folder is never removed to make room.
    """
    path = Path(path)
    if os.path.lexists(path) and not overwrite:
        message = "exists already (overwrite=True replaces it)"
        raise FileExistsError(errno.EEXIST, message, str(path))
    if path.is_dir() and not is_store(path):
        raise IsADirectoryError(errno.EISDIR, _FOLDER, str(path))
    created = exclusive and not os.path.lexists(path)  # then created, never replaced
    _remove_dead_temporaries(path)
    temporary = _temporary(path)
    try:
        yield temporary
        _sync(temporary)
        check_interrupted()  # after Ctrl-C on the command line, nothing more lands
        if path.is_dir() and not temporary.is_dir():
            raise IsADirectoryError(errno.EISDIR, _FOLDER, str(path))
        if temporary.is_dir() or path.is_dir():
            old = _temporary(path)
            if os.path.lexists(path):
                os.replace(path, old)
            try:
                os.replace(temporary, path)
            except BaseException:
                if os.path.lexists(old):
                    os.replace(old, path)
                raise
            _remove(old)
        elif created:
            _create(temporary, path)
        else:
            os.replace(temporary, path)
    except OSError as error:  # a full disk, say: named by the file asked for
        _remove(temporary)
        if error.errno is None or error.filename not in (None, str(temporary)):
            raise  # not the system's error about this file (a scheduler not answering, say)
        raise type(error)(error.errno, error.strerror, str(path)) from None
    except BaseException:
        _remove(temporary)
        raise


def check_room(path, size: int) -> None:
    """Raise ``OSError`` (ENOSPC) naming ``path`` unless its disk has ``size`` [byte] free and a
    few chunks to spare: HDF5 cannot recover from a failed write (it crashes on closing)."""
    free = shutil.disk_usage(Path(path).parent).free
    if free < size + 4 * CHUNK_BYTES:
        message = f"No space left on device: {size:,} bytes to write, {free:,} free"
        raise OSError(errno.ENOSPC, message, str(path))


_FOLDER = "is a folder, not a store written by ecofmaps: it is not replaced"
_RACED = "was written by another program meanwhile: this result is not written over it"


def is_store(path) -> bool:
    """Whether ``path`` is a directory holding a zarr store (its metadata file at the top)."""
    path = Path(path)
    return path.is_dir() and any((path / name).is_file() for name in STORE_MARKERS)


def _manifest(folder: Path) -> dict:
    """The entries of ``folder``'s manifest."""
    try:
        entries = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))["written"]
    except (OSError, ValueError, KeyError, TypeError):
        return {}
    return entries if isinstance(entries, dict) else {}


def _entry(path: Path) -> dict:
    """What the manifest keeps of ``path``."""
    if path.is_dir():
        return {"store": True}
    with open(path, "rb") as stream:
        digest = hashlib.file_digest(stream, "sha256").hexdigest()
    return {"size": path.stat().st_size, "sha256": digest}


def written_by_ecofmaps(path) -> bool:
    """Whether ``path`` is a file or store that ecofmaps wrote, unchanged since."""
    path = Path(path)
    if path.is_symlink() or not path.exists() or (path.is_dir() and not is_store(path)):
        return False
    recorded = _manifest(path.parent).get(path.name)
    if not isinstance(recorded, dict):
        return False
    if path.is_file() and recorded.get("size") != path.stat().st_size:
        return False  # not the file recorded: no need to read it
    return recorded == _entry(path)


def record_written(paths) -> None:
    """Add files and stores just written to the manifests of their folders (atomically)."""
    folders = {}
    for path in map(Path, paths):
        if path.exists() and not path.is_symlink():
            folders.setdefault(path.parent, {})[path.name] = _entry(path)
    for folder, entries in folders.items():
        for attempt in range(3):  # a run that created the manifest meanwhile: merge with it
            written = _manifest(folder) | entries
            try:
                write_text(folder / MANIFEST, json.dumps({"written": written}, indent=1) + "\n")
                break
            except FileExistsError:
                if attempt == 2:
                    raise


class FileLineError(ValueError):
    """Damaged input: the message names the file and where in it.

    Parameters
    ----------
    path : str or os.PathLike
    line : int, str or None
        The 1-based line of a text file; elsewhere a position such as ``"channel 'Rig/force',
        sample 1200"``; None for the whole file (``position`` is ``'line 12'``, it, or ``''``).
    message : str
        What is wrong (the attribute ``message``).
    """

    def __init__(self, path, line, message: str):
        self.path = Path(path)
        self.message = message
        if line is None or isinstance(line, str):  # a place in a file without lines
            self.line, self.position = None, line or ""
        else:
            self.line = int(line)
            self.position = f"line {self.line}"
        where = f"{self.path}, {self.position}" if self.position else self.path
        super().__init__(f"{where}: {message}")
