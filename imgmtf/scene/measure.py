"""The scan: every candidate target of a scene found, screened, measured,
grouped and ranked.

The scene's segments (:mod:`.detect`) are split at their junctions into
half-edges and paired into bars (:mod:`.segments`); each is a candidate,
measured on its own tilted ROI (:mod:`.roi`: a rectangle along it, clear
of its junctions, of fill and of its free ends), which the estimators see
as a mask (:func:`imgmtf.measure_edge`'s ``mask=``), so nothing outside it
enters the estimate.

Order of work, cheapest first: fill and the geometric screens (unread);
then, per batch of candidates sharing a tile (one windowed read, a task,
on the workers too: :mod:`.candidates`), each ROI's extent clear of
junctions and fill, a quick look at their pixels, and the estimate of
each it passes.  The measured candidates are then joined into targets
through the junctions they share and ranked.
"""
from __future__ import annotations

import math
import os
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..atomic import ensure_folder
from ..errors import ImageContentError, ParameterError
from ..estimate.field import field_position, resolve_centre
from ..estimate.geometry import direction_label
from ..inputs import MIN_SIZE_PX
from ..io import RasterInfo, raster_info
from ..kinds import get_kind
from ..parallel import auto_workers, preloaded, prestart_workers, run_tasks
from ..preloads import SCAN_TASK_MODULES
from ..records import CANDIDATE_SCOPE, Record, utc_now
from .candidates import Context, Plan, measure_batch
from .detect import detect_segments, tile_windows
from .features import crossing, placed_windows
from .fill import fill_screen
from .neighbours import components
from .roi import JUNCTION_CLEARANCE_PX, MIN_HALF_WIDTH_PX, plan_roi, roi_margin_px
from .screen import geometry_screen
from .settings import ScanSettings

if TYPE_CHECKING:
    from .segments import HalfEdge, Segment

# with workers chosen automatically, a local pool measures the candidates when each worker has at least
# this many (about 2-3 s of work against a pool's start of 0.2-0.5 s); fewer are measured here
AUTO_PLANS_PER_WORKER = 100
AUTO_TILES_PER_WORKER = 4       # ... and detection its tiles from this many a worker (0.2-0.3 s a tile)
TASKS_PER_WORKER = 4            # a pool's candidates are split into this many tasks a worker: a late tile waits less


def track_azimuth(info: RasterInfo, settings: ScanSettings) -> float | None:
    """The ground track's azimuth in the scene: the user's, else 0 (rows
    along track) for a scene in sensor geometry, unknown (None) for a
    map-projected one."""
    if settings.track_azimuth_deg is not None:
        return settings.track_azimuth_deg
    return None if info.crs else 0.0


def in_image_axes(info: RasterInfo, settings: ScanSettings) -> bool:
    """Whether the scene's directions are named by its own axes
    (horizontal, vertical): no CRS, no pixel size and no track azimuth
    given (a camera's photo), as :func:`imgmtf.raster_estimate.in_image_axes`."""
    return settings.track_azimuth_deg is None and not info.crs and info.gsd_m is None


