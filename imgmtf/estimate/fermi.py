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

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

# a 1-px pixel aperture alone gives a 10-90 % rise of 0.8 px, a Fermi width
# of 0.18 px: a fitted width below this is a collapse to a step, not a blur
MIN_WIDTH_PX = 0.15
MAX_STEP_CHANGE = 0.5          # a held row's step within this share of the rows' median step
STACK_ROWS = 1024              # fit_fermi_many stacks edges up to about this many rows (larger arrays leave the cache)


@dataclass(frozen=True, eq=False)
class FermiFit:
    """Per-row fit results; arrays of length n_rows.

    ``params`` is (n_rows, 4) holding a, b, c, d; ``rms`` the RMS residual
    (DN); ``ok`` is False where the fit diverged or left the data;
    ``pinned`` is True where the width collapsed and was held at
    ``MIN_WIDTH_PX``; ``rows`` which of the image's rows they are, where
    the rows fitted said so (:attr:`FermiRows.rows`).
    """

    params: np.ndarray
    rms: np.ndarray
    ok: np.ndarray
    pinned: np.ndarray | None = None
    rows: np.ndarray | None = None

    @property
    def location(self) -> np.ndarray:
        return self.params[:, 1]

    @property
    def width(self) -> np.ndarray:
        return self.params[:, 2]


@dataclass(frozen=True, eq=False)
class FermiRows:
    """One edge's rows to fit (:func:`fit_fermi`'s arguments): sample
    positions ``x`` (px), values ``y`` (DN) and weights (1 a sample, 0
    padding), each n_rows x n_samples, and each row's starting location
    ``b0`` (px); ``rows``, where given, marks which of the image's rows
    they are (their fit carries it on)."""

    x: np.ndarray
    y: np.ndarray
    weight: np.ndarray
    b0: np.ndarray
    rows: np.ndarray | None = None


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
    p = _levenberg_marquardt(x, y, w, _start(y, w, b0, c0), iterations)
    return _finished(x, y, w, p, iterations, [y.shape[0]])[0]


def fit_fermi_many(edges: Sequence[FermiRows], c0: float = 0.7, iterations: int = 40) -> list[FermiFit]:
    """:func:`fit_fermi` of every edge's rows, the rows of all stacked into
    one Levenberg-Marquardt: each edge's fit the same, to the bit, as its
    own (each edge iterates until its own rows converge, as alone), at the
    cost of one fit of many rows rather than of many fits of a few.

    Parameters
    ----------
    edges : sequence of FermiRows
        Each edge's rows; ``x`` two-dimensional and every edge's rows of one
        length to be stacked (else each is fitted alone).
    c0 : float, optional
        The starting width (px).
    iterations : int, optional
        At most this many iterations per edge.

    Returns
    -------
    list of FermiFit
        One per edge, in order.

    Examples
    --------
    >>> x = np.tile(np.arange(21.0), (6, 1))
    >>> edges = [FermiRows(x, fermi(x, np.array([[100.0, b, 0.8, 20.0]])), np.ones_like(x), np.full(6, 9.0))
    ...          for b in (9.5, 10.25)]
    >>> [round(float(f.location.mean()), 6) for f in fit_fermi_many(edges)]
    [9.5, 10.25]
    """
    if len({np.shape(e.y)[1:] for e in edges}) > 1 or any(np.ndim(e.x) != 2 for e in edges):
        out = [fit_fermi(e.x, e.y, e.weight, e.b0, c0, iterations) for e in edges]
    else:
        out, group = [], []
        for edge in edges:      # stacks of about STACK_ROWS rows: arrays that stay in the cache
            group.append(edge)
            if sum(np.shape(e.y)[0] for e in group) >= STACK_ROWS:
                out += _fit_stacked(group, c0, iterations)
                group = []
        out += _fit_stacked(group, c0, iterations) if group else []
    return [fit if e.rows is None else replace(fit, rows=e.rows) for fit, e in zip(out, edges)]


