"""Run independent tasks in parallel: in this process, in local worker
processes, or on a Dask distributed cluster, with one progress bar.

Tasks are module-level functions of picklable arguments that return plain
data, so they can travel to any worker.  :func:`run_tasks` yields results
in the order of the inputs, whatever order the workers finish in (or as
they complete, with their index).

Local workers scale: each runs its numerical libraries (BLAS, OpenMP,
OpenCV) on one thread, so ``workers`` is what parallelises rather than
every worker fighting for every core.  They ignore Ctrl-C (the parent
handles it), and end when their parent does, even if it was killed.

Interrupts: an interrupt (Ctrl-C, or SIGTERM under :func:`terminate_raises`)
while tasks run cancels the pending ones and terminates the workers at
once before it propagates; the caller keeps what had completed.
"""
from __future__ import annotations

import importlib
import itertools
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from typing import TYPE_CHECKING

from .errors import ParameterError

if TYPE_CHECKING:
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

# multiprocessing and concurrent.futures (about 20 ms to import) are imported where a pool is
# made: a run in this process (workers=1, a new process's one scene) never needs them

LOCAL_CLUSTER = "local"
SCHEDULER_TIMEOUT_S = 10        # how long to keep trying a remote Dask scheduler
_prestarted: list = []      # at most one pool started ahead by prestart_workers
_preloaded: set[str] = set()    # what this process's fork server was asked to import
MAX_WORKERS = 64
WATCHDOG_PERIOD_S = 0.5
SIGNAL_POLL_S = 0.1          # how long a signal can wait for a pool's wait to end
IN_FLIGHT_PER_WORKER = 2      # tasks submitted ahead per worker: one running, one queued
MANAGER_END_S = 5.0          # how long an interrupt waits for a stopped pool's manager thread to end
STUCK_S = 2.0                # how long a dead worker may go unseen by its pool before it is broken here
# what every worker's set-up imports (limit_threads): loaded once by a fork server, not by each worker
# as it starts (5-10 ms each); and the server's own quick exit
WORKER_MODULES = ("threadpoolctl", "imgmtf._server_exit")
# what the fork server imports before any other module: NumPy's unused submodules deferred (SciPy's
# first import would load them)
SERVER_PRELUDE = ("imgmtf._server_numpy",)
# what numerical libraries read, at load time, for their thread count
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS",
                    "OPENCV_FOR_THREADS_NUM")


class Interrupted(KeyboardInterrupt):
    """The run was stopped by a signal; ``signum`` says which (SIGINT for
    Ctrl-C), and ``exit_code`` is the shell's convention, 128 + signum."""

    def __init__(self, signum: int = signal.SIGINT):
        super().__init__(signal.Signals(signum).name)
        self.signum = int(signum)

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


