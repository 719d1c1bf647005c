"""Many scenes scanned, each summarised and fitted, each written to a
campaign store as it completes.

One scene is scanned here with its candidates on the workers
(:func:`imgmtf.scene.measure.scan_scene`); several are scanned one per
worker (:func:`imgmtf.parallel.run_tasks`), which keeps every worker busy
however few candidates a scene holds.  Each scene's outcome (its
candidates, its combined and fitted summaries, its acquisition) is
yielded as it completes, after its rows are in the store, and an
interrupt waits until the caller has reported it: every acquisition
stored is reported, every one reported is stored, and a scene cut short
is never stored.
"""
from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..errors import ImgmtfError, ParameterError
from ..kinds import get_kind
from ..records import INTERNAL, Record
from .settings import ScanSettings
from .targetfit import DEFAULT_STAGES

AUTO_SCENES_PER_WORKER = 2      # with workers chosen automatically, a pool scans several scenes from two a worker on


@dataclass(frozen=True, eq=False)
class SceneOutcome:
    """What one scene gave.

    Attributes
    ----------
    path : str
        The scene.
    records : tuple of Record
        Its candidates (:func:`imgmtf.scene.measure.scan_scene`).
    summaries : tuple of Record
        Its combined summaries (:func:`imgmtf.scene.combine.summarise_scan`),
        its across/along sections (:func:`imgmtf.scene.sections.section_rows`),
        then its fitted ones (:func:`imgmtf.scene.targetfit.fit_targets`), the
        one to quote per direction marked (:func:`imgmtf.scene.sections.recommend`).
    acquisition : imgmtf.campaign.acquisitions.Acquisition or None
        With a store: the acquisition its rows were stored as.
    error, reason : str or None
        Why the scene could not be scanned (the message names it).
    interrupt : KeyboardInterrupt or None
        What cut the scan short: ``records`` are then those measured so
        far, and nothing was stored.
    """

    path: str
    records: tuple[Record, ...] = ()
    summaries: tuple[Record, ...] = ()
    acquisition: Any = None
    error: str | None = None
    reason: str | None = None
    interrupt: BaseException | None = field(default=None, repr=False)
    figures_dir: str | None = field(default=None, repr=False)

    @property
    def interrupted(self) -> bool:
        return self.interrupt is not None

    @property
    def ok(self) -> bool:
        """A scan that found at least one usable target."""
        return self.error is None and any(r.ok for r in self.records)


def acquisition_settings(settings: ScanSettings, stages: str | None) -> dict:
    """The settings that make an acquisition's identity in a store: the
    estimate's, the scan's and the fitted stages."""
    return {**settings.measure_settings().params(), "method": settings.method, "target": settings.target,
            "scan": settings.as_dict(), "fit_stages": stages}


