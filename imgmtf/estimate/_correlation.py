"""One-dimensional correlation along an axis of an array, in NumPy.

The local-polynomial resampling (:mod:`.resampling`) needs only short
correlations along one axis, with zeros beyond the ends; doing them here
keeps SciPy's ndimage, about a fifth of a second to import, out of a
measurement's start-up.
"""
from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import ArrayLike

from ..errors import ParameterError


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
    moved = np.moveaxis(np.asarray(values, float), axis, -1)
    half, n = weights.size // 2, moved.shape[-1]
    if moved.size == 0:
        return np.zeros(np.shape(values))
    padded = np.zeros((*moved.shape[:-1], n + 2 * half))    # (np.pad's general machinery costs more)
    padded[..., half: half + n] = moved
    # every output's window as a strided view (no copy), weighted in one pass
    out = np.einsum("...nk,k->...n", sliding_window_view(padded, weights.size, axis=-1), weights)
    return np.moveaxis(out, -1, axis)
