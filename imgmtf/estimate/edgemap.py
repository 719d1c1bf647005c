"""Canny edge map and straight-line Hough accumulator, in NumPy.

The seed search (:mod:`.detection`) needs both on chips of at most 512 px a
side.  They follow scikit-image's ``feature.canny`` (Gaussian smoothing that
ignores masked pixels, Sobel gradients, bilinear non-maximum suppression,
hysteresis over 8-connected pixels) and ``transform.hough_line`` (one vote
per edge pixel and angle, at the rounded distance), step for step: the tests
find the same edge maps and accumulators on rendered chips, noise and
photographs.  They can differ only where floating-point rounding breaks a tie
differently (a non-maximum suppression between equal magnitudes, as on a
noise-free step; a distance within one rounding error of a half pixel).  They
exist to leave out scikit-image's imports, which pull in SciPy's ndimage and
spatial: about a third of a second of every measurement's start-up.
"""
from __future__ import annotations

import math

import numpy as np

from ..filters import correlate1d

GAUSSIAN_TRUNCATE = 4.0            # the kernel reaches this many sigma, as SciPy's does


def canny(image: np.ndarray, sigma: float = 1.0, low_threshold: float = 0.1, high_threshold: float = 0.2,
          mask: np.ndarray | None = None, use_quantiles: bool = False) -> np.ndarray:
    """Canny edge map of a 2-D float image.

    Parameters
    ----------
    image : (M, N) ndarray
        Values (any unit; the thresholds are in the same unit per pixel).
    sigma : float
        Standard deviation of the Gaussian smoothing, px.
    low_threshold, high_threshold : float
        Hysteresis thresholds on the gradient magnitude (Sobel of the
        smoothed image), or its quantiles in [0, 1] with ``use_quantiles``.
    mask : (M, N) bool ndarray, optional
        Pixels to use; the smoothing ignores the others and no edge lies
        next to them.  The image's outermost pixels are never edges.

    Returns
    -------
    (M, N) bool ndarray
        The edge pixels.

    Example
    -------
    >>> square = np.zeros((20, 20)); square[5:15, 5:15] = 1.0
    >>> int(canny(square, sigma=1.0)[5:15, 5].sum())
    10
    """
    image = np.asarray(image, float)
    smoothed, inside = _smooth(image, sigma, mask)
    di = correlate1d(correlate1d(smoothed, [-1.0, 0.0, 1.0], 0, "reflect"), [1.0, 2.0, 1.0], 1, "reflect")
    dj = correlate1d(correlate1d(smoothed, [-1.0, 0.0, 1.0], 1, "reflect"), [1.0, 2.0, 1.0], 0, "reflect")
    magnitude = np.hypot(di, dj)
    if use_quantiles:
        low_threshold, high_threshold = np.percentile(magnitude, [100.0 * low_threshold, 100.0 * high_threshold])
    low = _local_maxima(di, dj, magnitude, inside & (magnitude >= max(low_threshold, 1e-14)))
    return _hysteresis(low, low & (magnitude >= high_threshold))


def _smooth(image, sigma, mask):
    """Gaussian-smoothed image, zero beyond the edges and renormalised by the
    smoothed mask (so masked and outside pixels do not pull it down), and the
    pixels whose 3 x 3 neighbourhood lies wholly in the mask and the image."""
    radius = int(GAUSSIAN_TRUNCATE * sigma + 0.5)
    x = np.arange(-radius, radius + 1)
    kernel = np.exp(-0.5 * (x / sigma) ** 2)
    kernel /= kernel.sum()

    def blur(values):
        return correlate1d(correlate1d(values, kernel, 0), kernel, 1)
    if mask is None:        # the smoothed mask is separable: one product of two smoothed lines
        valid = np.ones(image.shape, bool)
        weight = np.outer(correlate1d(np.ones(image.shape[0]), kernel), correlate1d(np.ones(image.shape[1]), kernel))
        smoothed = blur(image)
    else:
        valid = np.asarray(mask, bool)
        weight = blur(valid.astype(float))
        smoothed = blur(np.where(valid, image, 0.0))
    smoothed /= weight + np.finfo(float).eps
    padded = np.pad(valid, 1)
    rows, cols = image.shape
    inside = np.ones(image.shape, bool)
    for dr in range(3):
        for dc in range(3):
            inside &= padded[dr: dr + rows, dc: dc + cols]
    return smoothed, inside


