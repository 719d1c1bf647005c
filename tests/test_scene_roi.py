"""A candidate's ROI: its rectangle along the segment, and the stretch of it
clear of junctions, fill and the scene's border."""
import math
import re

import numpy as np
import pytest
from affine import Affine

from imgmtf.estimate import gate
from imgmtf.io import RasterInfo
from imgmtf.scene.roi import END_TRIM_PX, JUNCTION_CLEARANCE_PX, Roi, clear_extent, plan_roi, roi_margin_px
from imgmtf.scene.segments import HalfEdge, Segment
from imgmtf.scene.settings import ScanSettings


def test_a_point_and_its_frame_are_inverse_and_the_corners_lie_at_the_half_width():
    roi = Roi(10.0, 20.0, 0.6, 0.8, 0.0, 50.0, 5.0)
    t, d = np.array([0.0, 12.5, 50.0]), np.array([-5.0, 0.0, 3.0])
    back = roi.frame(*roi.point(t, d))
    np.testing.assert_allclose(back, (t, d), atol=1e-12)
    corners = np.array(roi.corners())
    assert np.allclose(np.abs(roi.frame(corners[:, 0], corners[:, 1])[1]), 5.0, atol=0.01)
    assert roi.bbox(1000, 1000) == (6, 17, 39, 47)       # corners (14,17) (44,57) (36,63) (6,23)


def test_free_ends_are_trimmed_and_a_junction_end_is_kept():
    settings = ScanSettings()
    free = plan_roi(HalfEdge(Segment(0.0, 0.0, 0.0, 100.0), 100.0), settings)
    joined = plan_roi(HalfEdge(Segment(0.0, 0.0, 0.0, 100.0), 100.0, junctions=(3, None)), settings)
    assert (free.t0_px, free.t1_px) == (END_TRIM_PX, 100.0 - END_TRIM_PX)
    assert (joined.t0_px, joined.t1_px) == (0.0, 100.0 - END_TRIM_PX)
    assert (free.ux, free.uy, free.half_width_px) == (0.0, 1.0, settings.margin_px)
    # a segment running 15 px beside it narrows it to keep the clearance
    assert plan_roi(HalfEdge(Segment(0.0, 0.0, 0.0, 100.0), 100.0), settings, 15.0).half_width_px == pytest.approx(
        15.0 - JUNCTION_CLEARANCE_PX)


def test_a_bars_roi_holds_the_background_its_row_windows_need():
    from imgmtf.estimate.pulse import LOCATE_HALF_WINDOW_PX
    bar = HalfEdge(Segment(0.0, 0.0, 0.0, 100.0, width_px=3.0), 100.0)
    # the bar estimator's row windows about a seed on either side of the bar, and 2 px for rounding
    assert plan_roi(bar, ScanSettings(target="pulse")).half_width_px == LOCATE_HALF_WINDOW_PX + 2 + 1.5
    assert plan_roi(bar, ScanSettings(target="pulse", margin_px=20)).half_width_px == 20 + 1.5
    assert plan_roi(bar, ScanSettings()).half_width_px == 12 + 1.5              # an edge scan keeps its margin
    assert roi_margin_px(ScanSettings(target="pulse", margin_px=6)) == LOCATE_HALF_WINDOW_PX + 2


def _pixels(roi, width, height):
    ys, xs = np.mgrid[0:height, 0:width]
    t, d = roi.frame(xs.ravel().astype(float), ys.ravel().astype(float))
    inside = (np.abs(d) <= roi.half_width_px) & (t >= roi.t0_px) & (t < roi.t1_px)
    return t[inside], d[inside], xs.ravel()[inside], ys.ravel()[inside]


def test_the_clear_stretch_stops_short_of_a_partner_and_of_fill():
    info = RasterInfo("scene.tif", 100, 100, 1, ("gray",), "uint16", None, Affine.identity(), None)
    roi = Roi(50.0, 0.0, 0.0, 1.0, 0.0, 100.0, 8.0)          # a vertical line down the middle
    t, d, xs, ys = _pixels(roi, 100, 100)
    fill = np.zeros((ys.max() - ys.min() + 1, xs.max() - xs.min() + 1), bool)
    # a partner crossing at y = 70 ends the stretch JUNCTION_CLEARANCE_PX before it
    t0, t1 = clear_extent(roi, t, d, xs, ys, fill, [np.array([0.0, 70.0, 100.0, 70.0])], info)
    assert t0 == 0.0 and t1 == pytest.approx(70.0 - math.ceil(JUNCTION_CLEARANCE_PX))
    # fill along the line's whole length is a fill boundary, not a target
    fill[:, :] = np.abs(xs.min() + np.arange(fill.shape[1]) - 50)[None, :] <= 1
    reason, _ = clear_extent(roi, t, d, xs, ys, fill, [], info)
    assert reason == "fill"