def _fit_stacked(edges: list[FermiRows], c0: float, iterations: int) -> list[FermiFit]:
    """:func:`fit_fermi_many` of edges whose rows are stacked in one fit."""
    if len(edges) == 1:
        e = edges[0]
        return [fit_fermi(e.x, e.y, e.weight, e.b0, c0, iterations)]
    x, y, w = (np.concatenate([np.asarray(getattr(e, name), float) for e in edges]) for name in ("x", "y", "weight"))
    b0 = np.concatenate([np.broadcast_to(np.asarray(e.b0, float), np.shape(e.y)[:1]) for e in edges])
    sizes = [np.shape(e.y)[0] for e in edges]
    p = _levenberg_marquardt_stacked(x, y, w, _start(y, w, b0, c0), iterations,
                                     np.repeat(np.arange(len(edges)), sizes))
    return _finished(x, y, w, p, iterations, sizes)


def _start(y: np.ndarray, w: np.ndarray, b0, c0: float) -> np.ndarray:
    """Every row's starting (a, b, c, d): its levels from its outermost
    used samples, its location ``b0`` and width ``c0``."""
    left, right = _side_levels(y, w)
    return np.column_stack([left - right, b0, np.full(y.shape[0], c0), right])


def _finished(x: np.ndarray, y: np.ndarray, w: np.ndarray, p: np.ndarray, iterations: int,
              sizes: Sequence[int]) -> list[FermiFit]:
    """Each edge's fit (``sizes`` its rows, stacked in order) from its rows'
    fitted parameters ``p``: widths made positive, collapsed rows held, and
    which rows are fits.  Row by row but for the held rows' step, which is
    their edge's own."""
    # the model is symmetric under (a, c) -> (-a, -c) with d shifted: keep c > 0
    flip = p[:, 2] < 0
    p[flip] = np.column_stack([-p[flip, 0], p[flip, 1], -p[flip, 2], p[flip, 3] + p[flip, 0]])
    finite = np.all(np.isfinite(p), axis=1)
    pinned = finite & (p[:, 2] < MIN_WIDTH_PX) & (p[:, 0] != 0)
    ends = np.cumsum(sizes)
    edges = [slice(int(a), int(b)) for a, b in zip(ends - sizes, ends)]
    for rows in (edges if pinned.any() else ()):
        if not pinned[rows].any():
            continue
        py, pw, pp, held_rows = (a[rows] for a in (y, w, p, pinned))        # views: written in place
        start = pp[held_rows].copy()
        start[:, 2] = MIN_WIDTH_PX
        held = _levenberg_marquardt(x[rows][held_rows] if x.ndim == 2 else x, py[held_rows], pw[held_rows], start,
                                    iterations, free=np.array([True, True, False, True]))
        # a row held so is the target's only where its step is the target's
        step = float(np.median(np.abs(pp[finite[rows], 0])))
        alike = np.abs(np.abs(held[:, 0]) / step - 1.0) <= MAX_STEP_CHANGE
        held_rows[held_rows] = alike
        pp[held_rows] = held[alike]
    used = w.sum(axis=1)
    xmin = np.where(w > 0, x, np.inf).min(axis=1)
    xmax = np.where(w > 0, x, -np.inf).max(axis=1)
    ok = (np.all(np.isfinite(p), axis=1) & (used >= 6)
          & (p[:, 1] > xmin) & (p[:, 1] < xmax)
          & (p[:, 2] > 1e-3) & (p[:, 2] < (xmax - xmin) / 2))
    cost = np.einsum("rk,rk->r", *(2 * [(y - fermi(x, p)) * w]))
    rms = np.sqrt(cost / np.maximum(used, 1))
    return [FermiFit(p[rows], rms[rows], ok[rows], pinned[rows]) for rows in edges]


