"""Isolated outliers: hot and dead pixels.

A hot or dead pixel stands alone above (or below) every other pixel of
the 5 x 5 block about it by far more than the noise and than the block's
own range; a pixel on an edge or a bar never does (an edge's pixel lies
between its neighbours across the edge; a bar's peak pixel has pixels
along the bar within the block, and rises above them by less than the
bar's height, the block's range).  Such pixels
are left out of the estimate (as NaN, which every stage skips) and
counted, instead of throwing the row's edge fit off and the chip out as
not straight.
"""
from __future__ import annotations

import cv2
import numpy as np

from ._order import percentile

OUTLIER_NOISE = 8.0           # beyond every neighbour by this many noise sd...
OUTLIER_CONTRAST = 0.1        # ...and by this fraction of the chip's contrast


def isolated_outliers(data: np.ndarray, noise: float) -> np.ndarray:
    """Mask of the pixels of ``data`` (2-D, DN, NaN left out) that stand
    above all the other pixels of the 5 x 5 block about them, or below all
    of them, by more than
    ``OUTLIER_NOISE`` times ``noise`` (DN), ``OUTLIER_CONTRAST`` of the
    chip's contrast (its 1st to 99th percentile) and the block's own range,
    with no such pixel among
    their eight neighbours (a pixel, not a feature).

    Examples
    --------
    >>> chip = np.tile(np.where(np.arange(40) < 20, 100.0, 900.0), (40, 1))
    >>> chip[10, 5] = 4000.0
    >>> np.argwhere(isolated_outliers(chip, noise=2.0)).tolist()
    [[10, 5]]
    """
    finite = np.isfinite(data)
    if finite.sum() < 9:
        return np.zeros(data.shape, bool)
    # the noise's margin alone first: a pixel not beyond it is beyond no larger
    # one, and on most chips none is (the contrast's percentiles then spared)
    extremes = _extremes(data, finite)
    if OUTLIER_NOISE * noise > 0 and not _beyond(data, finite, extremes, OUTLIER_NOISE * noise).any():
        return np.zeros(data.shape, bool)
    low, high = percentile(data[finite], [1.0, 99.0])
    margin = max(OUTLIER_NOISE * noise, OUTLIER_CONTRAST * (high - low))
    if not margin > 0:
        return np.zeros(data.shape, bool)
    outlier = _beyond(data, finite, extremes, margin)
    # isolated: no outlying neighbour (a cluster is a feature, the gate's to judge)
    clustered = cv2.dilate(outlier.view(np.uint8), _ring(1), borderType=cv2.BORDER_CONSTANT, borderValue=0)
    return outlier & ~clustered.astype(bool)


def _extremes(data: np.ndarray, finite: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The largest and the smallest of the other pixels of each pixel's
    5 x 5 block (-inf and inf where none), and the block's range."""
    block = _ring(2)
    # the largest and smallest of the other pixels of each block (grey
    # dilation and erosion; beyond the border and at NaN, nothing)
    above = cv2.dilate(np.where(finite, data, -np.inf), block, borderType=cv2.BORDER_CONSTANT,
                       borderValue=-np.inf)
    below = cv2.erode(np.where(finite, data, np.inf), block, borderType=cv2.BORDER_CONSTANT,
                      borderValue=np.inf)
    # and beyond the block's own range: a thin bar's peak pixel rises above
    # its block by less than the bar's height (the block holds pixels along
    # the bar), a hot pixel on a level stands far out of its block's noise
    spread = np.where(np.isfinite(above - below), above - below, 0.0)
    return above, below, spread


def _beyond(data: np.ndarray, finite: np.ndarray, extremes: tuple[np.ndarray, np.ndarray, np.ndarray],
            margin: float) -> np.ndarray:
    """The pixels of ``data`` above all the other pixels of their block, or
    below all of them (``extremes``), by more than ``margin`` (DN) and the
    block's own range."""
    above, below, spread = extremes
    with np.errstate(invalid="ignore"):
        beyond = np.maximum(margin, spread)
        return finite & ((data > above + beyond) | (data < below - beyond))


def _ring(reach: int) -> np.ndarray:
    """The structuring element of a block of half-size ``reach`` without
    its centre pixel."""
    ring = np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)
    ring[reach, reach] = 0
    return ring
