"""Siemens stars: ISO 12233:2017's sinusoidal star (the s-SFR target, whose
intensity varies as ``cos(N theta)`` around its centre) and binary (bar)
stars; the star's frequency ``N / (2 pi r)`` grows towards its centre, so
that its rings read the MTF against frequency, and its sectors in every
direction.

A star is no line: it goes through its own small pipeline,
:mod:`imgmtf.estimate.star` (centre found, rings fitted per direction,
divided by the full contrast, smoothed against frequency), and is rendered
by :mod:`imgmtf.sensor.star`.  So the facts a line has and a star has not
are None here (``scene_response``, ``measuring``), and its result gives one
record per direction."""
from __future__ import annotations

from .kind import Column, Kind

STAR = Kind(
    name="star", noun="star", has_width=False,
    column=Column("star_cycles", "N", "cy"),
    record_fields=("direction_deg", "star_cycles", "star_profile", "centre_x_px", "centre_y_px",
                   "nyquist_radius_px", "unresolved_radius_px", "star_contrast", "contrast_method"),
    estimator="imgmtf.estimate.star.estimator:StarEstimator",
    result="imgmtf.estimate.star.result:StarResult",
    measuring=None,
    scene_response=None,
    profile_label="star rings", lsf_label="LSF", lsf_scale="1/px",
    described="Siemens star",
    lone_line=("not-a-star", "a straight line, not a Siemens star"),
    renderer="imgmtf.sensor.star:render_star",
    figure="imgmtf.plot.star:plot_star",
    rows_per_result="one per direction (8 over 180 deg)",
)
