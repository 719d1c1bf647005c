"""Run independent tasks in parallel: in this process, in local worker
processes, or on a Dask distributed cluster, with one progress bar.

Tasks are module-level functions of picklable arguments that return plain
data (dicts, lists), so they can travel to any worker.  Results come back
in the order of the inputs, whatever order the workers finish in.
"""
from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed

from tqdm import tqdm

from .errors import ParameterError

LOCAL_CLUSTER = "local"


def run_tasks(function: Callable, items: Iterable, *, workers: int = 1, scheduler: str | None = None,
              progress: bool | None = None, description: str = "measuring") -> Iterator:
    """``function(item)`` for every item, yielded in input order.

    Parameters
    ----------
    workers : local worker processes (1: run here, no processes).
    scheduler : a Dask distributed scheduler address (``tcp://host:8786``)
        to run on that cluster, or ``"local"`` for a local Dask cluster of
        ``workers`` processes; None for local processes.  The workers must
        see the same files at the same paths (a shared file system).
    progress : show a progress bar (on stderr); None shows it when stderr
        is a terminal and there is more than one item.
    """
    items = list(items)
    if progress is None:
        progress = len(items) > 1 and _stderr_is_terminal()
    bar = tqdm(total=len(items), desc=description, unit="task", disable=not progress, leave=False)
    done: dict[int, object] = {}
    next_index = 0
    with bar:
        for index, result in _completed(function, items, workers, scheduler):
            done[index] = result
            bar.update(1)
            while next_index in done:
                yield done.pop(next_index)
                next_index += 1


def _completed(function, items, workers, scheduler):
    """(index, result) pairs as tasks complete."""
    if workers < 1:
        raise ParameterError(f"workers must be >= 1, got {workers}")
    if scheduler is not None:
        yield from _dask_completed(function, items, workers, scheduler)
    elif workers == 1 or len(items) <= 1:
        for index, item in enumerate(items):
            yield index, function(item)
    else:
        with ProcessPoolExecutor(min(workers, len(items))) as pool:
            futures = {pool.submit(function, item): i for i, item in enumerate(items)}
            for future in as_completed(futures):
                yield futures[future], future.result()


def _dask_completed(function, items, workers, scheduler):
    try:
        from distributed import Client, LocalCluster
        from distributed import as_completed as dask_as_completed
    except ImportError:
        raise ParameterError("--scheduler needs Dask: pip install 'imgmtf[dask]'") from None
    cluster = None
    try:
        if scheduler == LOCAL_CLUSTER:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        else:
            client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        if cluster is not None:
            cluster.close()
        raise ParameterError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None
    try:
        futures = client.map(function, items, pure=False)
        index = {future.key: i for i, future in enumerate(futures)}
        for future in dask_as_completed(futures):
            yield index[future.key], future.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _stderr_is_terminal() -> bool:
    try:
        return os.isatty(2)
    except OSError:
        return False
