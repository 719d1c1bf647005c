"""Linear interpolation on uniform nodes as a least-squares design, kept
sparse: each sample touches two neighbouring nodes (``low`` with weight
1 - ``frac``, ``low + 1`` with ``frac``), so its normal matrix is
tridiagonal and its products with one right-hand side are sums over the
samples (:func:`numpy.bincount`), not products with a dense
samples x nodes matrix of which all but two columns are zero.

The elliptical inversion (:mod:`.inversion`) solves such designs for many
aspects and draws per target; dense, their normal matrices were most of a
dense chart's section time.  Every array has leading batch axes (aspects,
draws); the first node (log 1 = 0, fixed) is dropped from the unknowns,
as :func:`.inversion._hat` drops it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Hats:
    """Samples' linear-interpolation weights on ``size`` uniform nodes.

    Attributes
    ----------
    low : numpy.ndarray of int
        (batch, samples): the node at or below each sample, 0 to size - 2.
    frac : numpy.ndarray
        (batch, samples): the weight of node ``low + 1`` (``low``'s is
        1 - frac).
    size : int
        Nodes, the first fixed (not an unknown).
    flat : numpy.ndarray of int
        (batch x samples,): ``low`` as an index into the batch's rows of
        nodes laid end to end (their sums by node are one
        :func:`numpy.bincount`; made once here, not by each sum: making it
        was five sixths of a sum's time).
    """

    low: np.ndarray
    frac: np.ndarray
    size: int
    flat: np.ndarray


def hats(position: np.ndarray, size: int) -> Hats:
    """The weights of samples at ``position`` (batch, samples; in node
    steps from the first node) on ``size`` nodes, clipped to them exactly
    as :func:`.inversion._hat` clips.

    Examples
    --------
    >>> h = hats(np.array([[0.25, 1.5, 9.0]]), 3)
    >>> h.low.tolist(), h.frac.tolist()
    ([[0, 1, 1]], [[0.25, 0.5, 1.0]])
    """
    position = np.clip(position, 0, size - 1)
    low = np.minimum(np.floor(position).astype(int), size - 2)
    return Hats(low, position - low, size, (low + size * np.arange(low.shape[0])[:, None]).ravel())


def dense(h: Hats, weight: np.ndarray | None = None) -> np.ndarray:
    """The design (batch, samples, size - 1), the first node dropped: for
    products with many right-hand sides at once (BLAS does those best);
    with ``weight`` (batch, samples), each sample's row times its weight
    (W D, the same numbers as the product, without a pass over the zeros).

    Examples
    --------
    >>> dense(hats(np.array([[0.25, 1.5]]), 3)).tolist()
    [[[0.25, 0.0], [0.5, 0.5]]]
    >>> dense(hats(np.array([[0.25, 1.5]]), 3), np.array([[2.0, 4.0]])).tolist()
    [[[0.5, 0.0], [2.0, 2.0]]]
    """
    batch, samples = h.low.shape
    out = np.zeros((batch, samples, h.size))
    lower, upper = 1.0 - h.frac, h.frac
    if weight is not None:
        lower, upper = lower * weight, upper * weight
    # by flat indices into the rows of nodes: a third of the time of indexing by (batch, sample, node)
    flat, at = out.reshape(-1, h.size), np.arange(batch * samples)
    flat[at, h.low.ravel()] = lower.ravel()
    flat[at, h.low.ravel() + 1] = upper.ravel()
    return out[:, :, 1:]


def gram(h: Hats, weight: np.ndarray) -> np.ndarray:
    """The weighted normal matrix D^T W^2 D of each batch's design
    (batch, size - 1, size - 1): tridiagonal, from the samples' two
    weights each.

    Examples
    --------
    >>> h = hats(np.array([[0.25, 1.5]]), 3)
    >>> bool(np.allclose(gram(h, np.ones(2))[0], dense(h)[0].T @ dense(h)[0]))
    True
    """
    return tridiagonal(*gram_bands(h, weight))


def tridiagonal(diagonal: np.ndarray, beside: np.ndarray) -> np.ndarray:
    """The symmetric matrices (batch, n, n) of bands ``diagonal`` (batch,
    n) and ``beside`` (batch, n - 1): :func:`gram` of its
    :func:`gram_bands`, when those are wanted too.

    Examples
    --------
    >>> tridiagonal(np.array([[2.0, 3.0]]), np.array([[1.0]])).tolist()
    [[[2.0, 1.0], [1.0, 3.0]]]
    """
    batch, nodes = diagonal.shape
    out = np.zeros((batch, nodes, nodes))
    k = np.arange(nodes)
    out[:, k, k] = diagonal
    out[:, k[:-1], k[1:]] = beside
    out[:, k[1:], k[:-1]] = beside
    return out


def gram_bands(h: Hats, weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`gram`'s two bands, its diagonal (batch, size - 1) and the
    one beside it (batch, size - 2), without the matrix.

    Examples
    --------
    >>> h = hats(np.array([[0.25, 1.5]]), 3)
    >>> diagonal, beside = gram_bands(h, np.ones(2))
    >>> bool(np.array_equal(diagonal, np.diagonal(gram(h, np.ones(2)), axis1=1, axis2=2)))
    True
    """
    diagonal, beside = _gram_bands(h, weight)
    return diagonal[:, 1:], beside[:, 1:]


def _gram_bands(h: Hats, weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Gram matrix's bands with the first node: (batch, size), (batch, size - 1)."""
    lower, upper = weight * (1.0 - h.frac), weight * h.frac
    diagonal = _scatter(h, lower * lower) + _scatter(h, upper * upper, 1)
    return diagonal, _scatter(h, lower * upper)[:, :-1]


def transposed(h: Hats, values: np.ndarray) -> np.ndarray:
    """D^T ``values`` for one right-hand side per batch (batch, samples):
    (batch, size - 1).

    Examples
    --------
    >>> h = hats(np.array([[0.25, 1.5]]), 3)
    >>> transposed(h, np.array([[2.0, 4.0]])).tolist()
    [[2.5, 2.0]]
    """
    return (_scatter(h, (1.0 - h.frac) * values) + _scatter(h, h.frac * values, 1))[:, 1:]


def predicted(h: Hats, solution: np.ndarray) -> np.ndarray:
    """D ``solution`` for one solution per batch (batch, size - 1; the
    first node 0): each sample's interpolated value, (batch, samples).

    Examples
    --------
    >>> predicted(hats(np.array([[0.25, 1.5]]), 3), np.array([[2.0, 4.0]])).tolist()
    [[0.5, 3.0]]
    """
    full = np.concatenate([np.zeros((solution.shape[0], 1)), solution], axis=1)
    return (1.0 - h.frac) * np.take_along_axis(full, h.low, axis=1) + h.frac * np.take_along_axis(full, h.low + 1,
                                                                                                  axis=1)


def last_touched(h: Hats) -> np.ndarray:
    """The last node any sample weighs on (batch,), counted from the first
    (0: none beyond it), as a dense design's non-zero columns say: a
    sample weighs on ``low`` (1 - frac > 0 but at the last node) and on
    ``low + 1`` where frac > 0.

    Examples
    --------
    >>> last_touched(hats(np.array([[0.0, 1.0], [0.5, 0.0], [0.0, 0.0]]), 4)).tolist()
    [1, 1, 0]
    """
    return np.max(h.low + (h.frac != 0), axis=1, initial=0)


def _scatter(h: Hats, values: np.ndarray, above: int = 0) -> np.ndarray:
    """Sums of ``values`` (batch, samples) by node ``low + above`` (0 or
    1): (batch, size)."""
    batch = h.low.shape[0]
    return np.bincount(h.flat + above if above else h.flat, weights=np.broadcast_to(values, h.low.shape).ravel(),
                       minlength=batch * h.size).reshape(batch, h.size)
