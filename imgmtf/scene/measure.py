"""Measurement: each candidate's ROI read and measured, its outcome a
record; accepted targets ranked."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..batch import measure_raster
from ..io import RasterInfo, raster_info, read_raster
from ..parallel import run_tasks
from ..records import Record, utc_now
from .detect import END_TRIM_PX, Segment, detect_segments, pair_bars
from .screen import screen
from .settings import ScanSettings


def segment_roi(segment: Segment, info: RasterInfo, settings: ScanSettings) -> tuple[int, int, int, int]:
    """Axis-aligned (x, y, width, height) around the central part of the
    segment, at most ``max_length_px`` long and trimmed at its ends,
    ``margin_px`` beyond it across, clipped to the scene."""
    p0, p1 = np.array([segment.x0, segment.y0]), np.array([segment.x1, segment.y1])
    length = segment.length_px
    keep = min(length, settings.max_length_px)
    centre, u = (p0 + p1) / 2, segment.unit()
    a, b = centre - u * keep / 2, centre + u * keep / 2
    margin = settings.margin_px + segment.width_px / 2
    if segment.direction == "across-track":     # near-vertical: trim rows, widen columns
        x_lo, x_hi = min(a[0], b[0]) - margin, max(a[0], b[0]) + margin
        y_lo, y_hi = min(a[1], b[1]) + END_TRIM_PX, max(a[1], b[1]) - END_TRIM_PX
    else:
        x_lo, x_hi = min(a[0], b[0]) + END_TRIM_PX, max(a[0], b[0]) - END_TRIM_PX
        y_lo, y_hi = min(a[1], b[1]) - margin, max(a[1], b[1]) + margin
    x0, y0 = max(int(math.floor(x_lo)), 0), max(int(math.floor(y_lo)), 0)
    x1, y1 = min(int(math.ceil(x_hi)), info.width - 1), min(int(math.ceil(y_hi)), info.height - 1)
    return x0, y0, x1 - x0 + 1, y1 - y0 + 1


def measure_candidate(task) -> Record:
    """Measure one candidate ROI (a task of :func:`scan_scene`): a record
    with ``status`` accepted or rejected, whatever goes wrong."""
    path, roi, settings, run_utc = task
    measure = settings.measure_settings()
    params = measure.params()
    try:
        raster = read_raster(path, settings.band, window=roi)
        result = measure_raster(raster, measure)
        figures = {**result.to_dict(curves=False), "line_rms_px": _line_rms(result.geometry),
                   "side_variation": side_variation(result)}
    except Exception as exc:        # an estimator's refusal, or the safety net
        return Record.failed(path, settings.band, settings.target, settings.method, exc, params=params,
                             run_utc=run_utc, status="rejected")
    record = Record.measured(path, raster.band, figures, params=params, run_utc=run_utc,
                             status="accepted")
    variation, line_rms = figures["side_variation"], figures["line_rms_px"]
    if variation > settings.max_side_variation:
        return record.with_(status="rejected", reason="non-uniform", error=(
            f"{path}: a side of the target varies by {100 * variation:.0f} % of its contrast (at most "
            f"{100 * settings.max_side_variation:g} % allowed): not a uniform field"))
    if line_rms > settings.max_line_rms_px:
        return record.with_(status="rejected", reason="not-straight", error=(
            f"{path}: the per-row locations scatter {line_rms:.2f} px about the fitted line (at most "
            f"{settings.max_line_rms_px:g} px allowed): not a straight target"))
    return record


def _line_rms(geometry) -> float:
    kept = geometry.kept
    resid = geometry.locations[kept] - (geometry.slope * geometry.rows[kept] + geometry.intercept)
    return float(np.sqrt(np.mean(resid ** 2)))


def side_variation(result) -> float:
    """Largest level change over either flat side of the target (linear
    trend across the side, or twice the scatter about it), as a fraction of
    the target's contrast.  Sides start 3 px (plus half a bar) from the
    line."""
    d, v = result.samples_x_px, result.samples_dn
    if result.target == "edge":
        contrast = abs(result.levels_dn[1] - result.levels_dn[0])
        inner = 3.0
    else:
        contrast = abs(result.peak_dn - result.background_dn)
        inner = 3.0 + result.pulse_width_px / 2
    worst = 0.0
    for side in (d <= -inner, d >= inner):
        if side.sum() < 10:
            continue
        x, y = d[side], v[side]
        slope, intercept = np.polyfit(x, y, 1)
        trend = abs(slope) * (x.max() - x.min())
        scatter = 2.0 * np.std(y - (slope * x + intercept))
        worst = max(worst, trend, scatter)
    return float(worst / contrast) if contrast > 0 else math.inf


def scan_scene(path: str, settings: ScanSettings = ScanSettings(), *, workers: int = 1,
               scheduler: str | None = None, progress: bool | None = None) -> list[Record]:
    """Every candidate target of the scene as a record, accepted ones first
    in rank order, then rejected ones by length.

    An interrupt (KeyboardInterrupt, or SIGTERM under
    :func:`imgmtf.parallel.terminate_raises`) propagates with the records
    so far as its ``records`` attribute: candidates not yet measured are
    rejected with reason ``interrupted``.
    """
    path = str(path)
    run_utc = utc_now()
    info = raster_info(path)
    segments = detect_segments(path, settings)
    lone, bars = pair_bars(segments)
    candidates: list[tuple[Segment, tuple[str, str] | None]] = []
    if settings.target == "pulse":
        candidates += [(bar, None) for bar, _ in bars]
        candidates += [(s, ("not-a-bar", "a lone edge, not the two sides of a bar")) for s in lone]
    else:
        candidates += [(s, None) for s in lone]
        candidates += [(bar, ("two-targets", f"two parallel edges {bar.width_px:.1f} px apart (a bar: "
                              "measure it with --target pulse)")) for bar, _ in bars]
    records, tasks = [], []
    for segment, verdict in candidates:
        verdict = verdict or screen(segment, settings)
        roi = segment_roi(segment, info, settings)
        record = _segment_record(path, segment, roi, info, settings, run_utc)
        if verdict:
            record = record.with_(status="rejected", reason=verdict[0], error=f"{path}: {verdict[1]}")
        else:
            tasks.append((len(records), (path, roi, settings, run_utc)))
        records.append(record)

    def lost(task, exc):
        return Record.failed(path, settings.band, settings.target, settings.method, exc,
                             params=settings.measure_settings().params(), run_utc=run_utc,
                             status="rejected")
    try:
        for task_index, outcome in run_tasks(measure_candidate, [t for _, t in tasks], workers=workers,
                                             scheduler=scheduler, progress=progress,
                                             description="measuring targets", on_error=lost,
                                             ordered=False):
            index = tasks[task_index][0]
            records[index] = _measured(records[index], outcome)
    except KeyboardInterrupt as exc:
        stopped = [i for i, _ in tasks if records[i].status == "candidate"]
        for i in stopped:
            records[i] = records[i].with_(status="rejected", reason="interrupted",
                                          error=f"{path}: not measured: the scan was interrupted")
        exc.records = _ranked(records)
        raise
    return _ranked(records)


def _measured(candidate: Record, outcome: Record) -> Record:
    """A candidate with its measurement's outcome, figures and settings."""
    return candidate.with_(status=outcome.status, reason=outcome.reason, error=outcome.error,
                           band=outcome.band if outcome.band is not None else candidate.band,
                           figures=outcome.figures, params={**outcome.params, **candidate.params})


