"""Tasks run on a Dask distributed cluster, for :func:`imgmtf.parallel.run_tasks`
(its ``scheduler``): Dask is optional and imported only here, when a
scheduler is asked for."""
from __future__ import annotations

from .errors import ParameterError

__all__ = ["dask_completed"]


def dask_completed(function, items, workers: int, scheduler: str, on_error, *, local: bool, timeout_s: float):
    """(index, result) pairs as tasks complete on a Dask cluster: a local
    one of ``workers`` processes (``local``), else the scheduler at address
    ``scheduler``, tried for ``timeout_s``; ``on_error(item, exception)``
    gives a failed task's result (None lets the exception through).

    Raises
    ------
    ParameterError
        Dask is not installed, or the scheduler cannot be reached.
    """
    try:
        from distributed import Client, LocalCluster
        from distributed import as_completed as dask_as_completed
    except ImportError:
        raise ParameterError("a Dask scheduler needs Dask: pip install 'imgmtf[dask]'") from None
    cluster = None
    try:
        if local:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        else:
            client = Client(scheduler, timeout=f"{timeout_s}s")
    except (OSError, TimeoutError, ValueError) as exc:
        if cluster is not None:
            cluster.close()
        raise ParameterError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None
    futures = []
    try:
        futures = client.map(function, items, pure=False)
        index = {future.key: i for i, future in enumerate(futures)}
        for future in dask_as_completed(futures):
            i = index[future.key]
            try:
                result = future.result()
            except Exception as exc:
                if on_error is None:
                    raise
                result = on_error(items[i], exc)
            yield i, result
    finally:
        if futures:
            client.cancel(futures)
        client.close()
        if cluster is not None:
            cluster.close()
