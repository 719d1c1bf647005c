"""The two inversions of a 2-D MTF from its sections along measured
normals, each under its assumption (:mod:`.sections` chooses between them).

An edge whose normal makes the angle theta with the across-track axis
measures m(f) = M(f cos theta, f sin theta), f in cy/px along the normal.

- **separable**: M(u, v) = Mx(u) My(v).  In logs every measured point is
  a sum, log m(f) = log Mx(f |cos|) + log My(f |sin|): one linear least
  squares for both curves on a node grid (:func:`separable_model`).
- **elliptical**: M(u, v) = sinc(u) sinc(v) g(sqrt(u^2 + v^2 / a^2)), the
  square pixel times an elliptical remainder.  With the pixel divided out
  every section is g stretched: r(f) = g(f sqrt(cos^2 + sin^2 / a^2)); the
  aspect ``a`` is the one that lays the sections onto one curve
  (:func:`elliptical_model`).

Both are solved for many redrawn sections at once (:func:`drawn_models`):
one design and its weights (the central sections'), many right-hand sides.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ParameterError
from . import hats
from .banded import solve_pentadiagonal

NODE_STEP_CY_PX = 0.025     # the curves' node spacing
REACH_CY_PX = 0.8           # the sections are inverted up to this frequency on each axis
MIN_MTF = 0.02              # below it a measured MTF is noise in logs: not used
SD_FLOOR = 0.005            # what a measured MTF cannot be trusted to better (edge estimator bias)
MIN_SEPARATION_DEG = 30.0   # two normals closer than this hardly tell the axes apart
SMOOTHING = 3.0             # weight of the curves' second differences (per node, log units)
ASPECT_BOUNDS = (0.25, 4.0)  # the elliptical remainder's along/across width ratio searched
# from this many systems on, solved by their bands: fewer are solved faster as dense matrices (the banded
# loop's steps cost the same for one system as for a hundred; a hundred dense ones are megabytes)
BANDED_FROM = 48


@dataclass(frozen=True)
class SeparableModel:
    """log Mx and log My on ``nodes`` (cy/px), NaN beyond the data."""

    nodes: np.ndarray
    log_x: np.ndarray
    log_y: np.ndarray

    def transfer(self, u: ArrayLike, v: ArrayLike) -> np.ndarray:
        return np.exp(_interp(np.abs(u), self.nodes, self.log_x) + _interp(np.abs(v), self.nodes, self.log_y))


@dataclass(frozen=True)
class EllipticalModel:
    """log g on ``nodes`` (cy/px of the across-track axis) and the aspect."""

    nodes: np.ndarray
    log_g: np.ndarray
    aspect: float

    def transfer(self, u: ArrayLike, v: ArrayLike) -> np.ndarray:
        u, v = np.asarray(u, float), np.asarray(v, float)
        w = np.hypot(u, v / self.aspect)
        return np.sinc(u) * np.sinc(v) * np.exp(_interp(w, self.nodes, self.log_g))


def separable_model(normals_deg: ArrayLike, frequencies_cy_px: ArrayLike, mtfs: ArrayLike,
                    sd: ArrayLike | None = None) -> SeparableModel:
    """Mx(u) My(v) from sections along ``normals_deg`` (from the across-track
    axis): a weighted least-squares fit of log Mx + log My on nodes every
    ``NODE_STEP_CY_PX`` to ``REACH_CY_PX``, lightly smoothed.

    Examples
    --------
    >>> f = np.linspace(0, 1, 101)
    >>> truth = lambda u, v: np.exp(-2 * u ** 2 - 5 * v ** 2)
    >>> t = np.radians([16.8, -73.2])
    >>> m = [truth(f * np.cos(a), f * np.sin(a)) for a in t]
    >>> model = separable_model([16.8, -73.2], f, m)
    >>> round(float(model.transfer(0.5, 0.0)), 3), round(float(truth(0.5, 0.0)), 3)
    (0.607, 0.607)
    """
    return SeparableProblem(*prepared(normals_deg, frequencies_cy_px, mtfs, sd)).models()[0]


def elliptical_model(normals_deg: ArrayLike, frequencies_cy_px: ArrayLike, mtfs: ArrayLike,
                     sd: ArrayLike | None = None, aspect: float | None = None) -> EllipticalModel:
    """sinc(u) sinc(v) g(sqrt(u^2 + v^2 / a^2)) from sections along
    ``normals_deg``: the pixel divided out, the aspect a (searched in
    ``ASPECT_BOUNDS`` unless given) that lays the remainders onto one
    curve g, and g on its nodes.

    Examples
    --------
    >>> f = np.linspace(0, 1, 101)
    >>> truth = lambda u, v: np.sinc(u) * np.sinc(v) / (1 + 9 * (u ** 2 + v ** 2 / 0.7 ** 2))
    >>> t = np.radians([16.8, -73.2])
    >>> model = elliptical_model([16.8, -73.2], f, [truth(f * np.cos(a), f * np.sin(a)) for a in t])
    >>> round(model.aspect, 2), round(float(model.transfer(0.0, 0.5)), 3), round(float(truth(0.0, 0.5)), 3)
    (0.7, 0.114, 0.114)
    """
    problem = EllipticalProblem(*prepared(normals_deg, frequencies_cy_px, mtfs, sd))
    log_aspect = problem.search() if aspect is None else math.log(aspect)
    return problem.model(log_aspect, problem.log_r)


class SeparableProblem:
    """The separable least squares of some sections: its design and
    weights (fixed by the central sections), solved for any number of
    redrawn ones at once."""

    def __init__(self, theta: np.ndarray, f: np.ndarray, m: np.ndarray, weight: np.ndarray):
        self.nodes = _nodes(REACH_CY_PX)
        u, v = np.abs(np.cos(theta))[:, None] * f, np.abs(np.sin(theta))[:, None] * f
        self.use = (m >= MIN_MTF) & (u <= self.nodes[-1]) & (v <= self.nodes[-1])
        self.design = np.hstack([_hat(u[self.use], self.nodes), _hat(v[self.use], self.nodes)])
        self.weight = weight[self.use]
        self.m = m

    def models(self, many: np.ndarray | None = None) -> list[SeparableModel]:
        """The models of the sections ``many`` (draws x sections x
        frequencies; default the central ones)."""
        many = self.m[None] if many is None else many
        targets = np.log(np.clip(many[:, self.use], MIN_MTF / 2, None)).T
        solution, reach = _solve(self.design, targets, self.weight, 2, self.nodes.size)
        log_x = np.where(reach[0][:, None], solution[: self.nodes.size], np.nan).T
        log_y = np.where(reach[1][:, None], solution[self.nodes.size:], np.nan).T
        return [SeparableModel(self.nodes, log_x[k], log_y[k]) for k in range(many.shape[0])]


class EllipticalProblem:
    """The elliptical least squares of some sections: the remainders'
    logs, weights and used samples (fixed by the central sections), for
    any aspect and any number of redrawn sections."""

    def __init__(self, theta: np.ndarray, f: np.ndarray, m: np.ndarray, weight: np.ndarray):
        self.c, self.s, self.f = np.abs(np.cos(theta))[:, None], np.abs(np.sin(theta))[:, None], f
        pixel = np.sinc(f * self.c) * np.sinc(f * self.s)
        self.use = (m >= MIN_MTF) & (np.maximum(f * self.c, f * self.s) <= REACH_CY_PX) & (pixel > 0.05)
        self.log_pixel = np.log(pixel[self.use])
        self.log_r = np.log(m[self.use]) - self.log_pixel
        self.weight = weight[self.use]

    def remainders(self, many: np.ndarray) -> np.ndarray:
        """The log remainders of sections ``many`` (draws x sections x
        frequencies): samples x draws."""
        return (np.log(np.clip(many[:, self.use], MIN_MTF / 2, None)) - self.log_pixel).T

    def _fit(self, log_aspect: float, targets: np.ndarray):
        w = (self.f * np.sqrt(self.c ** 2 + self.s ** 2 * math.exp(-2 * log_aspect)))[self.use]
        nodes = _nodes(max(float(w.max(initial=0.0)), NODE_STEP_CY_PX), count=33)
        design = _hat(w, nodes)
        solution, reach = _solve(design, targets, self.weight, 1, nodes.size)
        misfit = self.weight.reshape(-1, *([1] * (targets.ndim - 1))) * (design @ solution[1:] - targets)
        return np.sum(misfit ** 2, axis=0), solution, reach, nodes

    def model(self, log_aspect: float, target: np.ndarray) -> EllipticalModel:
        _, solution, reach, nodes = self._fit(log_aspect, target)
        return EllipticalModel(nodes, np.where(reach[0], solution, np.nan), math.exp(log_aspect))

    def search(self) -> float:
        """The log aspect that best lays the central remainders onto one
        curve: 25 trials across ``ASPECT_BOUNDS``, three finer rounds of 9
        about the best, and a parabola (to 1e-4 in log)."""
        trials = np.linspace(math.log(ASPECT_BOUNDS[0]), math.log(ASPECT_BOUNDS[1]), 25)
        for _ in range(4):
            costs = self.costs(trials, self.log_r)
            i = int(np.argmin(costs))
            if _ < 3:
                trials = np.linspace(trials[max(i - 1, 0)], trials[min(i + 1, trials.size - 1)], 9)
        return _vertex(trials, costs)

    def models(self, many: np.ndarray, near: float) -> list[EllipticalModel]:
        """The models of sections ``many``, each with its own aspect (the
        aspect is uncertain too): 13 trials within 0.3 of ``near`` (log)
        for all of them at once, each refined by a parabola."""
        targets = self.remainders(many)
        trials = near + np.linspace(-0.3, 0.3, 13)
        return self.each_model(_vertices(trials, self.costs(trials, targets)), targets)

    def costs(self, log_aspects: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """The weighted misfit (:meth:`_fit`'s first value) of ``targets``
        (samples, or samples x k) at each of ``log_aspects``, every
        aspect's least squares solved in one call: (aspects,) or (aspects, k)."""
        _, h = self._stacked(log_aspects)
        if targets.ndim == 1:
            solution = self._solved(h, np.broadcast_to(targets, h.low.shape))
            return np.sum((self.weight * (hats.predicted(h, solution) - targets)) ** 2, axis=1)
        # many right-hand sides per aspect: one dense product each (BLAS), the normal matrices still sparse
        weighted = hats.dense(h) * self.weight[None, :, None]
        goal = targets * self.weight[:, None]
        # the inverses (one small factorisation each) times the right-hand sides: a third of the time of
        # solving for them, and as exact here (the normal matrices' condition is a few thousand)
        solution = np.linalg.inv(self._normal(h)) @ (np.transpose(weighted, (0, 2, 1)) @ goal)
        # the misfits an aspect at a time: all at once they were megabytes, fresh pages every call (twice the time)
        out = np.empty((len(h.low), goal.shape[1]))
        for a, (design, solved) in enumerate(zip(weighted, solution)):
            misfit = design @ solved - goal
            out[a] = np.einsum("sk,sk->k", misfit, misfit)
        return out

    def each_model(self, log_aspects: np.ndarray, targets: np.ndarray) -> list[EllipticalModel]:
        """:meth:`model` of each column of ``targets`` (samples x draws) at
        its own log aspect, solved together: each draw's design (its
        stretch, its nodes) kept sparse, the normal equations of all of
        them solved in one call (a call per draw cost a dense chart's
        scan, 484 targets of a hundred-odd draws each, a sixth of its
        time; their dense designs another sixth)."""
        nodes, h = self._stacked(log_aspects)
        size = nodes.shape[1]
        solution = np.concatenate([np.zeros((len(log_aspects), 1)), self._solved(h, targets.T)], axis=1)
        touched = hats.touched(h)                                                    # draws x (nodes - 1)
        last = np.where(touched.any(axis=1), size - 2 - np.argmax(touched[:, ::-1], axis=1), -1)
        reach = np.arange(size)[None, :] < np.where(last >= 0, last + 2, 1)[:, None]
        log_g = np.where(reach, solution, np.nan)
        return [EllipticalModel(nodes[k], log_g[k], math.exp(log_aspects[k])) for k in range(len(log_aspects))]

    def _stacked(self, log_aspects: np.ndarray) -> tuple[np.ndarray, hats.Hats]:
        """:meth:`_fit`'s nodes and design at each of ``log_aspects``,
        stacked: (aspects, 33) and the samples' interpolation weights
        (aspects x samples) on them."""
        stretch = np.sqrt(self.c ** 2 + self.s ** 2 * np.exp(-2 * np.asarray(log_aspects))[:, None, None])
        w = (self.f * stretch)[:, self.use]                                         # aspects x samples
        nodes = np.linspace(0.0, np.maximum(w.max(axis=1, initial=0.0), NODE_STEP_CY_PX), 33, axis=-1)
        step = nodes[:, 1] - nodes[:, 0]
        return nodes, hats.hats(w / step[:, None], nodes.shape[1])

    def _normal(self, h: hats.Hats) -> np.ndarray:
        """:func:`_solve`'s normal matrices of stacked designs (sparse)."""
        return hats.gram(h, self.weight) + _penalty(1, h.size) + 1e-10 * np.eye(h.size - 1)

    def _solved(self, h: hats.Hats, targets: np.ndarray) -> np.ndarray:
        """:func:`_solve`'s node values (but the first, 0) for stacked
        designs and one target each (batch x samples): batch x (nodes - 1);
        many at once by their normal matrices' bands (:mod:`.banded`)."""
        rhs = hats.transposed(h, self.weight * (targets * self.weight))
        if len(rhs) < BANDED_FROM:
            return np.linalg.solve(self._normal(h), rhs[:, :, None])[:, :, 0]
        return solve_pentadiagonal(*self._bands(h), rhs)

    def _bands(self, h: hats.Hats) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`_normal`'s three bands (the matrix pentadiagonal)."""
        diagonal, beside = hats.gram_bands(h, self.weight)
        p0, p1, p2 = _penalty_bands(h.size)
        return diagonal + p0 + 1e-10, beside + p1, np.broadcast_to(p2, (diagonal.shape[0], p2.size))


def _vertex(trials: np.ndarray, costs: np.ndarray) -> float:
    """Where the parabola through the lowest cost and its neighbours has
    its minimum (at most a step from the lowest; the lowest at an end)."""
    return float(_vertices(trials, costs[:, None])[0])


def _vertices(trials: np.ndarray, costs: np.ndarray) -> np.ndarray:
    """:func:`_vertex` of each column of ``costs`` (trials x k), the same
    arithmetic on arrays: (k,)."""
    i = np.argmin(costs, axis=0)
    inner = np.clip(i, 1, trials.size - 2)
    columns = np.arange(costs.shape[1])
    left, mid, right = costs[inner - 1, columns], costs[inner, columns], costs[inner + 1, columns]
    step = trials[1] - trials[0]
    curvature = left - 2 * mid + right
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.where(curvature > 0, 0.5 * step * (left - right) / curvature, 0.0)
    at_end = (i == 0) | (i == trials.size - 1)
    return np.where(at_end, trials[i], trials[i] + np.clip(shift, -step, step))


def fitted_model(assumption: str, normals, f, m, sd):
    if assumption == "separable":
        return separable_model(normals, f, m, sd)
    return elliptical_model(normals, f, m, sd)


def drawn_models(assumption: str, model, normals, f, m, sd, shifts: np.ndarray) -> list:
    """The models of the sections redrawn by ``shifts`` (draws x sections,
    in standard deviations ``sd``), each inverted again."""
    inputs = prepared(normals, f, m, sd)
    many = m[None] + shifts[:, :, None] * sd[None]
    if assumption == "separable":
        return SeparableProblem(*inputs).models(many)
    return EllipticalProblem(*inputs).models(many, math.log(model.aspect))


def prepared(normals_deg, frequencies_cy_px, mtfs, sd):
    """Normals (rad), frequencies, MTFs and the least squares' weights
    (1 / the standard deviation of log m, with ``SD_FLOOR``), validated."""
    normals = np.atleast_1d(np.asarray(normals_deg, float))
    f = np.asarray(frequencies_cy_px, float)
    m = np.atleast_2d(np.asarray(mtfs, float))
    if f.ndim != 1 or m.shape != (normals.size, f.size):
        raise ParameterError(f"mtfs must be (n normals, n frequencies) = ({normals.size}, {f.size}), "
                             f"got {m.shape}")
    if not (np.isfinite(normals).all() and np.isfinite(f).all()):
        raise ParameterError("normals and frequencies must be finite")
    doubled = np.radians(2 * normals)
    apart = np.degrees(np.arccos(np.clip(np.cos(doubled[:, None] - doubled[None, :]), -1, 1))) / 2
    if normals.size < 2 or apart.max() < MIN_SEPARATION_DEG:
        raise ParameterError(f"need sections along at least two normals {MIN_SEPARATION_DEG:g} deg apart, "
                             f"got {', '.join(f'{n:g}' for n in normals)} deg")
    spread = 0.0 if sd is None else np.broadcast_to(np.asarray(sd, float), m.shape)
    m = np.where(np.isfinite(m), m, 0.0)
    weight = np.clip(m, MIN_MTF, None) / np.hypot(np.nan_to_num(spread, nan=1.0), SD_FLOOR)
    return np.radians(normals), f, m, weight


def _nodes(reach: float, count: int | None = None) -> np.ndarray:
    if count is None:
        return np.arange(0.0, reach + 1e-9, NODE_STEP_CY_PX)
    return np.linspace(0.0, reach, count)


def _hat(x: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Linear interpolation's weights of ``x`` on the nodes after the
    first (whose value, log 1, is 0): (len(x), len(nodes) - 1)."""
    step = nodes[1] - nodes[0]
    position = np.clip(x / step, 0, nodes.size - 1)
    low = np.minimum(np.floor(position).astype(int), nodes.size - 2)
    frac = position - low
    out = np.zeros((x.size, nodes.size))
    rows = np.arange(x.size)
    out[rows, low] = 1.0 - frac
    out[rows, low + 1] = frac
    return out[:, 1:]


def _solve(design: np.ndarray, target: np.ndarray, weight: np.ndarray, curves: int, size: int):
    """Weighted least squares for ``curves`` curves of ``size`` nodes each
    (the first 0), smoothed by their second differences, for one target
    (samples) or many (samples x k); the nodes the data touch (``reach``,
    per curve)."""
    weighted = design * weight[:, None]
    # the normal equations: a few dozen unknowns, solved for many draws at once
    normal = weighted.T @ weighted + _penalty(curves, size) + 1e-10 * np.eye(curves * (size - 1))
    rhs = weighted.T @ (target * weight.reshape(-1, *([1] * (target.ndim - 1))))
    solution = np.linalg.solve(normal, rhs)
    touched = np.abs(design).sum(axis=0).reshape(curves, size - 1) > 0
    reach = np.zeros((curves, size), bool)
    for c in range(curves):
        last = np.flatnonzero(touched[c])
        reach[c, : (last[-1] + 2 if last.size else 1)] = True
    parts = np.split(solution, curves)
    zero = np.zeros((1, *solution.shape[1:]))
    return np.concatenate([np.concatenate([zero, part]) for part in parts]), reach


@functools.lru_cache(maxsize=8)
def _penalty(curves: int, size: int) -> np.ndarray:
    """The smoothing's normal matrix: the squared second differences of
    each curve's nodes (the first held at 0)."""
    second = np.diff(np.eye(size), 2, axis=0)[:, 1:] * SMOOTHING
    block = np.kron(np.eye(curves), second)
    return block.T @ block


@functools.lru_cache(maxsize=8)
def _penalty_bands(size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One curve's smoothing matrix (:func:`_penalty`) by its three bands:
    the diagonal and the two beside it (the rest is zero)."""
    penalty = _penalty(1, size)
    return np.diagonal(penalty).copy(), np.diagonal(penalty, 1).copy(), np.diagonal(penalty, 2).copy()


def _interp(x: ArrayLike, nodes: np.ndarray, values: np.ndarray) -> np.ndarray:
    x = np.asarray(x, float)
    inside = (x >= 0) & (x <= nodes[-1] + 1e-12)
    return np.where(inside, np.interp(x, nodes, values), np.nan)
