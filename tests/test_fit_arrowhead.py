"""The arrowhead solve: its blocks and steps are the dense normal
equations', and its bounded Levenberg-Marquardt reaches SciPy's optimum."""
import numpy as np
import pytest
from scipy import sparse
from scipy.optimize import least_squares
from scipy.special import erf

from imgmtf.estimate.fit.arrowhead import (
    NoConvergence,
    damped_step,
    normal_blocks,
    product,
    solve_arrowhead,
    split_columns,
)


def arrowhead(rng, n, counts):
    """A dense arrowhead Jacobian (nuisance columns scaled as the fit's) and
    the compressed-row one laid out as the model writes it."""
    rows = sum(counts)
    jacobian = np.zeros((rows, n + 3 * len(counts)))
    jacobian[:, :n] = rng.normal(size=(rows, n))
    edge = np.repeat(np.arange(len(counts)), counts)
    own = (n + 3 * edge)[:, None] + np.arange(3)
    values = rng.normal(size=(rows, 3)) * [1e3, 1e3, 1.0]
    np.put_along_axis(jacobian, own, values, axis=1)
    indices = np.hstack([np.broadcast_to(np.arange(n), (rows, n)), own]).astype(np.int32)
    data = np.hstack([jacobian[:, :n], values])
    laid_out = sparse.csr_array((data.ravel(), indices.ravel(), np.arange(0, data.size + 1, n + 3)),
                                shape=jacobian.shape)
    return jacobian, laid_out


def test_the_structured_step_is_the_dense_normal_equations_step():
    """Three stage columns and six edges of 7-40 rows: the blocks are J'J's
    and J'r's, and the step, damped or not and with a stage parameter
    fixed, solves the dense system to 1e-12 (relative)."""
    rng = np.random.default_rng(3)
    n, counts = 3, [7, 40, 12, 25, 9, 31]
    jacobian, laid_out = arrowhead(rng, n, counts)
    r = rng.normal(size=jacobian.shape[0])
    a, b = split_columns(laid_out, n, counts)
    assert np.shares_memory(a, laid_out.data)                     # read in place, not copied
    np.testing.assert_array_equal(np.hstack([a, b]), np.hstack(split_columns(jacobian, n, counts)))
    blocks = normal_blocks(a, b, counts, r)
    normal, gradient = jacobian.T @ jacobian, jacobian.T @ r
    np.testing.assert_allclose(blocks.g, gradient, rtol=1e-12, atol=1e-12 * np.abs(gradient).max())
    np.testing.assert_allclose(blocks.diagonal, np.diag(normal), rtol=1e-12)
    np.testing.assert_allclose(product(a, b, counts, gradient), jacobian @ gradient, rtol=1e-12,
                               atol=1e-12 * np.abs(jacobian @ gradient).max())
    damping = 1e-3 * np.diag(normal)
    for damped in (np.zeros(normal.shape[0]), damping):
        exact = -np.linalg.solve(normal + np.diag(damped), gradient)
        step = damped_step(blocks, damped)
        np.testing.assert_allclose(step, exact, rtol=1e-12, atol=1e-12 * np.abs(exact).max())
    keep = np.arange(normal.shape[0]) != 1                        # stage parameter 1 fixed
    exact = np.zeros(normal.shape[0])
    exact[keep] = -np.linalg.solve((normal + np.diag(damping))[np.ix_(keep, keep)], gradient[keep])
    step = damped_step(blocks, damping, np.array([False, True, False]))
    np.testing.assert_allclose(step, exact, rtol=1e-12, atol=1e-12 * np.abs(exact).max())


