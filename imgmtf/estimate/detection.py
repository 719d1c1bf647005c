"""Find straight edges in an image chip: the seed for the sub-pixel fits.

Canny edge pixels (scikit-image's algorithm, :mod:`.edgemap`) vote in a
Hough transform for lines; the strongest line is the edge.  A second line with comparable support, away
from the first, means the chip holds two edges (or a bar).

Angles follow :mod:`imgmtf.targets`: a line is x cos(theta) + y sin(theta)
= rho, with theta the angle of its normal from the x (column) axis, which
is also the tilt of the line from the column axis.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ImageContentError, TargetNotFoundError
from .edgemap import canny, hough_line

_THETA_STEP_DEG = 0.5          # the seed needs ~1 deg; the row fits refine it
_THETAS = np.deg2rad(np.arange(-90.0, 90.0, _THETA_STEP_DEG))


@dataclass(frozen=True)
class Line:
    """A straight line x cos(theta) + y sin(theta) = rho (pixels), with the
    number of edge pixels that voted for it."""

    theta_deg: float
    rho_px: float
    votes: int


SEED_MAX_SIDE_PX = 512         # larger chips are seeded on a block-averaged copy


def find_lines(image: np.ndarray, max_lines: int = 4, sigma: float = 2.0) -> list[Line]:
    """Straight lines of strong gradient, strongest first.

    Canny thresholds are set relative to the image's strongest gradients,
    so the result does not depend on the DN scale.  A chip larger than
    ``SEED_MAX_SIDE_PX`` is searched on a block-averaged copy (the per-row
    fits refine the seed anyway), the lines mapped back to full resolution.
    """
    factor = int(math.ceil(max(image.shape) / SEED_MAX_SIDE_PX))
    if factor > 1:
        rows, cols = (n // factor * factor for n in image.shape)
        small = image[:rows, :cols].reshape(rows // factor, factor, cols // factor, factor).mean(axis=(1, 3))
        centre = (factor - 1) / 2.0      # a block's centre in full-resolution pixels
        return [Line(ln.theta_deg,
                     factor * ln.rho_px + centre * (math.cos(math.radians(ln.theta_deg))
                                                    + math.sin(math.radians(ln.theta_deg))),
                     ln.votes)
                for ln in find_lines(small, max_lines, sigma)]
    valid = np.isfinite(image)
    lo, hi = np.percentile(image[valid], [1, 99])
    if not hi > lo:
        raise ImageContentError("the image is flat: no contrast to measure")
    norm = (fill_nearest(image, valid) - lo) / (hi - lo)
    mask = None if valid.all() else valid
    edges = canny(norm, sigma=sigma, low_threshold=0.1, high_threshold=0.2, mask=mask)
    if edges.sum() < 5:
        edges = canny(norm, sigma=sigma, low_threshold=0.5, high_threshold=0.8,
                      use_quantiles=True, mask=mask)
    if edges.sum() < 5:
        return []
    acc, thetas, rhos = hough_line(edges, _THETAS)
    return _peaks(acc, thetas, rhos, edges, max_lines)


def _peaks(acc, thetas, rhos, edges, max_lines, min_distance_px=5, min_angle_deg=8.0,
           on_line_px=1.0) -> list[Line]:
    """Strongest accumulator cells, strongest first: each line's own edge
    pixels (within ``on_line_px`` of it) then stop voting, and its
    neighbourhood (``min_distance_px`` in rho, ``min_angle_deg`` in theta)
    is suppressed, before the next is taken; cells below a quarter of the
    strongest are ignored.  Taking back the votes keeps a short segment
    far from the origin, whose pixels also elect lines a few degrees and
    more than ``min_distance_px`` away, from passing for two lines."""
    threshold = 0.25 * acc.max()
    dr = min_distance_px
    dt = int(round(min_angle_deg / _THETA_STEP_DEG))
    offset = int(round(-rhos[0]))
    cos, sin = np.cos(thetas), np.sin(thetas)
    ys, xs = np.nonzero(edges)
    voting = np.ones(xs.size, bool)
    lines = []
    for _ in range(max_lines):
        i, j = np.unravel_index(int(np.argmax(acc)), acc.shape)
        if acc[i, j] < threshold or acc[i, j] == 0:
            break
        lines.append(Line(float(np.rad2deg(thetas[j])), float(rhos[i]), int(acc[i, j])))
        on = voting & (np.abs(xs * cos[j] + ys * sin[j] - rhos[i]) <= on_line_px)
        if on.any():        # their votes in every direction, binned as hough_line bins them
            bins = np.rint(np.outer(xs[on], cos) + np.outer(ys[on], sin)).astype(np.int64) + offset
            cells = (bins * thetas.size + np.arange(thetas.size)).ravel()
            acc -= np.bincount(cells, minlength=acc.size).reshape(acc.shape)
            np.maximum(acc, 0, out=acc)
            voting &= ~on
        acc[max(i - dr, 0): i + dr + 1, max(j - dt, 0): j + dt + 1] = 0
    return lines


def find_edge(image: np.ndarray, min_votes: int = 10, min_contrast: float = 3.0,
              noise: float | None = None) -> tuple[Line, Line | None]:
    """The strongest straight edge of a chip, and a competitor if there is
    one.

    A line counts when at least ``min_votes`` Canny pixels lie on it and the
    mean levels 1-5 px either side of it differ by ``min_contrast`` times
    the image noise.  The competitor is a second such line with at least
    half the support of the first lying more than 3 px away from it inside
    the chip: another edge, or the far side of a bar (the quality gate
    tells them apart, :mod:`.gate`).  ``noise`` is the image's pixel noise
    (DN), measured by :func:`robust_noise` when not given.

    Raises
    ------
    TargetNotFoundError : no such line.
    """
    noise = robust_noise(image) if noise is None else noise
    lines = [ln for ln in find_lines(image)
             if ln.votes >= min_votes and step_contrast(image, ln) >= min_contrast * noise]
    if not lines:
        raise TargetNotFoundError("no straight edge found: no line of strong contrast "
                                  "stands out of the noise")
    best = lines[0]
    rival = next((other for other in lines[1:]
                  if other.votes >= 0.5 * best.votes and _separation(best, other, image.shape) > 3.0), None)
    return best, rival


def parallel_within(a: Line, b: Line, shape, distance_px: float, angle_deg: float = 3.0) -> bool:
    """Are ``a`` and ``b`` parallel (within ``angle_deg``) and nowhere in
    the chip more than ``distance_px`` apart: the two sides of one bar?"""
    da = abs((a.theta_deg - b.theta_deg + 90.0) % 180.0 - 90.0)
    return da <= angle_deg and _separation(a, b, shape) <= distance_px


def meet_inside(a: Line, b: Line, shape, min_angle_deg: float = 2.0) -> bool:
    """Do ``a`` and ``b``, at least ``min_angle_deg`` apart in direction,
    intersect inside the chip (a bent edge, a corner), rather than lie
    side by side?"""
    ta, tb = math.radians(a.theta_deg), math.radians(b.theta_deg)
    det = math.cos(ta) * math.sin(tb) - math.sin(ta) * math.cos(tb)
    if abs((a.theta_deg - b.theta_deg + 90.0) % 180.0 - 90.0) < min_angle_deg or abs(det) < 1e-12:
        return False
    x = (a.rho_px * math.sin(tb) - b.rho_px * math.sin(ta)) / det
    y = (b.rho_px * math.cos(ta) - a.rho_px * math.cos(tb)) / det
    rows, cols = shape
    return -0.5 <= x <= cols - 0.5 and -0.5 <= y <= rows - 0.5


def describe(line: Line) -> str:
    """A line as a user reads it: its normal's angle (the convention of
    ``normal_angle_deg``) and its distance from the chip's top-left pixel."""
    return f"normal {line.theta_deg:.1f} deg, {abs(line.rho_px):.0f} px from the top-left pixel"


