"""Least squares over an arrowhead Jacobian: a few shared (stage) columns
and three nuisance columns per edge acting on that edge's rows only.

The normal matrix of such a Jacobian J = [A | B_1 .. B_E] is

    [ P    Q_1 .. Q_E ]        P = A'A (n x n), Q_e = A_e'B_e (n x 3),
    [ Q_e'  D_e       ]        D_e = B_e'B_e (3 x 3, one per edge),

so a damped Gauss-Newton (Levenberg-Marquardt) step is solved exactly by
eliminating each edge's block: the shared step from the Schur complement
S = P - sum_e Q_e D_e^-1 Q_e' (n x n), then each edge's from its own
3 x 3 system.  Forming the blocks is one pass over the Jacobian's values
and each step costs O(E) small solves: linear in the edges, where an
iterative solver's (LSMR's) sparse products were a few hundred passes.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

#: values (8 bytes each) of one zero-padded stack of edges' columns in :func:`normal_blocks`
STACK_VALUES = 1 << 22
#: the damping (relative to the columns' squared norms) at which a solve that finds no lower cost gives up
MAX_DAMPING = 1e20

@dataclass(frozen=True)
class NormalBlocks:
    """An arrowhead Jacobian's normal matrix and gradient, by blocks.

    Attributes
    ----------
    p : numpy.ndarray, shape (n, n)
        The shared columns' normal block A'A.
    q : numpy.ndarray, shape (edges, n, 3)
        Each edge's coupling A_e'B_e.
    d : numpy.ndarray, shape (edges, 3, 3)
        Each edge's own block B_e'B_e.
    g : numpy.ndarray, shape (n + 3 edges,)
        The gradient J'r of half the residuals' sum of squares (zeros when
        no residuals were given).
    """

    p: np.ndarray
    q: np.ndarray
    d: np.ndarray
    g: np.ndarray

    @property
    def diagonal(self) -> np.ndarray:
        """The normal matrix's diagonal (the columns' squared norms), in the parameters' order."""
        return np.concatenate([np.diag(self.p), np.diagonal(self.d, axis1=1, axis2=2).ravel()])


def split_columns(jacobian, n_free: int, counts: list[int],
                  layout: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The shared columns A (rows, n_free) and each row's own edge's three
    columns B (rows, 3) of an arrowhead Jacobian, dense or sparse.  A
    compressed-row Jacobian laid out as :meth:`.model.Model.jacobian`
    writes it (each row's shared columns, then its edge's three) is read
    in place: without checking its column indices when they are
    ``layout``'s own memory (the model's, :meth:`.model.Model._jacobian_layout`)."""
    rows = jacobian.shape[0]
    width = n_free + 3
    if hasattr(jacobian, "indices") and getattr(jacobian, "format", "") == "csr" and jacobian.nnz == rows * width:
        indices = np.asarray(jacobian.indices).reshape(rows, width)
        if layout is not None and layout.size == indices.size and np.may_share_memory(layout, indices):
            values = np.asarray(jacobian.data).reshape(rows, width)
            return values[:, :n_free], values[:, n_free:]
        edge = np.repeat(np.arange(len(counts)), counts)
        if (np.array_equal(indices[:, :n_free], np.broadcast_to(np.arange(n_free), (rows, n_free)))
                and np.array_equal(indices[:, n_free:], (n_free + 3 * edge)[:, None] + np.arange(3))):
            values = np.asarray(jacobian.data).reshape(rows, width)
            return values[:, :n_free], values[:, n_free:]
    dense = jacobian.toarray() if hasattr(jacobian, "toarray") else np.asarray(jacobian)
    edge = np.repeat(np.arange(len(counts)), counts)
    own = (n_free + 3 * edge)[:, None] + np.arange(3)
    return dense[:, :n_free], np.take_along_axis(dense, own, axis=1)


def normal_blocks(a: np.ndarray, b: np.ndarray, counts: list[int], residuals: np.ndarray | None = None) -> NormalBlocks:
    """The normal matrix's blocks and the gradient of the Jacobian whose
    shared columns are ``a`` and whose rows' own edge's columns are ``b``
    (:func:`split_columns`), edges of ``counts`` rows in turn: each edge's
    rows [a, b, residuals] laid in a zero-padded stack and their Gram
    matrices made in one batched product.

    Examples
    --------
    >>> a = np.array([[1.0], [1.0], [2.0]])
    >>> b = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 1.0]])
    >>> blocks = normal_blocks(a, b, [3], np.ones(3))
    >>> blocks.p.tolist(), blocks.q[0].tolist(), blocks.g.tolist()
    ([[6.0]], [[3.0, 3.0, 2.0]], [4.0, 2.0, 2.0, 1.0])
    """
    n = a.shape[1]
    counts_array = np.asarray(counts)
    columns = [a[:, k] for k in range(n)] + [b[:, k] for k in range(3)] + ([residuals] if residuals is not None else [])
    ends = np.cumsum(counts_array)
    starts = ends - counts_array
    gram = np.zeros((len(counts), n + 4, n + 4))
    # a few million values a stack, so a scene's edges take a few stacks and one long edge does not pad all
    per_stack = max(1, STACK_VALUES // (int(counts_array.max()) * (n + 4)))
    for first in range(0, len(counts), per_stack):
        last = min(first + per_stack, len(counts))
        here = counts_array[first:last]
        longest = int(here.max())
        # each edge's columns as rows of an (edges, n + 4, longest) stack: column by column, a boolean
        # mask's contiguous writes (a row-wise scatter of the same values costs three times more)
        stacked = np.zeros((last - first, n + 4, longest))
        inside = np.arange(longest) < here[:, None]
        rows = slice(starts[first], ends[last - 1])
        for k, column in enumerate(columns):
            stacked[:, k, :][inside] = column[rows]
        gram[first:last] = np.matmul(stacked, stacked.transpose(0, 2, 1))
    p = gram[:, :n, :n].sum(axis=0)
    q = np.ascontiguousarray(gram[:, :n, n: n + 3])
    d = np.ascontiguousarray(gram[:, n: n + 3, n: n + 3])
    g = np.concatenate([gram[:, :n, n + 3].sum(axis=0), gram[:, n: n + 3, n + 3].ravel()])
    return NormalBlocks(p, q, d, g)


def _inverse3(d: np.ndarray) -> np.ndarray:
    """Each 3 x 3 block's inverse (its pseudo-inverse where it is singular:
    an edge whose levels are equal leaves its offset's column zero)."""
    try:
        out = np.linalg.inv(d)
        if np.all(np.isfinite(out)):
            return out
    except np.linalg.LinAlgError:
        pass
    return np.linalg.pinv(d)


