"""The channels of a recording, in memory or out of core, read a block of samples at a time.

:class:`Samples` holds the displacement, force, cycle numbers and a mask of missing samples
of one recording, as NumPy arrays or as dask arrays (a long test read lazily,
:func:`ecofmaps.io.read_recording`). Its :meth:`Samples.map` runs a function over blocks of
consecutive samples: on NumPy arrays, once over the whole recording (the function goes
through it a chunk at a time itself); on dask arrays, once per block of a grid of
``block`` samples, each block read where its task runs (:class:`ecofmaps._parallel.Runner`),
so that no more than a few blocks are in memory at once. The grid's blocks start at
multiples of ``chunk`` samples, so a function that works a ``chunk`` at a time from its
block's start goes through the same chunks whichever way it is run, and gives the same
numbers to the bit.
"""

from __future__ import annotations

import sys

import numpy as np

from ecofmaps._parallel import stretch

__all__ = ["CHANNELS", "Samples", "is_lazy"]

#: The channels of a recording, in the order a block function receives them.
CHANNELS = ("displacement", "force", "cycle", "missing")

#: Samples per block of a lazy recording when its own chunks do not say.
_BLOCK = 1 << 22


def is_lazy(value) -> bool:
    """Whether ``value`` is a dask collection, or an xarray object backed by one."""
    if "dask" not in sys.modules:  # nothing can be lazy before dask is imported
        return False
    import dask

    data = getattr(value, "data", None) if hasattr(value, "dims") else value
    return dask.is_dask_collection(data)


def _task(function, start, stop, arguments, *arrays):
    """A block of :meth:`Samples.map` as run in a task (the arrays read by then)."""
    return function(start, stop, arguments, *arrays)


class Samples:
    """The channels of one recording (see the module notes).

    Parameters
    ----------
    displacement, force : numpy.ndarray or dask.array.Array
        Float64, one value per sample. [m], [N]
    cycle : numpy.ndarray or dask.array.Array, optional
        Cycle number of each sample. [1]
    missing : numpy.ndarray or dask.array.Array of bool, optional
        True for samples to treat as missing besides the non-finite ones.
    runner : ecofmaps._parallel.Runner, optional
        Where the blocks of a lazy recording run (required for dask arrays).
    chunk : int
        The blocks of a lazy recording start at multiples of this many samples.
    block : int, optional
        Samples per block of a lazy recording; by default the multiple of ``chunk``
        nearest the displacement's own dask chunks (or 2**22).
    """

    def __init__(
        self, displacement, force, cycle=None, missing=None, *, runner=None, chunk, block=None
    ):
        self.arrays = (displacement, force, cycle, missing)
        self.size = int(displacement.shape[0])
        self.lazy = any(is_lazy(a) for a in self.arrays if a is not None)
        self.runner = runner
        if self.lazy and runner is None:
            raise ValueError("a lazy recording needs a runner")
        if block is None:
            chunks = getattr(displacement, "chunks", None)
            block = int(chunks[0][0]) if chunks and chunks[0] else _BLOCK
        self.block = max(1, round(block / chunk)) * chunk

    def constant_cycle(self) -> Samples:
        """These samples with every cycle number 0 (the whole recording one cycle)."""
        x = self.arrays[0]
        if self.lazy:
            import dask.array as da

            cycle = da.zeros(self.size, dtype=np.int64, chunks=x.chunks)
        else:
            cycle = np.zeros(self.size, dtype=np.int64)
        copy = object.__new__(Samples)
        copy.__dict__.update(self.__dict__)
        copy.arrays = (self.arrays[0], self.arrays[1], cycle, self.arrays[3])
        return copy

    def channel(self, name: str):
        """The channel ``name`` (one of :data:`CHANNELS`), or None."""
        return self.arrays[CHANNELS.index(name)]

    def blocks(self):
        """``(start, stop)`` of each block of a lazy recording (the grid)."""
        return [(a, min(a + self.block, self.size)) for a in range(0, self.size, self.block)]

    def map(self, function, channels, arguments=(), extra: int = 0) -> list:
        """``function(start, stop, arguments, *arrays)`` over the recording's blocks.

        Parameters
        ----------
        function : callable
            A module-level function. ``arrays`` are the ``channels`` asked for (None for
            one the recording lacks) over samples ``start`` to ``stop - 1`` and up to
            ``extra`` samples beyond, as NumPy arrays.
        channels : sequence of str
            Names from :data:`CHANNELS`.
        arguments : tuple
            Passed through to every call.
        extra : int
            Samples past the block's end to read as well (a look ahead).

        Returns
        -------
        results : list
            One result per block, in order (one block, the whole recording, in memory).
        """
        selected = [self.channel(name) for name in channels]
        if not self.lazy:
            return [function(0, self.size, arguments, *selected)]

        def tasks():
            for a, b in self.blocks():
                end = min(b + extra, self.size)
                arrays = (None if s is None else stretch(s, a, end) for s in selected)
                yield (function, a, b, arguments, *arrays)

        return list(self.runner.map(_task, tasks()))
