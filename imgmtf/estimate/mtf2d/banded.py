"""Many small symmetric positive definite pentadiagonal systems solved at
once, by their banded Cholesky factors.

The elliptical inversion's normal matrices (:mod:`.inversion`) are a
linear-interpolation design's tridiagonal Gram matrix plus the smoothing's
second differences (pentadiagonal): a hundred of them per target and
draw set, 32 unknowns each.  Solved as dense matrices they were built,
copied and factored as a hundred 32 x 32 arrays (megabytes of fresh memory
per call, most of the cost); by their three bands the work is a loop over
the 32 unknowns, each step one array operation over all the systems.
"""
from __future__ import annotations

import numpy as np


def solve_pentadiagonal(diagonal: np.ndarray, first: np.ndarray, second: np.ndarray,
                        rhs: np.ndarray) -> np.ndarray:
    """Solve A x = ``rhs`` for a batch of symmetric positive definite
    pentadiagonal matrices A given by their bands.

    Parameters
    ----------
    diagonal : numpy.ndarray
        (batch, n): A[i, i].
    first : numpy.ndarray
        (batch, n - 1): A[i, i + 1] (= A[i + 1, i]).
    second : numpy.ndarray
        (batch, n - 2): A[i, i + 2].
    rhs : numpy.ndarray
        (batch, n) or (batch, n, k): one or k right-hand sides per matrix.

    Returns
    -------
    numpy.ndarray
        x, shaped as ``rhs``.  NaN where a matrix is not positive definite.

    Examples
    --------
    >>> a = np.array([[4.0, 1.0, 0.5], [1.0, 4.0, 1.0], [0.5, 1.0, 4.0]])
    >>> x = solve_pentadiagonal(np.array([[4.0, 4, 4]]), np.array([[1.0, 1]]), np.array([[0.5]]),
    ...                         np.array([[1.0, 2.0, 3.0]]))
    >>> bool(np.allclose(x[0], np.linalg.solve(a, [1.0, 2.0, 3.0])))
    True
    """
    n = diagonal.shape[1]
    # the factor L (A = L L^T) by its bands, unknowns first: l0[i] = L[i, i], l1[i] = L[i + 1, i],
    # l2[i] = L[i + 2, i]; a row of each is one step's values for every system
    d0, d1, d2 = diagonal.T, _padded(first.T, n), _padded(second.T, n)
    l0, l1, l2 = np.empty_like(d0), np.zeros_like(d0), np.zeros_like(d0)
    with np.errstate(invalid="ignore", divide="ignore"):
        for i in range(n):
            pivot = d0[i] - (l1[i - 1] ** 2 if i >= 1 else 0.0) - (l2[i - 2] ** 2 if i >= 2 else 0.0)
            l0[i] = np.sqrt(pivot)
            l1[i] = (d1[i] - (l2[i - 1] * l1[i - 1] if i >= 1 else 0.0)) / l0[i]
            l2[i] = d2[i] / l0[i]
    b = np.moveaxis(rhs, 1, 0)                                 # unknowns first: (n, batch[, k])
    tail = (slice(None), slice(None)) + (None,) * (b.ndim - 2)
    l0, l1, l2 = l0[tail], l1[tail], l2[tail]
    y = np.empty(b.shape)
    for i in range(n):                                         # L y = b
        value = b[i] - l1[i - 1] * y[i - 1] if i >= 1 else b[i]
        y[i] = (value - l2[i - 2] * y[i - 2] if i >= 2 else value) / l0[i]
    x = np.empty(b.shape)
    for i in range(n - 1, -1, -1):                             # L^T x = y
        value = y[i] - l1[i] * x[i + 1] if i + 1 < n else y[i]
        x[i] = (value - l2[i] * x[i + 2] if i + 2 < n else value) / l0[i]
    return np.moveaxis(x, 0, 1)


def _padded(band: np.ndarray, n: int) -> np.ndarray:
    """A band (length n - 1 or n - 2, first axis) padded with zeros to n."""
    out = np.zeros((n, *band.shape[1:]))
    out[: band.shape[0]] = band
    return out
