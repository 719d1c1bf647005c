"""The local polynomial's sums and solves under a stack of weightings (the
bootstrap's replicates), done for every weighting at once.

A bootstrap replicate weights every sample of a row by how often the row
was drawn, so a stack of weightings takes only a few distinct columns (one
per row).  The window sums of the local polynomial
(:func:`imgmtf.estimate.resampling.local_polynomial`) are linear in the
weights, so they are summed once per group of samples that share their
weights, and every weighting's sums are one matrix product with the groups'
weights, not a correlation of every weighting's per-bin sums with each power
of the window's offsets.  The windows' normal equations are symmetric positive definite;
only their first unknown (the fitted level) is wanted, which elimination
from the last unknown up gives without back-substitution, for all windows in
one pass of array operations rather than one LAPACK call each.  The floats
differ from a LAPACK solve's in their last bits.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

#: samples fall into at most this many groups per tap of the window for their sums to be taken per group:
#: the product with the groups' weights grows with the groups, correlating the per-bin sums with the taps
#: (a bootstrap of 50 replicates, 21 taps: 44-48 ms grouped against 54-64 ms at 295 groups, 8 against 36 ms
#: at 43)
MAX_GROUPS_PER_TAP = 16
#: the samples' contributions to the windows that hold them (samples x taps) are taken at once up to this
#: many (about 30 MB of arrays); beyond, the per-bin sums are correlated
MAX_CONTRIBUTIONS = 250_000


def weight_groups(weights: np.ndarray, max_groups: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The distinct columns of a stack of weightings and each sample's.

    Parameters
    ----------
    weights : numpy.ndarray
        Shape (replicates, samples).
    max_groups : int
        More distinct columns than this are not grouped.

    Returns
    -------
    (columns, group) or None
        ``columns`` (replicates, groups) and ``group`` (samples,) with
        ``columns[:, group] == weights`` exactly; None where the samples
        form more than ``max_groups`` groups.

    Examples
    --------
    >>> w = np.array([[1.0, 1.0, 2.0], [0.0, 0.0, 1.0]])
    >>> columns, group = weight_groups(w, 10)
    >>> columns.tolist(), group.tolist()
    ([[1.0, 2.0], [0.0, 1.0]], [0, 0, 1])
    >>> weight_groups(w, 1) is None
    True
    """
    replicates = weights.shape[0]
    # a column's key: its weights in a fixed irrational mix (equal columns, equal keys); the
    # exact comparison below catches the rare unequal columns that share one
    key = np.sqrt(np.arange(2.0, replicates + 2.0)) @ weights
    _, first, group = np.unique(key, return_index=True, return_inverse=True)
    if first.size > max_groups:
        return None
    columns = weights[:, first]
    if not np.array_equal(columns[:, group], weights):
        return None
    return columns, group.ravel()


def window_sums(distance: np.ndarray, values: np.ndarray, weights: np.ndarray, bins: np.ndarray,
                grid: np.ndarray, scale: float, half_bins: int, order: int):
    """Every weighting's window sums of the local polynomial: for each grid
    point g, the sums over the samples in the bins within ``half_bins`` of
    it of w u^k (k = 0 .. 2 order) and of w u^k v (k = 0 .. order), with
    u = (distance - grid[g]) / scale.

    Parameters
    ----------
    distance, values : numpy.ndarray
        The samples on the grid (px, DN), shape (samples,).
    weights : numpy.ndarray
        The stack of weightings, shape (replicates, samples).
    bins : numpy.ndarray
        Each sample's grid index.
    grid : numpy.ndarray
        The bins' centres (px).
    scale : float
        The window's half width (px): local coordinates in [-1, 1].
    half_bins : int
        The window's half width in bins.
    order : int
        The polynomial's order.

    Returns
    -------
    (moments, rhs) or None
        ``moments`` (replicates, 2 order + 1, grid) and ``rhs``
        (replicates, grid, order + 1); None where grouping would not pay
        (:data:`MAX_GROUPS_PER_TAP`, :data:`MAX_CONTRIBUTIONS`).

    Examples
    --------
    >>> d, v = np.array([-0.1, 0.0, 0.1]), np.array([1.0, 2.0, 3.0])
    >>> m, rhs = window_sums(d, v, np.array([[1.0, 1.0, 1.0], [0.0, 1.0, 1.0]]), np.array([0, 1, 2]),
    ...                      np.array([-0.1, 0.0, 0.1]), 0.15, 1, 1)
    >>> m[:, 0].tolist(), rhs[:, 1, 0].tolist()         # samples and sum of values about the middle
    ([[2.0, 3.0, 2.0], [1.0, 2.0, 2.0]], [6.0, 5.0])
    """
    taps = 2 * half_bins + 1
    if distance.size * taps > MAX_CONTRIBUTIONS:
        return None
    grouped = weight_groups(weights, MAX_GROUPS_PER_TAP * taps)
    if grouped is None:
        return None
    columns, group = grouped
    n_grid, nk, nv = grid.size, 2 * order + 1, order + 1
    # every sample's contribution to each window that holds it: (samples, taps)
    at = bins[:, None] + np.arange(-half_bins, half_bins + 1)          # (samples, taps)
    inside = (at >= 0) & (at < n_grid)
    at = np.where(inside, at, 0)
    u = (distance[:, None] - grid[at]) / scale
    powers = np.empty((nk + nv, *u.shape))
    powers[0] = inside
    for k in range(1, nk):
        powers[k] = powers[k - 1] * u
    powers[nk:] = powers[:nv] * values[:, None]
    # summed per group: (groups, moments, grid), then every weighting's sums at once
    where = ((group[:, None] * (nk + nv))[None] + np.arange(nk + nv)[:, None, None]) * n_grid + at[None]
    per_group = np.bincount(where.ravel(), weights=powers.ravel(),
                            minlength=columns.shape[1] * (nk + nv) * n_grid)
    # laid out (moment, grid, replicate), each moment of all windows one block, as first_levels reads them
    sums = (per_group.reshape(columns.shape[1], -1).T @ columns.T).reshape(nk + nv, n_grid, -1)
    return np.moveaxis(sums[:nk], -1, 0), np.moveaxis(sums[nk:], 0, -1).transpose(1, 0, 2)


