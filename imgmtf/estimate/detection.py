"""Find straight edges in an image chip: the seed for the sub-pixel fits.

OpenCV finds them: Canny edge pixels (``cv2.Canny`` on Sobel gradients of
the Gaussian-smoothed chip) vote in a Hough transform for lines
(``cv2.HoughLinesPointSet``); the strongest line is the edge.  A second line
with comparable support, away from the first, means the chip holds two
edges (or a bar).  The tests hold the seed to within 1 deg of
scikit-image's ``feature.canny`` and ``transform.hough_line``.

Angles follow :mod:`imgmtf.sensor.targets`: a line is x cos(theta) + y sin(theta)
= rho, with theta the angle of its normal from the x (column) axis, which
is also the tilt of the line from the column axis.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import cv2
import numpy as np

from ..errors import ImageContentError, TargetNotFoundError
from ._order import median, percentile

_THETA_STEP_DEG = 0.5          # the seed needs ~1 deg; the row fits refine it
GAUSSIAN_TRUNCATE = 4.0        # the smoothing kernel reaches this many sigma (as scikit-image's)
# cv2.Canny takes 16-bit gradients: the strongest is scaled to this, or the
# low threshold to GRADIENT_LOW_UNITS where outliers would squeeze it below
GRADIENT_FULL_SCALE = 16383
GRADIENT_LOW_UNITS = 64


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

    Canny thresholds are set relative to the image's own range (its 1st to
    99th percentile), so the result does not depend on the DN scale or the
    bit depth.  A chip larger than ``SEED_MAX_SIDE_PX`` is searched on a
    block-averaged copy (the per-row fits refine the seed anyway), the lines
    mapped back to full resolution.  Left-out pixels (NaN) are ignored.

    Parameters
    ----------
    image : (M, N) ndarray
        The chip, DN; NaN where left out.
    max_lines : int
        At most this many lines.
    sigma : float
        Standard deviation of the Gaussian smoothing before the gradients, px.

    Returns
    -------
    list of Line
        Strongest first; empty when the chip has fewer than 5 edge pixels.

    Raises
    ------
    ImageContentError
        The image is flat.

    Examples
    --------
    >>> step = np.zeros((30, 40)); step[:, 20:] = 1.0      # a vertical edge between columns 19 and 20
    >>> [(abs(line.theta_deg) <= 1.0, abs(line.rho_px - 19.5) <= 1.0) for line in find_lines(step)]
    [(True, True)]
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
    lo, hi = percentile(image[valid], [1, 99])
    if not hi > lo:
        raise ImageContentError("the image is flat: no contrast to measure")
    dx, dy = _gradients(np.where(valid, (image - lo) / (hi - lo), 0.0), valid, sigma)
    inside = _interior(valid)
    edges = _canny(dx, dy, 0.1, 0.2, inside)
    if np.count_nonzero(edges) < 5:
        low, high = percentile(np.hypot(dx, dy), [50.0, 80.0])      # weak edges: quantiles instead
        edges = _canny(dx, dy, float(low), float(high), inside)
    if np.count_nonzero(edges) < 5:
        return []
    return _strongest_lines(edges, max_lines)


def _gradients(image: np.ndarray, valid: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """Sobel gradients along x (columns) and y (rows) of ``image`` smoothed
    by a Gaussian that ignores the pixels outside ``valid`` and beyond the
    edges (the smoothed image divided by the smoothed mask: they neither
    pull it down nor cut a false edge into it)."""
    weight = _full_weight(valid.shape, sigma) if valid.all() else _mask_weight(valid.astype(np.float32), sigma)
    smoothed = _blur(image.astype(np.float32), sigma) / weight
    dx = cv2.Sobel(smoothed, cv2.CV_32F, 1, 0, ksize=3, borderType=cv2.BORDER_REFLECT)
    dy = cv2.Sobel(smoothed, cv2.CV_32F, 0, 1, ksize=3, borderType=cv2.BORDER_REFLECT)
    return dx, dy


def _blur(values: np.ndarray, sigma: float) -> np.ndarray:
    """``values`` smoothed by a Gaussian truncated at ``GAUSSIAN_TRUNCATE``
    sigma, nothing beyond the image."""
    radius = int(GAUSSIAN_TRUNCATE * sigma + 0.5)
    return cv2.GaussianBlur(values, (2 * radius + 1, 2 * radius + 1), sigma, borderType=cv2.BORDER_CONSTANT)


def _mask_weight(valid: np.ndarray, sigma: float) -> np.ndarray:
    """:func:`_gradients`' divisor: the smoothed mask (plus 1e-12, where
    no valid pixel reaches)."""
    return _blur(valid, sigma) + np.float32(1e-12)


@functools.lru_cache(maxsize=64)
def _full_weight(shape: tuple[int, int], sigma: float) -> np.ndarray:
    """:func:`_mask_weight` where every pixel is valid: the same for every
    chip of a shape (a scan's many chips are of a few; read only)."""
    weight = _mask_weight(np.ones(shape, np.float32), sigma)
    weight.flags.writeable = False
    return weight


def _interior(valid: np.ndarray) -> np.ndarray:
    """The pixels whose 3 x 3 neighbourhood lies wholly in ``valid`` and in
    the image: only they may be edges (their gradients see no left-out
    pixel)."""
    if valid.all():
        return _full_interior(valid.shape)
    return cv2.erode(valid.astype(np.uint8), np.ones((3, 3), np.uint8),
                     borderType=cv2.BORDER_CONSTANT, borderValue=0).astype(bool)


@functools.lru_cache(maxsize=64)
def _full_interior(shape: tuple[int, int]) -> np.ndarray:
    """:func:`_interior` where every pixel is valid: all but the border
    (read only)."""
    inside = np.zeros(shape, bool)
    inside[1:-1, 1:-1] = True
    inside.flags.writeable = False
    return inside


def _canny(dx: np.ndarray, dy: np.ndarray, low: float, high: float, inside: np.ndarray) -> np.ndarray:
    """Canny edge map (``cv2.Canny``, L2 gradient magnitude) from float
    gradients and hysteresis thresholds in their unit, restricted to
    ``inside``.  OpenCV takes 16-bit gradients: they are scaled so that the
    strongest fills the range, unless outliers would then leave the low
    threshold fewer than ``GRADIENT_LOW_UNITS`` steps (those saturate)."""
    strongest = max(float(np.abs(dx).max()), float(np.abs(dy).max()), 1e-30)
    scale = GRADIENT_FULL_SCALE / strongest
    if low > 0:
        scale = max(scale, GRADIENT_LOW_UNITS / low)

    def fixed(values):
        return np.clip(np.rint(values * scale), -32767, 32767).astype(np.int16)
    edges = cv2.Canny(fixed(dx), fixed(dy), min(low * scale, 32767.0), min(high * scale, 32767.0),
                      L2gradient=True)
    return (edges > 0) & inside


def _strongest_lines(edges, max_lines, min_distance_px=5, min_angle_deg=8.0, on_line_px=1.0) -> list[Line]:
    """Lines of the Hough transform of the edge pixels, strongest first:
    each line's own edge pixels (within ``on_line_px`` of it) then stop
    voting and the transform is run again on the others; a line within
    ``min_distance_px`` in rho and ``min_angle_deg`` in theta of one taken
    is passed over, and lines with under a quarter of the first's votes are
    ignored.  Taking back the votes keeps a short segment far from the
    origin, whose pixels also elect lines a few degrees and more than
    ``min_distance_px`` away, from passing for two lines."""
    ys, xs = np.nonzero(edges)
    points = np.column_stack([xs, ys]).astype(np.float32)
    reach = math.ceil(math.hypot(*edges.shape)) + 1
    lines: list[Line] = []
    threshold = 0
    while len(lines) < max_lines and len(points):
        found = cv2.HoughLinesPointSet(points.reshape(-1, 1, 2), 4 * max_lines + 4, threshold,
                                       -reach, reach, 1.0, -math.pi / 2, math.pi / 2,
                                       math.radians(_THETA_STEP_DEG))
        if found is None:
            break
        # (OpenCV returns single-precision angles: put them back on the grid; made
        # one by one up to the first one kept, usually the first)
        candidates = (Line(_THETA_STEP_DEG * round(math.degrees(theta) / _THETA_STEP_DEG), float(rho), int(votes))
                      for votes, rho, theta in found.reshape(-1, 3).tolist())
        line = next((c for c in candidates if not any(_near(c, taken, min_distance_px, min_angle_deg)
                                                      for taken in lines)), None)
        if line is None:
            break
        if not lines:
            threshold = max(math.ceil(0.25 * line.votes) - 1, 0)     # OpenCV keeps votes > threshold
        t = math.radians(line.theta_deg)
        on = np.abs(points[:, 0] * math.cos(t) + points[:, 1] * math.sin(t) - line.rho_px) <= on_line_px
        lines.append(_fitted(line, points[on]))
        points = points[~on]
    return lines


def _fitted(line: Line, points: np.ndarray) -> Line:
    """``line`` moved onto the straight line through its own edge pixels
    (their principal axis): a cell of the Hough transform is one of a
    plateau of cells several degrees wide for a short segment."""
    if len(points) < 3:
        return line
    centre = points.mean(axis=0, dtype=float)
    _, _, axes = np.linalg.svd(points - centre, full_matrices=False)
    normal = axes[1]
    t = math.radians(line.theta_deg)
    if normal[0] * math.cos(t) + normal[1] * math.sin(t) < 0:
        normal = -normal
    theta = math.atan2(normal[1], normal[0])
    rho = float(centre @ normal)
    if theta >= math.pi / 2 or theta < -math.pi / 2:       # the convention's range: [-90, 90) deg
        theta, rho = theta - math.copysign(math.pi, theta), -rho
    return Line(math.degrees(theta), rho, line.votes)


def _near(a: Line, b: Line, distance_px: float, angle_deg: float) -> bool:
    """Is ``a`` within ``distance_px`` in rho and ``angle_deg`` in theta of
    ``b`` (in the Hough transform's cells)?"""
    return abs(a.rho_px - b.rho_px) <= distance_px and abs(a.theta_deg - b.theta_deg) <= angle_deg


def find_edge(image: np.ndarray, min_votes: int = 10, min_contrast: float = 3.0,
              noise: float | None = None) -> tuple[Line, Line | None]:
    """The strongest straight edge of a chip, and a competitor if there is
    one.

    A line counts when at least ``min_votes`` Canny pixels lie on it and the
    mean levels 1-5 px either side of it differ by ``min_contrast`` times
    the image noise; the strongest has the most votes times that
    difference.  The competitor is a second such line with at least
    half the support of the first lying more than 3 px away from it inside
    the chip: another edge, or the far side of a bar (the quality gate
    tells them apart, :mod:`.gate`).  ``noise`` is the image's pixel noise
    (DN), measured by :func:`robust_noise` when not given.

    Raises
    ------
    TargetNotFoundError : no such line.
    """
    noise = robust_noise(image) if noise is None else noise
    scored = [(ln, step_contrast(image, ln)) for ln in find_lines(image) if ln.votes >= min_votes]
    strong = [(ln, contrast) for ln, contrast in scored if contrast >= min_contrast * noise]
    lines = [ln for ln, contrast in sorted(strong, key=lambda pair: -pair[0].votes * pair[1])]
    if not lines:
        raise TargetNotFoundError("no straight edge found: no line of strong contrast "
                                  "stands out of the noise")
    # lines crossing the whole chip get nearly the same votes: the one with the
    # largest step across it is the target (a road's sides beside an edge have
    # as much support as the edge, and less contrast)
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
    y, x = np.arange(shape[0])[:, None], np.arange(shape[1])[None, :]
    return x * math.cos(t) + y * math.sin(t) - line.rho_px


def robust_noise(image: np.ndarray) -> float:
    """Noise standard deviation (DN) from the median absolute difference of
    horizontally adjacent pixels, which an edge barely affects (pairs with a
    left-out, NaN, pixel skipped).  Integer pixels are taken as floats, so
    that their differences cannot wrap."""
    return noise_of_differences(np.diff(np.asarray(image, float), axis=1))


def noise_of_differences(diff: np.ndarray) -> float:
    """:func:`robust_noise` from the differences of the pixel pairs (DN, any
    shape; NaN ones skipped): what a caller holding its pairs' differences
    already (a scan's band of pixels) passes."""
    diff = diff[np.isfinite(diff)]
    mad = median(np.abs(diff - median(diff)))
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