def damped_step(blocks: NormalBlocks, damping: np.ndarray | float = 0.0,
                fixed: np.ndarray | None = None) -> np.ndarray:
    """The step s solving (J'J + diag(damping)) s = -J'r exactly, by the
    Schur complement of the edges' blocks; shared parameters ``fixed``
    (a boolean mask over them: those held at a bound) do not move.

    Parameters
    ----------
    blocks : NormalBlocks
        The normal matrix and gradient (:func:`normal_blocks`).
    damping : float or numpy.ndarray, shape (n + 3 edges,)
        Added to the normal matrix's diagonal.
    fixed : numpy.ndarray of bool, shape (n,), optional
        Shared parameters that stay where they are.

    Returns
    -------
    numpy.ndarray, shape (n + 3 edges,)
        The step, in the parameters' order.

    Examples
    --------
    >>> a = np.array([[1.0], [1.0], [2.0], [0.5]])
    >>> b = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 1.0], [0.0, 0.0, 1.0]])
    >>> j = np.hstack([a, b]); r = np.array([1.0, -2.0, 0.5, 3.0])
    >>> s = damped_step(normal_blocks(a, b, [4], r))
    >>> bool(np.allclose(s, -np.linalg.solve(j.T @ j, j.T @ r)))
    True
    """
    n = blocks.p.shape[0]
    edges = blocks.d.shape[0]
    damping = np.broadcast_to(np.asarray(damping, float), (n + 3 * edges,))
    own = blocks.d + damping[n:].reshape(edges, 3)[:, :, None] * np.eye(3)
    inverse = _inverse3(own)
    g_u, g_e = blocks.g[:n], blocks.g[n:].reshape(edges, 3)
    qd = blocks.q @ inverse                                              # Q_e D_e^-1, (edges, n, 3)
    schur = blocks.p + np.diag(damping[:n]) - np.einsum("eij,ekj->ik", qd, blocks.q)
    right = -g_u + np.einsum("eij,ej->i", qd, g_e)
    step_u = np.zeros(n)
    free = np.ones(n, bool) if fixed is None else ~np.asarray(fixed, bool)
    if free.any():
        kept = schur[np.ix_(free, free)]
        try:
            step_u[free] = np.linalg.solve(kept, right[free])
        except np.linalg.LinAlgError:
            step_u[free] = np.linalg.lstsq(kept, right[free], rcond=None)[0]
    step_e = -np.einsum("eij,ej->ei", inverse, g_e + np.einsum("eij,i->ej", blocks.q, step_u))
    return np.concatenate([step_u, step_e.ravel()])


