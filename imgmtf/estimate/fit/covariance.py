"""The fitted parameters' covariance from the weighted Jacobian of the
residuals.

The fit's parameters are the shared stage coordinates (the first
``n_free``) and three nuisance parameters per edge (its levels and offset),
which act on that edge's bins only.  What the fit asks of the covariance is
its stage columns: the stage parameters' own block (their standard errors,
correlations and the model's MTF band) and how every parameter moves with
a stage parameter held (:meth:`.model.Model.hold`).  With a few edges the
normal matrix is inverted whole; with many, its arrowhead structure is
used: the nuisance blocks (3 x 3 per edge) inverted one by one, the stage
block through their Schur complement, so the cost grows with the edges,
where the whole inverse's grew with their cube (a 1936-edge chart's normal
matrix is 5812 x 5812).
"""
from __future__ import annotations

import numpy as np

from .arrowhead import normal_blocks, split_columns


def parameter_covariance(jacobian, reduced_chi_square: float, n_free: int | None = None,
                         counts: list[int] | None = None) -> np.ndarray:
    """The covariance's stage columns from the weighted (sparse) Jacobian,
    scaled up by the reduced chi-square when the residuals exceed the noise
    (never down: on noise-free integer chips the noise is the
    quantisation's, 1/sqrt(12) DN, which flat plateaus do not show).

    Parameters
    ----------
    jacobian : numpy.ndarray or scipy.sparse array, shape (rows, n_free + 3 edges)
        The weighted residuals' Jacobian: the stage columns, then each
        edge's three nuisance columns, which act on its own rows only.
    reduced_chi_square : float
        The scale (taken at least 1).
    n_free : int, optional
        The stage columns (default: all columns, the whole covariance).
    counts : list of int, optional
        Each edge's rows, in turn.  Given with ``n_free`` and a sparse
        Jacobian, the covariance is made block by block
        (:func:`arrowhead_columns`); else by inverting the normal matrix
        whole (its pseudo-inverse).

    Returns
    -------
    numpy.ndarray, shape (n_free + 3 edges, n_free)
        The covariance's first ``n_free`` columns (all of it without ``n_free``).

    Examples
    --------
    One stage column and one edge's three, on four rows:

    >>> j = np.array([[1.0, 1.0, 0.0, 0.0], [1.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 1.0], [2.0, 1.0, 1.0, 1.0]])
    >>> parameter_covariance(j, 1.0, 1).round(3).ravel().tolist()
    [4.0, -3.0, -3.0, -3.0]
    >>> from scipy import sparse
    >>> parameter_covariance(sparse.csr_array(j), 1.0, 1, [4]).round(3).ravel().tolist()
    [4.0, -3.0, -3.0, -3.0]
    """
    scale = max(reduced_chi_square, 1.0)
    columns = jacobian.shape[1] if n_free is None else n_free
    if counts is not None and hasattr(jacobian, "tocoo") and columns == jacobian.shape[1] - 3 * len(counts):
        return arrowhead_columns(jacobian, columns, counts) * scale
    normal = jacobian.T @ jacobian
    whole = np.linalg.pinv(normal.toarray() if hasattr(normal, "toarray") else normal)
    return whole[:, :columns] * scale


def arrowhead_columns(jacobian, n_free: int, counts: list[int]) -> np.ndarray:
    """The first ``n_free`` columns of the inverse normal matrix of a
    Jacobian whose last columns come in threes, each acting on one block
    of ``counts`` rows only: with A the stage columns, B_e edge e's three
    (on its rows), P = A'A, Q_e = A_e'B_e and D_e = B_e'B_e, the stage
    block is S^+ with S = P - sum Q_e D_e^+ Q_e', and edge e's rows of
    those columns are -D_e^+ Q_e' S^+ (the inverse of the blocks, equal to
    the whole's pseudo-inverse when the normal matrix is regular)."""
    blocks = normal_blocks(*split_columns(jacobian, n_free, counts), counts)
    q, d = blocks.q, blocks.d
    d_inverse = np.linalg.pinv(d)
    qd = q @ d_inverse                                                                     # Q_e D_e^+
    schur = blocks.p - np.einsum("eij,ekj->ik", qd, q)
    s_inverse = np.linalg.pinv(schur)
    below = -np.einsum("eij,ik->ejk", qd, s_inverse).reshape(-1, n_free)                  # -D_e^+ Q_e' S^+
    return np.vstack([s_inverse, below])
