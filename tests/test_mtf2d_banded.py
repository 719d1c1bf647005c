"""Banded solves of many pentadiagonal systems (imgmtf.estimate.mtf2d.banded):
the dense solver's answers, and the elliptical inversion's normal matrices
solved either way alike."""
import numpy as np

from imgmtf.estimate.mtf2d import hats
from imgmtf.estimate.mtf2d.banded import solve_pentadiagonal
from imgmtf.estimate.mtf2d.inversion import EllipticalProblem, _one, _penalty, prepared


def dense(diagonal, first, second):
    n = diagonal.shape[1]
    k = np.arange(n)
    out = np.zeros((diagonal.shape[0], n, n))
    out[:, k, k] = diagonal
    out[:, k[:-1], k[1:]] = out[:, k[1:], k[:-1]] = first
    out[:, k[:-2], k[2:]] = out[:, k[2:], k[:-2]] = second
    return out


def test_many_systems_and_right_hand_sides_solved_as_dense_ones():
    """Random positive definite bands (diagonally dominant), one and k
    right-hand sides, sizes down to the smallest the bands allow."""
    rng = np.random.default_rng(7)
    for n in (3, 5, 32):
        first, second = rng.normal(size=(6, n - 1)), rng.normal(size=(6, n - 2))
        diagonal = 5.0 + rng.uniform(0, 1, (6, n))
        matrices = dense(diagonal, first, second)
        one, many = rng.normal(size=(6, n)), rng.normal(size=(6, n, 4))
        assert np.allclose(solve_pentadiagonal(diagonal, first, second, one),
                           np.linalg.solve(matrices, one[:, :, None])[:, :, 0], rtol=1e-12, atol=1e-12)
        assert np.allclose(solve_pentadiagonal(diagonal, first, second, many), np.linalg.solve(matrices, many),
                           rtol=1e-12, atol=1e-12)


def test_the_inversions_normal_matrices_solved_by_bands_as_dense():
    """A hundred aspects' normal matrices of measured-like sections (the
    draws' case, solved by bands) against the dense matrices solved."""
    f = np.linspace(0.0, 1.0, 101)
    theta = np.radians([16.8, -73.2])
    m = np.array([np.sinc(f * abs(np.cos(t))) * np.sinc(f * abs(np.sin(t))) * np.exp(-1.5 * f) for t in theta])
    problem = EllipticalProblem(*_one(prepared(np.degrees(theta), f, m, 0.01 * f[None] / 0.5)))
    _, h = problem._stacked(np.linspace(-0.4, 0.4, 50)[None])
    weight = problem._each(50)
    normal = hats.gram(h, weight) + _penalty(1, h.size) + 1e-10 * np.eye(h.size - 1)
    assert np.array_equal(dense(*problem._bands(h, weight)), normal)
    targets = problem.log_r + np.random.default_rng(8).normal(0, 0.01, (h.low.shape[0], problem.log_r.shape[1]))
    rhs = hats.transposed(h, weight * (targets * weight))
    assert np.allclose(problem._solved(h, weight, targets), np.linalg.solve(normal, rhs[:, :, None])[:, :, 0],
                       rtol=1e-10, atol=1e-12)