# -- the scan -------------------------------------------------------------------------
def scan_scene(path: str, settings: ScanSettings | None = None, *, workers: int | None = 1,
               scheduler: str | None = None, progress: bool | None = None,
               figures_dir: str | None = None) -> list[Record]:
    """Every candidate target of the scene as a record: accepted ones first
    in rank order, then rejected ones by length.

    Parameters
    ----------
    path : str
        The scene (any raster GDAL reads, up to 1 Gpx).
    settings : ScanSettings, optional
        How to scan (:class:`imgmtf.ScanSettings`; default its defaults).
    workers : int or None, optional
        Local worker processes (default 1: none, the work runs here); None
        chooses: the available cores for the detection when each has
        ``AUTO_TILES_PER_WORKER`` tiles to read, and for the candidates'
        measurement when each has ``AUTO_PLANS_PER_WORKER`` of them
        (:func:`imgmtf.parallel.auto_workers`), else none.  The records are
        the same whatever the workers.
    scheduler : str, optional
        A Dask distributed scheduler's address, or ``"local"`` for a local
        Dask cluster (:func:`imgmtf.parallel.run_tasks`).
    progress : bool, optional
        Show a progress bar on stderr (default: when stderr is a terminal).
    figures_dir : str, optional
        A folder (created) for one measurement figure per accepted
        candidate, ``edge<id>.png`` (:func:`imgmtf.plot.plot_measurement`:
        its locations, profile, LSF and MTF); its path is the record's
        ``plot``.

    Returns
    -------
    list of Record
        One per candidate (a half-edge between junctions, or a bar), with
        ``status`` accepted or rejected, the reason of a rejection, the
        figures of an accepted one and its estimate (``measurement``: an
        EdgeResult or PulseResult, in memory only), and in its site where it lies
        (``x0_px``...), its ROI (``roi``, ``roi_polygon_px``), ``id``,
        ``rank`` and, for the half-edges of a target with an accepted
        one, ``target_id``.  Combine them with
        :func:`imgmtf.scene.combine.summarise_scan`.

    Raises
    ------
    ImgmtfError
        The scene cannot be read or scanned (too large, flat, unreadable);
        a ParameterError for a path or settings of the wrong kind.
        An interrupt (KeyboardInterrupt, or SIGTERM under
        :func:`imgmtf.parallel.terminate_raises`) propagates with the
        records so far as its ``records`` attribute: candidates not yet
        measured are rejected with reason ``interrupted``.

    Examples
    --------
    >>> records = scan_scene("data/scene.tif", ScanSettings(track_azimuth_deg=0.0))  # doctest: +SKIP
    >>> [(r.site["rank"], r.figures["mtf_nyquist"]) for r in records if r.ok]  # doctest: +SKIP
    [(1, 0.261544), (2, 0.266206)]
    """
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"path must be the scene's file name (str or os.PathLike), got {type(path).__name__}")
    path = str(path)
    settings = ScanSettings() if settings is None else settings
    if not isinstance(settings, ScanSettings):
        raise ParameterError(f"settings must be a ScanSettings, got {settings!r}")
    run_utc = utc_now()
    info = raster_info(path)
    if min(info.width, info.height) < MIN_SIZE_PX:
        # a strip or a one-pixel scene holds no chip: refused before any tile is read
        raise ImageContentError(f"{path}: the scene is {info.width} x {info.height} px; an edge or bar chip needs "
                                f"at least {MIN_SIZE_PX} x {MIN_SIZE_PX}, so no target can be measured in it")
    detecting = (auto_workers(len(tile_windows(info, settings.tile_px)), AUTO_TILES_PER_WORKER) if workers is None
                 else workers)
    if scheduler is None and detecting > 1 and not preloaded(SCAN_TASK_MODULES):
        # once, not by each of the two pools' workers; a fork server running them already (the
        # command's) is left to import them while detection searches its first tiles here
        prestart_workers(detecting, SCAN_TASK_MODULES)
    from .segments import (
        BAR_MAX_SEPARATION_PX,
        SampledSegments,
        find_junctions,
        parallel_clearance,
        segment_rows,
        split_at_junctions,
    )
    segments, fill_fraction = detect_segments(path, settings, workers=detecting, scheduler=scheduler, progress=progress)
    _prestart_for_candidates(len(segments), workers, detecting, scheduler)
    sampled = SampledSegments.of(segments)          # one sampling for the junctions, the lines and the neighbours
    junctions, events = find_junctions(sampled)
    halves = split_at_junctions(sampled, junctions, events, fill_fraction)
    track = track_azimuth(info, settings)
    params = {**settings.measure_settings().params(), "track_azimuth_deg": track, "scan": settings.as_dict()}
    if figures_dir is not None:
        figures_dir = str(ensure_folder(figures_dir))
    context = Context(path, info, settings, track, params, run_utc, figures_dir)
    candidates = [(half, verdict or fill_screen(half.fill_fraction) or geometry_screen(half, settings))
                  for half, verdict in _candidates(halves, settings)]
    features: list = [None] * len(candidates)
    if settings.roi is not None:        # a vector layer's sites: only the candidates crossing one of them
        owners = crossing(segment_rows([half.segment for half, _ in candidates]), placed_windows(settings.roi, info))
        candidates = [c for c, owner in zip(candidates, owners) if owner is not None]
        features = [owner for owner in owners if owner is not None]
    unscreened = [i for i, (_, verdict) in enumerate(candidates) if verdict is None]
    beside = np.full(len(candidates), np.inf)
    beside[unscreened] = parallel_clearance([candidates[i][0].segment for i in unscreened], sampled,
                                            roi_margin_px(settings) + JUNCTION_CLEARANCE_PX + BAR_MAX_SEPARATION_PX)
    verdicts = [verdict or _beside_screen(half, clearance) for (half, verdict), clearance in zip(candidates, beside)]
    plans = [Plan(k, plan_roi(half, settings, clearance), segment_rows(half.partners), half.segment.width_px)
             for k, ((half, _), clearance, verdict) in enumerate(zip(candidates, beside, verdicts)) if not verdict]
    measuring = auto_workers(len(plans), AUTO_PLANS_PER_WORKER) if workers is None else workers
    batches = _batches(plans, info, settings.tile_px)
    if measuring > 1:
        batches = _split_batches(batches, measuring * TASKS_PER_WORKER)
    halves = [half for half, _ in candidates]

    def lost(task, exc):
        """Every candidate of a batch whose task died with its worker."""
        return [(plan.index, Record.failed(path, settings.band, settings.target, settings.method, exc,
                                           params=context.params, run_utc=run_utc, status="rejected"))
                for plan in task[2]]
    records: list[Record] = []
    try:
        for _, outcomes in run_tasks(measure_batch, [(context, window, batch) for window, batch in batches],
                                     workers=measuring, scheduler=scheduler, progress=progress,
                                     description="measuring targets", on_error=lost, ordered=False):
            # the candidates' records made once the first outcome is in: on a pool, while its
            # workers measure the tasks queued for them
            records = records or _candidate_records(halves, verdicts, features, context)
            for index, outcome in outcomes:
                records[index] = _measured(records[index], outcome)
    except KeyboardInterrupt as exc:
        records = records or _candidate_records(halves, verdicts, features, context)
        pending = {plan.index for _, batch in batches for plan in batch}
        for i in pending:
            if records[i].status == "candidate":
                records[i] = records[i].with_(status="rejected", reason="interrupted",
                                              error=f"{path}: not measured: the scan was interrupted")
        exc.records = _named_figures(_ranked(_grouped(records, halves)))  # type: ignore[attr-defined]  # kept
        raise
    records = records or _candidate_records(halves, verdicts, features, context)
    return _named_figures(_ranked(_grouped(records, halves)))


