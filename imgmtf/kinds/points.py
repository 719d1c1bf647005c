"""Point targets: an array of compact targets, bright or dark (stars,
convex mirrors, lamps, Rauchmiller's squares), each at its own sub-pixel
phase; together they give the whole 2-D PSF and MTF.

Points are no line: they do not go through the 1-D pipeline of edges and
bars (:mod:`imgmtf.estimate.pipeline`) but through their own small one
beside it, :mod:`imgmtf.estimate.mtf2d.points` (targets found, judged and
located by :mod:`imgmtf.estimate.mtf2d.sources`, stacked by their phases,
transformed), are rendered by :mod:`imgmtf.sensor.points` and are found
in whole scenes, array by array, by :mod:`imgmtf.scene.points`.  So the
facts a line has and a point has not are None here: ``scene_response``
(the renderer of lines does not draw them), ``measuring`` (no part of the
1-D pipeline); a point has no width along a normal (``has_width``), but it
may have a known size (``size_keyword``)."""
from __future__ import annotations

from .kind import Column, Kind

POINTS = Kind(
    name="points", noun="point", has_width=False,
    column=Column("points_used", "N", "pts"),
    record_fields=("points_used", "points_refused", "point_size_px", "alias_weight", "phase_cells",
                   "phase_uniform_p"),
    estimator="imgmtf.estimate.mtf2d.estimator:PointsEstimator",
    result="imgmtf.estimate.mtf2d.points:PointsResult",
    measuring=None,
    scene_response=None,
    profile_label="stacked PSF", lsf_label="LSF", lsf_scale="1/px",
    described="point array", masked_by="the squares' sinc",
    lone_line=("not-points", "a straight line, not a point target"),
    size_keyword="point_size_px",
    renderer="imgmtf.sensor.points:render_points",
    figure="imgmtf.plot.points:plot_points",
    rows_per_result="one per direction (across and along track)",
    scanner="imgmtf.scene.points:scan_point_arrays",
)
