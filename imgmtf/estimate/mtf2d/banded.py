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
    # the factor L (A = L L^T) by its bands, one list entry per unknown holding every system's value:
    # l0[i] = L[i, i], l1[i] = L[i + 1, i], l2[i] = L[i + 2, i] (lists of rows: a step is a few array operations)
    d0, d1, d2 = list(diagonal.T), list(first.T), list(second.T)
    zero = np.zeros(diagonal.shape[0])
    l0: list[np.ndarray] = []
    l1: list[np.ndarray] = []
    l2: list[np.ndarray] = []
    with np.errstate(invalid="ignore", divide="ignore"):
        for i in range(n):
            pivot = d0[i]
            if i >= 1:
                pivot = pivot - l1[i - 1] * l1[i - 1]
            if i >= 2:
                pivot = pivot - l2[i - 2] * l2[i - 2]
            l0.append(np.sqrt(pivot))
            if i + 1 < n:
                l1.append(((d1[i] - l2[i - 1] * l1[i - 1]) if i >= 1 else d1[i]) / l0[i])
            if i + 2 < n:
                l2.append(d2[i] / l0[i])
        l1.append(zero)
        l2 += [zero, zero]
        b = list(np.moveaxis(rhs, 1, 0))                       # unknowns first: n of (batch[, k])
        if b[0].ndim == 2:
            l0, l1, l2 = ([v[:, None] for v in band] for band in (l0, l1, l2))
        y: list[np.ndarray] = []
        for i in range(n):                                     # L y = b
            value = b[i] - l1[i - 1] * y[i - 1] if i >= 1 else b[i]
            y.append((value - l2[i - 2] * y[i - 2] if i >= 2 else value) / l0[i])
        x: list[np.ndarray] = [zero] * n
        for i in range(n - 1, -1, -1):                         # L^T x = y
            value = y[i] - l1[i] * x[i + 1] if i + 1 < n else y[i]
            x[i] = (value - l2[i] * x[i + 2] if i + 2 < n else value) / l0[i]
    return np.stack(x, axis=1)
