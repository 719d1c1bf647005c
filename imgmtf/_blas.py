"""Run NumPy's linear algebra on one BLAS thread for a while.

The estimators' matrices are small (a few hundred rows, or tall and a few
columns wide): OpenBLAS's threads cost more than they save there, and on a
machine whose cores are busy with other work, many times more (a sensor fit
of two edges took 4.9 s with two threads against 1.0 s with one, at a load of
4 on 2 cores).  Worker processes run on one thread anyway
(:func:`imgmtf.parallel.limit_threads`); this serves a computation in the
caller's own process, and gives the threads back after it.
"""
from __future__ import annotations

import functools
import importlib
import sys
from contextlib import nullcontext

_for_good = False       # this process's BLAS is on one thread for its life (a worker process)


def one_blas_thread(load: str | None = None):
    """A context manager: BLAS on one thread inside it, as before after it
    (NumPy's BLAS, and SciPy's where SciPy's linear algebra is loaded: load
    it before entering, or name a module that loads it as ``load``).  In a
    process on one thread for good (:func:`one_thread_for_good`) ``load`` is
    not imported: whatever loads a library later finds the environment
    asking for one thread, and a worker that never needs the module (a
    sensor fit's SciPy solver is its fallback) does not pay its import.

    Examples
    --------
    >>> import numpy as np
    >>> with one_blas_thread():
    ...     float(np.linalg.det(np.eye(3)))
    1.0
    """
    if _for_good:
        return nullcontext()
    if load is not None:
        importlib.import_module(load)
    return _controller("scipy.linalg" in sys.modules).limit(limits=1, user_api="blas")


@functools.cache
def _controller(scipy_loaded: bool):
    """The libraries' thread pools, found once (a few ms) for each of the two
    states that matter: before and after SciPy brings its own BLAS."""
    from threadpoolctl import ThreadpoolController
    return ThreadpoolController()


def one_thread_for_good() -> None:
    """Say that this process's BLAS runs on one thread for the rest of its
    life (a worker process, :func:`imgmtf.parallel.limit_threads`):
    :func:`one_blas_thread` then does nothing, rather than look for the
    libraries (20-30 ms, on each worker's first task) and set them."""
    global _for_good
    _for_good = True
