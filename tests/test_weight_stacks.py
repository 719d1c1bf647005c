"""The local polynomial under a stack of weightings, summed per group of
equally weighted samples and solved by elimination, equals each weighting
fitted alone."""
import numpy as np
import pytest

from imgmtf.estimate.resampling import local_polynomial
from imgmtf.estimate.weight_stacks import first_levels, weight_groups


@pytest.mark.parametrize("per_row", [True, False])
def test_a_stack_of_weightings_fits_as_each_weighting_alone(per_row):
    rng = np.random.default_rng(3)
    rows = np.repeat(np.arange(25), 40)
    d = rng.uniform(-5, 5, rows.size)
    v = np.tanh(d / 0.7) + rng.normal(0, 0.01, d.size)
    if per_row:     # a bootstrap's draws of rows: few groups, summed per group
        stack = rng.multinomial(25, np.full(25, 1 / 25), size=20).astype(float)[:, rows]
    else:           # a weight of its own for every sample: the per-bin sums correlated
        stack = rng.uniform(0.5, 2.0, (20, rows.size))
    assert (weight_groups(stack, 84) is not None) == per_row
    stacked = local_polynomial(d, v, 0.05, 4.0, weights=stack)
    for r in (0, 7, 19):
        alone = local_polynomial(d, v, 0.05, 4.0, weights=stack[r])
        np.testing.assert_allclose(stacked.values[r], alone.values, rtol=0, atol=1e-11, equal_nan=True)


def test_weight_groups_are_exact_or_refused():
    w = np.array([[1.0, 2.0, 1.0, 0.0], [3.0, 0.0, 3.0, 1.0]])
    columns, group = weight_groups(w, 3)
    np.testing.assert_array_equal(columns[:, group], w)
    assert columns.shape == (2, 3)
    assert weight_groups(w, 2) is None
    assert weight_groups(np.random.default_rng(0).uniform(size=(3, 50)), 49) is None


def test_first_levels_solve_positive_definite_systems():
    rng = np.random.default_rng(4)
    u = rng.uniform(-1, 1, (2, 3, 30))                         # 2 x 3 windows of 30 samples
    moments = np.stack([(u ** k).sum(-1) for k in range(9)], axis=1)                   # (2, 9, 3)
    values = rng.normal(size=u.shape)
    rhs = np.stack([(u ** k * values).sum(-1) for k in range(5)], axis=-1)              # (2, 3, 5)
    valid = np.array([[True, False, True], [True, True, True]])
    normal = moments[:, np.arange(5)[:, None] + np.arange(5)[None, :], :].transpose(0, 3, 1, 2)
    expected = np.linalg.solve(normal[valid], rhs[valid][..., None])[:, 0, 0]
    np.testing.assert_allclose(first_levels(moments, rhs, valid), expected, rtol=1e-10)
