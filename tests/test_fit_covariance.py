"""The fit's covariance: made block by block for many edges, the whole
normal matrix's pseudo-inverse for a few."""
import numpy as np
from scipy import sparse

from imgmtf.estimate.fit.covariance import parameter_covariance


def test_the_arrowhead_columns_are_the_whole_inverses():
    """Four stage columns and five edges' three nuisance columns (levels in
    DN scaled 1e3 against the offset, as the fit's are): the stage columns
    of the inverse, made from the blocks, are the whole normal matrix's
    pseudo-inverse's to 1e-9, and scaled by the reduced chi-square above 1
    only."""
    rng = np.random.default_rng(7)
    n, counts = 4, [30, 12, 25, 40, 18]
    jacobian = np.zeros((sum(counts), n + 3 * len(counts)))
    jacobian[:, :n] = rng.normal(size=(sum(counts), n))
    for e, (start, count) in enumerate(zip(np.cumsum([0, *counts[:-1]]), counts)):
        jacobian[start:start + count, n + 3 * e:n + 3 * e + 3] = rng.normal(size=(count, 3)) * [1e3, 1e3, 1.0]
    whole = np.linalg.inv(jacobian.T @ jacobian)[:, :n]
    blocks = parameter_covariance(sparse.csr_array(jacobian), 2.5, n, counts)
    assert blocks.shape == (n + 3 * len(counts), n)
    assert np.allclose(blocks, 2.5 * whole, rtol=1e-9, atol=1e-9 * np.abs(whole).max())
    assert np.allclose(parameter_covariance(jacobian, 0.5, n), whole, rtol=1e-9, atol=1e-9 * np.abs(whole).max())