def _prestart_for_candidates(segments: int, workers: int | None, detecting: int, scheduler: str | None) -> None:
    """Where workers are chosen, the tiles were searched here and the
    segments found promise a pool for the candidates (one candidate or more
    each; a pool when :func:`imgmtf.parallel.auto_workers` gives it for as
    many), its fork server started now importing the candidates' modules
    (:func:`imgmtf.parallel.prestart_workers`): on another core while this
    process splits the segments at their junctions and plans the ROIs
    (0.4-0.8 s on a dense chart), rather than each worker importing them
    after (0.5 s with both cores idle)."""
    from ..parallel import can_preload
    if workers is not None or detecting > 1 or scheduler is not None or preloaded(SCAN_TASK_MODULES) \
            or not can_preload():
        return
    pool = auto_workers(segments, AUTO_PLANS_PER_WORKER)
    if pool > 1:
        prestart_workers(pool, SCAN_TASK_MODULES)


def _candidate_records(halves: list[HalfEdge], verdicts: list, features: list, context: Context) -> list[Record]:
    """Each candidate's record before it is measured (:func:`_candidate_record`):
    rejected by its screen's verdict, or a candidate; with the site of the
    vector layer's feature it crosses, and where it lies in a lens's field,
    where the scan has them."""
    info, settings = context.info, context.settings
    segments = [half.segment for half in halves]
    rounded = _rounded_ends(segments)
    centre = resolve_centre(settings.optical_centre, info.width, info.height)
    mapped = _map_ends(segments, info)
    records = []
    for k, (half, verdict) in enumerate(zip(halves, verdicts)):
        record = _candidate_record(half, context, rounded[k], None if mapped is None else mapped[k], verdict)
        if features[k] is not None:
            record = record.with_(site=features[k].record_fields())
        if centre is not None:          # where the candidate lies in a lens's field
            s = half.segment
            record = record.with_(site=field_position((s.x0 + s.x1) / 2, (s.y0 + s.y1) / 2, s.normal_angle_deg, centre))
        records.append(record)
    return records


def _named_figures(records: list[Record]) -> list[Record]:
    """Each accepted candidate's figure renamed from its measuring order to
    its id (``edge<id>.png``), which is known only once all are ranked."""
    out = []
    for r in records:
        if r.plot:
            named = str(Path(r.plot).with_name(f"edge{r.site['id']}.png"))
            os.replace(r.plot, named)
            r = r.with_(plot=named)
        out.append(r)
    return out


