"""Ctrl-C that stops the command line cleanly, at the next safe point, writing nothing more.

Standard library only, so the command line can install it before importing anything heavy.
"""

from __future__ import annotations

import contextlib
import signal
import threading

__all__ = ["INTERRUPTED", "check_interrupted", "interrupts_stop_writes"]

#: Set by the Ctrl-C handler of :func:`interrupts_stop_writes`, only while it is installed.
INTERRUPTED = threading.Event()


def check_interrupted() -> None:
    """Raise ``KeyboardInterrupt`` if Ctrl-C was pressed under :func:`interrupts_stop_writes`.

    Called where stopping is safe: between blocks of work and before a file is renamed into
    place. Outside the block (the library used from Python) it does nothing.
    """
    if INTERRUPTED.is_set():
        raise KeyboardInterrupt


@contextlib.contextmanager
def interrupts_stop_writes():
    """Within the block, Ctrl-C stops the program at the next safe point, writing nothing more.

    The first Ctrl-C only sets a flag; :func:`check_interrupted`, called between blocks of
    work and before every :func:`ecofmaps.io.files.atomic_store` renames its file into
    place, then raises ``KeyboardInterrupt``, and so does leaving the block. A
    ``KeyboardInterrupt`` raised at once, anywhere, would land inside JAX's compiled
    extensions (during their import, or in a garbage-collector callback) and crash the
    process or be swallowed there. A second Ctrl-C raises at once. Only in the main
    thread; where Ctrl-C is ignored (a background job) it stays ignored.

    Yields
    ------
    interrupted : threading.Event
        Set once Ctrl-C was pressed in the block; it stays set after the block, so a caller
        can tell an interrupt from an error it caused.
    """
    interrupted = threading.Event()
    previous = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or previous == signal.SIG_IGN:
        yield interrupted
        return

    def handler(signum, frame):
        if interrupted.is_set():  # the second Ctrl-C: stop now
            raise KeyboardInterrupt
        interrupted.set()
        INTERRUPTED.set()

    INTERRUPTED.clear()
    signal.signal(signal.SIGINT, handler)
    try:
        yield interrupted
        check_interrupted()
    finally:
        signal.signal(signal.SIGINT, previous)
        INTERRUPTED.clear()