def scan_scenes(paths: Sequence[str], settings: ScanSettings | None = None, *, stages: str | None = DEFAULT_STAGES,
                store: str | None = None, facts: Mapping[str, str | None] | None = None, workers: int | None = 1,
                scheduler: str | None = None, progress: bool | None = None,
                figures_dirs: Mapping[str, str] | None = None,
                overviews: Mapping[str, str] | None = None) -> Iterator[SceneOutcome]:
    """Scan, summarise and fit each scene; with a ``store``, write each
    acquisition's rows as it completes.

    Parameters
    ----------
    paths : sequence of str
        The scenes.
    settings : ScanSettings, optional
        How to scan (:class:`imgmtf.ScanSettings`; default its defaults).
    stages : str, optional
        The stages fitted to each target's half-edges, comma-separated
        (default "optics,detector"; None: no fit).
    store : str, optional
        A campaign GeoPackage (created when missing): each scene's
        accepted half-edges and its summaries, written in one transaction
        as the scene completes (:func:`imgmtf.campaign.store.write_acquisition`).
    facts : mapping of str to str, optional
        What the files may not say, for every scene: ``acquired``,
        ``platform``, ``instrument``, ``band_name``
        (:func:`imgmtf.campaign.acquisitions.read_acquisition`).
    workers : int or None, optional
        Local worker processes (default 1: none, the work runs here); None
        chooses: with several scenes, one worker per ``AUTO_SCENES_PER_WORKER``
        scenes up to the available cores; with one, as
        :func:`imgmtf.scene.measure.scan_scene` chooses for its candidates
        and its fits.  The outcomes are the same whatever the workers.
    scheduler : str, optional
        A Dask distributed scheduler's address, or ``"local"`` for a local
        Dask cluster (:func:`imgmtf.parallel.run_tasks`).
    progress : bool, optional
        Show a progress bar on stderr (default: when stderr is a terminal).
    figures_dirs : mapping of str to str, optional
        Scene -> a folder for its accepted half-edges' figures.
    overviews : mapping of str to str, optional
        Scene -> where its overview figure is written (by
        :func:`imgmtf.scene.export.write_outputs`), recorded with its
        acquisition so that a campaign report shows it.

    Yields
    ------
    SceneOutcome
        One per scene, in the order given (each stored as it is yielded;
        a scene finished on a worker ahead of those before it waits for
        them, except on Ctrl-C, when every finished scene is stored and
        yielded at once).

    Raises
    ------
    KeyboardInterrupt
        On Ctrl-C (or SIGTERM under :func:`imgmtf.parallel.terminate_raises`):
        after the outcome of a single scene cut short (``interrupted``),
        or, with several, at once; every acquisition yielded before is in
        the store.
    ImgmtfError
        The store cannot be written (:class:`imgmtf.campaign.store.StoreError`,
        FileWriteError): the scenes stored so far stay.

    Examples
    --------
    >>> for outcome in scan_scenes(["2020.tif", "2021.tif"], store="site.gpkg"):    # doctest: +SKIP
    ...     print(outcome.path, outcome.acquisition.acquired_utc, len(outcome.summaries))
    """
    settings = ScanSettings() if settings is None else settings
    if not isinstance(settings, ScanSettings):
        raise ParameterError(f"settings must be a ScanSettings, got {settings!r}")
    paths = [str(p) for p in paths]
    figures_dirs = dict(figures_dirs or {})
    overviews = dict(overviews or {})
    facts = None if store is None else dict(facts or {})
    if store is not None:
        from ..campaign.store import ensure_store
        ensure_store(store)             # a store that cannot be written fails before any scan
    if len(paths) == 1:
        outcome = scan_one(paths[0], settings, stages, facts, workers=workers, scheduler=scheduler,
                           progress=progress, figures_dir=figures_dirs.get(paths[0]), overview=overviews.get(paths[0]))
        yield from _stored(outcome, store)
        if outcome.interrupt is not None:
            raise outcome.interrupt
        return
    from ..parallel import run_tasks

    def lost(item, exc):
        return SceneOutcome(item[0], error=f"{item[0]}: internal error: {type(exc).__name__}: {exc}",
                            reason=INTERNAL)
    tasks = [(path, settings, stages, facts, figures_dirs.get(path), overviews.get(path)) for path in paths]
    if workers is None:
        workers = scenes_workers(len(paths))
    # scenes finish in any order on a pool; each is stored and reported in
    # the order given (what a reader of the output and of the docs expects),
    # and on Ctrl-C every scene already finished is stored and reported
    # before the interrupt goes on
    finished: dict[int, SceneOutcome] = {}
    following = 0
    try:
        for index, outcome in run_tasks(_scan_task, tasks, workers=workers, scheduler=scheduler,
                                        progress=progress, description="scanning scenes", on_error=lost,
                                        ordered=False):
            finished[index] = outcome
            while following in finished:
                yield from _stored(finished.pop(following), store)
                following += 1
    except KeyboardInterrupt:
        for index in sorted(finished):
            yield from _stored(finished.pop(index), store)
        raise


def scenes_workers(scenes: int) -> int:
    """The local workers chosen for ``scenes`` scenes scanned each on its
    own worker (:func:`imgmtf.parallel.auto_workers`).

    Examples
    --------
    >>> scenes_workers(1)
    1
    """
    from ..parallel import auto_workers
    return auto_workers(scenes, AUTO_SCENES_PER_WORKER) if scenes > 1 else 1


def _scan_task(item) -> SceneOutcome:
    path, settings, stages, facts, figures_dir, overview = item
    return scan_one(path, settings, stages, facts, progress=False, figures_dir=figures_dir, overview=overview)