def _segment_record(path, segment: Segment, roi, info: RasterInfo, settings: ScanSettings,
                    run_utc: str) -> Record:
    site = {
        "x0_px": round(segment.x0, 2), "y0_px": round(segment.y0, 2),
        "x1_px": round(segment.x1, 2), "y1_px": round(segment.y1, 2),
        "length_px": round(segment.length_px, 1), "tilt_deg": round(segment.tilt_deg, 2),
        "direction": segment.direction, "roi": list(roi),
    }
    if settings.target == "pulse":
        site["bar_width_px"] = round(segment.width_px, 2)
    if not info.transform.is_identity:
        (mx0, my0), (mx1, my1) = (info.transform @ (x + 0.5, y + 0.5)
                                  for x, y in ((segment.x0, segment.y0), (segment.x1, segment.y1)))
        site.update(map_x0=mx0, map_y0=my0, map_x1=mx1, map_y1=my1)
    params = {"scan": _scan_params(settings), "intervals": settings.intervals.as_dict()}
    return Record(path, settings.band, settings.target, settings.method, "candidate", site=site,
                  params=params, run_utc=run_utc)


def _scan_params(settings: ScanSettings) -> dict:
    return {k: getattr(settings, k) for k in ("min_length_px", "max_length_px", "margin_px",
                                             "max_side_variation", "max_line_rms_px", "tile_px")}


def _ranked(records: list[Record]) -> list[Record]:
    """Accepted records by interval width (then SNR), rejected ones by
    length; ``id`` (and ``rank`` for accepted ones) first in their site."""
    accepted = [r for r in records if r.ok]
    rejected = [r for r in records if not r.ok]

    def interval_width(r):
        low, high = r.figures.get("mtf_nyquist_ci") or (None, None)
        return (high - low) if low is not None and high is not None else math.inf
    accepted.sort(key=lambda r: (interval_width(r), -(r.figures.get("snr") or math.inf)))
    rejected.sort(key=lambda r: -r.site["length_px"])
    ranked = [(r, rank) for rank, r in enumerate(accepted, 1)] + [(r, None) for r in rejected]
    return [replace(r, site={"id": i, "rank": rank, **r.site}) for i, (r, rank) in enumerate(ranked, 1)]
