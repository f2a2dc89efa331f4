"""Blocks of work run on local threads or on a dask cluster, their results in order as they
come; Ctrl-C stops at the next block (``docs/parallel.md``)."""

import asyncio
import collections
import concurrent.futures
import contextlib
import itertools
import logging
import os
import signal
import threading
import time
import warnings
from multiprocessing import resource_tracker

from ecofmaps._interrupts import check_interrupted

#: Seconds to wait for a dask scheduler given by address to answer.
CONNECT_TIMEOUT = 5.0

#: Memory a local cluster's worker process needs: NumPy, JAX, dask and a block loaded. [byte]
WORKER_MEMORY = 512 * 2**20

#: Seconds between looks at a running task (and at Ctrl-C).
_POLL = 0.01

#: The attribute of a dask array holding its source when that reads samples (:func:`stretch`).
SOURCE = "ecofmaps_source"


class SchedulerError(OSError):
    """A dask scheduler that cannot be reached (the message names its address)."""


class Slice:
    """``source[start:stop]``, read where the task that receives it runs."""

    __slots__ = ("source", "start", "stop")

    def __init__(self, source, start: int, stop: int):
        self.source, self.start, self.stop = source, int(start), int(stop)

    def read(self):
        return self.source[self.start : self.stop]


def stretch(array, start: int, stop: int):
    """``array[start:stop]`` for a task to read where it runs."""
    source = getattr(array, SOURCE, None)
    return array[start:stop] if source is None else Slice(source, start, stop)


def _call(function, arguments):
    """``function(*arguments)`` where the task runs, its Slices read, dask collections computed."""
    import dask

    arguments = tuple(a.read() if isinstance(a, Slice) else a for a in arguments)
    if any(dask.is_dask_collection(value) for value in arguments):
        arguments = dask.compute(*arguments, scheduler="sync")
    return function(*arguments)


class Runner:
    """Run tasks, a bounded number at a time, in a ``with`` block: on ``workers`` threads, a new
    ``LocalCluster`` (``cluster=True``), a ``scheduler``'s address or a ``client`` (left open)."""

    def __init__(self, workers=None, *, scheduler=None, cluster=False, client=None, timeout=None):
        if scheduler is not None and cluster:
            raise ValueError("give a scheduler address or start a local cluster, not both")
        self.local = scheduler is None and client is None  # the tasks see this machine's files
        check_workers(workers, processes=cluster, here=self.local)
        self.scheduler, self.cluster, self.timeout = scheduler, cluster, timeout
        self.workers = int(workers) if workers else (1 if scheduler else os.cpu_count() or 1)
        self._given = client
        self._client = self._cluster = self._pool = None

    def __enter__(self) -> "Runner":
        if not self.local:
            self._client = self._given
            if self._client is None:
                self._client = _connect(self.scheduler, self.timeout or CONNECT_TIMEOUT)
            self.workers = max(len(self._client.scheduler_info()["workers"]), 1)
        elif self.cluster:
            import dask
            from distributed import Client, LocalCluster

            # No MALLOC_TRIM_THRESHOLD_ (with it glibc maps every NumPy temporary above 128 kB
            # afresh), no sampling of the task's stack for a dashboard (it takes the GIL).
            environ = dask.config.get("distributed.nanny.pre-spawn-environ")
            environ = {k: v for k, v in environ.items() if k != "MALLOC_TRIM_THRESHOLD_"}
            settings = {
                "distributed.nanny.pre-spawn-environ": environ,
                "distributed.worker.profile.enabled": False,
            }
            check_interrupted()  # stopped before the cluster starts: start none
            # before Ctrl-C is held: starting the tracker unblocks SIGINT in this thread
            start_resource_tracker_quietly()
            with dask.config.set(settings), _sigint_held():
                self._cluster = LocalCluster(
                    n_workers=self.workers,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    # the scheduler's HTTP server on a free port: two runs at once, no warning
                    scheduler_kwargs={"dashboard_address": ":0"},
                    # no log: a task's error comes back here, and Ctrl-C's farewells are noise
                    silence_logs=logging.CRITICAL + 1,
                )
                self._client = Client(self._cluster, set_as_default=False)
            try:
                check_interrupted()  # a signal held while the cluster started
            except KeyboardInterrupt:  # no with block runs: close the cluster here
                self.__exit__(KeyboardInterrupt, None, None)
                raise
        else:
            self._pool = concurrent.futures.ThreadPoolExecutor(self.workers)
        return self

    def __exit__(self, *exc):
        if exc[0] is not None and issubclass(exc[0], KeyboardInterrupt):
            for name in ("distributed", "tornado", "asyncio"):  # the cluster's farewells: noise
                logging.getLogger(name).setLevel(logging.CRITICAL + 1)
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
        if self._client is not None and self._given is None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()
        self._client = self._cluster = self._pool = None

    def _submit(self, function, arguments):
        if self._pool is not None:
            return self._pool.submit(_call, function, arguments)
        # A recording parsed into memory travels with its tasks: no advice to load it with dask.
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Sending large graph", category=UserWarning)
            return self._client.submit(_call, function, arguments, pure=False)

    def map(self, function, tasks):
        """``function(*arguments)`` (picklable by name) for each tuple of ``tasks``: the results
        in order as they come, with twice as many calls in flight as workers."""
        pending = collections.deque()
        tasks = iter(tasks)
        try:
            while True:
                more = itertools.islice(tasks, 2 * self.workers - len(pending))
                pending.extend(self._submit(function, arguments) for arguments in more)
                if not pending:
                    return
                future = pending.popleft()
                # Polled, not future.result(timeout=...): distributed's result with a timeout
                # can lose the result in a race (an UnboundLocalError inside distributed).
                while not future.done():
                    time.sleep(_POLL)
                    check_interrupted()
                check_interrupted()
                yield future.result()
        finally:
            for future in pending:
                future.cancel()


