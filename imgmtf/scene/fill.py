"""Fill and nodata in a scene: the pixels that are not ground (NaN, and
regions at one fill value with a hard boundary), found as detection reads its
tiles; a segment along them is a boundary of the fill, never an edge of the
scene, and every ROI keeps clear of them."""
from __future__ import annotations

import numpy as np
from numpy.typing import DTypeLike

from ..estimate import gate

FILL_SIDE_PX = 3.0              # fill this close to a segment along half of it: a boundary of the fill
MIN_FILL_PIXELS = 8             # fewer pixels at a fill value are not a fill region


def fill_screen(fill_fraction: float) -> tuple[str, str] | None:
    """``fill`` when fill or nodata lies beside a segment along half its
    length or more: a boundary of the fill, never an edge of the scene."""
    if fill_fraction >= 0.5:
        return "fill", (f"a boundary of fill or nodata along {100 * fill_fraction:.0f} % of its length "
                        "(not an edge of the scene)")
    return None


def fill_mask(window: np.ndarray, dtype: DTypeLike) -> np.ndarray:
    """The fill and nodata pixels of a window of the scene: NaN (declared
    nodata), and every region at one fill value (0, an integer type's
    limits) whose boundary is hard, as the gate tells fill from a clipped
    side (:func:`imgmtf.estimate.gate.fill_check`): the pixels around it
    differ from it by more than ``FILL_BOUNDARY`` of the window's contrast,
    where a dark side clipped at 0 meets values close to 0.

    Examples
    --------
    >>> w = np.full((20, 20), 900.0); w[:, :6] = 300.0; w[:, 12:] = 0.0
    >>> int(fill_mask(w, "uint16").sum())
    160
    """
    nodata = ~np.isfinite(window)
    values = window[~nodata] if nodata.any() else window.ravel()
    fill = nodata.copy()
    if values.size == 0:
        return fill
    low, high = float(values.min()), float(values.max())
    for value in gate.fill_values(values, dtype):
        if not (value == low or value == high):     # a fill value is the least or the greatest
            continue
        at = window == value
        count = int(at.sum())
        if count < MIN_FILL_PIXELS or count == values.size:
            continue
        contrast = gate.fill_contrast(value, values[values != value])
        if contrast <= 0:
            continue
        border = grown(at, 1) & ~at & ~nodata
        if border.any() and np.median(np.abs(window[border] - value)) > gate.FILL_BOUNDARY * contrast:
            fill |= at
    return fill


def may_hold_fill(window: np.ndarray, dtype: DTypeLike) -> bool:
    """False when no part of ``window`` can hold fill or nodata
    (:func:`fill_mask` of any part of it is empty): it has no NaN, and
    every value lies above 0 (the least fill value, negative sentinels
    included) and below infinity and, for an integer type, below its
    greatest value.  Two
    reductions of a batch's window spare each of its candidates its own
    :func:`fill_mask`.

    Examples
    --------
    >>> w = np.full((20, 20), 900.0)
    >>> may_hold_fill(w, "uint16"), may_hold_fill(np.where(w > 0, w, 0) * (np.arange(20) < 12), "uint16")
    (False, True)
    """
    if window.size == 0:
        return False
    low, high = float(window.min()), float(window.max())
    if not low > 0 or high == np.inf:   # a NaN, 0, a negative value, or an infinity (nodata to fill_mask)
        return True
    return bool(np.issubdtype(np.dtype(dtype), np.integer) and high >= np.iinfo(np.dtype(dtype)).max)


def grown(mask: np.ndarray, px: int) -> np.ndarray:
    """``mask`` dilated by a square of ``px`` pixels each way."""
    if px <= 0 or not mask.any():
        return mask.copy()
    import cv2
    return cv2.dilate(mask.astype(np.uint8), np.ones((2 * px + 1, 2 * px + 1), np.uint8)).astype(bool)
