"""Cubic splines through a few hundred knots, in NumPy.

The 8-bit staircase rebuild (:mod:`.quantisation`) draws a smooth curve
through its level crossings: a monotone piecewise-cubic interpolant (as
``scipy.interpolate.PchipInterpolator``) for a few, a cubic smoothing spline
with its smoothing chosen by generalised cross-validation (as
``scipy.interpolate.make_smoothing_spline``) for many.  They are here, in
closed form and vectorised, because SciPy's interpolate module costs a
noise-free 8-bit chip about a quarter of a second to import and its GCV loops
over the knots in Python; the tests hold them to SciPy's.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._blas import one_blas_thread

GCV_GRID = np.geomspace(1e-9, 1.0, 241)        # smoothing tried, as a fraction of the knots' span cubed


@dataclass(frozen=True)
class CubicCurve:
    """A piecewise cubic through ``(x, y)`` with first derivatives ``slope``
    at the knots (``x`` increasing); evaluated within [x[0], x[-1]]."""

    x: np.ndarray
    y: np.ndarray
    slope: np.ndarray

    def __call__(self, at: np.ndarray) -> np.ndarray:
        """Values at ``at`` (clipped into the knots' range)."""
        at = np.clip(at, self.x[0], self.x[-1])
        i = np.clip(np.searchsorted(self.x, at, side="right") - 1, 0, self.x.size - 2)
        h = self.x[i + 1] - self.x[i]
        t = (at - self.x[i]) / h
        # the cubic Hermite basis
        return ((1 + 2 * t) * (1 - t) ** 2 * self.y[i] + t * (1 - t) ** 2 * h * self.slope[i]
                + t ** 2 * (3 - 2 * t) * self.y[i + 1] - t ** 2 * (1 - t) * h * self.slope[i + 1])


def monotone_cubic(x: np.ndarray, y: np.ndarray) -> CubicCurve:
    """The shape-preserving piecewise-cubic (PCHIP) interpolant of Fritsch
    and Butland: monotone wherever the data are, its knot slopes the
    weighted harmonic mean of the neighbouring secants (0 at a local
    extremum), its end slopes from a one-sided three-point formula kept
    from overshooting; ``scipy.interpolate.PchipInterpolator``'s rule.

    Parameters
    ----------
    x : (n,) ndarray
        Knots, strictly increasing; n >= 3.
    y : (n,) ndarray
        Values at the knots.

    Returns
    -------
    CubicCurve
        The interpolant, callable at any x (clipped into the knots' range).

    Examples
    --------
    >>> curve = monotone_cubic(np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 0.0, 1.0, 1.0]))
    >>> [round(float(v), 3) for v in curve(np.array([0.5, 1.5, 2.5]))]
    [0.0, 0.5, 1.0]
    """
    h = np.diff(x)
    secant = np.diff(y) / h
    slope = np.zeros(x.size)
    w1, w2 = 2 * h[1:] + h[:-1], h[1:] + 2 * h[:-1]
    flat = (np.sign(secant[1:]) != np.sign(secant[:-1])) | (secant[1:] == 0) | (secant[:-1] == 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        harmonic = (w1 + w2) / (w1 / secant[:-1] + w2 / secant[1:])
    slope[1:-1] = np.where(flat, 0.0, harmonic)
    slope[0] = _end_slope(h[0], h[1], secant[0], secant[1])
    slope[-1] = _end_slope(h[-1], h[-2], secant[-1], secant[-2])
    return CubicCurve(x, y, slope)


def _end_slope(h0, h1, m0, m1) -> float:
    """A one-sided three-point slope at an end, kept to the sign of the
    first secant and to three times it where the secants change sign."""
    d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > abs(3 * m0):
        return float(3 * m0)
    return float(d)


def smoothing_spline(x: np.ndarray, y: np.ndarray, weights: np.ndarray | None = None) -> CubicCurve:
    """The natural cubic smoothing spline g minimising sum w_i (y_i -
    g(x_i))^2 + lam * integral g''(u)^2 du, lam chosen by generalised
    cross-validation (Craven and Wahba 1979): the smallest of
    n sum w_i (y_i - g(x_i))^2 / (n - trace S)^2, S the smoother matrix.

    With the knots' penalty K = Q R^-1 Q' (Green and Silverman 1994,
    section 2.1), scaled by the weights, diagonalised once, S and the
    criterion are closed forms for every lam: the minimum is sought on a log
    grid (``GCV_GRID``); the spline's curvatures then follow from its
    values.

    Parameters
    ----------
    x : (n,) ndarray
        Knots, strictly increasing; n >= 3 (a hundred or so at most: the
        diagonalisation is O(n^3)).
    y : (n,) ndarray
        Values at the knots.
    weights : (n,) ndarray, optional
        Positive weights (default 1).

    Returns
    -------
    CubicCurve
        The smoothing spline, callable at any x (clipped into the knots' range).

    Examples
    --------
    >>> x = np.linspace(0.0, 1.0, 50)
    >>> y = x ** 2 + 0.01 * np.random.default_rng(0).normal(size=50)
    >>> bool(abs(smoothing_spline(x, y)(np.array([0.5]))[0] - 0.25) < 0.01)
    True
    """
    with one_blas_thread():
        return _smoothing_spline(x, y, weights)


def _smoothing_spline(x, y, weights):
    h = np.diff(x)
    n = x.size
    root_w = np.ones(n) if weights is None else np.sqrt(weights / np.mean(weights))
    # Q (n x n-2): the second divided differences; R (n-2 x n-2): tridiagonal
    q = np.zeros((n, n - 2))
    columns = np.arange(n - 2)
    q[columns, columns], q[columns + 2, columns] = 1.0 / h[:-1], 1.0 / h[1:]
    q[columns + 1, columns] = -1.0 / h[:-1] - 1.0 / h[1:]
    r = np.diag((h[:-1] + h[1:]) / 3.0) + np.diag(h[1:-1] / 6.0, 1) + np.diag(h[1:-1] / 6.0, -1)
    scaled_q = q / root_w[:, None]
    penalty = scaled_q @ np.linalg.solve(r, scaled_q.T)           # W^-1/2 K W^-1/2
    eigenvalues, vectors = np.linalg.eigh(0.5 * (penalty + penalty.T))
    eigenvalues = np.maximum(eigenvalues, 0.0)
    coefficients = vectors.T @ (root_w * y)

    def smoothers(lams):
        """S's eigenvalues per lam (rows), and the GCV criterion."""
        kept = 1.0 / (1.0 + lams[:, None] * eigenvalues)
        residual = (((1.0 - kept) * coefficients) ** 2).sum(axis=1)
        return kept, n * residual / np.maximum(n - kept.sum(axis=1), 1e-12) ** 2
    lams = GCV_GRID * (x[-1] - x[0]) ** 3
    _, gcv = smoothers(lams)
    # the smoothest local minimum: GCV often has another near interpolation,
    # fitting the crossings' jitter (Wahba 1990, section 4.9)
    lower = np.r_[True, gcv[1:] <= gcv[:-1]] & np.r_[gcv[:-1] <= gcv[1:], True]
    best = int(np.flatnonzero(lower)[-1])
    # then finely between its neighbours
    kept, gcv = smoothers(np.geomspace(lams[max(best - 1, 0)], lams[min(best + 1, lams.size - 1)], 41))
    kept = kept[int(np.argmin(gcv))]
    values = vectors @ (kept * coefficients) / root_w
    curvature = np.zeros(n)
    curvature[1:-1] = np.linalg.solve(r, q.T @ values)
    # slopes at the knots from the values and curvatures of a natural cubic spline
    secant = np.diff(values) / h
    slope = np.empty(n)
    slope[:-1] = secant - h * (2 * curvature[:-1] + curvature[1:]) / 6.0
    slope[-1] = secant[-1] + h[-1] * (curvature[-2] + 2 * curvature[-1]) / 6.0
    return CubicCurve(x, values, slope)