def product(a: np.ndarray, b: np.ndarray, counts: list[int], step: np.ndarray) -> np.ndarray:
    """J s for the arrowhead Jacobian (``a``, ``b``: :func:`split_columns`)."""
    n = a.shape[1]
    own = np.repeat(step[n:].reshape(-1, 3), counts, axis=0)
    return a @ step[:n] + np.einsum("ij,ij->i", b, own)


class NoConvergence(Exception):
    """The solve ran out of residual evaluations."""


def solve_arrowhead(residuals: Callable[[np.ndarray], np.ndarray], jacobian: Callable[[np.ndarray], object],
                    z: np.ndarray, n_free: int, counts: list[int], lower: np.ndarray, upper: np.ndarray,
                    max_evaluations: int = 200, tolerance: float = 1e-12, layout: np.ndarray | None = None,
                    ftol: float | None = None):
    """Bounded nonlinear least squares over an arrowhead Jacobian by
    Levenberg-Marquardt steps solved exactly (:func:`damped_step`), the
    damping scaled by the columns' largest squared norms so far
    (Marquardt's, as SciPy's ``x_scale="jac"`` scales them).  A step
    leaving the bounds (the shared parameters' only) is cut back to them,
    and a parameter at a bound that the gradient pushes out of it stays
    there.  It stops where the full Gauss-Newton step would lower half
    the sum of squares by less than ``tolerance`` times it: a thousandth of
    SciPy's ``ftol=1e-9`` on the last step's reduction, and on the
    prediction at the last point rather than the reduction of the step
    that led there.

    ``layout`` is the compressed-row Jacobian's column indices, when known
    (:func:`split_columns`).  With ``ftol`` it also stops, as SciPy's
    ``least_squares`` does, after an accepted step that lowered half the
    sum of squares by less than ``ftol`` times it (the Jacobian then
    evaluated at the new point): a few edges' fits, whose last steps at
    the 1e-12 criterion were mostly rejected at rounding level.

    Returns
    -------
    z, jacobian
        The solution and the Jacobian there (the last one evaluated).

    Raises
    ------
    NoConvergence
        Not converged within ``max_evaluations`` residual evaluations, no
        step lowering the cost, or residuals not finite at the start.
    """
    z = np.clip(np.asarray(z, float), lower, upper)
    r = residuals(z)
    evaluations = 1
    cost = 0.5 * float(r @ r)
    if not np.isfinite(cost):
        raise NoConvergence("the residuals are not finite at the start")
    jac = jacobian(z)
    scale = np.zeros(z.size)
    damping, growth = 1e-3, 2.0
    while True:
        a, b = split_columns(jac, n_free, counts, layout)
        blocks = normal_blocks(a, b, counts, r)
        scale = np.maximum(scale, blocks.diagonal)
        u, g_u = z[:n_free], blocks.g[:n_free]
        fixed = ((u <= lower[:n_free]) & (g_u > 0)) | ((u >= upper[:n_free]) & (g_u < 0))
        newton = damped_step(blocks, 0.0, fixed)

        if -0.5 * float(blocks.g @ newton) <= tolerance * cost:
            return z, jac
        while True:
            step = damped_step(blocks, damping * scale, fixed)
            trial = np.clip(z + step, lower, upper)
            step = trial - z
            model_change = product(a, b, counts, step)
            predicted = -float(blocks.g @ step) - 0.5 * float(model_change @ model_change)
            if evaluations >= max_evaluations:
                raise NoConvergence(f"no convergence in {max_evaluations} evaluations")
            r_trial = residuals(trial)
            evaluations += 1
            cost_trial = 0.5 * float(r_trial @ r_trial) if np.all(np.isfinite(r_trial)) else np.inf
            actual = cost - cost_trial
            if actual > 0:
                ratio = actual / predicted if predicted > 0 else 0.0
                damping *= max(1 / 3, 1 - (2 * ratio - 1) ** 3) if ratio > 0 else growth
                growth = 2.0
                break
            if predicted <= tolerance * cost * 1e-3 and cost_trial - cost <= 1e-12 * cost:
                return z, jac                 # no step can lower the cost within rounding
            damping *= growth
            growth *= 2.0
            if damping > MAX_DAMPING:                     # no step lowers the cost: nowhere to go
                raise NoConvergence("no step lowers the cost")
        settled = ftol is not None and actual <= ftol * cost
        z, r, cost = trial, r_trial, cost_trial
        jac = jacobian(z)
        if settled:
            return z, jac
