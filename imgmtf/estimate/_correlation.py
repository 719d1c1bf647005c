"""One-dimensional correlation along an axis of an array, by OpenCV.

The local-polynomial resampling (:mod:`.resampling`) needs only short
correlations along one axis, with zeros beyond the ends, about twenty per
profile: ``cv2.filter2D`` (OpenCV is loaded for the seed anyway) does each
in a few microseconds, where SciPy's ndimage costs about a fifth of a
second to import and a NumPy sliding-window sum ten times the time.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ParameterError

#: below this many taps cv2.filter2D correlates float64 rows one by one, each row's result its own
#: whatever the rows beside it; from it on it goes through DFTs of blocks of rows, whose rounding
#: depends on the block (tests/test_correlation.py checks both)
ROW_BY_ROW_TAPS = 50


def correlate1d(values: ArrayLike, weights: ArrayLike, axis: int = -1) -> np.ndarray:
    """Correlate ``values`` with ``weights`` along ``axis``:
    ``out[i] = sum_k weights[k] * values[i + k - len(weights) // 2]``.

    Parameters
    ----------
    values : ndarray
        Any shape; computed in float64.
    weights : 1-D array of odd length
        The correlation kernel, centred on its middle element.
    axis : int
        The axis to correlate along; zeros beyond its ends (as
        ``scipy.ndimage.correlate1d`` with ``mode="constant"``).

    Returns
    -------
    ndarray
        Same shape as ``values``, float64.

    Raises
    ------
    ParameterError
        An even-length or empty kernel.

    Examples
    --------
    >>> correlate1d(np.array([0.0, 1.0, 0.0, 0.0]), np.array([1.0, 2.0, 3.0]))
    array([3., 2., 1., 0.])
    """
    weights = np.asarray(weights, float)
    if weights.ndim != 1 or weights.size % 2 == 0:
        raise ParameterError(f"correlate1d takes a kernel of odd length, got shape {weights.shape}")
    import cv2  # here, not at import: a batch's parent imports the method registry, never measures
    values = np.asarray(values, float)
    last = axis in (-1, values.ndim - 1)
    moved = values if last else np.moveaxis(values, axis, -1)
    if moved.size == 0:
        return np.zeros(values.shape)
    # every leading index is one row of a 2-D image; the kernel a 1 x k one
    # anchored on its middle, zeros beyond the ends
    rows = np.ascontiguousarray(moved.reshape(-1, moved.shape[-1]))
    out = cv2.filter2D(rows, cv2.CV_64F, weights[None, :], borderType=cv2.BORDER_CONSTANT).reshape(moved.shape)
    return out if last else np.moveaxis(out, -1, axis)