def check_workers(workers, processes: bool, here: bool = True) -> None:
    """``ValueError`` unless ``workers`` is None or a whole number this machine can run."""
    if workers is None:
        return
    if isinstance(workers, bool) or int(workers) != workers or workers < 1:
        raise ValueError(f"workers must be a positive integer; got {workers!r}")
    if not here:
        return
    limit, why = worker_limit(processes=processes)
    if workers > limit:
        raise ValueError(f"workers={workers} is more than this machine can run: {why}")


def worker_limit(processes: bool) -> tuple[int, str]:
    """The most workers this machine can run at once, and why, in words."""
    cores = os.cpu_count() or 1
    why = f"{cores} cores (os.cpu_count())"
    if not processes:
        return cores, why
    import psutil  # with distributed, which a cluster needs

    available = psutil.virtual_memory().available
    by_memory = max(1, available // WORKER_MEMORY)
    if by_memory < cores:
        return by_memory, (
            f"{available / 2**30:.3g} GiB of memory available, for workers of about "
            f"{WORKER_MEMORY / 2**30:.3g} GiB each"
        )
    return cores, f"{why}, each worker a process"


@contextlib.contextmanager
def _sigint_held():
    """SIGINT blocked in this thread for the block, and for good in the threads it starts."""
    main = threading.current_thread() is threading.main_thread()
    if not main or not hasattr(signal, "pthread_sigmask"):
        yield
        return
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def start_resource_tracker_quietly() -> None:
    """Start multiprocessing's resource tracker with its standard error on the null device."""
    saved, null = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 2)
        resource_tracker.ensure_running()
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(null)


def _connect(address: str, timeout: float):
    """A client of the dask scheduler at ``address``, once it answers within ``timeout`` [s]."""
    from distributed import Client

    async def identity() -> dict:
        from distributed.comm import connect

        comm = await connect(address, timeout=timeout)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        try:
            answer = pool.submit(asyncio.run, asyncio.wait_for(identity(), timeout)).result()
        except Exception as error:  # whatever went wrong, no scheduler answered
            answer = str(error) or f"no answer after {timeout:g} s"
            if not isinstance(error, ValueError):
                answer = f"{type(error).__name__}: {answer}"
    if not isinstance(answer, dict) or answer.get("type") != "Scheduler":
        if isinstance(answer, dict):
            answer = f"it answers as a {answer.get('type', 'something else')}"
        raise SchedulerError(
            f"no dask scheduler at {address}: {answer}; is it running, and is the address "
            "right (tcp://host:8786, not the dashboard's http:// address)?"
        )
    try:
        return Client(address, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as error:
        raise SchedulerError(
            f"no dask scheduler at {address}: no client within {timeout:g} s "
            f"({type(error).__name__}: {error}); is it running, and is the address right?"
        ) from None
