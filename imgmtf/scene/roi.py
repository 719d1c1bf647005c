"""A candidate's ROI: the tilted rectangle along it that it is measured on,
and the stretch of it clear of what must not enter the estimate.

The ROI spans ``margin_px`` either side of the candidate's line (plus half
a bar; for a kind with a width, at least what the bar estimator needs:
:func:`roi_margin_px`), stops ``JUNCTION_CLEARANCE_PX`` short of every
segment it meets at a junction (the other quadrants of a checkerboard), ``FILL_CLEARANCE_PX``
short of fill and nodata, and ``END_TRIM_PX`` short of a free end.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..estimate import gate
from ..io import RasterInfo
from ..kinds import get_kind
from .fill import FILL_SIDE_PX, fill_screen, grown
from .settings import ScanSettings

if TYPE_CHECKING:
    from .segments import HalfEdge

JUNCTION_CLEARANCE_PX = 4.0     # an ROI keeps this far from the segments its target meets
FILL_CLEARANCE_PX = 4           # ... this far from fill and nodata (the target was blurred with the ground beyond it)
END_TRIM_PX = 3.0               # ... and stops this short of a free end (a corner LSD did not see)
MIN_HALF_WIDTH_PX = 10.0        # an ROI narrower either side of its target holds too little of the sides
SEED_SLACK_PX = 2               # a bar's row windows reach this much farther than their half-width (see roi_margin_px)


@dataclass(frozen=True)
class Roi:
    """A tilted rectangle: from (``x``, ``y``) along the unit vector
    (``ux``, ``uy``) over ``t0_px`` to ``t1_px``, and ``half_width_px``
    either side of that line (scene pixels)."""

    x: float
    y: float
    ux: float
    uy: float
    t0_px: float
    t1_px: float
    half_width_px: float

    def frame(self, xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(t, d) of points: along the line from (x, y), and across it (px)."""
        rx, ry = xs - self.x, ys - self.y
        return rx * self.ux + ry * self.uy, -rx * self.uy + ry * self.ux

    def point(self, t, d) -> tuple[np.ndarray, np.ndarray]:
        t, d = np.asarray(t, float), np.asarray(d, float)
        return self.x + t * self.ux - d * self.uy, self.y + t * self.uy + d * self.ux

    def corners(self, t0: float | None = None, t1: float | None = None) -> list[list[float]]:
        """The rectangle's corners (x, y), optionally over [t0, t1] only."""
        return [[round(float(x), 2), round(float(y), 2)] for x, y in self._corners(t0, t1)]

    def bbox(self, width: int, height: int) -> tuple[int, int, int, int]:
        """(x, y, w, h) of the pixels it touches, within a scene of that size."""
        xs, ys = zip(*self._corners())
        x0, y0 = max(math.floor(min(xs)), 0), max(math.floor(min(ys)), 0)
        x1, y1 = min(math.ceil(max(xs)), width - 1), min(math.ceil(max(ys)), height - 1)
        return x0, y0, max(x1 - x0 + 1, 1), max(y1 - y0 + 1, 1)

    def _corners(self, t0: float | None = None, t1: float | None = None) -> list[tuple[float, float]]:
        """The corners (x, y) over [t0, t1] (default the ROI's), as :meth:`point`
        computes them, in plain floats: a few of them cost less without NumPy."""
        t0 = self.t0_px if t0 is None else t0
        t1 = self.t1_px if t1 is None else t1
        h = self.half_width_px
        return [(self.x + t * self.ux - d * self.uy, self.y + t * self.uy + d * self.ux)
                for t, d in ((t0, -h), (t1, -h), (t1, h), (t0, h))]


def roi_margin_px(settings: ScanSettings) -> float:
    """How far (px) a candidate's ROI reaches beyond its target's
    half-width: the scan's ``margin_px``, and for a kind with a width (a
    bar) at least the background its estimator needs.  That estimator
    follows a bar row by row in windows reaching
    :data:`imgmtf.estimate.pulse.LOCATE_HALF_WINDOW_PX` either side of a
    seed line that may lie on either side of the bar (the seed's half-bar
    offset is the half-width the ROI adds), plus ``SEED_SLACK_PX`` for the
    windows' rounding to whole pixels and the seed's own error: with the
    default 12 px margin every row of a lone 1.5 px bar fell a pixel short.

    Examples
    --------
    >>> from imgmtf.scene.settings import ScanSettings
    >>> roi_margin_px(ScanSettings()), roi_margin_px(ScanSettings(target="pulse"))
    (12, 14)
    >>> roi_margin_px(ScanSettings(target="pulse", margin_px=20))
    20
    """
    if not get_kind(settings.target).has_width:
        return settings.margin_px
    # (imported here: the workers reading ROIs need not load the estimator)
    from ..estimate.pulse import LOCATE_HALF_WINDOW_PX
    return max(settings.margin_px, LOCATE_HALF_WINDOW_PX + SEED_SLACK_PX)


def plan_roi(half: HalfEdge, settings: ScanSettings, beside_px: float = math.inf) -> Roi:
    """The largest ROI a candidate may have: along its segment (a free end
    trimmed by ``END_TRIM_PX``; a junction end reaching the junction, which
    the partners' clearance then keeps off), at most ``max_length_px`` of
    its middle, :func:`roi_margin_px` (plus half a bar) either side, or less, to
    stay ``JUNCTION_CLEARANCE_PX`` clear of a segment running beside it
    ``beside_px`` away."""
    s = half.segment
    length = s.length_px
    ux, uy = (s.x1 - s.x0) / length, (s.y1 - s.y0) / length
    t0 = 0.0 if half.junctions[0] is not None else min(END_TRIM_PX, length / 2)
    t1 = length if half.junctions[1] is not None else max(length - END_TRIM_PX, length / 2)
    if t1 - t0 > settings.max_length_px:
        middle = (t0 + t1) / 2
        t0, t1 = middle - settings.max_length_px / 2, middle + settings.max_length_px / 2
    half_width = min(roi_margin_px(settings) + s.width_px / 2, beside_px - JUNCTION_CLEARANCE_PX)
    return Roi(s.x0, s.y0, ux, uy, t0, t1, half_width)


