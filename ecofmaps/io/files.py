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
import uuid
from pathlib import Path

from ecofmaps._interrupts import INTERRUPTED

__all__ = ["TEMPORARY_NAME", "FileLineError", "atomic_path"]

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