def first_levels(moments: np.ndarray, rhs: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """The fitted level (the first unknown) of every valid window's normal
    equations, sum_j moments[i + j] x_j = rhs[i], symmetric positive
    definite, by eliminating the unknowns from the last up (symmetric pivots,
    stable for such matrices; the lower triangle only) for all windows at
    once, every matrix entry one array of the windows.

    Parameters
    ----------
    moments : numpy.ndarray
        Shape (replicates, 2 order + 1, grid): the windows' moment sums
        (read fastest as :func:`window_sums` lays them out).
    rhs : numpy.ndarray
        Shape (replicates, grid, order + 1).
    valid : numpy.ndarray
        Shape (replicates, grid): the windows wanted (the others, possibly
        singular, are solved too and dropped).

    Returns
    -------
    numpy.ndarray
        The first unknown of each valid window, in the order of ``valid``'s
        True entries.

    Examples
    --------
    >>> m = np.array([[[2.0], [0.0], [2.0]]])          # two samples at u = -1, 1
    >>> first_levels(m, np.array([[[4.0, 2.0]]]), np.array([[True]]))    # values 1 and 3: level 2
    array([2.])
    """
    by_entry = np.moveaxis(moments, 0, -1)                   # (moment, grid, replicate)
    return first_unknown(by_entry, [rhs[..., i].T for i in range(rhs.shape[-1])]).T[valid]


def first_unknown(moments: np.ndarray, rhs: Sequence[np.ndarray]) -> np.ndarray:
    """The first unknown x_0 of many symmetric positive definite Hankel
    systems sum_j moments[i + j] x_j = rhs[i] (i, j < n = len(rhs)), by
    eliminating the unknowns from the last up (symmetric pivots, stable for
    such matrices; the lower triangle only), every matrix entry one array
    of all the systems: a LAPACK solve per system costs a microsecond of
    call each, and its floats differ in their last bits with what else is
    solved.

    Parameters
    ----------
    moments : numpy.ndarray
        The 2 n - 1 moment arrays along its first axis, each of the
        systems' shape.
    rhs : sequence of numpy.ndarray
        The n right-hand sides, each broadcasting against a moment array
        (a leading axis of its own solves several right-hand sides at once).

    Returns
    -------
    numpy.ndarray
        x_0 of every system (a singular one gives inf or nan).

    Examples
    --------
    >>> m = np.array([[2.0], [0.0], [2.0]])                         # two samples at u = -1, 1
    >>> first_unknown(m, [np.array([4.0]), np.array([2.0])])          # values 1 and 3: level 2
    array([2.])
    """
    n = len(rhs)
    a = {(i, j): np.array(moments[i + j], float) for i in range(n) for j in range(i + 1)}
    b = [np.array(r, float) for r in rhs]
    with np.errstate(divide="ignore", invalid="ignore"):
        for k in range(n - 1, 0, -1):
            inverse = 1.0 / a[k, k]
            for i in range(k):
                factor = a[k, i] * inverse
                for j in range(i + 1):
                    a[i, j] -= factor * a[k, j]
                b[i] -= factor * b[k]
        return b[0] / a[0, 0]