def _levenberg_marquardt(x, y, w, p, iterations, free=None):
    """Every row's parameters from ``p`` on; ``free`` (4 bools) holds the
    others at their start."""
    held = None if free is None else np.asarray(free, float)
    scratch = _Scratch()
    p = np.array(p, float)
    lam = np.full(y.shape[0], 1e-2)
    cost, terms = _cost(x, y, w, p, scratch)
    jtj, jtr = (a.copy() for a in _normal_equations(x, y, w, p, terms, scratch, held))
    for _ in range(iterations):
        step = _solve_rows(_damped(jtj, lam), jtr)
        trial = p + step
        trial_cost, terms = _cost(x, y, w, trial, scratch)
        _accept(x, y, w, (p, cost, jtj, jtr, lam), (trial, trial_cost, terms), scratch, held)
        # converged: no row proposes to move its edge by more than 1e-5 px
        if np.all((lam > 1e8) | (np.abs(step[:, 1]) < 1e-5)):
            break
    return p


def _levenberg_marquardt_stacked(x, y, w, p, iterations, edges):
    """:func:`_levenberg_marquardt` of many edges' rows stacked (``edges``
    each row's edge, ascending): every row computed as in its edge's own
    fit, and an edge's rows set aside once its own rows converged, as its
    own fit would stop there."""
    scratch = _Scratch()
    out = np.array(p, float)
    p = out.copy()
    live = np.arange(y.shape[0])            # the rows of the edges still iterating, and their state
    lam = np.full(live.size, 1e-2)
    cost, terms = _cost(x, y, w, p, scratch)
    jtj, jtr = (a.copy() for a in _normal_equations(x, y, w, p, terms, scratch))
    ids = edges
    for _ in range(iterations):
        step = _solve_by_edge(_damped(jtj, lam), jtr, ids)
        trial = p + step
        trial_cost, terms = _cost(x, y, w, trial, scratch)
        _accept(x, y, w, (p, cost, jtj, jtr, lam), (trial, trial_cost, terms), scratch)
        # an edge has converged when none of its rows proposes to move its edge by more than 1e-5 px
        moving = ~((lam > 1e8) | (np.abs(step[:, 1]) < 1e-5))
        going = np.bincount(ids, weights=moving, minlength=int(edges[-1]) + 1)[ids] > 0
        if not going.all():
            out[live[~going]] = p[~going]
            live = live[going]
            if live.size == 0:
                return out
            x, y, w, p, ids, cost, jtj, jtr, lam = (a[going] for a in (x, y, w, p, ids, cost, jtj, jtr, lam))
    out[live] = p
    return out


class _Scratch:
    """Arrays reused from one iteration to the next, each a view of the
    start of a buffer kept by name.  A stack's arrays are larger than
    what the allocator keeps at hand: made afresh, each is mapped from
    the system anew and its pages faulted in, which cost as much as the
    arithmetic done in them."""

    def __init__(self) -> None:
        self._buffers: dict[str, np.ndarray] = {}

    def __call__(self, name: str, shape: tuple[int, ...]) -> np.ndarray:
        size = math.prod(shape)
        buffer = self._buffers.get(name)
        if buffer is None or buffer.size < size:
            buffer = self._buffers[name] = np.empty(size)
        return buffer[:size].reshape(shape)


def _cost(x, y, w, p, scratch):
    """Each row's cost (weighted sum of squared residuals) at ``p``, as
    :func:`fermi` evaluates the model, and the terms its Jacobian reuses:
    (x - b) / c clipped, and 1 + its exponential (in ``scratch``)."""
    a, b, c, d = (p[:, k, None] for k in range(4))
    u = np.subtract(x, b, out=scratch("u", y.shape))
    u /= c
    np.clip(u, -50.0, 50.0, out=u)
    one_plus_e = np.exp(u, out=scratch("one_plus_e", y.shape))
    one_plus_e += 1.0
    r = np.divide(a, one_plus_e, out=scratch("r", y.shape))
    r += d
    np.subtract(y, r, out=r)
    r *= w
    return np.einsum("rk,rk->r", r, r), (u, one_plus_e)


