"""Sparse linear-interpolation designs (imgmtf.estimate.mtf2d.hats): the
dense design's algebra, and the draws' vertices, batched, each exactly
what one at a time gives."""
import numpy as np

from imgmtf.estimate.mtf2d import hats
from imgmtf.estimate.mtf2d.inversion import _hat, _vertex, _vertices


def test_the_sparse_designs_algebra_is_the_dense_designs():
    """Normal matrix, transposed and direct products, touched nodes: those
    of the dense design (:func:`.inversion._hat`'s, row for row), samples
    below, between, on and beyond the nodes."""
    rng = np.random.default_rng(4)
    nodes = np.linspace(0.0, 0.8, 9)
    x = np.concatenate([rng.uniform(-0.1, 0.5, (3, 12)), np.tile(nodes[[0, 2]], (3, 1))], axis=1)
    h = hats.hats(x / (nodes[1] - nodes[0]), nodes.size)
    design = np.array([_hat(row, nodes) for row in x])
    assert np.array_equal(hats.dense(h), design)
    weight, values, solution = rng.uniform(0.5, 2.0, x.shape[1]), rng.normal(size=x.shape), rng.normal(size=(3, 8))
    weighted = design * weight[None, :, None]
    assert np.array_equal(hats.dense(h, np.broadcast_to(weight, x.shape)), weighted)        # W D at once
    assert np.allclose(hats.gram(h, weight), np.transpose(weighted, (0, 2, 1)) @ weighted, rtol=1e-13, atol=1e-13)
    diagonal, beside = hats.gram_bands(h, weight)
    assert np.array_equal(hats.tridiagonal(diagonal, beside), hats.gram(h, weight))
    assert np.array_equal(diagonal, np.diagonal(hats.gram(h, weight), axis1=1, axis2=2))
    assert np.array_equal(beside, np.diagonal(hats.gram(h, weight), offset=1, axis1=1, axis2=2))
    assert np.allclose(hats.transposed(h, values), np.einsum("bsn,bs->bn", design, values), rtol=1e-13, atol=1e-13)
    assert np.allclose(hats.predicted(h, solution), np.einsum("bsn,bn->bs", design, solution), rtol=1e-13,
                       atol=1e-13)
    touched = np.abs(design).sum(axis=1) > 0                   # the unknowns (the nodes after the first)
    assert np.array_equal(hats.last_touched(h), [np.flatnonzero(row).max(initial=-1) + 1 for row in touched])
    assert hats.last_touched(h).max() < nodes.size - 3          # nothing reaches past 0.5 cy/px


def test_the_draws_vertices_are_each_draws_own():
    """Columns with their lowest inside, at either end, tied, flat (no
    curvature): the vectorised vertices bit for bit the one-column rule."""
    trials = np.linspace(-0.3, 0.3, 13) + np.log(0.8)
    rng = np.random.default_rng(5)
    costs = (trials[:, None] - rng.uniform(-0.5, 0.5, 40)) ** 2 + rng.uniform(0, 1e-3, (13, 40))
    costs[:, 0] = 1.0                                          # flat: the first trial
    costs[6:9, 1] = 0.5                                        # a tie
    together = _vertices(trials[None], costs[None])[0]
    assert np.array_equal(together, [_vertex(trials, costs[:, k]) for k in range(costs.shape[1])])