def scan_one(path: str, settings: ScanSettings, stages: str | None = DEFAULT_STAGES,
             facts: Mapping[str, str | None] | None = None, *, workers: int | None = 1,
             scheduler: str | None = None, progress: bool | None = None,
             figures_dir: str | None = None, overview: str | None = None) -> SceneOutcome:
    """One scene scanned, its targets combined and fitted, and (with
    ``facts``, a mapping, even empty) its acquisition read, naming its
    ``overview`` figure (an absolute path) when one is to be written; an outcome
    with the error when the scene cannot be scanned, ``interrupted`` with
    the records so far on Ctrl-C."""
    from ..io import raster_info
    from .afterscan import sections_and_fits
    from .combine import summarise_scan
    from .measure import in_image_axes, scan_scene
    from .sections import recommend
    try:
        acquisition = None
        if facts is not None:
            from ..campaign.acquisitions import read_acquisition
            acquisition = read_acquisition(path, band=settings.band, settings=acquisition_settings(settings, stages),
                                           **facts)
            if overview:
                acquisition = replace(acquisition, overview=str(Path(overview).resolve()))
        scanner = get_kind(settings.target).scanner
        if scanner is not None:             # a kind that is no line scans the scene its own way (points)
            records, summaries = get_kind(settings.target).load("scanner")(path, settings)
            summaries = recommend(summaries)
            if in_image_axes(raster_info(path), settings):
                records, summaries = _image_axes(records), _image_axes(summaries)
            return SceneOutcome(path, _reported(records), tuple(summaries), acquisition, figures_dir=figures_dir)
        try:
            records = scan_scene(path, settings, workers=workers, scheduler=scheduler, progress=progress,
                                 figures_dir=figures_dir)
        except KeyboardInterrupt as exc:
            partial = getattr(exc, "records", None)
            if partial is None:
                raise
            return SceneOutcome(path, _reported(partial), tuple(summarise_scan(partial)), interrupt=exc)
        summaries = summarise_scan(records)
        # the sections and the fits on one pool: neither waits for the other's last task
        sections, fits = sections_and_fits(records, summaries, stages if get_kind(settings.target).fits_sensor
                                           else None, workers=workers, scheduler=scheduler, progress=progress)
        summaries = recommend(summaries + sections + fits)
        if in_image_axes(raster_info(path), settings):
            records, summaries = _image_axes(records), _image_axes(summaries)
    except ImgmtfError as exc:
        message = " ".join(str(exc).split())
        return SceneOutcome(path, error=message if message.startswith(path) else f"{path}: {message}",
                            reason=exc.reason)
    return SceneOutcome(path, _reported(records), tuple(summaries), acquisition, figures_dir=figures_dir)


def _image_axes(records) -> list[Record]:
    """Records whose directions, worked out with rows along track, are
    named by the image's axes (horizontal, vertical): the same directions."""
    from ..estimate.geometry import image_axis_label

    def named(fields):
        return {"direction": image_axis_label(fields["direction"])} if "direction" in fields else {}
    return [r.with_(figures=named(r.figures), site=named(r.site)) for r in records]


def _reported(records) -> tuple[Record, ...]:
    """The records without their measurements: those served the fit; an
    outcome is what is reported and stored, and it may travel back from a
    worker and be held for a whole campaign (a measurement is ~0.3 MB)."""
    return tuple(r.with_(measurement=None) if r.measurement is not None else r for r in records)


def _stored(outcome: SceneOutcome, store: str | None) -> Iterator[SceneOutcome]:
    """The scene's accepted half-edges and usable summaries written to the
    store, then the outcome yielded, with Ctrl-C held back until the caller
    has reported it: a scene is stored and reported, or neither."""
    from ..parallel import signals_deferred
    with signals_deferred():
        if store is not None and outcome.acquisition is not None and outcome.ok and not outcome.interrupted:
            from ..campaign import store as stores
            # a store whose schema predates a kind of summary (the sections) keeps the others
            kept = getattr(stores, "SUMMARY_METHODS", ())
            stores.write_acquisition(store, outcome.acquisition, [r for r in outcome.records if r.ok],
                                     [r for r in outcome.summaries
                                      if r.ok and (not kept or (r.figures.get("summary") or "combined") in kept)])
        yield outcome


def outputs_folder(out_dir: str, path: str, taken: set[str]) -> str:
    """A scene's own sub-folder of ``out_dir`` (its file name without the
    suffix; numbered when two scenes share one), recorded in ``taken``."""
    stem = Path(path).stem or "scene"
    name, k = stem, 1
    while name in taken:
        k += 1
        name = f"{stem}-{k}"
    taken.add(name)
    return str(Path(out_dir) / name)
