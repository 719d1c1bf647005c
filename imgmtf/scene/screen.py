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

    :func:`quick_looks` glances at many ROIs at once.
    """
    return quick_looks(values, d, t, np.zeros(np.size(values), int), [noise_dn], [half_width_px], [bar_width_px])[0]


def quick_looks(values: np.ndarray, d: np.ndarray, t: np.ndarray, roi: np.ndarray, noise_dn, half_width_px,
                bar_width_px) -> list[tuple[str, str] | None]:
    """:func:`quick_look` of many ROIs in one pass (a scan's batch of
    candidates: a few dozen NumPy calls for them all, not for each): the
    pixels of all of them, ``roi`` numbering the ROI of each (0 to n - 1,
    ascending: each ROI's pixels together), and per ROI its noise (DN), half-width
    and bar width (px).  One verdict per ROI."""
    values, d, t = (np.asarray(a, float).ravel() for a in (values, d, t))
    roi = np.asarray(roi, int).ravel()
    noise = np.asarray(noise_dn, float).ravel()
    n = noise.size
    bar = np.broadcast_to(np.asarray(bar_width_px, float), (n,))
    start = (np.maximum(SIDE_START_PX, np.asarray(half_width_px, float) / 2) + bar / 2)[roi]
    # each side of each ROI a group, 2 x ROI (left) and 2 x ROI + 1 (right), its pixels gathered
    # together: sums over contiguous runs (reduceat) cost a tenth of bincount's
    on = np.flatnonzero((d <= -start) | (d >= start))
    group = 2 * roi[on] + (d[on] >= start[on])
    by_group = np.argsort(group, kind="stable")
    on, group = on[by_group], group[by_group]
    x, y, v = d[on], t[on], values[on]
    m = 2 * n
    count = np.bincount(group, minlength=m)
    filled = count > 0
    first_of = (np.cumsum(count) - count)[filled]

    def total(w: np.ndarray, ufunc=np.add) -> np.ndarray:
        """Per group, ``w`` reduced by ``ufunc`` (0 for an empty group)."""
        out = np.zeros(m)
        if first_of.size:
            out[filled] = ufunc.reduceat(w, first_of)
        return out
    x = x - (total(x) / np.maximum(count, 1))[group]          # each side's across and along, about its centre
    y = y - (total(y) / np.maximum(count, 1))[group]
    sx, sy, sxy = total(x), total(y), total(x * y)
    normal = np.stack([np.stack([count, sx, sy], 1), np.stack([sx, total(x * x), sxy], 1),
                       np.stack([sy, sxy, total(y * y)], 1)], 1) + _RIDGE
    moments = np.stack([total(v), total(x * v), total(y * v)], 1)
    coef = np.linalg.solve(normal, moments[:, :, None])[:, :, 0]      # each side's level and trends
    resid = v - (coef[group, 0] + coef[group, 1] * x + coef[group, 2] * y)
    square = total(resid * resid)
    spans = [total(w, np.maximum) - total(w, np.minimum) for w in (x, y)]
    trend = np.maximum(np.abs(coef[:, 1]) * spans[0], np.abs(coef[:, 2]) * spans[1])
    first = np.searchsorted(roi, np.arange(n + 1)) if np.any(bar > 0) else None
    out: list[tuple[str, str] | None] = []
    for i in range(n):
        if count[2 * i] < 12 or count[2 * i + 1] < 12:
            out.append(None)                    # too little to judge: the gate will
            continue
        sides = [(float(coef[k, 0]), float(trend[k]),
                  math.sqrt(max(float(square[k]) / max(int(count[k]) - 3, 1) - float(noise[i]) ** 2, 0.0)))
                 for k in (2 * i, 2 * i + 1)]
        out.append(_verdict(sides, float(noise[i]), float(bar[i]),
                            None if first is None else slice(first[i], first[i + 1]), values, d))
    return out


def _verdict(sides, noise: float, bar_width_px: float, pixels: slice | None, values: np.ndarray,
             d: np.ndarray) -> tuple[str, str] | None:
    """A ROI's quick look from its sides' (level, trend, texture): for a
    bar, its contrast is its core's (its ``pixels`` of ``values`` and ``d``)."""
    if bar_width_px > 0 and pixels is not None:
        core = np.abs(d[pixels]) <= max(bar_width_px / 2, 0.5)
        background = 0.5 * (sides[0][0] + sides[1][0])
        contrast = abs(float(np.median(values[pixels][core])) - background) if core.any() else 0.0
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