def test_a_target_with_no_clear_row_says_none_of_its_rows_not_only_0():
    info = RasterInfo("scene.tif", 100, 100, 1, ("gray",), "uint16", None, Affine.identity(), None)
    roi = Roi(50.0, 40.0, 0.0, 1.0, 0.0, 30.0, 8.0)          # 30 rows, crossed at both ends and the middle
    t, d, xs, ys = _pixels(roi, 100, 100)
    fill = np.zeros((ys.max() - ys.min() + 1, xs.max() - xs.min() + 1), bool)
    partners = [np.array([0.0, y, 100.0, y]) for y in np.arange(40.0, 71.0, 5.0)]
    reason, message = clear_extent(roi, t, d, xs, ys, fill, partners, info)
    assert reason == "too-short" and message.startswith("none of its 30 rows lie clear of the junctions")
    reason, message = clear_extent(roi, t, d, xs, ys, fill, [np.array([0.0, 55.0, 100.0, 55.0])], info)
    assert reason == "too-short" and re.match(r"1\d of its 30 rows lie clear", message)


def _reference_bad_bins(roi, t, xs, ys, partners, info):
    """The bins of the ROI not clear, computed directly: every pixel's
    distance from every partner, every bin's cross-section against the border."""
    bins = max(math.ceil(roi.t1_px - roi.t0_px), 1)
    k = np.clip(np.floor(t - roi.t0_px).astype(int), 0, bins - 1)
    bad = np.zeros(bins, bool)
    for p in partners:
        dx, dy = p[2] - p[0], p[3] - p[1]
        f = np.clip(((xs - p[0]) * dx + (ys - p[1]) * dy) / max(dx * dx + dy * dy, 1e-12), 0.0, 1.0)
        bad[k[np.hypot(xs - (p[0] + f * dx), ys - (p[1] + f * dy)) <= JUNCTION_CLEARANCE_PX]] = True
    centres = roi.t0_px + np.arange(bins) + 0.5
    for side in (-1.0, 1.0):
        px, py = roi.point(centres, side * roi.half_width_px)
        bad |= (px < -0.5) | (py < -0.5) | (px > info.width - 0.5) | (py > info.height - 0.5)
    return bad


def test_the_clear_stretch_is_the_longest_run_clear_of_partners_and_border_wherever_they_lie():
    # partners are sought only near their bounding box, the border only near it: the same stretch
    info = RasterInfo("scene.tif", 120, 90, 1, ("gray",), "uint16", None, Affine.identity(), None)
    rng = np.random.default_rng(2)
    measured = 0
    for _ in range(80):
        angle = rng.uniform(0, 2 * math.pi)
        roi = Roi(rng.uniform(-5, 125), rng.uniform(-5, 95), math.cos(angle), math.sin(angle), 0.0,
                  rng.uniform(30, 90), rng.uniform(4, 14))
        t, d, xs, ys = _pixels(roi, 120, 90)
        if t.size == 0:
            continue
        fill = np.zeros((ys.max() - ys.min() + 1, xs.max() - xs.min() + 1), bool)
        # partners from a point near the ROI (or on it) to anywhere in the scene
        partners = [np.array([*roi.point(rng.uniform(-10, 90), rng.uniform(-20, 20)),
                              rng.uniform(0, 120), rng.uniform(0, 90)], float) for _ in range(rng.integers(0, 3))]
        bad = _reference_bad_bins(roi, t, xs, ys, partners, info)
        free = np.concatenate([[0], (~bad).astype(int), [0]])
        starts, ends = np.nonzero(np.diff(free) == 1)[0], np.nonzero(np.diff(free) == -1)[0]
        got = clear_extent(roi, t, d, xs, ys, fill, partners, info)
        longest = int(np.argmax(ends - starts)) if starts.size else None
        if longest is not None and int((ends - starts)[longest] * max(abs(roi.ux), abs(roi.uy))) >= gate.MIN_ROWS:
            assert got == (roi.t0_px + starts[longest], roi.t0_px + ends[longest])
            measured += 1
        else:
            assert got[0] == "too-short"
    assert measured >= 10
