"""Ctrl-C and SIGTERM stop the command line at the next safe point, writing nothing more
(standard library only: installed before anything heavy is imported)."""

import contextlib
import signal
import threading

#: The signals :func:`interrupts_stop_writes` turns into a clean stop.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Stop(threading.Event):
    """Set once a stop signal came: the first ``signal``, and ``notes`` (:func:`add_stop_note`)."""

    def __init__(self):
        super().__init__()
        self.signal, self.notes, self.deferred = None, [], 0

    def note(self):
        """What the stop left (after ``interrupted;``): the first note that says something."""
        return next((told for told in (note() for note in self.notes) if told), None)


#: Set by the handler of :func:`interrupts_stop_writes` while it is installed (notes None outside).
INTERRUPTED = Stop()
INTERRUPTED.notes = None


class Interrupted(KeyboardInterrupt):
    """A stop that tells what was kept and how to go on."""

    def __init__(self, note: str):
        super().__init__(note)
        self.note = note


def add_stop_note(note) -> None:
    """Have the line that reports a stop in this block say what ``note()`` returns."""
    if INTERRUPTED.notes is not None:
        INTERRUPTED.notes.append(note)


def check_interrupted() -> None:
    """Raise ``KeyboardInterrupt`` if a stop signal came under :func:`interrupts_stop_writes`."""
    if INTERRUPTED.is_set() and not INTERRUPTED.deferred:
        raise KeyboardInterrupt


def interrupted_waiting(function):
    """``function()`` in a thread of its own while this one acts on a stop within 0.1 s (a
    handler waits for a call into C, such as XLA's compiling, to return)."""
    import concurrent.futures  # not when the command line starts

    check_interrupted()
    pool = concurrent.futures.ThreadPoolExecutor(1)
    future = pool.submit(function)
    pool.shutdown(wait=False)
    while not future.done():
        concurrent.futures.wait([future], 0.1)
        check_interrupted()
    return future.result()  # raised in the waiting thread, if it raised


@contextlib.contextmanager
def interrupts_deferred():
    """Within the block a first stop signal is let pass (to complete an output in place)."""
    INTERRUPTED.deferred += 1
    try:
        yield
    finally:
        INTERRUPTED.deferred -= 1


@contextlib.contextmanager
def interrupts_stop_writes():
    """Within the block, Ctrl-C or SIGTERM stops at the next safe point, writing nothing more."""
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
    INTERRUPTED.signal, INTERRUPTED.notes = None, interrupted.notes
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