@contextmanager
def terminate_raises():
    """While active (in the main thread), SIGTERM raises
    :class:`Interrupted` like Ctrl-C raises KeyboardInterrupt, so that a
    terminated run stops its workers and keeps what it measured."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def raise_interrupted(signum, frame):
        raise Interrupted(signum)
    previous = signal.signal(signal.SIGTERM, raise_interrupted)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextmanager
def signals_deferred():
    """Ctrl-C and SIGTERM held back until the block ends, then handled as
    they would have been: for a step that must not be cut in two, such as
    writing one row to every output.  (Python runs signal handlers in the
    main thread only, so outside it there is nothing to defer.)"""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    arrived: list[int] = []
    previous = {signum: signal.signal(signum, lambda signum, frame: arrived.append(signum))
                for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        for signum in arrived:
            handler = previous[signum]
            if callable(handler):
                handler(signum, None)
            elif handler == signal.SIG_DFL:
                signal.raise_signal(signum)


def run_tasks(function: Callable, items: Iterable, *, workers: int = 1, scheduler: str | None = None,
              progress: bool | None = None, description: str = "measuring",
              on_error: Callable | None = None, ordered: bool = True) -> Iterator:
    """``function(item)`` for every item, yielded in input order.

    Parameters
    ----------
    function : callable
        What to run on each item (picklable: a module's function).
    items : iterable
        The tasks' arguments, one each.  A sequence (list, tuple) is taken
        whole; any other iterable (a generator) is taken lazily, on local
        workers a few items ahead of those running, so that the work of
        making later items overlaps the workers' on earlier ones (its
        progress bar then has no total).
    workers : int, optional
        Local worker processes (1, the default: run here, no processes), at
        most :data:`MAX_WORKERS`.
    scheduler : str, optional
        A Dask distributed scheduler address (``tcp://host:8786``) to run on
        that cluster, or ``"local"`` for a local Dask cluster of ``workers``
        processes; None for local processes.  The workers must see the same
        files at the same paths (a shared file system).
    progress : bool, optional
        Show a progress bar (on stderr); None shows it when stderr is a
        terminal and there is more than one item.
    description : str, optional
        The progress bar's label (default "measuring").
    on_error : callable, optional
        ``on_error(item, exception)`` gives the result of a task that raised
        or whose worker died; None lets the exception through.
    ordered : bool, optional
        False yields ``(index, result)`` pairs as tasks complete (default
        True: results in input order).

    Yields
    ------
    object
        Each task's result (or ``(index, result)`` pairs, unordered).

    Examples
    --------
    >>> list(run_tasks(abs, [-2, 1, -3], workers=2))
    [2, 1, 3]
    """
    if isinstance(items, Sequence):
        items = list(items)
    check_workers(workers)
    total = len(items) if isinstance(items, list) else None
    if progress is None:
        progress = (total is None or total > 1) and _stderr_is_terminal()
    completed = _completed(function, items, workers, scheduler, on_error)
    if progress:
        completed = _with_progress(completed, total, description)
    try:
        if ordered:
            reorder = InputOrder()
            for index, result in completed:
                yield from reorder.push(index, result)
        else:
            yield from completed
    finally:
        completed.close()       # on an interrupt or an early stop: workers stopped now


def check_workers(workers) -> None:
    """Refuse a count of workers that is not an integer from 1 to
    :data:`MAX_WORKERS`.

    Raises
    ------
    ParameterError
        ``workers`` is out of range or not an integer.

    Examples
    --------
    >>> check_workers(2)
    >>> check_workers(0)
    Traceback (most recent call last):
    ...
    imgmtf.errors.ParameterError: workers must be an integer from 1 to 64, got 0
    """
    if not (isinstance(workers, int) and 1 <= workers <= MAX_WORKERS):
        raise ParameterError(f"workers must be an integer from 1 to {MAX_WORKERS}, got {workers!r}")


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity where the system
    says, else the machine's count), at most :data:`MAX_WORKERS`.

    Examples
    --------
    >>> 1 <= available_cores() <= MAX_WORKERS
    True
    """
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):       # not on Linux: the machine's count
        cores = os.cpu_count() or 1
    return max(1, min(cores, MAX_WORKERS))