def _beside_screen(half: HalfEdge, clearance_px: float) -> tuple[str, str] | None:
    """``two-targets`` when another segment runs so close beside the
    candidate that its ROI, kept clear of it, would be narrower than
    ``MIN_HALF_WIDTH_PX`` either side."""
    if clearance_px - JUNCTION_CLEARANCE_PX < MIN_HALF_WIDTH_PX + half.segment.width_px / 2:
        return "two-targets", (f"another edge runs beside it {clearance_px:.1f} px away: no ROI holds this "
                               "target alone")
    return None


def _candidates(halves: list[HalfEdge], settings: ScanSettings) -> list[tuple[HalfEdge, tuple[str, str] | None]]:
    """The half-edges as candidates of the scan's target: for edges, lone
    half-edges and bars alike (the gate tells an edge from a bar); for
    pulses, bars, and lone half-edges rejected as ``not-a-bar``."""
    from .segments import HalfEdge, pair_bars
    long_enough = [h for h in halves if h.line_length_px >= settings.min_length_px / 2]
    lone, bars = pair_bars([h.segment for h in long_enough])
    out: list[tuple[HalfEdge, tuple[str, str] | None]] = []
    lone_verdict = get_kind(settings.target).lone_line
    out += [(long_enough[i], lone_verdict) for i in lone]
    for i, j, bar in bars:
        a, b = long_enough[i], long_enough[j]
        out.append((HalfEdge(bar, min(a.line_length_px, b.line_length_px), (None, None),
                             a.partners + b.partners, max(a.fill_fraction, b.fill_fraction)), None))
    return out


