"""A scan driven by a vector layer (``scan --roi-file``): only the
candidates that cross one of its features' windows are measured, each
carrying that feature's id and attributes."""
from __future__ import annotations

import numpy as np

from ..io import RasterInfo
from ..vectors import FeatureWindow, Unplaced, VectorROIs


def placed_windows(rois: VectorROIs, info: RasterInfo) -> list[FeatureWindow]:
    """Every feature's window on the scene.

    Raises
    ------
    ParameterError
        The scene has no CRS, or a feature has no window on it (outside
        it, too small, or neither a polygon nor a line): a scan of the
        layer's sites measures every one or says which it cannot.
    """
    windows = rois.windows(info)
    for window in windows:
        if isinstance(window, Unplaced):
            raise window.error
    return [w for w in windows if isinstance(w, FeatureWindow)]


def crossing(ends: np.ndarray, windows: list[FeatureWindow]) -> list[FeatureWindow | None]:
    """The first window each segment crosses (None: none).

    Parameters
    ----------
    ends : numpy.ndarray, shape (n, 4)
        Segments x0, y0, x1, y1 in the scene's pixels (pixel centres at
        integers, as the scan's segments are).
    windows : list of FeatureWindow
        The features' windows (x, y, w, h: pixel edges).

    Returns
    -------
    list of FeatureWindow or None
        Per segment.

    Examples
    --------
    >>> w = FeatureWindow("0", {}, (10, 10, 20, 20), (), "polygon")
    >>> [c is w for c in crossing(np.array([[0.0, 0.0, 40.0, 40.0], [0.0, 0.0, 40.0, 5.0]]), [w])]
    [True, False]
    """
    ends = np.asarray(ends, float).reshape(-1, 4) + 0.5       # pixel centres -> the windows' frame
    out: list[FeatureWindow | None] = [None] * len(ends)
    start, step = ends[:, :2], ends[:, 2:] - ends[:, :2]
    for window in windows:
        x, y, w, h = window.window
        low, high = np.array([x, y], float), np.array([x + w, y + h], float)
        # Liang-Barsky: the segment's parameter t in [0, 1] inside the box, per axis
        with np.errstate(divide="ignore", invalid="ignore"):
            t0 = (low - start) / step
            t1 = (high - start) / step
        enter = np.where(step == 0, np.where((start >= low) & (start <= high), -np.inf, np.inf), np.minimum(t0, t1))
        leave = np.where(step == 0, np.where((start >= low) & (start <= high), np.inf, -np.inf), np.maximum(t0, t1))
        inside = np.maximum(enter.max(axis=1), 0.0) <= np.minimum(leave.min(axis=1), 1.0)
        for i in np.flatnonzero(inside):
            if out[i] is None:
                out[i] = window
    return out