def auto_workers(tasks: int, per_worker: int, cores: int | None = None) -> int:
    """How many local workers pay for ``tasks`` units of work when a worker
    pays for itself from ``per_worker`` of them on: one (no pool, the work
    runs here) below twice that, else one per ``per_worker`` units, at most
    the ``cores`` available (default :func:`available_cores`).  A pool's
    start (0.2-0.5 s) and its messages cost more than a few units save.

    Examples
    --------
    >>> auto_workers(30, 100, cores=8), auto_workers(450, 100, cores=8), auto_workers(5000, 100, cores=8)
    (1, 4, 8)
    """
    cores = available_cores() if cores is None else cores
    return max(1, min(cores, tasks // max(per_worker, 1), MAX_WORKERS))


def prestart_workers(workers: int, modules: Iterable[str] = ()) -> None:
    """Get ``workers`` local worker processes with ``modules`` imported
    ready now for the next :func:`run_tasks` of as many workers: their
    start-up (Python and the numerical libraries' imports, 0.2-0.5 s) then
    overlaps the caller's own instead of following it.

    Where processes can be forked from a fork server and this process has
    not started one yet, it is started now importing ``modules`` once, with
    one numerical-library thread (a process without threads forks safely),
    and every worker forked from it starts with them loaded: one import on
    one core rather than one per worker competing with the caller's.  A
    process has one fork server, so this sets its preloaded modules and
    thread count for the process's life: it is meant for a command-line
    run such as ``imgmtf measure``.  Elsewhere the workers are started now
    and each imports them."""
    if workers < 2 or _prestarted or not 1 <= workers <= MAX_WORKERS:
        return
    import multiprocessing
    if "forkserver" in multiprocessing.get_all_start_methods() and not _fork_server_running():
        return _start_fork_server(modules)
    # every worker imports the modules as it starts (not as a task: one
    # worker could take every such task while another was still starting)
    pool = _new_pool(workers, tuple(modules))
    for _ in range(workers):        # a process is started per task submitted while none is idle
        pool.submit(int)
    _prestarted.append((workers, pool))


def can_preload() -> bool:
    """Whether this system starts workers from a fork server (Linux, and
    Unix but macOS), whose preloaded imports every worker forked from it
    shares: a pool's workers then start in milliseconds.

    Examples
    --------
    >>> isinstance(can_preload(), bool)
    True
    """
    import multiprocessing
    return "forkserver" in multiprocessing.get_all_start_methods()


def preloaded(modules: Iterable[str]) -> bool:
    """Whether this process's fork server runs (:func:`prestart_workers`)
    with every one of ``modules`` imported: a pool forked from it has them
    loaded, or soon will, in its workers from their start.

    Examples
    --------
    >>> preloaded(["a.module.never.preloaded"])
    False
    """
    return set(modules) <= _preloaded and _fork_server_running()


def _fork_server_running() -> bool:
    from multiprocessing import forkserver
    server = getattr(forkserver, "_forkserver", None)
    return getattr(server, "_forkserver_pid", None) is not None


def _start_fork_server(modules: Iterable[str]) -> None:
    """Start this process's fork server (if not yet running) importing
    ``modules``, its environment asking for one thread of each numerical
    library; the call does not wait for the imports."""
    from multiprocessing import forkserver
    forkserver.set_forkserver_preload([*SERVER_PRELUDE, *modules, *WORKER_MODULES])
    _preloaded.update([*modules, *WORKER_MODULES])
    saved = {name: os.environ.get(name) for name in THREAD_VARIABLES}
    os.environ.update(dict.fromkeys(THREAD_VARIABLES, "1"))
    try:
        forkserver.ensure_running()
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def _take_prestarted(workers: int):
    """The prestarted pool if it has ``workers`` processes, else None; any
    other prestarted pool is shut down."""
    if not _prestarted:
        return None
    size, pool = _prestarted.pop()
    if size == workers:
        return pool
    pool.shutdown(wait=False, cancel_futures=True)
    return None


def _new_pool(workers: int, modules: tuple[str, ...] = ()) -> ProcessPoolExecutor:
    from concurrent.futures import ProcessPoolExecutor
    return ProcessPoolExecutor(workers, mp_context=_fresh_processes(), initializer=_init_worker,
                               initargs=(os.getpid(), modules))


class InputOrder:
    """Reorder ``(index, value)`` pairs that arrive in any order: ``push``
    returns the values now ready in index order; ``pending`` those still
    waiting for an earlier one (what an interrupt would otherwise lose)."""

    def __init__(self):
        self._waiting: dict[int, object] = {}
        self._next = 0

    def push(self, index: int, value) -> list:
        self._waiting[index] = value
        ready = []
        while self._next in self._waiting:
            ready.append(self._waiting.pop(self._next))
            self._next += 1
        return ready

    def pending(self) -> list:
        return [self._waiting.pop(i) for i in sorted(self._waiting)]


def _with_progress(completed, total: int | None, description: str):
    from tqdm import tqdm
    with tqdm(total=total, desc=description, unit="task", leave=False) as bar:
        try:
            for pair in completed:
                bar.update(1)
                yield pair
        finally:
            completed.close()


def _completed(function, items, workers, scheduler, on_error):
    """(index, result) pairs as tasks complete.  A lone task runs here (a
    pool's start would cost more than it saves), unless a fork server this
    process prestarted has its modules loaded already: its worker starts in
    milliseconds, and this process need not import them."""
    if scheduler is not None:
        from .dask_tasks import dask_completed
        yield from dask_completed(function, list(items), workers, scheduler, on_error,
                                  local=scheduler == LOCAL_CLUSTER, timeout_s=SCHEDULER_TIMEOUT_S)
    elif workers == 1 or (isinstance(items, list) and (
            not items or (len(items) == 1 and not (_preloaded and _fork_server_running())))):
        _take_prestarted(0)
        for index, item in enumerate(items):
            yield index, _call(function, item, on_error)
    else:
        yield from _pool_completed(function, items, workers, on_error)


def _call(function, item, on_error):
    if on_error is None:
        return function(item)
    try:
        return function(item)
    except Exception as exc:
        return on_error(item, exc)


def _pool_completed(function, items, workers, on_error):
    """(index, result) pairs from a pool of ``workers`` processes.  Only
    ``IN_FLIGHT_PER_WORKER`` tasks per worker are submitted at a time, so
    that each wait (and a stop's cancelling) looks at a few futures however
    long the batch; and items are taken from ``items`` only as they are
    submitted (a generator's work on the next ones overlaps the workers')."""
    from concurrent.futures.process import BrokenProcessPool
    pool = _take_prestarted(workers) or _new_pool(min(workers, len(items)) if isinstance(items, list) else workers)
    queue = iter(enumerate(items))
    in_flight: dict = {}        # future: (index, item)
    finished = False
    try:
        while True:
            failed = []         # tasks the pool refused: it broke (a worker died)
            # taken before the signals are held back: a lazy iterable's work on them may be long
            taken = list(itertools.islice(queue, IN_FLIGHT_PER_WORKER * workers - len(in_flight)))
            with signals_deferred():
                for index, item in taken:
                    try:
                        in_flight[pool.submit(function, item)] = index, item
                    except BrokenProcessPool as exc:
                        failed.append((index, item, exc))
            for index, item, broken in failed:
                yield index, _died(item, broken, on_error)
            if not in_flight:
                break
            done, _ = _wait_between_signals(set(in_flight), pool)
            for future in done:
                index, item = in_flight.pop(future)
                try:
                    result = future.result()
                except BrokenProcessPool as exc:
                    result = _died(item, exc, on_error)
                except Exception as exc:
                    if on_error is None:
                        raise
                    result = on_error(item, exc)
                yield index, result
        finished = True
    finally:
        if finished:
            pool.shutdown()
        else:
            _stop(pool)


def _died(item, exc: BrokenProcessPool, on_error):
    """The result of a task whose worker died (or whose pool a dead worker
    broke), through ``on_error``; without it the error goes on."""
    if on_error is None:
        raise exc
    return on_error(item, RuntimeError(f"its worker process died ({exc}); a crash in a library, "
                                       "or out of memory"))


def _wait_between_signals(waiting: set, pool: ProcessPoolExecutor) -> tuple[set, set]:
    """``wait(waiting, return_when=FIRST_COMPLETED)`` on ``pool``'s futures
    (a pool a worker's death left stuck is broken), with Ctrl-C and
    SIGTERM handled only between waits: an exception raised inside
    concurrent.futures' wait can leave a future's lock taken, and the
    pool's manager thread then blocks on it for ever, so the interpreter
    hangs at exit.  Short waits keep the signal's handling prompt."""
    from concurrent.futures import FIRST_COMPLETED, wait
    dead_since = None
    while True:
        with signals_deferred():
            done, waiting = wait(waiting, timeout=SIGNAL_POLL_S, return_when=FIRST_COMPLETED)
        if done:
            return done, waiting
        dead_since = _broken_if_stuck(pool, dead_since)


def _broken_if_stuck(pool: ProcessPoolExecutor, dead_since: float | None) -> float | None:
    """Break ``pool`` if one of its workers has been dead for
    :data:`STUCK_S` and the pool has not seen it.  A worker that died
    part-way through sending its result (killed by the system, out of
    memory) leaves part of a message in the results' pipe: the pool's
    manager thread waits for the rest of it, never sees the death, and
    nothing would end.  Its other workers are then stopped and that wait
    ended: the pool breaks, and its tasks fail as a dead worker's do.
    Returns when a dead worker was first seen (None: none is)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    if getattr(pool, "_broken", False) or all(process.exitcode is None for process in processes):
        return None
    now = time.monotonic()
    if dead_since is None:
        return now
    if now - dead_since >= STUCK_S:
        _end_workers(processes, getattr(pool, "_result_queue", None))
    return dead_since


def _stop(pool: ProcessPoolExecutor) -> None:
    """Terminate the workers now (not after their current task), reap them,
    and end the pool's wait for their results; the tasks not started are
    cancelled by the pool's own shutdown (a future cancelled here instead
    could be failed by the pool again, and its manager thread would stop on
    the error, with a traceback, in Python before 3.12).  The pool's
    manager thread is given a moment to end: the interpreter's exit wakes it
    without its lock, and in Python before 3.12 a thread still closing its
    pipes then fails the exit with a traceback (``Bad file descriptor``)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    results = getattr(pool, "_result_queue", None)
    manager = getattr(pool, "_executor_manager_thread", None)
    pool.shutdown(wait=False, cancel_futures=True)
    _end_workers(processes, results)
    if manager is not None:
        manager.join(timeout=MANAGER_END_S)


def _end_workers(processes: list, results) -> None:
    """Terminate ``processes`` (a pool's workers), reap them, then end the
    pool's wait on its ``results`` queue.  A worker that died while it sent
    a result (terminated here: a large one takes a while through the pipe)
    leaves part of a message there, and the pool's manager thread waits for
    the rest for ever; the interpreter's exit joins that thread, so the
    command would never end.  With the workers gone, this process's end for
    writing is the pipe's last: closing it ends that wait with an EOF."""
    for process in processes:
        if process.is_alive():
            process.terminate()
    for process in processes:
        process.join(timeout=2)
        if process.is_alive():
            process.kill()
            process.join(timeout=1)
    if results is not None and not any(process.is_alive() for process in processes):
        results._writer.close()


def _fresh_processes():
    """Workers started without a copy of this process: a fork of a process
    whose OpenCV or BLAS thread pools have run can deadlock in them, and a
    fresh worker loads its libraries after :func:`limit_threads` has set
    their thread counts."""
    import multiprocessing
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def _init_worker(parent_pid: int, modules: tuple[str, ...] = ()) -> None:
    """Set up a local worker process: a watchdog that ends the worker when
    the parent is gone, Ctrl-C left to the parent, one numerical-library
    thread; then import ``modules``."""
    threading.Thread(target=_watch_parent, args=(parent_pid, os.getppid()), daemon=True,
                     name="imgmtf-parent-watchdog").start()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    # a worker whose environment asked for one thread from its start (forked from a fork server started
    # so, or spawned from such a parent) has its libraries loaded on one thread: threadpoolctl's search
    # of the loaded libraries (about 10 ms) would find nothing to change
    limit_threads(loaded_on_one=all(os.environ.get(name) == "1" for name in THREAD_VARIABLES))
    for name in modules:
        importlib.import_module(name)


def limit_threads(loaded_on_one: bool = False) -> None:
    """One thread for every numerical library of this process: the loaded
    ones now (threadpoolctl, OpenCV), those loaded later through the
    environment they read when they load; for good (the estimators' own
    :func:`imgmtf._blas.one_blas_thread` then does nothing).
    ``loaded_on_one``: the loaded libraries read an environment asking for
    one thread when they loaded (threadpoolctl need not look for them)."""
    from ._blas import one_thread_for_good
    for name in THREAD_VARIABLES:
        os.environ[name] = "1"
    if not loaded_on_one:
        try:
            from threadpoolctl import threadpool_limits
            threadpool_limits(limits=1)
        except ImportError:          # an optional speed-up: without it the environment still applies
            pass
    if "cv2" in sys.modules:
        sys.modules["cv2"].setNumThreads(1)
    one_thread_for_good()


def _watch_parent(parent_pid: int, first_ppid: int) -> None:
    """Exit when the parent has gone: this process was re-parented (the
    parent, or the fork server between us, died), even by SIGKILL."""
    while True:
        time.sleep(WATCHDOG_PERIOD_S)
        ppid = os.getppid()
        if ppid != first_ppid or (ppid != parent_pid and not _alive(parent_pid)):
            os._exit(1)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _stderr_is_terminal() -> bool:
    try:
        return os.isatty(2)
    except OSError:
        return False
