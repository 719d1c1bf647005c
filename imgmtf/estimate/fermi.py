"""Batched Levenberg-Marquardt fit of the Fermi edge model, one edge per row.

f(x) = a / (1 + exp((x - b) / c)) + d      (Tzannes; paper eq. 7)

``b`` is the sub-pixel edge location, ``c`` the transition width, ``a`` the
step (left level minus right level) and ``d`` the right-hand level.  All
rows are solved together: each iteration builds every row's 4 x 4 normal
equations with one matrix product and solves them in one batched call, with
a damping factor per row.

A row whose fitted width collapses below what a pixel grid resolves (a
sharpened edge's overshoots pull a logistic to a step, whose location is
then free anywhere between two samples) is refitted with its width held
at ``MIN_WIDTH_PX``: a logistic that still interpolates between the two
samples astride the edge, so that the row keeps a location (where its
step is like the other rows': a collapse on something else, a second
feature or texture, keeps its free fit).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# a 1-px pixel aperture alone gives a 10-90 % rise of 0.8 px, a Fermi width
# of 0.18 px: a fitted width below this is a collapse to a step, not a blur
MIN_WIDTH_PX = 0.15
MAX_STEP_CHANGE = 0.5          # a held row's step within this share of the rows' median step


@dataclass(frozen=True, eq=False)
class FermiFit:
    """Per-row fit results; arrays of length n_rows.

    ``params`` is (n_rows, 4) holding a, b, c, d; ``rms`` the RMS residual
    (DN); ``ok`` is False where the fit diverged or left the data;
    ``pinned`` is True where the width collapsed and was held at
    ``MIN_WIDTH_PX``.
    """

    params: np.ndarray
    rms: np.ndarray
    ok: np.ndarray
    pinned: np.ndarray | None = None

    @property
    def location(self) -> np.ndarray:
        return self.params[:, 1]

    @property
    def width(self) -> np.ndarray:
        return self.params[:, 2]


def fermi(x: np.ndarray, params: np.ndarray) -> np.ndarray:
    """Evaluate the model; ``params[..., k]`` broadcast against ``x`` rows."""
    a, b, c, d = (params[..., k, None] for k in range(4))
    return a / (1.0 + np.exp(np.clip((x - b) / c, -50.0, 50.0))) + d


def fit_fermi(x: np.ndarray, y: np.ndarray, weight: np.ndarray, b0: np.ndarray,
              c0: float = 0.7, iterations: int = 40) -> FermiFit:
    """Fit every row of ``y(x)`` (shape n_rows x n_samples) at once.

    ``weight`` is 1 for samples to use and 0 for padding; ``b0`` is the
    starting edge location per row (px).  Level starting values come from
    the outermost used samples on each side.  Rows whose width collapses
    below ``MIN_WIDTH_PX`` are refitted with the width held there.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    w = np.asarray(weight, float)
    n = y.shape[0]
    left, right = _side_levels(y, w)
    p = _levenberg_marquardt(x, y, w, np.column_stack([left - right, b0, np.full(n, c0), right]), iterations)
    # the model is symmetric under (a, c) -> (-a, -c) with d shifted: keep c > 0
    flip = p[:, 2] < 0
    p[flip] = np.column_stack([-p[flip, 0], p[flip, 1], -p[flip, 2], p[flip, 3] + p[flip, 0]])
    finite = np.all(np.isfinite(p), axis=1)
    pinned = finite & (p[:, 2] < MIN_WIDTH_PX) & (p[:, 0] != 0)
    if pinned.any():
        start = p[pinned].copy()
        start[:, 2] = MIN_WIDTH_PX
        held = _levenberg_marquardt(x[pinned] if x.ndim == 2 else x, y[pinned], w[pinned], start,
                                    iterations, free=np.array([True, True, False, True]))
        # a row held so is the target's only where its step is the target's
        step = float(np.median(np.abs(p[finite, 0])))
        alike = np.abs(np.abs(held[:, 0]) / step - 1.0) <= MAX_STEP_CHANGE
        pinned[pinned] = alike
        p[pinned] = held[alike]
    used = w.sum(axis=1)
    xmin = np.where(w > 0, x, np.inf).min(axis=1)
    xmax = np.where(w > 0, x, -np.inf).max(axis=1)
    ok = (np.all(np.isfinite(p), axis=1) & (used >= 6)
          & (p[:, 1] > xmin) & (p[:, 1] < xmax)
          & (p[:, 2] > 1e-3) & (p[:, 2] < (xmax - xmin) / 2))
    cost = np.einsum("rk,rk->r", *(2 * [(y - fermi(x, p)) * w]))
    rms = np.sqrt(cost / np.maximum(used, 1))
    return FermiFit(p, rms, ok, pinned)