def edges_problem(width_upper=np.inf):
    """Five noisy blurred edges sharing two widths (one per half of them),
    each with its own levels and offset: residuals and an arrowhead
    Jacobian in the model's layout."""
    rng = np.random.default_rng(11)
    counts = [60, 45, 80, 50, 70]
    x = [np.sort(rng.uniform(-4, 4, c)) for c in counts]
    truth = [(10.0 + e, 200.0 - 3 * e, 0.1 * e - 0.2) for e in range(5)]
    widths = np.array([0.8, 1.3])
    which = [0, 1, 0, 1, 1]
    y = [lo + (hi - lo) * 0.5 * (1 + erf((xe - x0) / widths[k])) + rng.normal(0, 2.0, xe.size)
         for (lo, hi, x0), xe, k in zip(truth, x, which)]

    def residuals(z):
        out = []
        for e, (xe, ye, k) in enumerate(zip(x, y, which)):
            lo, hi, x0 = z[2 + 3 * e: 5 + 3 * e]
            out.append((ye - lo - (hi - lo) * 0.5 * (1 + erf((xe - x0) / z[k]))) / 2.0)
        return np.concatenate(out)

    def jacobian(z):
        rows = []
        for e, (xe, k) in enumerate(zip(x, which)):
            lo, hi, x0 = z[2 + 3 * e: 5 + 3 * e]
            t = (xe - x0) / z[k]
            esf, gauss = 0.5 * (1 + erf(t)), np.exp(-t * t) / np.sqrt(np.pi)
            stage = np.zeros((xe.size, 2))
            stage[:, k] = (hi - lo) * gauss * t / z[k] / 2.0
            rows.append(np.column_stack([stage, (esf - 1) / 2.0, -esf / 2.0, (hi - lo) * gauss / z[k] / 2.0]))
        values = np.vstack(rows)
        edge = np.repeat(np.arange(5), counts)
        indices = np.hstack([np.broadcast_to(np.arange(2), (edge.size, 2)), (2 + 3 * edge)[:, None] + np.arange(3)])
        return sparse.csr_array((values.ravel(), indices.ravel(), np.arange(0, values.size + 1, 5)),
                                shape=(edge.size, 17))

    z0 = np.concatenate([[0.5, 0.5], np.ravel([(np.min(ye), np.max(ye), 0.0) for ye in y])])
    lower = np.r_[0.05, 0.05, [-np.inf] * 15]
    upper = np.r_[width_upper, width_upper, [np.inf] * 15]
    return residuals, jacobian, z0, counts, lower, upper


@pytest.mark.parametrize("width_upper", [np.inf, 1.0])
def test_the_arrowhead_solve_reaches_scipys_optimum(width_upper):
    """Free, the widths and every edge's levels and offset reach SciPy's
    exact trust-region optimum to 1e-6 (its cost to 1e-12); with the
    widths bounded at 1.0 the wider one stops on the bound, as SciPy's."""
    residuals, jacobian, z0, counts, lower, upper = edges_problem(width_upper)
    z, final = solve_arrowhead(residuals, jacobian, z0, 2, counts, lower, upper)
    assert np.allclose(final.toarray(), jacobian(z).toarray())      # the Jacobian at the solution
    reference = least_squares(residuals, z0, jac=lambda v: jacobian(v).toarray(), bounds=(lower, upper),
                              method="trf", x_scale="jac", ftol=1e-14, xtol=1e-14, gtol=1e-14)
    cost, best = 0.5 * np.sum(residuals(z) ** 2), 0.5 * np.sum(residuals(reference.x) ** 2)
    assert cost <= best * (1 + 1e-12)
    np.testing.assert_allclose(z, reference.x, rtol=1e-6, atol=1e-6)
    if np.isfinite(width_upper):
        assert z[1] == width_upper and z[0] < width_upper


def test_residuals_not_finite_at_the_start_end_the_solve_at_once():
    residuals, jacobian, z0, counts, lower, upper = edges_problem()
    calls = []

    def broken(z):
        calls.append(1)
        return np.full(residuals(z).size, np.nan)
    with pytest.raises(NoConvergence, match="not finite"):
        solve_arrowhead(broken, jacobian, z0, 2, counts, lower, upper)
    assert len(calls) == 1


def test_stopped_as_scipys_trust_region_the_solve_ends_near_the_optimum():
    """With ``ftol`` (a target's few edges) the solve stops after a step
    that lowered the cost by less than ftol of it: within that of its
    tight optimum, in no more residual evaluations than to its own tight
    end, and with the Jacobian at the point it returns."""
    residuals, jacobian, z0, counts, lower, upper = edges_problem()
    calls = []

    def counted(z):
        calls.append(1)
        return residuals(z)
    z_tight, _ = solve_arrowhead(counted, jacobian, z0, 2, counts, lower, upper)
    tight = len(calls)
    calls.clear()
    z, final = solve_arrowhead(counted, jacobian, z0, 2, counts, lower, upper, ftol=1e-9)
    assert len(calls) <= tight
    assert np.array_equal(final.toarray(), jacobian(z).toarray())
    cost, best = 0.5 * np.sum(residuals(z) ** 2), 0.5 * np.sum(residuals(z_tight) ** 2)
    assert best <= cost * (1 + 1e-12) and cost <= best * (1 + 1e-9)
    np.testing.assert_allclose(z, z_tight, rtol=1e-4, atol=1e-4)
