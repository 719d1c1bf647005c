"""Find and measure every usable edge (or bar) in a scene.

1. detect: the scene is read tile by tile (windowed reads: a large scene is
   never loaded whole), scaled to 8 bits with levels taken from a decimated
   overview, and OpenCV's line segment detector (LSD) finds straight
   segments in each tile; collinear pieces (across tiles too) are merged;
2. pair: two parallel segments a few pixels apart are the two sides of a
   bar, one pulse candidate (and, for edges, a rejection: a bar is not an
   edge);
3. screen: a candidate shorter than ``min_length_px`` or tilted less than
   ``MIN_ANGLE_DEG`` from an image axis or more than ``MAX_ANGLE_DEG`` is
   rejected before it is read;
4. measure: an axis-aligned ROI around each candidate (``margin_px`` beyond
   it across, its ends trimmed) is read and measured; the estimator's own
   refusals (another edge in the ROI, saturation, border...) become the
   rejection reason, and an accepted target must have uniform sides and a
   straight line (:class:`ScanSettings`);
5. rank: accepted targets by the width of their MTF-at-Nyquist confidence
   interval, which grows as SNR, length or straightness fall.

Every candidate becomes a :class:`imgmtf.records.Record` with ``status``
(accepted/rejected), ``reason`` and, in its ``site``, ``id``, ``rank``,
the segment in pixels (``x0_px``...) and, when georeferenced, in map
coordinates.  An unexpected failure on one candidate rejects it (reason
``internal``), never the scan.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import cv2
import numpy as np

from .atomic import atomic_output, ensure_folder
from .batch import MeasureSettings, measure_raster, save_figure
from .errors import FileWriteError, ImgmtfError, ParameterError
from .estimate.geometry import MAX_ANGLE_DEG, MIN_ANGLE_DEG
from .estimate.intervals import Intervals
from .inputs import saturation_levels
from .io import RasterInfo, raster_info, read_raster
from .parallel import run_tasks
from .records import SCAN_CSV_COLUMNS, Record, json_safe, utc_now, write_csv
from .version import __version__

# Scenes larger than this are refused: detection reads every tile, and 1 Gpx
# (32768 x 32768) is already minutes of it.  Crop a part to scan it.
MAX_SCAN_PIXELS = 2 ** 30

MERGE_ANGLE_DEG = 2.0        # pieces of one line differ by less than this in direction
MERGE_OFFSET_PX = 1.5        # ... lie within this of each other's line
MERGE_GAP_PX = 6.0           # ... and leave at most this gap between them
BAR_MAX_SEPARATION_PX = 8.0  # two parallel sides closer than this are one bar
END_TRIM_PX = 3              # rows dropped at each end of a segment (its corners)
TILE_OVERLAP_PX = 32


@dataclass(frozen=True)
class Segment:
    """A straight segment from (x0, y0) to (x1, y1), pixel coordinates of
    the scene (x to the right, y down, pixel centres at integers).
    ``width_px`` is 0 for an edge and the separation of its sides for a
    bar."""

    x0: float
    y0: float
    x1: float
    y1: float
    width_px: float = 0.0

    @property
    def length_px(self) -> float:
        return math.hypot(self.x1 - self.x0, self.y1 - self.y0)

    @property
    def tilt_deg(self) -> float:
        """Smallest angle (deg) between the segment and an image axis."""
        a = abs(math.degrees(math.atan2(self.y1 - self.y0, self.x1 - self.x0))) % 90.0
        return min(a, 90.0 - a)

    @property
    def direction(self) -> str:
        """A near-vertical line (rows along track) measures across track."""
        return "across-track" if abs(self.y1 - self.y0) >= abs(self.x1 - self.x0) else "along-track"

    def unit(self) -> np.ndarray:
        d = np.array([self.x1 - self.x0, self.y1 - self.y0])
        return d / np.linalg.norm(d)


@dataclass(frozen=True)
class ScanSettings:
    """How to scan a scene.

    target : "edge" or "pulse".
    min_length_px : shortest usable target (px along it).
    max_length_px : longer targets are measured over their central part.
    margin_px : ROI extent beyond the target across it (px).
    max_side_variation : largest level change (trend or spread) of a side,
        as a fraction of the target's contrast, for a uniform side.
    max_line_rms_px : largest RMS scatter of the per-row target locations
        about their line (px) for a straight target.
    tile_px : side of the tiles read for detection (px).
    method, band, pulse_width, intervals, track_azimuth_deg : as in
        :class:`imgmtf.batch.MeasureSettings`.
    """

    target: str = "edge"
    min_length_px: float = 40.0
    max_length_px: float = 300.0
    margin_px: int = 12
    max_side_variation: float = 0.1
    max_line_rms_px: float = 0.25
    tile_px: int = 1024
    method: str = "msg"
    band: int | None = None
    pulse_width: tuple[float, str] | None = None
    intervals: Intervals = field(default_factory=Intervals)
    track_azimuth_deg: float | None = None

    def __post_init__(self):
        if not self.min_length_px >= 16:
            raise ParameterError(f"--min-length must be at least 16 px, got {self.min_length_px}")
        if self.margin_px < 6:
            raise ParameterError(f"the ROI margin must be at least 6 px, got {self.margin_px}")
        if self.band == "all":
            raise ParameterError("scan one band at a time (--band N)")
        self.measure_settings()

    def measure_settings(self) -> MeasureSettings:
        return MeasureSettings(self.target, self.method, self.band, None, self.pulse_width, self.intervals,
                               track_azimuth_deg=self.track_azimuth_deg)


# -- detection -----------------------------------------------------------------
def detect_segments(path: str, settings: ScanSettings = ScanSettings()) -> list[Segment]:
    """Straight segments of the scene at least half ``min_length_px`` long
    (shorter ones are texture, not worth reporting), merged across tiles."""
    info = raster_info(path)
    check_scene_size(info)
    lo, hi = _display_levels(path, settings.band, info)
    detector = cv2.createLineSegmentDetector(cv2.LSD_REFINE_STD)
    pieces = []
    step = settings.tile_px - TILE_OVERLAP_PX
    for y in range(0, max(info.height - TILE_OVERLAP_PX, 1), step):
        for x in range(0, max(info.width - TILE_OVERLAP_PX, 1), step):
            w, h = min(settings.tile_px, info.width - x), min(settings.tile_px, info.height - y)
            tile = read_raster(path, settings.band, window=(x, y, w, h)).data
            found = detector.detect(_to_8bit(tile, lo, hi))[0]
            if found is not None:
                pieces.extend(found.reshape(-1, 4).astype(float) + (x, y, x, y))
    merged = merge_segments(np.array(pieces, float).reshape(-1, 4))
    return [s for s in merged if s.length_px >= settings.min_length_px / 2]


def check_scene_size(info: RasterInfo) -> None:
    """Refuse a scene above :data:`MAX_SCAN_PIXELS` (its header's word)."""
    if info.width * info.height > MAX_SCAN_PIXELS:
        raise ImgmtfError(
            f"{info.path}: the scene is {info.width} x {info.height} px "
            f"({info.width * info.height / 2**30:.1f} Gpx), more than the {MAX_SCAN_PIXELS // 2**30} Gpx "
            "a scan reads; scan a part of it (crop it, e.g. gdal_translate -srcwin X Y W H)",
            reason="too-large")


def _display_levels(path, band, info: RasterInfo) -> tuple[float, float]:
    """The 0.5 and 99.5 percentiles of a decimated read of the whole scene,
    saturated pixels (at an integer type's limits) left out so that a
    clipped field cannot squash the rest of the scene into a few levels."""
    scale = max(info.width, info.height) / 1024
    shape = (max(int(info.height / scale), 1), max(int(info.width / scale), 1)) if scale > 1 else None
    data = read_raster(path, band, out_shape=shape).data
    finite = data[np.isfinite(data)]
    limits = saturation_levels(info.dtype)
    if limits is not None:
        finite = finite[(finite > limits[0]) & (finite < limits[1])]
    if finite.size == 0:
        raise ImgmtfError(f"{path}: every pixel is nodata or saturated", reason="image")
    lo, hi = np.percentile(finite, [0.5, 99.5])
    if not hi > lo:
        raise ImgmtfError(f"{path}: the image is flat: no contrast to scan", reason="image")
    return float(lo), float(hi)


def _to_8bit(tile: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """The tile scaled so that [lo, hi] fills 0-255 (nodata as the tile's median)."""
    finite = np.isfinite(tile)
    filled = np.where(finite, tile, np.median(tile[finite]) if finite.any() else lo)
    return np.clip(np.rint((filled - lo) / (hi - lo) * 255), 0, 255).astype(np.uint8)


def merge_segments(pieces: np.ndarray) -> list[Segment]:
    """Join pieces (rows x0, y0, x1, y1) that lie on one line: parallel
    within ``MERGE_ANGLE_DEG``, within ``MERGE_OFFSET_PX`` of each other's
    line, and at most ``MERGE_GAP_PX`` apart along it; longest first."""
    if pieces.size == 0:
        return []
    order = np.argsort(-np.hypot(pieces[:, 2] - pieces[:, 0], pieces[:, 3] - pieces[:, 1]))
    pieces = pieces[order]
    used = np.zeros(len(pieces), bool)
    out = []
    for i in range(len(pieces)):
        if used[i]:
            continue
        group = pieces[i].reshape(2, 2)
        used[i] = True
        grown = True
        while grown:
            grown = False
            p0, p1 = group[0], group[1]
            u = (p1 - p0) / np.linalg.norm(p1 - p0)
            n = np.array([-u[1], u[0]])
            rest = np.nonzero(~used)[0]
            if rest.size == 0:
                break
            a, b = pieces[rest, :2], pieces[rest, 2:]
            v = b - a
            lengths = np.linalg.norm(v, axis=1)
            parallel = np.abs(v @ u) / np.maximum(lengths, 1e-9) >= math.cos(math.radians(MERGE_ANGLE_DEG))
            offset = np.maximum(np.abs((a - p0) @ n), np.abs((b - p0) @ n))
            ta, tb = (a - p0) @ u, (b - p0) @ u
            length = np.linalg.norm(p1 - p0)
            gap = np.maximum(np.minimum(ta, tb) - length, -np.maximum(ta, tb))
            join = rest[parallel & (offset <= MERGE_OFFSET_PX) & (gap <= MERGE_GAP_PX)]
            if join.size:
                used[join] = True
                ends = np.vstack([group, pieces[join, :2], pieces[join, 2:]])
                t = (ends - p0) @ u
                group = np.array([p0 + t.min() * u, p0 + t.max() * u])
                # re-centre the line on all the ends, perpendicular offsets averaged
                shift = np.mean((ends - p0) @ n)
                group = group + shift * n
                grown = True
        out.append(Segment(*group[0], *group[1]))
    return sorted(out, key=lambda s: -s.length_px)


def pair_bars(segments: list[Segment]) -> tuple[list[Segment], list[tuple[Segment, Segment]]]:
    """Split segments into lone ones and pairs of parallel sides closer than
    ``BAR_MAX_SEPARATION_PX`` that overlap along half the shorter one (the
    two sides of a bar); a pair becomes one segment along its centre line
    with ``width_px`` the separation."""
    lone, bars = [], []
    taken = set()
    for i, a in enumerate(segments):
        if i in taken:
            continue
        u = a.unit()
        n = np.array([-u[1], u[0]])
        p0 = np.array([a.x0, a.y0])
        match = None
        for j in range(i + 1, len(segments)):
            b = segments[j]
            if j in taken or abs(b.unit() @ u) < math.cos(math.radians(MERGE_ANGLE_DEG)):
                continue
            q = np.array([[b.x0, b.y0], [b.x1, b.y1]]) - p0
            separation = abs(np.mean(q @ n))
            t = np.sort(q @ u)
            overlap = min(t[1], a.length_px) - max(t[0], 0.0)
            if 0.5 < separation <= BAR_MAX_SEPARATION_PX and overlap >= 0.5 * min(a.length_px, b.length_px):
                match = j
                break
        if match is None:
            lone.append(a)
            continue
        taken.add(match)
        b = segments[match]
        q = np.array([[b.x0, b.y0], [b.x1, b.y1]]) - p0
        shift = np.mean(q @ n) / 2
        t = np.sort(q @ u)
        start, end = max(t[0], 0.0), min(t[1], a.length_px)
        c0, c1 = p0 + start * u + shift * n, p0 + end * u + shift * n
        bars.append((Segment(*c0, *c1, width_px=2 * abs(shift)), b))
    return lone, bars


# -- ROIs and screening ----------------------------------------------------------
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


def screen(segment: Segment, settings: ScanSettings) -> tuple[str, str] | None:
    """(reason, message) when the segment can be rejected unread."""
    if segment.length_px < settings.min_length_px:
        return "too-short", (f"{segment.length_px:.0f} px long, shorter than the minimum "
                             f"{settings.min_length_px:g} px")
    if segment.tilt_deg < MIN_ANGLE_DEG:
        return "angle", (f"{segment.tilt_deg:.2f} deg from the image axis: too close for "
                         f"sub-pixel sampling (needs {MIN_ANGLE_DEG:g} to {MAX_ANGLE_DEG:g} deg)")
    if segment.tilt_deg > MAX_ANGLE_DEG:
        return "angle", (f"{segment.tilt_deg:.2f} deg from the image axis: too close to 45 deg "
                         f"for sub-pixel sampling (needs {MIN_ANGLE_DEG:g} to {MAX_ANGLE_DEG:g} deg)")
    return None


# -- measurement ------------------------------------------------------------------
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


# -- outputs ------------------------------------------------------------------------
def to_geojson(records: list[Record], info: RasterInfo) -> dict:
    """The candidates as a GeoJSON FeatureCollection of LineStrings.

    Georeferenced scenes (a CRS): geometry in longitude/latitude (WGS 84,
    as RFC 7946 requires), the scene's own map coordinates in the
    properties (``map_x0``...).  Scenes without a CRS: geometry in pixel
    coordinates (x right, y down; the ``imgmtf_coordinates`` member says
    so).  Every feature's properties carry the pixel coordinates and the
    record's figures."""
    rows = [r.to_dict() for r in records]
    if info.crs:
        from rasterio.warp import transform as warp
        xs = [v for r in rows for v in (r["map_x0"], r["map_x1"])]
        ys = [v for r in rows for v in (r["map_y0"], r["map_y1"])]
        lon, lat = warp(info.crs, "EPSG:4326", xs, ys) if xs else ([], [])
        lines = [[[lon[2 * i], lat[2 * i]], [lon[2 * i + 1], lat[2 * i + 1]]] for i in range(len(rows))]
        coordinates = "longitude/latitude (EPSG:4326)"
    else:
        lines = [[[r["x0_px"], r["y0_px"]], [r["x1_px"], r["y1_px"]]] for r in rows]
        coordinates = "pixel (x right, y down, pixel centres at integers)"
    features = [{"type": "Feature", "id": r["id"],
                 "geometry": {"type": "LineString", "coordinates": line},
                 "properties": {k: v for k, v in r.items() if k not in ("frequencies_cy_px", "mtf")}}
                for r, line in zip(rows, lines)]
    return {"type": "FeatureCollection", "imgmtf_coordinates": coordinates,
            "imgmtf_source": info.path, "imgmtf_version": __version__, "features": features}


def write_outputs(records: list[Record], info: RasterInfo, out_dir: str, overview_band=None) -> list[str]:
    """CSV, GeoJSON and overview PNG of a scan in ``out_dir`` (each written
    atomically); their paths."""
    from .plot import plot_scan
    out = ensure_folder(out_dir)
    csv_path, json_path, png_path = (str(out / n) for n in ("targets.csv", "targets.geojson", "overview.png"))
    write_csv(records, csv_path, SCAN_CSV_COLUMNS)
    with atomic_output(json_path) as partial:
        try:
            Path(partial).write_text(json.dumps(json_safe(to_geojson(records, info)), indent=1))
        except OSError as exc:
            raise FileWriteError(f"{json_path}: cannot write: {exc.strerror or exc}") from None
    scale = max(max(info.width, info.height) / 1500, 1.0)
    shape = (max(int(info.height / scale), 1), max(int(info.width / scale), 1))
    overview = read_raster(info.path, overview_band, out_shape=shape).data
    levels = _display_levels(info.path, overview_band, info)
    rows = [r.to_dict() for r in records]
    save_figure(lambda: plot_scan(overview, info.width / shape[1], rows, levels), png_path)
    return [csv_path, json_path, png_path]
