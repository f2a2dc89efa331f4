"""Ctrl-C and SIGTERM that stop the command line cleanly, at the next safe point, writing
nothing more (standard library only: installed before anything heavy is imported).
"""

from __future__ import annotations

import contextlib
import signal
import threading

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
        """What the stop left (the sentence after ``interrupted;``): the first of :attr:`notes`
        that has something to say, or None."""
        return next((told for told in (note() for note in self.notes) if told), None)


#: Set by the handler of :func:`interrupts_stop_writes`, only while it is installed; its
#: :attr:`Stop.notes` are the block's while one runs, None outside.
INTERRUPTED = Stop()
INTERRUPTED.notes = None


class Interrupted(KeyboardInterrupt):
    """A stop by Ctrl-C or SIGTERM that has something to tell: what was kept, how to go on."""

    def __init__(self, note: str):
        super().__init__(note)
        self.note = note


def add_stop_note(note) -> None:
    """Have the line that reports a stop in the running :func:`interrupts_stop_writes`
    block say what ``note()`` returns when the line is written."""
    if INTERRUPTED.notes is not None:
        INTERRUPTED.notes.append(note)


def check_interrupted() -> None:
    """Raise ``KeyboardInterrupt`` if Ctrl-C was pressed (or SIGTERM came) under
    :func:`interrupts_stop_writes`."""
    if INTERRUPTED.is_set() and not INTERRUPTED.deferred:
        raise KeyboardInterrupt


def interrupted_waiting(function):
    """``function()`` run in a thread of its own, its exception raised here, while this one
    acts on a stop within 0.1 s (a signal's handler waits for a call into C, such as XLA's
    compiling, to return); on a stop the thread is left running."""
    check_interrupted()
    outcome = []

    def run():
        try:
            outcome.append((function(), None))
        except BaseException as error:  # raised in the waiting thread
            outcome.append((None, error))

    thread = threading.Thread(target=run)
    thread.start()
    while thread.is_alive():
        thread.join(0.1)
        check_interrupted()
    result, error = outcome[0]
    if error is not None:
        raise error
    return result


@contextlib.contextmanager
def interrupts_deferred():
    """Within the block, :func:`check_interrupted` lets a first stop signal pass: for what
    completes an output already in place (the record of the files a command wrote)."""
    INTERRUPTED.deferred += 1
    try:
        yield
    finally:
        INTERRUPTED.deferred -= 1


@contextlib.contextmanager
def interrupts_stop_writes():
    """Within the block, Ctrl-C or SIGTERM stops the program at the next safe point, writing
    nothing more."""
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
