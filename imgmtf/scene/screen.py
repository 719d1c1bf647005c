"""Cheap screens: what rejects a candidate before it is measured.

Three kinds, from cheapest on:

1. fill (:mod:`imgmtf.scene.fill`): the pixels of the scene that are fill
   or nodata, found as detection reads its tiles; a segment with fill
   beside it is a boundary of the fill (reason ``fill``) and is never
   measured, and every other ROI stops short of fill;
2. geometry (:func:`geometry_screen`), unread: a line shorter than
   ``min_length_px``, or tilted less than ``MIN_ANGLE_DEG`` from an image
   axis or more than ``MAX_ANGLE_DEG``;
3. a quick look at the ROI's pixels (:func:`quick_look`): its contrast
   against the pixel noise and the uniformity of its two sides.  It
   rejects only what fails the quality gate's own limits
   (:mod:`imgmtf.estimate.gate`) ``QUICK_LOOK_SLACK`` times over, so that
   what it rejects the gate would have refused; everything else is
   measured, and its verdict is the gate's.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..estimate import gate
from ..estimate.geometry import MAX_ANGLE_DEG, MIN_ANGLE_DEG
from .settings import ScanSettings

if TYPE_CHECKING:
    from .segments import HalfEdge

QUICK_LOOK_SLACK = 1.0          # the quick look rejects what fails the gate's limits this many times over
SIDE_START_PX = 4.0             # a side's level is read this far from the target at least (px)
_RIDGE = 1e-9 * np.eye(3)       # keeps a side's normal equations solvable when its pixels lie on a line


def geometry_screen(half: HalfEdge, settings: ScanSettings) -> tuple[str, str] | None:
    """(reason, message) when the candidate can be rejected unread: it is
    shorter than ``min_length_px`` (``too-short``: the longer of the line it
    was split from and the half-edge itself, whose ends the junctions may
    have moved outward) or its tilt is outside the estimators' range
    (``angle``); None otherwise."""
    segment = half.segment
    length = max(half.line_length_px, segment.length_px)
    if length < settings.min_length_px:
        return "too-short", (f"a straight line {length:.1f} px long, shorter than the minimum "
                             f"{settings.min_length_px:g} px")
    if segment.tilt_deg < MIN_ANGLE_DEG:
        return "angle", (f"{segment.tilt_deg:.2f} deg from the image axis: too close for "
                         f"sub-pixel sampling (needs {MIN_ANGLE_DEG:g} to {MAX_ANGLE_DEG:g} deg)")
    if segment.tilt_deg > MAX_ANGLE_DEG:
        return "angle", (f"{segment.tilt_deg:.2f} deg from the image axis: too close to 45 deg "
                         f"for sub-pixel sampling (needs {MIN_ANGLE_DEG:g} to {MAX_ANGLE_DEG:g} deg)")
    return None


def quick_look(values: np.ndarray, d: np.ndarray, t: np.ndarray, noise_dn: float, half_width_px: float,
               bar_width_px: float = 0.0) -> tuple[str, str] | None:
    """(reason, message) when a glance at the ROI's pixels says the gate
    would refuse it; None otherwise.

    ``values`` are the ROI's pixels (DN), ``d`` their signed distances from
    the target line and ``t`` their positions along it (px); ``noise_dn``
    the pixel noise (DN), as the gate measures it
    (:func:`imgmtf.estimate.detection.robust_noise`).  Each side
    (from ``SIDE_START_PX`` beyond the target, or half the ROI's width,
    whichever is farther) is fitted with a level and a trend across and
    along; the contrast is the difference of the two levels:

    * ``snr``: the contrast is under ``MIN_SNR / QUICK_LOOK_SLACK`` times
      the pixel noise;
    * ``non-uniform``: a side's trend over its extent exceeds
      ``QUICK_LOOK_SLACK * MAX_SIDE_TREND`` of the contrast, or its texture
      (scatter beyond the pixel noise) ``QUICK_LOOK_SLACK *
      MAX_SIDE_TEXTURE``.
    """
    start = max(SIDE_START_PX, half_width_px / 2) + bar_width_px / 2
    noise = noise_dn
    designs, values_of = [], []
    for side in (d <= -start, d >= start):
        x, y, v = d[side], t[side], values[side]
        if v.size < 12:
            return None                  # too little to judge: the gate will
        design = np.empty((3, v.size))
        design[0], design[1], design[2] = 1.0, x - x.mean(), y - y.mean()
        designs.append((design, x.max() - x.min(), y.max() - y.min()))
        values_of.append(v)
    # both sides' planes in one solve
    normal = np.stack([design @ design.T + _RIDGE for design, _, _ in designs])
    moments = np.stack([design @ v for (design, _, _), v in zip(designs, values_of)])
    coefs = np.linalg.solve(normal, moments[:, :, None])[:, :, 0]
    sides = []
    for (design, x_span, y_span), v, coef in zip(designs, values_of, coefs):
        resid = v - coef @ design
        trend = max(abs(coef[1]) * x_span, abs(coef[2]) * y_span)
        texture = math.sqrt(max(float(resid @ resid) / max(v.size - 3, 1) - noise ** 2, 0.0))
        sides.append((float(coef[0]), trend, texture))
    if bar_width_px > 0:
        core = np.abs(d) <= max(bar_width_px / 2, 0.5)
        background = 0.5 * (sides[0][0] + sides[1][0])
        contrast = abs(float(np.median(values[core])) - background) if core.any() else 0.0
    else:
        contrast = abs(sides[1][0] - sides[0][0])
    if contrast < gate.MIN_SNR / QUICK_LOOK_SLACK * noise:
        return "snr", (f"a contrast of {contrast:.1f} DN against a pixel noise of {noise:.1f} DN: "
                       "no target stands out")
    for name, (_, trend, texture) in zip(("left", "right"), sides):
        if trend > QUICK_LOOK_SLACK * gate.MAX_SIDE_TREND * contrast:
            return "non-uniform", (f"the {name} side's level drifts by {100 * trend / contrast:.0f} % of the "
                                   f"contrast (the gate allows {100 * gate.MAX_SIDE_TREND:.0f} %): not a uniform field")
        if texture > QUICK_LOOK_SLACK * gate.MAX_SIDE_TEXTURE * contrast:
            return "non-uniform", (f"the {name} side is textured ({100 * texture / contrast:.0f} % of the contrast "
                                   f"beyond the pixel noise; the gate allows {100 * gate.MAX_SIDE_TEXTURE:.0f} %): "
                                   "not a uniform field")
    return None