def line_distance(shape: tuple[int, int], line: Line) -> np.ndarray:
    """Signed distance (px) of every pixel centre of an image of ``shape``
    from ``line``."""
    t = math.radians(line.theta_deg)
    y, x = np.indices(shape)
    return x * math.cos(t) + y * math.sin(t) - line.rho_px


def fill_nearest(image: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """``image`` with every pixel outside ``valid`` set to its nearest valid
    pixel's value: left-out pixels continue the chip instead of cutting a
    false edge into it."""
    if valid.all():
        return image
    from scipy.ndimage import distance_transform_edt
    index = distance_transform_edt(~valid, return_distances=False, return_indices=True)
    return image[tuple(index)]


def robust_noise(image: np.ndarray) -> float:
    """Noise standard deviation (DN) from the median absolute difference of
    horizontally adjacent pixels, which an edge barely affects (pairs with a
    left-out, NaN, pixel skipped)."""
    diff = np.diff(image, axis=1)
    diff = diff[np.isfinite(diff)]
    mad = np.median(np.abs(diff - np.median(diff)))
    # a noise-free (or coarsely quantised) image has MAD 0: its noise is nil
    return max(float(1.4826 * mad / np.sqrt(2.0)), 1e-12)


def step_contrast(image: np.ndarray, line: Line) -> float:
    """|mean level 1-5 px on one side of ``line`` - on the other| (DN)."""
    d = line_distance(image.shape, line)
    valid = np.isfinite(image)
    near, far = (d > 1) & (d < 5) & valid, (d < -1) & (d > -5) & valid
    if not near.any() or not far.any():
        return 0.0
    return float(abs(image[near].mean() - image[far].mean()))


def bar_contrast(image: np.ndarray, line: Line, reach_px: float = 8.0) -> float:
    """Largest |mean level of a 1-px strip parallel to ``line`` - the image's
    median| within ``reach_px`` of the line (DN): large for a bar along it,
    wherever across the strips the seed line fell; small for noise."""
    d = line_distance(image.shape, line)
    valid = np.isfinite(image)
    near = (np.abs(d) < reach_px) & valid
    if not near.any():
        return 0.0
    strips = np.floor(d[near] + reach_px).astype(int)
    counts = np.bincount(strips)
    means = np.bincount(strips, weights=image[near])[counts > 0] / counts[counts > 0]
    return float(np.max(np.abs(means - np.median(image[valid]))))


def _separation(a: Line, b: Line, shape) -> float:
    """Largest distance from line a to line b over the chip's rows/columns
    crossed by a (px)."""
    rows, cols = shape
    ta, tb = math.radians(a.theta_deg), math.radians(b.theta_deg)
    ts = np.linspace(0, 1, 11)
    if abs(math.cos(ta)) >= abs(math.sin(ta)):
        y = ts * (rows - 1)
        x = (a.rho_px - y * math.sin(ta)) / math.cos(ta)
    else:
        x = ts * (cols - 1)
        y = (a.rho_px - x * math.cos(ta)) / math.sin(ta)
    return float(np.max(np.abs(x * math.cos(tb) + y * math.sin(tb) - b.rho_px)))