def _local_maxima(di, dj, magnitude, candidates):
    """Candidates whose magnitude is no less than the magnitude interpolated
    (bilinearly between the two neighbours the gradient passes) one pixel
    ahead and one behind along the gradient.  ``di``, ``dj``: gradients
    along rows (axis 0) and columns (axis 1)."""
    r, c = np.nonzero(candidates)
    gi, gj = di[r, c], dj[r, c]
    a, b = np.abs(gi), np.abs(gj)
    step = np.where((gi > 0) == (gj > 0), 1, -1)      # the row step of the diagonal neighbour
    rows_major = np.where(step > 0, a > b, a >= b)
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(rows_major, b / a, a / b)
    # the neighbours ahead: n1 along the major axis, n2 on the diagonal
    r1, c1 = np.where(rows_major, step, 0), np.where(rows_major, 0, 1)
    m = magnitude[r, c]
    ahead = magnitude[r + step, c + 1] * w + magnitude[r + r1, c + c1] * (1.0 - w) <= m
    behind = magnitude[r - step, c - 1] * w + magnitude[r - r1, c - c1] * (1.0 - w) <= m
    out = np.zeros(candidates.shape, bool)
    out[r[ahead & behind], c[ahead & behind]] = True
    return out


def _hysteresis(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """The pixels of ``low`` 8-connected (through ``low``) to a pixel of
    ``high``: connected components by hooking each pair of neighbours' roots
    to the smaller and halving paths, a few passes over the pairs."""
    rows, cols = low.shape
    index = np.full((rows + 2, cols + 2), -1, np.int64)
    index[1:-1, 1:-1][low] = np.arange(int(low.sum()))
    n = int(low.sum())
    if n == 0:
        return low.copy()
    centre = index[1:-1, 1:-1]
    pairs = []
    for dr, dc in ((0, 1), (1, -1), (1, 0), (1, 1)):        # each neighbour pair once
        other = index[1 + dr: rows + 1 + dr, 1 + dc: cols + 1 + dc]
        both = (centre >= 0) & (other >= 0)
        pairs.append((centre[both], other[both]))
    a = np.concatenate([p[0] for p in pairs])
    b = np.concatenate([p[1] for p in pairs])
    parent = np.arange(n)
    while True:
        pa, pb = parent[a], parent[b]
        differ = pa != pb
        if not differ.any():
            break
        smaller = np.minimum(pa[differ], pb[differ])
        np.minimum.at(parent, pa[differ], smaller)
        np.minimum.at(parent, pb[differ], smaller)
        while True:                                     # point every pixel at its root
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand
    strong = np.zeros(n, bool)
    strong[parent[index[1:-1, 1:-1][high]]] = True
    out = np.zeros(low.shape, bool)
    out[low] = strong[parent]
    return out


def hough_line(edges: np.ndarray, thetas: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Straight-line Hough accumulator of a boolean edge map.

    Every edge pixel (x, y) votes, for each angle theta, for the distance
    rho = x cos(theta) + y sin(theta) rounded to the nearest pixel.

    Parameters
    ----------
    edges : (M, N) bool ndarray
    thetas : 1-D ndarray
        Angles, radians.

    Returns
    -------
    accumulator : (R, T) int64 ndarray
        Votes per distance and angle.
    thetas : (T,) ndarray
        The angles given.
    rhos : (R,) ndarray
        Distances, px: the integers from -D to D, D the image diagonal
        rounded up.

    Example
    -------
    >>> edges = np.zeros((10, 10), bool); edges[:, 3] = True
    >>> acc, t, rhos = hough_line(edges, np.array([0.0, np.pi / 4]))
    >>> int(acc[:, 0].max()), float(rhos[acc[:, 0].argmax()])
    (10, 3.0)
    """
    thetas = np.asarray(thetas, float)
    offset = int(math.ceil(math.hypot(*edges.shape)))
    rhos = np.arange(-offset, offset + 1, dtype=float)
    accumulator = np.zeros(rhos.size * thetas.size, np.int64)
    ys, xs = np.nonzero(edges)
    cos, sin = np.cos(thetas), np.sin(thetas)
    columns = np.arange(thetas.size)
    chunk = max(1, 2 ** 18 // max(thetas.size, 1))      # votes held at once: few MB, faster than all at once
    for start in range(0, xs.size, chunk):
        x, y = xs[start: start + chunk, None], ys[start: start + chunk, None]
        # the flat cell index, in floats (exact for integers this size) until one cast
        cells = np.rint(x * cos + y * sin)
        cells += offset
        cells *= thetas.size
        cells += columns
        accumulator += np.bincount(cells.astype(np.intp).ravel(), minlength=accumulator.size)
    return accumulator.reshape(rhos.size, thetas.size), thetas, rhos
