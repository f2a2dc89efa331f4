"""Writing files safely, and reporting where a file is damaged.

Every file ecofmaps writes (cache entries, figures, result tables) goes through
:func:`atomic_path`: the data are written to a temporary file in the destination's
directory, flushed to disk and renamed onto the destination in one step, so a reader never
sees a half-written file and a failed write leaves an existing file as it was.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import uuid
from pathlib import Path

from ecofmaps._interrupts import INTERRUPTED

__all__ = ["TEMPORARY_NAME", "FileLineError", "atomic_directory", "atomic_path"]

#: Names of the temporary files :func:`atomic_path` writes (left behind only by a crash).
TEMPORARY_NAME = re.compile(r"^\..+\.[0-9a-f]{32}\.tmp$")


@contextlib.contextmanager
def atomic_path(path):
    """A temporary path to write, renamed onto ``path`` when the block succeeds.

    Parameters
    ----------
    path : str or os.PathLike
        The file to create or replace; its directory must exist.

    Yields
    ------
    temporary : pathlib.Path
        ``.<name>.<32 hex digits>.tmp`` beside ``path``: write the whole file there. On
        leaving the block it is flushed to disk and moved onto ``path`` (``os.replace``);
        if the block raises, it is removed and ``path`` is left as it was.
    """
    path = Path(path)
    temporary = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        yield temporary
        with open(temporary, "rb+") as stream:
            os.fsync(stream.fileno())
        if INTERRUPTED.is_set():  # an interrupt that was swallowed on its way up
            raise KeyboardInterrupt
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def atomic_directory(path):
    """A temporary directory path to write, renamed onto ``path`` when the block succeeds.

    For outputs made of many files (a zarr store): a reader never sees a partial store
    under ``path``, and an interrupted or failed write leaves an existing ``path`` as it
    was.

    Parameters
    ----------
    path : str or os.PathLike
        The directory (or file) to create or replace; its parent directory must exist.

    Yields
    ------
    temporary : pathlib.Path
        ``.<name>.<32 hex digits>.tmp`` beside ``path`` (not created): write the whole
        store there. On leaving the block it is renamed onto ``path`` (an existing
        ``path`` is first renamed aside, then removed); if the block raises, it is removed
        and ``path`` is left as it was. Unlike :func:`atomic_path`, the files are not
        flushed to disk one by one (a store may hold thousands).
    """
    path = Path(path)
    temporary = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        yield temporary
        if INTERRUPTED.is_set():  # an interrupt that was swallowed on its way up
            raise KeyboardInterrupt
        if path.exists() or path.is_symlink():
            old = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
            os.replace(path, old)
            try:
                os.replace(temporary, path)
            except BaseException:
                os.replace(old, path)
                raise
            _remove(old)
        else:
            os.replace(temporary, path)
    except BaseException:
        _remove(temporary)
        raise


def _remove(path: Path) -> None:
    """Remove a file or a directory tree, if it is there."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)


class FileLineError(ValueError):
    """Damaged input: the message names the file and the 1-based line number.

    Attributes
    ----------
    path : pathlib.Path
        The file.
    line : int
        1-based line number in the file.
    """

    def __init__(self, path, line: int, message: str):
        self.path = Path(path)
        self.line = int(line)
        super().__init__(f"{self.path}, line {self.line}: {message}")
