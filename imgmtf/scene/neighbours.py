"""Which points lie near which, and which pairs link into groups, on NumPy
alone: a grid of square cells as wide as the search radius (each point is
compared with the points of its own cell and the eight around it), and
connected components by label propagation.

They answer what SciPy's k-d tree (``cKDTree.sparse_distance_matrix``,
``query_pairs``) and ``scipy.sparse.csgraph.connected_components`` would,
pair for pair and label for label, without importing SciPy's sparse and
spatial packages (0.2-0.3 s at a scan's start-up, before its first tile).
The cost grows with the points and the pairs found, as a tree's does, for
points spread along lines as a scene's segments are.
"""
from __future__ import annotations

import numpy as np

__all__ = ["close_pairs", "components", "pairs_within"]


def pairs_within(queries: np.ndarray, points: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Every (query, point) index pair at most ``radius`` apart (Euclidean,
    in the points' units), each once, in no particular order.

    Parameters
    ----------
    queries, points : (n, 2) and (m, 2) arrays
        Coordinates, px.
    radius : float
        The largest distance of a pair, px (> 0).

    Returns
    -------
    (i, j) : int arrays
        ``queries[i]`` lies within ``radius`` of ``points[j]``.

    Examples
    --------
    >>> i, j = pairs_within(np.array([[0.0, 0.0], [5.0, 5.0]]), np.array([[0.5, 0.0], [9.0, 9.0]]), 1.0)
    >>> i.tolist(), j.tolist()
    ([0], [0])
    """
    queries = np.asarray(queries, float).reshape(-1, 2)
    points = np.asarray(points, float).reshape(-1, 2)
    if len(queries) == 0 or len(points) == 0:
        return np.zeros(0, np.intp), np.zeros(0, np.intp)
    grid = _Grid(points, radius, np.minimum(queries.min(axis=0), points.min(axis=0)))
    found = [grid.near(queries, dx) for dx in (-1, 0, 1)]
    return np.concatenate([i for i, _ in found]), np.concatenate([j for _, j in found])


def close_pairs(points: np.ndarray, radius: float) -> np.ndarray:
    """Every pair of distinct points at most ``radius`` apart, as rows
    (i, j) with i < j, each once, in no particular order.

    Examples
    --------
    >>> close_pairs(np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 0.5]]), 1.0).tolist()
    [[0, 2]]
    """
    points = np.asarray(points, float).reshape(-1, 2)
    if len(points) < 2:
        return np.zeros((0, 2), np.intp)
    grid = _Grid(points, radius, points.min(axis=0))
    i, j = grid.near(points, 0)         # its own column of cells: each pair seen from both ends
    keep = i < j
    i2, j2 = grid.near(points, 1)       # the next column: each pair seen from its left end only
    i, j = np.concatenate([i[keep], i2]), np.concatenate([j[keep], j2])
    return np.column_stack([np.minimum(i, j), np.maximum(i, j)])


class _Grid:
    """Points binned in square cells ``radius`` wide, sorted by column
    then row: a column's three cells around a row are one run of the
    sorted points."""

    def __init__(self, points: np.ndarray, radius: float, origin: np.ndarray):
        self.points, self.radius, self.origin = points, radius, origin
        cells = self.cells(points)
        self.rows = int(cells[:, 1].max()) + 3          # room for a row either side
        keys = cells[:, 0] * self.rows + cells[:, 1]
        self.order = np.argsort(keys, kind="stable")
        self.keys = keys[self.order]

    def cells(self, xy: np.ndarray) -> np.ndarray:
        return np.floor((xy - self.origin) / self.radius).astype(np.int64) + 1

    def near(self, queries: np.ndarray, dx: int) -> tuple[np.ndarray, np.ndarray]:
        """(query, point) pairs within the radius, of the points in the
        column ``dx`` cells to the right of each query's, in its row and
        the rows either side."""
        cells = self.cells(queries)
        key = (cells[:, 0] + dx) * self.rows + np.minimum(cells[:, 1], self.rows - 2)
        lo = np.searchsorted(self.keys, key - 1, "left")
        counts = np.searchsorted(self.keys, key + 1, "right") - lo
        total = int(counts.sum())
        i = np.repeat(np.arange(len(queries)), counts)
        j = self.order[np.repeat(lo - (np.cumsum(counts) - counts), counts) + np.arange(total)]
        d = queries[i] - self.points[j]
        near = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] <= self.radius * self.radius
        return i[near], j[near]


def components(n: int, a: np.ndarray, b: np.ndarray) -> tuple[int, np.ndarray]:
    """The connected components of the undirected graph of ``n`` nodes and
    edges (a[k], b[k]): their count and each node's label, components
    numbered from 0 in the order of their lowest node (as SciPy's
    ``connected_components`` numbers them).

    Examples
    --------
    >>> count, label = components(5, np.array([3, 1]), np.array([4, 3]))
    >>> count, label.tolist()
    (3, [0, 1, 2, 1, 1])
    """
    a = np.asarray(a, np.intp).ravel()
    b = np.asarray(b, np.intp).ravel()
    label = np.arange(n)
    while True:
        # each edge pulls both its ends to the lower of their labels, then labels jump to their
        # label's label: the lowest node of a component spreads to all of it in a few rounds
        low = np.minimum(label[a], label[b])
        before = label.copy()
        np.minimum.at(label, a, low)
        np.minimum.at(label, b, low)
        while True:
            jumped = label[label]
            if np.array_equal(jumped, label):
                break
            label = jumped
        if np.array_equal(label, before):
            break
    roots, label = np.unique(label, return_inverse=True)
    return len(roots), label.reshape(-1)