def clear_extent(roi: Roi, t, d, xs, ys, fill, partners, info: RasterInfo):
    """The longest stretch [t0, t1) of the ROI clear of fill (and
    ``FILL_CLEARANCE_PX`` around it), of the partners (within
    ``JUNCTION_CLEARANCE_PX``) and of the scene's border, in whole pixels
    along the line; or (reason, message) when none is long enough: ``fill``
    for a boundary of the fill (fill along its sides) or an ROI the fill
    leaves too short, ``too-short`` otherwise.  ``t``, ``d``, ``xs``, ``ys``
    describe the ROI's pixels; ``fill`` is the fill of the window they
    index (its top-left pixel at the smallest ``xs``, ``ys``), or None
    where the window holds none.  The pixels
    come row by row (``ys`` ascending), as :func:`numpy.nonzero` gives them."""
    bins = max(math.ceil(roi.t1_px - roi.t0_px), 1)

    def bin_of(pixels):
        """The bins along the line of the ROI's ``pixels`` (an index or a mask): only those asked
        for, mostly the few beside a partner.  (np.minimum and np.maximum: np.clip's own overhead
        is most of a small array's cost.)"""
        return np.minimum(np.maximum(np.floor(t[pixels] - roi.t0_px).astype(int), 0), bins - 1)
    bad = np.zeros(bins, bool)
    by_fill = np.zeros(bins, bool)
    if fill is not None and fill.any():
        r, c = ys - ys.min(), xs - xs.min()
        near_fill = fill[r, c] & (np.abs(d) <= FILL_SIDE_PX)
        boundary = fill_screen(float(np.mean(np.bincount(bin_of(near_fill), minlength=bins) > 0)))
        if boundary:
            return boundary
        by_fill = np.bincount(bin_of(grown(fill, FILL_CLEARANCE_PX)[r, c]), minlength=bins) > 0
        bad |= by_fill
    for p in np.asarray(partners, float).reshape(-1, 4).tolist():
        # only the pixels within the clearance of the partner's bounding box can be within it of the
        # partner: those of its rows (a slice: the pixels come row by row), then of its columns
        first = np.searchsorted(ys, min(p[1], p[3]) - JUNCTION_CLEARANCE_PX, "left")
        last = np.searchsorted(ys, max(p[1], p[3]) + JUNCTION_CLEARANCE_PX, "right")
        if first == last:
            continue
        row_xs = xs[first:last]
        near = first + np.flatnonzero((row_xs >= min(p[0], p[2]) - JUNCTION_CLEARANCE_PX)
                                      & (row_xs <= max(p[0], p[2]) + JUNCTION_CLEARANCE_PX))
        if near.size:
            close = distance_to_segment(xs[near], ys[near], p) <= JUNCTION_CLEARANCE_PX
            bad[bin_of(near[close])] = True
    # the band's cross-section must lie inside the scene (checked when the rectangle, a pixel longer
    # at each end than the bins' centres reach, is not inside it whole)
    reach = roi._corners(roi.t0_px - 1.0, roi.t0_px + bins + 1.0)
    if not all(0.0 < x < info.width - 1.0 and 0.0 < y < info.height - 1.0 for x, y in reach):
        centres = roi.t0_px + np.arange(bins) + 0.5
        for side in (-1.0, 1.0):
            px, py = roi.point(centres, side * roi.half_width_px)
            bad |= (px < -0.5) | (py < -0.5) | (px > info.width - 0.5) | (py > info.height - 0.5)
    free = np.zeros(bins + 2, np.int8)
    free[1:-1] = ~bad
    step = np.diff(free)
    starts, ends = np.flatnonzero(step == 1), np.flatnonzero(step == -1)
    longest = int(np.argmax(ends - starts)) if starts.size else None
    length = float(ends[longest] - starts[longest]) if longest is not None else 0.0
    along = max(abs(roi.ux), abs(roi.uy))
    rows = int(length * along)                              # rows (or columns) it crosses
    if rows < gate.MIN_ROWS:
        clear = f"{rows} of its {int(bins * along)} rows" if rows else f"none of its {int(bins * along)} rows"
        if by_fill.mean() >= 0.5:
            return "fill", (f"fill or nodata leaves {clear} clear (at least {gate.MIN_ROWS} needed)")
        return "too-short", (f"{clear} lie clear of the junctions, fill and the scene's border (at least "
                             f"{gate.MIN_ROWS} needed)")
    return roi.t0_px + starts[longest], roi.t0_px + ends[longest]


def distance_to_segment(xs, ys, s) -> np.ndarray:
    """Distance (px) of points from the segment s = (x0, y0, x1, y1)."""
    dx, dy = s[2] - s[0], s[3] - s[1]
    length2 = max(dx * dx + dy * dy, 1e-12)
    f = np.minimum(np.maximum(((xs - s[0]) * dx + (ys - s[1]) * dy) / length2, 0.0), 1.0)
    return np.hypot(xs - (s[0] + f * dx), ys - (s[1] + f * dy))