def _batches(plans: list[Plan], info: RasterInfo, tile_px: int) -> list[tuple[tuple[int, int, int, int], list[Plan]]]:
    """Plans grouped by the tile their ROI's centre falls in, each group
    with the window (x, y, w, h) that holds all their ROIs: one read each."""
    groups: dict[tuple[int, int], list[Plan]] = {}
    boxes: dict[tuple[int, int], list[tuple[int, int, int, int]]] = {}
    for plan in plans:
        box = plan.roi.bbox(info.width, info.height)
        key = ((box[0] + box[2] // 2) // tile_px, (box[1] + box[3] // 2) // tile_px)
        groups.setdefault(key, []).append(plan)
        boxes.setdefault(key, []).append(box)
    out = []
    for key in sorted(groups):
        b = np.array(boxes[key])
        x0, y0 = b[:, 0].min(), b[:, 1].min()
        x1, y1 = (b[:, 0] + b[:, 2]).max(), (b[:, 1] + b[:, 3]).max()
        out.append(((int(x0), int(y0), int(x1 - x0), int(y1 - y0)), groups[key]))
    return out


def _split_batches(batches: list[tuple[tuple[int, int, int, int], list[Plan]]], tasks: int
                   ) -> list[tuple[tuple[int, int, int, int], list[Plan]]]:
    """The batches cut into about ``tasks`` tasks of similar numbers of
    plans, each piece keeping its batch's window: a candidate is read from
    the same pixels, and measured alike, whichever piece holds it."""
    total = sum(len(batch) for _, batch in batches)
    size = max(1, math.ceil(total / max(tasks, 1)))
    return [(window, batch[i: i + size]) for window, batch in batches for i in range(0, len(batch), size)]


# -- records ----------------------------------------------------------------------------
def _candidate_record(half: HalfEdge, context: Context, ends: list[float], map_ends: list[float] | None,
                      verdict: tuple[str, str] | None) -> Record:
    """A candidate's record before it is measured: where it lies (its
    ``ends`` x0, y0, x1, y1, rounded, and in map coordinates
    ``map_ends`` when the scene has them), ``candidate``, or rejected by a
    screen's ``verdict``."""
    segment, info, settings = half.segment, context.info, context.settings
    site = {
        "scope": CANDIDATE_SCOPE,
        **dict(zip(("x0_px", "y0_px", "x1_px", "y1_px"), ends)),
        "length_px": round(segment.length_px, 1), "line_length_px": round(half.line_length_px, 1),
        "tilt_deg": round(segment.tilt_deg, 2), "normal_angle_deg": round(segment.normal_angle_deg, 2),
        "direction": direction_label(segment.normal_angle_deg, context.track_azimuth_deg),
        "ends": [_end(j) for j in half.junctions],
        "roi": list(plan_roi(half, settings).bbox(info.width, info.height)),
    }
    if segment.width_px > 0 or get_kind(settings.target).has_width:
        site["bar_width_px"] = round(segment.width_px, 2)
    if map_ends is not None:
        site.update(zip(("map_x0", "map_y0", "map_x1", "map_y1"), map_ends))
    if verdict:
        site["verdict_by"] = "screen"
        return Record(context.path, settings.band, settings.target, settings.method, "rejected", verdict[0],
                      f"{context.path}: {verdict[1]}", site=site, params=context.params, run_utc=context.run_utc)
    return Record(context.path, settings.band, settings.target, settings.method, "candidate", site=site,
                  params=context.params, run_utc=context.run_utc)


def _rounded_ends(segments: list[Segment]) -> list[list[float]]:
    """The segments' ends (x0, y0, x1, y1) rounded to 0.01 px: a
    half-edge's as NumPy rounds (x 100, to the nearest integer), all in one
    pass; a bar's centre line's as Python's ``round`` does (the nearest of
    the exact value), as the records always had them (the two differ where
    a value lies within rounding of a half-step)."""
    from .segments import segment_rows
    by_numpy = np.round(segment_rows(segments), 2).tolist()
    return [[round(v, 2) for v in (s.x0, s.y0, s.x1, s.y1)] if s.width_px > 0 else by_numpy[k]
            for k, s in enumerate(segments)]


def _map_ends(segments: list, info: RasterInfo) -> list[list[float]] | None:
    """The segments' ends (x0, y0, x1, y1 of their pixel centres) in the
    scene's map coordinates, all in one pass; None where its transform is
    the identity (pixel coordinates are all it has)."""
    if info.transform.is_identity or not segments:
        return None
    from .segments import segment_rows
    ends = segment_rows(segments) + 0.5
    x0, y0 = info.transform @ (ends[:, 0], ends[:, 1])
    x1, y1 = info.transform @ (ends[:, 2], ends[:, 3])
    return np.column_stack([x0, y0, x1, y1]).tolist()


def _end(junction: int | None) -> str:
    return "free" if junction is None else f"junction {junction}"


def _measured(candidate: Record, outcome: Record) -> Record:
    """A candidate with its measurement's outcome, figures and settings."""
    return candidate.with_(status=outcome.status, reason=outcome.reason, error=outcome.error,
                           band=outcome.band if outcome.band is not None else candidate.band,
                           figures=outcome.figures, site=outcome.site, plot=outcome.plot,
                           params={**outcome.params, **candidate.params}, measurement=outcome.measurement)


def _grouped(records: list[Record], halves: list[HalfEdge]) -> list[Record]:
    """Targets: the measured candidates (those that reached the gate, or
    were accepted) joined through the junctions they share; each target
    with an accepted half-edge gets a ``target_id`` (1, 2... in the order
    of its best rank is assigned after ranking, see :func:`_ranked`)."""
    reached = [i for i, r in enumerate(records) if r.site.get("verdict_by") == "gate"]
    owners: dict[int, list[int]] = {}
    for i in reached:
        for j in halves[i].junctions:
            if j is not None:
                owners.setdefault(j, []).append(i)
    n = len(records)
    a = [m[0] for m in owners.values() for _ in m[1:]]
    b = [x for m in owners.values() for x in m[1:]]
    _, label = components(n, np.array(a, np.intp), np.array(b, np.intp))
    groups_with_accepted = {label[i] for i, r in enumerate(records) if r.ok}
    return [r.with_(site={"group": int(label[i])}) if i in reached and label[i] in groups_with_accepted else r
            for i, r in enumerate(records)]


def _ranked(records: list[Record]) -> list[Record]:
    """Accepted records by interval width (then SNR), rejected ones by
    length; ``id`` (and ``rank`` for accepted ones) first in their site,
    and ``target_id`` numbering the targets by their best rank."""
    accepted = [r for r in records if r.ok]
    rejected = [r for r in records if not r.ok]

    def interval_width(r):
        low, high = r.figures.get("mtf_nyquist_ci") or (None, None)
        return (high - low) if low is not None and high is not None else math.inf
    accepted.sort(key=lambda r: (interval_width(r), -(r.figures.get("snr") or math.inf)))
    rejected.sort(key=lambda r: -r.site["length_px"])
    ranked = [(r, rank) for rank, r in enumerate(accepted, 1)] + [(r, None) for r in rejected]
    target_ids: dict[int, int] = {}
    for r, _ in ranked:
        if "group" in r.site and r.site["group"] not in target_ids:
            target_ids[r.site["group"]] = len(target_ids) + 1
    out = []
    for i, (r, rank) in enumerate(ranked, 1):
        site = {k: v for k, v in r.site.items() if k != "group"}
        target = target_ids.get(r.site["group"]) if "group" in r.site else None
        out.append(replace(r, site={"id": i, "rank": rank, "target_id": target, **site}))
    return out
