"""What follows a scene's scan and its combined summaries, run on one
pool: the targets' across/along sections (:mod:`.sections`) and the
sensor model's fits (:mod:`.targetfit`).

Neither needs the other: both follow the scan's records and their
summaries.  Run one after the other, each stage waited for its last task
(a barrier), and the scene's fit is one task as long as all its targets'
(11 s of a dense chart's 21 s on two workers): while it ran alone the
other worker waited.  Here the sections' tasks go first, then the
scene's fit and the targets' fits, on the same workers, and each task's
rows are put back in their place: the rows are those the two stages give
apart, in the same order.  The fits' tasks are made (and their
half-edges packed, below) only once the sections' are in the workers'
hands (:func:`imgmtf.parallel.run_tasks` takes its tasks lazily): the
parent's 0.4 s on a dense chart had kept both workers waiting.

On local workers the fits' half-edges are pickled once into shared memory
(:mod:`imgmtf.shared_pickle`), each worker loads them once, and a fit's
task names its half-edges by index: the scene's fit and its targets' had
each carried them all (a dense chart's 1936, 90 MB pickled, twice).  The
targets' fits go a few to a task (each 30 ms on that chart).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from ..records import Record

SECTIONS, FIT, FITS = "sections", "fit", "fits"
#: targets' fits per task at most; and the tasks each worker gets at least before fits are grouped
TARGETS_PER_TASK, TASKS_PER_WORKER = 4, 8


def sections_and_fits(records: Sequence[Record], summaries: Sequence[Record], stages: str | list[str] | None, *,
                      workers: int | None = 1, scheduler: str | None = None,
                      progress: bool | None = False) -> tuple[list[Record], list[Record]]:
    """A scan's section rows and fit rows, their tasks on one pool.

    Parameters
    ----------
    records : sequence of Record
        The scene's scan records (:func:`imgmtf.scene.measure.scan_scene`).
    summaries : sequence of Record
        Their summaries (:func:`imgmtf.scene.combine.summarise_scan`).
    stages : str or list of str or None
        The stages fitted (:func:`imgmtf.scene.targetfit.fit_targets`);
        None: no fit, the sections only.
    workers : int or None, optional
        Local worker processes (default 1: none, the work runs here);
        None chooses as each stage would (the more of the two).
    scheduler : str, optional
        A Dask distributed scheduler's address, or ``"local"``
        (:func:`imgmtf.parallel.run_tasks`).
    progress : bool, optional
        Show one progress bar on stderr for both (default False; None:
        when stderr is a terminal).

    Returns
    -------
    (list of Record, list of Record)
        :func:`imgmtf.scene.sections.section_rows`' rows and
        :func:`imgmtf.scene.targetfit.fit_targets`' rows, each what the
        stage alone gives, whatever the workers.

    Raises
    ------
    ParameterError
        ``summaries`` or ``records`` are not Records, ``workers`` out of
        range, or ``stages`` names no stage.

    Examples
    --------
    >>> records = scan_scene("chart.tif")                                  # doctest: +SKIP
    >>> sections, fits = sections_and_fits(records, summarise_scan(records), "auto", workers=2)  # doctest: +SKIP
    """
    from ..errors import ParameterError
    from ..parallel import IN_FLIGHT_PER_WORKER, can_preload, check_workers, run_tasks, signals_deferred
    from .sections import section_groups, section_tasks, sections_workers
    from .targetfit import fit_tasks, fitted_rows
    groups = section_groups(summaries)
    if workers is not None:
        check_workers(workers)
    records = list(records)
    if any(not isinstance(r, Record) for r in records):
        raise ParameterError("records must be a scan's Records (imgmtf.scan_scene)")
    fitting = fit_workers(records, workers) if stages else 1
    chosen = max(sections_workers(len(groups), workers), fitting)
    here = chosen == 1 and scheduler is None
    # with fits to make ready, the sections go in as many tasks as the pool takes at once, so that the
    # workers have them all in hand while this process makes the fits' tasks (0.4 s on a dense chart)
    pieces = [groups] if here else _chunks(groups, IN_FLIGHT_PER_WORKER * chosen) if stages else section_tasks(groups)
    sectioned = [(SECTIONS, t) for t in pieces if t]
    planned: list[tuple[list, int, list[int]]] = []       # the fits' tasks, their scene's count and order
    shared: list = []           # the shared block of the fits' half-edges, once made

    def staged():
        """The sections' tasks, then the fits' (made only once the sections' are handed out: on
        workers, the fits' tasks and their shared block are made while the workers section)."""
        yield from sectioned
        fits, scenes = fit_tasks(records, stages, workers=chosen, scheduler=scheduler) if stages else ([], 0)
        # the scene's fit first (the longest), then the targets' fits, the last-numbered first:
        # targets are numbered by their best rank (the narrowest interval, then the highest SNR), and
        # the last are the noisiest, often misfit, whose fits try more stages (0.4-1.6 s against
        # 0.02 s on the 4096 px bench scene): started last, one of them ran alone
        order = [*range(scenes), *range(len(fits) - 1, scenes - 1, -1)]
        planned.append((fits, scenes, order))
        # many targets' fits a few to a task: each is short (30 ms on the dense chart) beside a task's round trip
        targets = [fits[k] for k in order[scenes:]]
        per_task = fits_per_task(len(targets), chosen)
        fit_work = [(FIT, fits[k]) for k in order[:scenes]] + \
            [(FITS, targets[k:k + per_task]) for k in range(0, len(targets), per_task)]
        if not here and scheduler is None and can_preload() and fit_work:
            with signals_deferred():       # the block made and owned at once (closed below)
                block, fit_work = _shipped_once(fit_work)
                shared.append(block)
        yield from fit_work

    tasks: list[tuple] = []             # the tasks as they were handed out, in order

    def handed():
        for task in staged():
            tasks.append(task)
            yield task
    try:
        if here:
            results = [_stage_task(task) for task in handed()]
        else:
            results = list(run_tasks(_stage_task, handed(), workers=chosen, scheduler=scheduler,
                                     progress=progress, description="sections and fits"))
    finally:
        for block in shared:
            block.close()
    fits, scenes, order = planned[0]
    done: list[tuple[str, list]] = []
    for (kind, _), rows in zip(tasks, results):
        done.extend([(FIT, each) for each in rows] if kind == FITS else [(kind, rows)])
    sections = [row for kind, rows in done if kind == SECTIONS for row in rows]
    fitted: list[list[Record]] = [[] for _ in fits]
    for k, rows in zip(order, (rows for kind, rows in done if kind == FIT)):
        fitted[k] = rows
    return sections, fitted_rows(fitted, scenes)


def _chunks(groups: list, tasks: int) -> list[list]:
    """``groups`` cut into at most ``tasks`` runs of about equal length, in
    order (their sections' rows, joined, are those of all the groups).

    Examples
    --------
    >>> _chunks([1, 2, 3, 4, 5], 2), _chunks([1], 4)
    ([[1, 2, 3], [4, 5]], [[1]])
    """
    size = max(1, -(-len(groups) // max(tasks, 1)))
    return [groups[k: k + size] for k in range(0, len(groups), size)]


def fits_per_task(targets: int, workers: int) -> int:
    """How many of ``targets`` fits go in one task on ``workers``: up to
    ``TARGETS_PER_TASK``, but one each until every worker would get
    ``TASKS_PER_WORKER`` tasks.  A scene's few fits are uneven (the noisiest
    targets' 0.4-1.6 s against 0.02 s on the 4096 px bench scene, and sent
    first): four of them in one task left the other worker idle.

    Examples
    --------
    >>> fits_per_task(484, 2), fits_per_task(40, 2), fits_per_task(20, 2)
    (4, 2, 1)
    """
    return max(1, min(TARGETS_PER_TASK, targets // (TASKS_PER_WORKER * max(workers, 1))))


def fit_workers(records: Sequence[Record], workers: int | None) -> int:
    """The workers of a scene's fits: as given, or chosen (None) as its
    candidates' were, by its accepted half-edges; but where the workers'
    fork server has the fits' modules loaded already (a command started it
    with them, :func:`imgmtf.parallel.prestart_workers`), even a few fits
    go to its workers, rather than SciPy's optimizer (0.35-0.6 s) being
    imported here after the scene's measurement."""
    if workers is not None:
        return workers
    from ..parallel import auto_workers, preloaded
    from ..preloads import FITTING_MODULES
    from .measure import AUTO_PLANS_PER_WORKER
    accepted = sum(r.ok for r in records)
    chosen = auto_workers(accepted, AUTO_PLANS_PER_WORKER)
    return auto_workers(accepted, 1) if chosen == 1 and preloaded(FITTING_MODULES) else chosen


def _shipped_once(tasks: list[tuple]) -> tuple[Any, list[tuple]]:
    """The fit tasks' half-edges (each record and its measurement) pickled
    once into shared memory (:class:`imgmtf.shared_pickle.SharedPickle`),
    and the tasks naming theirs by index in it: the scene's fit and its
    targets' take the same half-edges, which went to the workers twice (a
    dense chart's 90 MB pickled: 2 s of CPU, and the scene's task held the
    pipe while the other worker waited for its first)."""
    from ..shared_pickle import SharedPickle
    index: dict[int, int] = {}
    halves: list[tuple] = []
    fits = [item for kind, item in tasks if kind == FIT] + \
        [each for kind, item in tasks if kind == FITS for each in item]
    for records, _, _, measured in fits:
        for record, measurement in zip(records, measured):
            if index.setdefault(id(record), len(halves)) == len(halves):
                halves.append((record, measurement))
    shared = SharedPickle(halves)

    def light(item: tuple) -> tuple:
        """A fit's task with its half-edges named by their indices in the block."""
        return Shared(shared.name), item[1], item[2], [index[id(r)] for r in item[0]]

    def lightened(kind: str, item):
        if kind == FIT:
            return light(item)
        return [light(each) for each in item] if kind == FITS else item       # (sections: as they are)
    return shared, [(kind, lightened(kind, item)) for kind, item in tasks]


@dataclass(frozen=True)
class Shared:
    """The shared memory block a task's half-edges are in, by name."""

    name: str


def _stage_task(task: tuple) -> list:
    """One task's rows: a few targets' sections, or one fit's (its
    half-edges given, or named by their indices in a shared block), or
    each of a few fits' rows."""
    kind, item = task
    if kind == FITS:
        return [_stage_task((FIT, each)) for each in item]
    if kind == SECTIONS:
        from .sections import _task_rows
        return _task_rows(item)
    from .targetfit import _fit_task
    if isinstance(item[0], Shared):
        from ..shared_pickle import load
        halves = load(item[0].name)
        members = [halves[k] for k in item[3]]
        item = ([r for r, _ in members], item[1], item[2], [m for _, m in members])
    return _fit_task(item)
