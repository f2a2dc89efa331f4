"""Ctrl-C and SIGTERM that stop the command line cleanly, at the next safe point, writing
nothing more.

Standard library only, so the command line can install it before importing anything heavy.
"""

from __future__ import annotations

import contextlib
import signal
import threading

__all__ = [
    "INTERRUPTED",
    "STOP_SIGNALS",
    "Interrupted",
    "Stop",
    "add_stop_note",
    "check_interrupted",
    "interrupts_deferred",
    "interrupts_stop_writes",
]

#: The signals :func:`interrupts_stop_writes` turns into a clean stop: Ctrl-C (SIGINT) and
#: SIGTERM (``kill``, a batch system ending a job).
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Stop(threading.Event):
    """Set once a stop signal came; :attr:`signal` is the first one (None before), and
    :attr:`notes` the functions :func:`add_stop_note` gave to tell what a stop left."""

    def __init__(self):
        super().__init__()
        self.signal = None
        self.notes = []
        self.deferred = 0

    def note(self):
        """What the stop left, as the first of :attr:`notes` that has something to say
        tells it now (the sentence after ``interrupted;``), or None."""
        for note in self.notes:
            told = note()
            if told:
                return told
        return None


#: Set by the handler of :func:`interrupts_stop_writes`, only while it is installed; its
#: :attr:`Stop.notes` are the block's while one runs, None outside.
INTERRUPTED = Stop()
INTERRUPTED.notes = None


class Interrupted(KeyboardInterrupt):
    """A stop by Ctrl-C or SIGTERM that has something to tell: what was kept, how to go on.

    Parameters
    ----------
    note : str
        One sentence for the user, printed after ``interrupted;`` on the same line.
    """

    def __init__(self, note: str):
        super().__init__(note)
        self.note = note


def add_stop_note(note) -> None:
    """Have the line that reports a stop in the running :func:`interrupts_stop_writes`
    block say what ``note()`` returns when the line is written.

    Asked then, once everything the stop interrupted has unwound, ``note`` tells what is
    left at that moment (a resume folder kept, say), not what was left when the signal
    came: a block of work that lands in between cannot make the line untrue. It returns a
    sentence, or None when it has nothing to say (the line then says that nothing was left
    half written). Outside such a block (the library used from Python) it is not kept.

    Parameters
    ----------
    note : callable
        Called without arguments; returns str or None.
    """
    if INTERRUPTED.notes is not None:
        INTERRUPTED.notes.append(note)


def check_interrupted() -> None:
    """Raise ``KeyboardInterrupt`` if Ctrl-C was pressed (or SIGTERM came) under
    :func:`interrupts_stop_writes`.

    Called where stopping is safe: between blocks of work and before a file is renamed into
    place. Outside the block (the library used from Python), and within
    :func:`interrupts_deferred`, it does nothing.
    """
    if INTERRUPTED.is_set() and not INTERRUPTED.deferred:
        raise KeyboardInterrupt


@contextlib.contextmanager
def interrupts_deferred():
    """Within the block, a stop signal does not stop the work at :func:`check_interrupted`:
    for what completes an output already in place (the record of the files a command
    wrote, say), which a stop would leave complete but unrecorded. Leaving the
    :func:`interrupts_stop_writes` block still raises ``KeyboardInterrupt``, unless the
    command's work returned (:func:`ecofmaps.cli.main.main`). A second signal still stops
    at once.
    """
    INTERRUPTED.deferred += 1
    try:
        yield
    finally:
        INTERRUPTED.deferred -= 1


@contextlib.contextmanager
def interrupts_stop_writes():
    """Within the block, Ctrl-C or SIGTERM stops the program at the next safe point, writing
    nothing more.

    The first signal only sets a flag; :func:`check_interrupted`, called between blocks of
    work and before every :func:`ecofmaps.io.files.atomic_store` renames its file into
    place, then raises ``KeyboardInterrupt``, and so does leaving the block. A
    ``KeyboardInterrupt`` raised at once, anywhere, would land inside JAX's compiled
    extensions (during their import, or in a garbage-collector callback) and crash the
    process or be swallowed there. A second signal raises at once. Only in the main
    thread; a signal that is ignored (Ctrl-C in a background job), or whose handler was
    not set from Python, is left alone.

    Yields
    ------
    interrupted : Stop
        Set once a stop signal came in the block, with the signal's number in its
        ``signal``; it stays set after the block, so a caller can tell an interrupt from
        an error it caused, and which signal it was.
    """
    interrupted = Stop()
    if threading.current_thread() is not threading.main_thread():
        yield interrupted
        return
    previous = {number: signal.getsignal(number) for number in STOP_SIGNALS}

    def handler(signum, frame):
        if interrupted.is_set():  # the second signal: stop now
            raise KeyboardInterrupt
        interrupted.signal = INTERRUPTED.signal = signal.Signals(signum)
        interrupted.set()
        INTERRUPTED.set()

    INTERRUPTED.clear()
    INTERRUPTED.signal = None
    INTERRUPTED.notes = interrupted.notes
    ours = [number for number, before in previous.items() if before not in (signal.SIG_IGN, None)]
    for number in ours:
        signal.signal(number, handler)
    try:
        yield interrupted
        check_interrupted()
    finally:
        for number in ours:
            signal.signal(number, previous[number])
        INTERRUPTED.clear()
        INTERRUPTED.signal = INTERRUPTED.notes = None
