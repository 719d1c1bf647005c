"""An object pickled once into shared memory, for local workers to load by
name rather than receive in every task: its NumPy arrays (pickled out of
band, protocol 5) are copied from the block in one piece and unpickled as
views of that copy.

A dense chart's 1936 half-edges were 90 MB pickled, and went twice to the
workers, in the scene's fit task and again in its targets' (2 s of CPU
between the parent's pickling and the workers' unpickling, and the pipe
held the other worker's first task behind the scene's).  Pickled once here,
each worker loads the whole once and each task names what it needs by
index.

Only for workers on this machine: a remote (Dask) worker cannot see the
block.  The block is registered with multiprocessing's resource tracker,
which removes it should the parent die before :meth:`SharedPickle.close`.

Layout of a block: two int64 (the in-band pickle's length, the number of
out-of-band buffers), each buffer's offset and length (int64 pairs), the
in-band pickle, then the buffers, each at a 64-byte boundary.
"""
from __future__ import annotations

import gc
import pickle
from contextlib import contextmanager
from typing import Any

import numpy as np

ALIGN = 64
_HEADER = 2 * 8
#: what this process loaded, by the block's name (one at a time: a worker's pool serves one stage, whose
#: block is the only one in use)
_loaded: dict[str, Any] = {}


class SharedPickle:
    """``value`` pickled into a new block of shared memory, its arrays out
    of band; :func:`load` (in any process of this machine) gives it back
    from :attr:`name`.  Close it (or use it as a context manager) to free
    the block: processes that loaded it keep their copy.

    Examples
    --------
    >>> import numpy as np
    >>> with SharedPickle({"a": np.arange(3.0), "b": "text"}) as shared:
    ...     loaded = load(shared.name)
    ...     print(loaded["a"], loaded["b"], loaded["a"].flags.writeable)
    [0. 1. 2.] text False
    """

    def __init__(self, value: Any):
        from multiprocessing import shared_memory

        from .parallel import signals_deferred
        buffers: list[pickle.PickleBuffer] = []
        with _collector_paused():
            inband = pickle.dumps(value, protocol=5, buffer_callback=buffers.append)
            raws = [b.raw() for b in buffers]
            starts, offset = [], _aligned(_HEADER + 16 * len(raws) + len(inband))
            for raw in raws:
                starts.append(offset)
                offset = _aligned(offset + raw.nbytes)
            table = np.array([starts, [raw.nbytes for raw in raws]], np.int64).T.copy()
        self._memory = None
        try:
            with signals_deferred():        # made and owned at once: an interrupt between would leave it behind
                self._memory = shared_memory.SharedMemory(create=True, size=max(offset, 1))
            self.name: str = self._memory.name
            block = self._memory.buf
            assert block is not None
            block[:_HEADER] = np.array([len(inband), len(raws)], np.int64).tobytes()
            block[_HEADER:_HEADER + table.nbytes] = table.tobytes()
            start = _HEADER + table.nbytes
            block[start:start + len(inband)] = inband
            for start, raw in zip(starts, raws):
                block[start:start + raw.nbytes] = raw
            del block
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Free the block (this process's own loaded copy forgotten too)."""
        if self._memory is not None:
            memory, self._memory = self._memory, None
            _loaded.pop(memory.name, None)
            memory.close()
            memory.unlink()

    def __enter__(self) -> SharedPickle:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def load(name: str) -> Any:
    """The object a :class:`SharedPickle` named ``name`` holds, loaded
    once per process (later calls give the same object); its arrays are
    read-only.  Loading another block forgets the one loaded before.

    The block is copied (one copy of its bytes, 20-40 ms for 90 MB) and
    unmapped at once: the arrays are views of that copy, so nothing ties
    their life to the block's."""
    if name in _loaded:
        return _loaded[name]
    from multiprocessing import parent_process, shared_memory
    if _loaded and parent_process() is not None:
        gc.unfreeze()           # the block loaded before (frozen below) goes back to the collector with it
    _loaded.clear()
    memory = shared_memory.SharedMemory(name=name)
    try:
        assert memory.buf is not None
        block = memoryview(bytes(memory.buf))
    finally:
        memory.close()
    size, count = np.frombuffer(block[:_HEADER], np.int64).tolist()
    table = np.frombuffer(block[_HEADER:_HEADER + 16 * count], np.int64).reshape(count, 2)
    start = _HEADER + 16 * count
    with _collector_paused():
        value = pickle.loads(block[start:start + size],
                             buffers=[block[a:a + n] for a, n in zip(table[:, 0].tolist(), table[:, 1].tolist())])
    _loaded[name] = value
    if parent_process() is not None:
        # a worker's: the collector's later passes would walk it all again and again (the dense chart's
        # target fits took 4 s more CPU on two workers that held its half-edges than on those that did not)
        gc.freeze()
    return value


@contextmanager
def _collector_paused():
    """The cyclic garbage collector held off: pickling makes or walks
    millions of objects that live on, and each of its passes meanwhile
    would walk them all again (the dense chart's load took 0.95 s with it,
    0.28 s without)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def _aligned(offset: int) -> int:
    return -(-offset // ALIGN) * ALIGN
