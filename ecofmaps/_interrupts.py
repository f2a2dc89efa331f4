"""Ctrl-C that really stops: an interrupt that Python swallowed still stops every write.

Standard library only, so the command line can install it before importing anything heavy.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading

__all__ = ["INTERRUPTED", "interrupts_stop_writes"]

#: Set by the Ctrl-C handler of :func:`interrupts_stop_writes`, only while it is installed.
INTERRUPTED = threading.Event()


@contextlib.contextmanager
def interrupts_stop_writes():
    """Within the block, Ctrl-C stops the program and every write not yet finished.

    Ctrl-C raises ``KeyboardInterrupt`` as usual; it is also remembered, because Python
    swallows an exception raised inside a garbage-collector callback (JAX runs one), and
    then the program would go on. Every :func:`ecofmaps.io.files.atomic_path` finishing
    after the interrupt raises ``KeyboardInterrupt`` instead of renaming its file into
    place, and so does leaving the block. Python's report of the swallowed exception
    (``Exception ignored in: ...``) is not printed. Only in the main thread; where Ctrl-C
    is ignored (a background job) it stays ignored.

    Yields
    ------
    interrupted : threading.Event
        Set once Ctrl-C was pressed in the block; it stays set after the block, so a caller
        can tell an interrupt from the error it turned into (an extension's ImportError).
    """
    interrupted = threading.Event()
    previous = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or previous == signal.SIG_IGN:
        yield interrupted
        return

    def handler(signum, frame):
        interrupted.set()
        INTERRUPTED.set()
        raise KeyboardInterrupt

    previous_hook = sys.unraisablehook

    def unraisable(report):
        if not isinstance(report.exc_value, KeyboardInterrupt):
            previous_hook(report)

    INTERRUPTED.clear()
    signal.signal(signal.SIGINT, handler)
    sys.unraisablehook = unraisable
    try:
        yield interrupted
        if interrupted.is_set():
            raise KeyboardInterrupt
    finally:
        signal.signal(signal.SIGINT, previous)
        sys.unraisablehook = previous_hook
        INTERRUPTED.clear()
