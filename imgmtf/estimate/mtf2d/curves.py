"""Many 2-D MTF models' sections at once: the redrawn models of an
interval (a hundred per assumption and target) evaluated on one frequency
grid together, each row exactly what the model's own ``transfer``
gives (:mod:`.inversion`), and the MTF50 of many curves.

A model evaluated one at a time costs a few NumPy calls of a hundred
values each; a dense chart's scan asks for some 400 of them per target,
which was a third of its section summaries' time.
"""
from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np

from .inversion import EllipticalModel, SeparableModel

try:        # numpy.interp's compiled core: what it calls for real values, without its checks (a third of a row's time)
    from numpy._core.multiarray import interp as _interp_row
except ImportError:                                     # pragma: no cover - another numpy's layout
    _interp_row = np.interp


def interp_rows(x: np.ndarray, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """:func:`numpy.interp` of each row: ``x`` ((k, n), or (n,) shared) on
    nodes ``xp`` ((k, m), or (m,) shared) with values ``fp`` (k, m): (k,
    n), each row ``np.interp(x[i], xp[i], fp[i])`` (its rule on NaN values
    included).  ``xp`` rows increase.

    Examples
    --------
    >>> nodes = np.array([0.0, 1.0, 2.0])
    >>> values = np.array([[0.0, 2.0, 4.0], [1.0, 1.0, np.nan]])
    >>> interp_rows(np.array([[0.5, 2.5], [1.0, 1.5]]), nodes, values).tolist()
    [[1.0, 4.0], [1.0, nan]]
    """
    fp = np.asarray(fp, float)
    x, xp = np.asarray(x, float), np.asarray(xp, float)
    k = fp.shape[0]
    # numpy's own interpolation row by row: a row of a few hundred points is one C call, where the same
    # search and arithmetic on whole arrays took some 25-45 passes over them (twice the time of this loop on
    # a dense chart's draws, shared points and nodes or not); shared ones passed as they are, not as a view
    # per row (a third of the loop's time)
    out = np.empty((k, x.shape[-1]))
    points = itertools.repeat(x, k) if x.ndim == 1 else np.broadcast_to(x, out.shape)
    nodes = itertools.repeat(xp, k) if xp.ndim == 1 else xp
    for row, (at, on, values) in enumerate(zip(points, nodes, fp)):
        out[row] = _interp_row(at, on, values)
    return out


def _interp_inside(x: np.ndarray, nodes: np.ndarray, values: np.ndarray) -> np.ndarray:
    """As :func:`.inversion._interp`, row by row: NaN outside the nodes."""
    last = (nodes[..., -1] if nodes.ndim == 2 else np.full(values.shape[0], nodes[-1]))[:, None]
    inside = (x >= 0) & (x <= last + 1e-12)
    return np.where(inside, interp_rows(x, nodes, values), np.nan)


def transfers(models: SeparableModel | EllipticalModel | Sequence[SeparableModel] | Sequence[EllipticalModel],
              u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Each model's 2-D MTF at the points (``u``, ``v``; (points,) shared,
    or (models, points) each row its own), cy/px: (models, points), row i
    exactly ``models[i].transfer(u, v)``.  The models are of one kind (the
    draws of one assumption), a sequence or stacked (one model whose arrays
    have a leading model axis, as :mod:`.inversion`'s problems give them).

    Examples
    --------
    >>> nodes = np.linspace(0.0, 0.8, 33)
    >>> models = [EllipticalModel(nodes, -a * nodes ** 2, 0.8) for a in (1.0, 2.0)]
    >>> grid = np.array([0.0, 0.25, 0.5])
    >>> bool(np.array_equal(transfers(models, 0 * grid, grid)[1], models[1].transfer(0 * grid, grid)))
    True
    """
    u, v = np.asarray(u, float), np.asarray(v, float)
    stacked = _stacked(models)
    if stacked is None:
        return np.empty((0, u.shape[-1]))
    if isinstance(stacked, SeparableModel):
        return np.exp(_interp_inside(np.abs(u), stacked.nodes, stacked.log_x) +
                      _interp_inside(np.abs(v), stacked.nodes, stacked.log_y))
    w = np.hypot(u, v / np.asarray(stacked.aspect, float)[:, None])
    return np.sinc(u) * np.sinc(v) * np.exp(_interp_inside(w, stacked.nodes, stacked.log_g))


def _stacked(models) -> SeparableModel | EllipticalModel | None:
    """``models`` as one stacked model (None: no models)."""
    if isinstance(models, (SeparableModel, EllipticalModel)):
        return models
    if not len(models):
        return None
    if all(isinstance(m, SeparableModel) for m in models):
        return SeparableModel(_shared_nodes(models), np.array([m.log_x for m in models]),
                              np.array([m.log_y for m in models]))
    if all(isinstance(m, EllipticalModel) for m in models):
        return EllipticalModel(np.array([m.nodes for m in models]), np.array([m.log_g for m in models]),
                               np.array([m.aspect for m in models]))
    raise TypeError("transfers takes models of one kind, separable or elliptical")


def _shared_nodes(models: Sequence[SeparableModel]) -> np.ndarray:
    """The models' nodes: one array when they all share it, else per row."""
    first = models[0].nodes
    if all(m.nodes is first or np.array_equal(m.nodes, first) for m in models):
        return first
    return np.array([m.nodes for m in models])


def mtf50_rows(grid: np.ndarray, curves: np.ndarray) -> np.ndarray:
    """Where each curve (rows of ``curves`` on ``grid``, cy/px) first
    falls below 0.5, linear between samples; NaN where it never does,
    starts below, or is not finite up to there.

    Examples
    --------
    >>> grid = np.array([0.0, 0.1, 0.2])
    >>> mtf50_rows(grid, np.array([[1.0, 0.6, 0.4], [1.0, 0.9, 0.8]])).tolist()
    [0.15000000000000002, nan]
    """
    below = curves < 0.5
    k = np.argmax(below, axis=1)
    rows = np.arange(curves.shape[0])
    unfinite = np.cumsum(~np.isfinite(curves), axis=1)[rows, k] > 0
    ok = below.any(axis=1) & (k > 0) & ~unfinite
    before = np.maximum(k - 1, 0)
    c0, c1 = curves[rows, before], curves[rows, k]
    with np.errstate(invalid="ignore", divide="ignore"):
        value = grid[before] + (c0 - 0.5) / (c0 - c1) * (grid[k] - grid[before])
    return np.where(ok, value, math.nan)