def _levenberg_marquardt(x, y, w, p, iterations, free=None):
    """Every row's parameters from ``p`` on; ``free`` (4 bools) holds the
    others at their start."""
    n = y.shape[0]
    lam = np.full(n, 1e-2)
    cost, jac, resid = _evaluate(x, y, w, p)
    held = None if free is None else np.asarray(free, float)
    if held is not None:
        jac = jac * held
    for _ in range(iterations):
        weighted = np.swapaxes(jac * w[..., None], 1, 2)
        jtj = weighted @ jac
        jtr = (weighted @ resid[..., None])[..., 0]
        diag = np.einsum("rii->ri", jtj)
        damped = jtj + (lam[:, None] * np.maximum(diag, 1e-12))[:, :, None] * np.eye(4)
        try:
            step = np.linalg.solve(damped, jtr[..., None])[..., 0]
        except np.linalg.LinAlgError:
            step = np.stack([np.linalg.lstsq(m, v, rcond=None)[0] for m, v in zip(damped, jtr)])
        trial = p + step
        trial_cost, trial_jac, trial_resid = _evaluate(x, y, w, trial)
        if held is not None:
            trial_jac = trial_jac * held
        better = np.isfinite(trial_cost) & (trial_cost < cost)
        p = np.where(better[:, None], trial, p)
        cost = np.where(better, trial_cost, cost)
        jac = np.where(better[:, None, None], trial_jac, jac)
        resid = np.where(better[:, None], trial_resid, resid)
        lam = np.where(better, lam / 3.0, lam * 4.0)
        # converged: no row proposes to move its edge by more than 1e-5 px
        if np.all((lam > 1e8) | (np.abs(step[:, 1]) < 1e-5)):
            break
    return p


def _side_levels(y, w):
    """Mean of the first and last three used samples of each row."""
    idx = np.arange(y.shape[1])
    first = np.where(w > 0, idx, np.inf).min(axis=1).astype(int)
    last = np.where(w > 0, idx, -np.inf).max(axis=1).astype(int)
    rows = np.arange(y.shape[0])[:, None]
    k = np.arange(3)[None, :]
    left = y[rows, np.minimum(first[:, None] + k, y.shape[1] - 1)].mean(axis=1)
    right = y[rows, np.maximum(last[:, None] - k, 0)].mean(axis=1)
    return left, right


def _evaluate(x, y, w, p):
    """Each row's cost (weighted sum of squared residuals), Jacobian in
    (a, b, c, d) and weighted residuals at ``p``, from one exponential:
    the cost as :func:`fermi` evaluates the model, the residuals with
    the Jacobian's logistic."""
    a, b, c, d = (p[:, k, None] for k in range(4))
    u = np.clip((x - b) / c, -50.0, 50.0)
    e = np.exp(u)
    r = (y - (a / (1.0 + e) + d)) * w
    s = 1.0 / (1.0 + e)
    ds = s * (1.0 - s)
    jac = np.stack([s, a * ds / c, a * ds * u / c, np.ones_like(s)], axis=-1)
    resid = (y - (a * s + d)) * w
    return np.einsum("rk,rk->r", r, r), jac, resid
