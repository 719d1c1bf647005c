"""Order statistics of small 1-D samples as NumPy computes them, without
its per-call overhead.

``np.median`` and ``np.percentile`` spend most of their time on a chip's
few hundred values in Python (axis handling, method tables, the checks for
NaN): a scan's edge calls them about fifteen times, twice as long as the
partitions themselves.  These functions do the same arithmetic (the same
order statistics, NumPy's mean of the two middle values, its "linear"
interpolation) on the flattened values and give the same floats to the
bit; where a value is NaN, or there is none, they hand the call to NumPy,
which says so as it always has.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike


def median(values: ArrayLike) -> np.float64:
    """``np.median(values)`` (of all the values, flattened).

    Parameters
    ----------
    values : array_like
        The values (any shape; taken as float64).

    Returns
    -------
    numpy.float64
        The middle value, or the mean of the two middle ones; NaN (NumPy's)
        where a value is NaN or there is none.

    Examples
    --------
    >>> float(median([3.0, 1.0, 2.0, 10.0]))
    2.5
    >>> bool(median(np.arange(7.0)) == np.median(np.arange(7.0)))
    True
    """
    flat = np.asarray(values, float).ravel()
    n = flat.size
    if n == 0:
        return np.median(flat)
    half = n // 2
    if n % 2:
        part = np.partition(flat, [half, -1])        # NumPy's own order statistics, NaN last
        if np.isnan(part[-1]):
            return np.median(flat)
        return np.add.reduce(part[half: half + 1]) / 1
    part = np.partition(flat, [half - 1, half, -1])
    if np.isnan(part[-1]):
        return np.median(flat)
    return np.add.reduce(part[half - 1: half + 1]) / 2


def quantile(values: ArrayLike, q: ArrayLike) -> Any:
    """``np.quantile(values, q)`` by its default ("linear") method, of all
    the values, flattened.

    Parameters
    ----------
    values : array_like
        The values (any shape; taken as float64).
    q : float or array_like
        Quantiles in [0, 1].

    Returns
    -------
    numpy.float64 or numpy.ndarray
        One value per quantile, shaped as ``q``; NaN (NumPy's) where a
        value is NaN or there is none.

    Examples
    --------
    >>> float(quantile(np.arange(11.0), 0.25))
    2.5
    >>> bool((quantile(np.arange(5.0), [0.1, 0.9]) == np.quantile(np.arange(5.0), [0.1, 0.9])).all())
    True
    """
    flat = np.asarray(values, float).ravel()
    quantiles = np.asanyarray(q, float)
    n = flat.size
    if n == 0 or quantiles.size == 0:
        return np.quantile(flat, quantiles)
    virtual = np.asanyarray((n - 1) * quantiles)
    # arrays even for one quantile (0-d), to be written below (out=... needs NumPy 2.1)
    previous = np.array(np.floor(virtual))
    following = np.array(previous + 1)
    above = virtual >= n - 1
    previous[above] = -1
    following[above] = -1
    below = virtual < 0
    previous[below] = 0
    following[below] = 0
    if np.isnan(virtual).any():
        return np.quantile(flat, quantiles)
    previous_i, following_i = previous.astype(np.intp), following.astype(np.intp)
    # the positions NumPy partitions at, sorted (np.unique costs as much as the partition)
    part = np.partition(flat, sorted({0, -1, *previous_i.ravel().tolist(), *following_i.ravel().tolist()}))
    if np.isnan(part[-1]):
        return np.quantile(flat, quantiles)
    low, high = part[previous_i], part[following_i]
    gamma = np.asanyarray(virtual - previous_i)
    # NumPy's lerp: from the lower value below gamma 1/2, from the upper one above
    diff = high - low
    out = np.array(np.add(low, diff * gamma))
    np.subtract(high, diff * (1 - gamma), out=out, where=gamma >= 0.5, casting="unsafe")
    return out[()] if out.ndim == 0 else out


def percentile(values: ArrayLike, q: ArrayLike) -> Any:
    """``np.percentile(values, q)`` (``q`` in percent; :func:`quantile`).

    Examples
    --------
    >>> [float(v) for v in percentile(np.arange(101.0), [1, 99])]
    [1.0, 99.0]
    """
    return quantile(values, np.true_divide(np.asanyarray(q, float), 100))


def distinct(values: np.ndarray, return_inverse: bool = False) -> Any:
    """``np.unique(values)`` of a 1-D array of integers (a profile's row
    numbers), and with ``return_inverse`` each value's index among them:
    counted in bins (np.unique sorts, and costs some 40 microseconds on
    a chip's thousand samples).  Other arrays, and integers spread far
    wider than they are many, are handed to np.unique.

    Examples
    --------
    >>> distinct(np.array([3, 1, 3, 2]))
    array([1, 2, 3])
    >>> ids, inverse = distinct(np.array([3, 1, 3, 2]), return_inverse=True)
    >>> ids[inverse].tolist()
    [3, 1, 3, 2]
    """
    values = np.asarray(values)
    if values.ndim != 1 or values.size == 0 or values.dtype.kind not in "iu":
        return _unique(values, return_inverse)
    low, high = int(values.min()), int(values.max())
    if high - low > 4 * values.size + 1024:
        return _unique(values, return_inverse)
    offset = values - low
    present = np.bincount(offset) > 0
    ids = (np.flatnonzero(present) + low).astype(values.dtype, copy=False)
    if not return_inverse:
        return ids
    index = np.cumsum(present) - 1
    return ids, index[offset]


def _unique(values: np.ndarray, return_inverse: bool) -> Any:
    return np.unique(values, return_inverse=True) if return_inverse else np.unique(values)
