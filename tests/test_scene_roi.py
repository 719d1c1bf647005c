"""A candidate's ROI: its rectangle along the segment, and the stretch of it
clear of junctions, fill and the scene's border."""
import math

import numpy as np
import pytest
from affine import Affine

from imgmtf.io import RasterInfo
from imgmtf.scene.roi import END_TRIM_PX, JUNCTION_CLEARANCE_PX, Roi, clear_extent, plan_roi
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