def _normal_equations(x, y, w, p, terms, scratch, held=None):
    """Every row's J'WJ and J'Wr at ``p`` (``terms`` from :func:`_cost`; in
    ``scratch``), the Jacobian in (a, b, c, d) from the model's logistic;
    ``held`` (4 floats) zeroes the columns of parameters held."""
    u, one_plus_e = terms
    a, c, d = (p[:, k, None] for k in (0, 2, 3))
    s = np.divide(1.0, one_plus_e, out=scratch("s", y.shape))
    ds = np.subtract(1.0, s, out=scratch("ds", y.shape))
    ds *= s
    jac = scratch("jac", (*y.shape, 4))
    jac[..., 0] = s
    a_ds = np.multiply(a, ds, out=ds)
    np.divide(a_ds, c, out=jac[..., 1])
    a_ds *= u
    np.divide(a_ds, c, out=jac[..., 2])
    jac[..., 3] = 1.0
    if held is not None:
        jac *= held
    s *= a
    s += d
    resid = np.subtract(y, s, out=s)
    resid *= w
    weighted = np.swapaxes(np.multiply(jac, w[..., None], out=scratch("weighted", jac.shape)), 1, 2)
    jtj = np.matmul(weighted, jac, out=scratch("jtj", (y.shape[0], 4, 4)))
    jtr = scratch("jtr", (y.shape[0], 4))
    np.matmul(weighted, resid[..., None], out=jtr[..., None])
    return jtj, jtr


def _damped(jtj, lam):
    """Every row's Levenberg-Marquardt matrix: J'WJ damped by ``lam``
    times its diagonal."""
    damped = jtj.copy()
    diagonal = np.arange(4)
    damped[:, diagonal, diagonal] += lam[:, None] * np.maximum(jtj[:, diagonal, diagonal], 1e-12)
    return damped


def _accept(x, y, w, state, trial, scratch, held=None):
    """Each row's state (parameters, cost, normal equations, damping;
    updated in place) after a trial step: the trial's where it lowered the
    cost (damping / 3), the row's own before where not (damping x 4).  The
    normal equations are made for every row when most improved (a row's
    are the same made among any rows), else for those rows alone."""
    p, cost, jtj, jtr, lam = state
    trial_p, trial_cost, terms = trial
    better = np.isfinite(trial_cost) & (trial_cost < cost)
    improved = int(np.count_nonzero(better))
    if improved == better.size:
        p[:] = trial_p
        cost[:] = trial_cost
        jtj[:], jtr[:] = _normal_equations(x, y, w, trial_p, terms, scratch, held)
        lam /= 3.0
        return
    lam[:] = np.where(better, lam / 3.0, lam * 4.0)
    if not improved:
        return
    p[better] = trial_p[better]
    cost[better] = trial_cost[better]
    if 2 * improved > better.size:
        new_jtj, new_jtr = _normal_equations(x, y, w, trial_p, terms, scratch, held)
        jtj[better], jtr[better] = new_jtj[better], new_jtr[better]
    else:
        rows = np.flatnonzero(better)
        jtj[rows], jtr[rows] = _normal_equations(x[rows] if x.ndim == 2 else x, y[rows], w[rows], trial_p[rows],
                                                 tuple(t[rows] for t in terms), scratch, held)


def _solve_rows(damped: np.ndarray, jtr: np.ndarray) -> np.ndarray:
    """Every row's step: all at once, or, where a matrix is singular, each
    row by least squares."""
    try:
        return np.linalg.solve(damped, jtr[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.stack([np.linalg.lstsq(m, v, rcond=None)[0] for m, v in zip(damped, jtr)])


def _solve_by_edge(damped: np.ndarray, jtr: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """Every row's step, as its edge's own fit solves it: all at once, or,
    where a matrix is singular, edge by edge (:func:`_solve_rows`, as
    alone)."""
    try:
        return np.linalg.solve(damped, jtr[..., None])[..., 0]
    except np.linalg.LinAlgError:
        step = np.empty_like(jtr)
        for edge in np.unique(ids):
            rows = ids == edge
            step[rows] = _solve_rows(damped[rows], jtr[rows])
        return step


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
