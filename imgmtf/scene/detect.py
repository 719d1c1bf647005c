"""Detection: straight segments of a scene read tile by tile, found by
OpenCV's line segment detector, merged across tiles, and paired into bars."""
from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from ..errors import ImgmtfError
from ..inputs import saturation_levels
from ..io import RasterInfo, raster_info, read_raster
from .settings import ScanSettings

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
