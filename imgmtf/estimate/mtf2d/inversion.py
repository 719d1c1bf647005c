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
one design and its weights (the central sections'), many right-hand sides;
and for many targets at once: :class:`SeparableProblem` and
:class:`EllipticalProblem` take their sections stacked along a leading
target axis (:func:`stacked_inputs`), each target's used samples padded to
one length with zero weights, and give their models stacked
(:func:`model_row` takes one out).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import cast

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
# a least-squares misfit below this fraction of its data's sum of squares is summed sample by sample (the
# normal equations' difference would lose its digits)
CANCELLATION = 1e-6


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
    """log g on ``nodes`` (cy/px of the across-track axis) and the aspect
    (stacked models, :func:`model_row`: an array, one per model)."""

    nodes: np.ndarray
    log_g: np.ndarray
    aspect: float | np.ndarray

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
    return cast(SeparableModel,
                model_row(SeparableProblem(*_one(prepared(normals_deg, frequencies_cy_px, mtfs, sd))).models(), 0))


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
    problem = EllipticalProblem(*_one(prepared(normals_deg, frequencies_cy_px, mtfs, sd)))
    log_aspect = problem.search() if aspect is None else np.array([math.log(aspect)])
    return cast(EllipticalModel, model_row(problem.model(log_aspect), 0))


def model_row(models: SeparableModel | EllipticalModel, k: int) -> SeparableModel | EllipticalModel:
    """Model ``k`` of stacked ones (each array with a leading model axis, as
    the problems below give them)."""
    if isinstance(models, SeparableModel):
        nodes = models.nodes if models.nodes.ndim == 1 else models.nodes[k]
        return SeparableModel(nodes, models.log_x[k], models.log_y[k])
    return EllipticalModel(models.nodes[k], models.log_g[k], float(np.asarray(models.aspect)[k]))


def _packed(use: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each target's used samples (``use``, targets x sections x
    frequencies) in their order, padded to the most any target uses: their
    flat indices into its sections (targets x samples) and which are real.
    A padded sample weighs 0: it adds exact zeros to every sum."""
    flat = use.reshape(use.shape[0], -1)
    count = flat.sum(axis=1)
    rows, columns = np.nonzero(flat)
    position = np.arange(rows.size) - (np.cumsum(count) - count)[rows]
    index = np.zeros((flat.shape[0], int(count.max(initial=0))), int)
    valid = np.zeros(index.shape, bool)
    index[rows, position] = columns
    valid[rows, position] = True
    return index, valid


def _gathered(values: np.ndarray, index: np.ndarray) -> np.ndarray:
    """The used samples of ``values`` (targets x [draws x] sections x
    frequencies, broadcast): targets x [draws x] samples."""
    flat = values.reshape(*values.shape[:-2], -1)
    return np.take_along_axis(flat, index.reshape(index.shape[0], *([1] * (flat.ndim - 2)), index.shape[1]), axis=-1)


class SeparableProblem:
    """The separable least squares of T targets' sections at once
    (:func:`stacked_inputs`): each one's design and weights (fixed by its
    central sections), solved for any number of redrawn ones."""

    def __init__(self, theta: np.ndarray, f: np.ndarray, m: np.ndarray, weight: np.ndarray):
        self.nodes = _nodes(REACH_CY_PX)
        u = np.abs(np.cos(theta))[..., None] * f[:, None, :]
        v = np.abs(np.sin(theta))[..., None] * f[:, None, :]
        self.index, self.valid = _packed((m >= MIN_MTF) & (u <= self.nodes[-1]) & (v <= self.nodes[-1]))
        us, vs = (np.where(self.valid, _gathered(x, self.index), 0.0).ravel() for x in (u, v))
        self.design = np.hstack([_hat(us, self.nodes), _hat(vs, self.nodes)]).reshape(*self.valid.shape, -1)
        self.weight = np.where(self.valid, _gathered(weight, self.index), 0.0)
        self.m = m

    def models(self, many: np.ndarray | None = None) -> SeparableModel:
        """The models of the sections ``many`` (targets x draws x sections
        x frequencies; default the central ones), stacked (targets x draws)."""
        many = self.m[:, None] if many is None else many
        logs = np.log(np.clip(_gathered(many, self.index), MIN_MTF / 2, None))
        targets = np.swapaxes(np.where(self.valid[:, None], logs, 0.0), 1, 2)
        solution, reach = _solve(self.design, targets, self.weight, 2, self.nodes.size)
        size = self.nodes.size
        log_x = np.where(reach[:, 0, :, None], solution[:, :size], np.nan)
        log_y = np.where(reach[:, 1, :, None], solution[:, size:], np.nan)
        return SeparableModel(self.nodes, *(np.swapaxes(x, 1, 2).reshape(-1, size) for x in (log_x, log_y)))


class EllipticalProblem:
    """The elliptical least squares of T targets' sections at once
    (:func:`stacked_inputs`): the remainders' logs, weights and used
    samples (fixed by each target's central sections, padded to one
    length with zero weights), for any aspects and redrawn sections."""

    def __init__(self, theta: np.ndarray, f: np.ndarray, m: np.ndarray, weight: np.ndarray):
        c, s = np.abs(np.cos(theta))[..., None], np.abs(np.sin(theta))[..., None]
        fc, fs = f[:, None, :] * c, f[:, None, :] * s
        pixel = np.sinc(fc) * np.sinc(fs)
        self.index, self.valid = _packed((m >= MIN_MTF) & (np.maximum(fc, fs) <= REACH_CY_PX) & (pixel > 0.05))
        self.f, self.c, self.s = (np.where(self.valid, _gathered(np.broadcast_to(x, m.shape), self.index), 0.0)
                                  for x in (f[:, None, :], c, s))
        self.log_pixel = np.log(np.where(self.valid, _gathered(pixel, self.index), 1.0))
        self.log_r = np.log(np.where(self.valid, _gathered(m, self.index), 1.0)) - self.log_pixel
        self.weight = np.where(self.valid, _gathered(weight, self.index), 0.0)

    def remainders(self, many: np.ndarray) -> np.ndarray:
        """The log remainders of sections ``many`` (targets x draws x
        sections x frequencies): targets x samples x draws."""
        logs = np.log(np.clip(_gathered(many, self.index), MIN_MTF / 2, None)) - self.log_pixel[:, None]
        return np.swapaxes(np.where(self.valid[:, None], logs, 0.0), 1, 2)

    def search(self) -> np.ndarray:
        """Each target's log aspect that best lays its central remainders
        onto one curve: 25 trials across ``ASPECT_BOUNDS``, three finer
        rounds of 9 about the best, and a parabola (to 1e-4 in log); every
        target's round in one call."""
        targets = np.arange(self.f.shape[0])
        trials = np.tile(np.linspace(math.log(ASPECT_BOUNDS[0]), math.log(ASPECT_BOUNDS[1]), 25), (targets.size, 1))
        for _ in range(4):
            costs = self.costs(trials, self.log_r)
            i = np.argmin(costs, axis=1)
            if _ < 3:
                trials = np.linspace(trials[targets, np.maximum(i - 1, 0)],
                                     trials[targets, np.minimum(i + 1, trials.shape[1] - 1)], 9, axis=-1)
        return _vertices(trials, costs[:, :, None])[:, 0]

    def model(self, log_aspects: np.ndarray) -> EllipticalModel:
        """Each target's model of its central sections at its log aspect
        (targets,), stacked."""
        return self.each_model(np.asarray(log_aspects, float)[:, None], self.log_r[:, :, None])

    def models(self, many: np.ndarray, near: np.ndarray) -> EllipticalModel:
        """The models of sections ``many`` (targets x draws x sections x
        frequencies), each with its own aspect (the aspect is uncertain
        too): 13 trials within 0.3 of its target's ``near`` (log) for all
        of them at once, each refined by a parabola; stacked (targets x
        draws)."""
        targets = self.remainders(many)
        trials = np.asarray(near, float)[:, None] + np.linspace(-0.3, 0.3, 13)
        return self.each_model(_vertices(trials, self.costs(trials, targets)), targets)

    def costs(self, log_aspects: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """The weighted misfit of each target's least squares at each of
        its ``log_aspects`` (targets x aspects) to its ``targets``
        (targets x samples, or targets x samples x k), every aspect's
        solved in one call: targets x aspects [x k]."""
        count, aspects = log_aspects.shape
        _, h = self._stacked(log_aspects)
        weight = self._each(aspects)
        if targets.ndim == 2:
            each = np.broadcast_to(targets[:, None], (count, aspects, targets.shape[1])).reshape(weight.shape)
            misfit = weight * (hats.predicted(h, self._solved(h, weight, each)) - each)
            # summed in order (a padded sample adds an exact 0): the same sum whatever the targets batched with
            return np.cumsum(misfit ** 2, axis=1)[:, -1].reshape(count, aspects)
        # many right-hand sides per aspect: one dense product each (BLAS), the normal matrices still sparse
        weighted = hats.dense(h, weight).reshape(count, aspects, *h.low.shape[1:], -1)
        goal = targets * self.weight[:, :, None]
        unknowns = h.size - 1
        bands = hats.gram_bands(h, weight)
        gram = hats.tridiagonal(*bands)
        # the inverses (by their bands: half the time of dense ones) times the right-hand sides: a third of the
        # time of solving for them, and as exact here (the normal matrices' condition is a few thousand)
        inverse = solve_pentadiagonal(*self._bands(h, weight, bands),
                                      np.broadcast_to(np.eye(unknowns), (weight.shape[0], unknowns, unknowns)))
        projected = np.swapaxes(weighted, 2, 3) @ goal[:, None]                     # b = (W D)^T g
        solution = inverse.reshape(count, aspects, unknowns, unknowns) @ projected
        # |W D x - g|^2 = g.g - 2 b.x + x.(D^T W^2 D) x: products of the unknowns, not of the samples (those
        # were half of the work)
        squares = np.einsum("tsk,tsk->tk", goal, goal)[:, None]
        out = squares - 2 * np.einsum("tank,tank->tak", projected, solution) + \
            np.einsum("tank,tank->tak", solution, gram.reshape(count, aspects, unknowns, unknowns) @ solution)
        # where the misfit is a sliver of g.g (data a model fits almost exactly) that difference loses its
        # digits: the misfit itself, sample by sample
        for t, a in zip(*np.nonzero(np.any(out < CANCELLATION * squares, axis=2))):
            misfit = weighted[t, a] @ solution[t, a] - goal[t]
            out[t, a] = np.einsum("sk,sk->k", misfit, misfit)
        return out

    def each_model(self, log_aspects: np.ndarray, targets: np.ndarray) -> EllipticalModel:
        """:meth:`model` of each column of ``targets`` (targets x samples
        x draws) at its own log aspect (targets x draws), solved together
        and stacked (targets x draws): each draw's design (its stretch, its
        nodes) kept sparse, the normal equations of all of them solved in
        one call (a call per draw cost a dense chart's scan, 484 targets
        of a hundred-odd draws each, a sixth of its time; their dense
        designs another sixth)."""
        count, draws = log_aspects.shape
        nodes, h = self._stacked(log_aspects)
        size = nodes.shape[-1]
        each = np.swapaxes(targets, 1, 2).reshape(count * draws, -1)
        solution = np.concatenate([np.zeros((count * draws, 1)), self._solved(h, self._each(draws), each)],
                                  axis=1)
        # the nodes up to the last the data touch (the first, log 1 = 0, always)
        reach = np.arange(size)[None, :] <= hats.last_touched(h)[:, None]
        aspects = np.array([math.exp(a) for a in log_aspects.ravel().tolist()])
        return EllipticalModel(nodes.reshape(-1, size), np.where(reach, solution, np.nan), aspects)

    def _each(self, repeats: int) -> np.ndarray:
        """Each target's weights for each of ``repeats`` systems: (targets x repeats) x samples."""
        return np.repeat(self.weight, repeats, axis=0)

    def _stacked(self, log_aspects: np.ndarray) -> tuple[np.ndarray, hats.Hats]:
        """Each target's nodes and design at each of its ``log_aspects``
        (targets x aspects), stacked: (targets, aspects, 33) and the
        samples' interpolation weights ((targets x aspects) x samples) on
        them."""
        squeeze = np.exp(-2 * np.asarray(log_aspects))[:, :, None]
        stretch = np.sqrt(self.c[:, None] ** 2 + self.s[:, None] ** 2 * squeeze)
        w = self.f[:, None] * stretch                                     # targets x aspects x samples
        nodes = np.linspace(0.0, np.maximum(w.max(axis=2, initial=0.0), NODE_STEP_CY_PX), 33, axis=-1)
        step = nodes[..., 1] - nodes[..., 0]
        return nodes, hats.hats((w / step[..., None]).reshape(-1, w.shape[2]), nodes.shape[-1])

    def _solved(self, h: hats.Hats, weight: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """:func:`_solve`'s node values (but the first, 0) for stacked
        designs, weights and one target each (batch x samples): batch x
        (nodes - 1), solved by their bands (:mod:`.banded`): the same
        arithmetic however many targets share the call (and for the many
        systems of a batch of targets' aspects and draws a third of the
        time of dense ones)."""
        return solve_pentadiagonal(*self._bands(h, weight), hats.transposed(h, weight * (targets * weight)))

    def _bands(self, h: hats.Hats, weight: np.ndarray,
               gram: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The normal matrices of stacked designs (:func:`_solve`'s: the
        Gram matrix, the smoothing and a ridge of 1e-10) by their three
        bands (the matrix pentadiagonal); ``gram``: the Gram matrix's
        (:func:`.hats.gram_bands`), when made already."""
        diagonal, beside = hats.gram_bands(h, weight) if gram is None else gram
        p0, p1, p2 = _penalty_bands(h.size)
        return diagonal + p0 + 1e-10, beside + p1, np.broadcast_to(p2, (diagonal.shape[0], p2.size))


def _vertex(trials: np.ndarray, costs: np.ndarray) -> float:
    """Where the parabola through the lowest cost and its neighbours has
    its minimum (at most a step from the lowest; the lowest at an end)."""
    return float(_vertices(trials[None], costs[None, :, None])[0, 0])


def _vertices(trials: np.ndarray, costs: np.ndarray) -> np.ndarray:
    """:func:`_vertex` of each target's trials (targets x trials) and each
    column of its costs (targets x trials x k), the same arithmetic on
    arrays: targets x k."""
    i = np.argmin(costs, axis=1)
    inner = np.clip(i, 1, trials.shape[1] - 2)

    def at(index: np.ndarray) -> np.ndarray:
        return np.take_along_axis(costs, index[:, None], axis=1)[:, 0]

    left, mid, right = at(inner - 1), at(inner), at(inner + 1)
    step = (trials[:, 1] - trials[:, 0])[:, None]
    curvature = left - 2 * mid + right
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.where(curvature > 0, 0.5 * step * (left - right) / curvature, 0.0)
    at_end = (i == 0) | (i == trials.shape[1] - 1)
    lowest = np.take_along_axis(trials, i, axis=1)
    return np.where(at_end, lowest, lowest + np.clip(shift, -step, step))


def fitted_model(assumption: str, normals, f, m, sd):
    """One target's central model under ``assumption``."""
    if assumption == "separable":
        return separable_model(normals, f, m, sd)
    return elliptical_model(normals, f, m, sd)


def drawn_models(assumption: str, model, normals, f, m, sd, shifts: np.ndarray):
    """The models of one target's sections redrawn by ``shifts`` (draws x
    sections, in standard deviations ``sd``), each inverted again:
    stacked (:func:`.curves.transfers` evaluates them)."""
    inputs = _one(prepared(normals, f, m, sd))
    many = (m[None] + shifts[:, :, None] * sd[None])[None]
    if assumption == "separable":
        return SeparableProblem(*inputs).models(many)
    return EllipticalProblem(*inputs).models(many, np.array([math.log(model.aspect)]))


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
    return stacked_inputs(normals, f, m, 0.0 if sd is None else np.broadcast_to(np.asarray(sd, float), m.shape))


def stacked_inputs(normals_deg, f, m, sd):
    """:func:`prepared`'s arithmetic, unchecked, on one target's or many
    targets' sections (leading axes: normals_deg (T, n), f (T, F), m and
    sd (T, n, F)): the problems above take them stacked."""
    m = np.where(np.isfinite(m), m, 0.0)
    weight = np.clip(m, MIN_MTF, None) / np.hypot(np.nan_to_num(sd, nan=1.0), SD_FLOOR)
    return np.radians(normals_deg), f, m, weight


def _one(inputs):
    """One target's :func:`prepared` inputs as a batch of one."""
    return tuple(np.asarray(x)[None] for x in inputs)


def _solve(design: np.ndarray, target: np.ndarray, weight: np.ndarray, curves: int, size: int):
    """Weighted least squares for ``curves`` curves of ``size`` nodes each
    (the first 0), smoothed by their second differences, for each
    target's design (targets x samples x unknowns) and its many right-hand
    sides (targets x samples x k); the nodes the data touch (``reach``,
    targets x curves x size)."""
    weighted = design * weight[..., None]
    # the normal equations: a few dozen unknowns, solved for many draws at once
    normal = np.swapaxes(weighted, 1, 2) @ weighted + _penalty(curves, size) + 1e-10 * np.eye(curves * (size - 1))
    rhs = np.swapaxes(weighted, 1, 2) @ (target * weight[..., None])
    solution = np.linalg.solve(normal, rhs)
    touched = (np.abs(design).sum(axis=1) > 0).reshape(-1, curves, size - 1)
    last = np.where(touched.any(axis=2), size - 2 - np.argmax(touched[:, :, ::-1], axis=2), -1)
    reach = np.arange(size) < np.where(last >= 0, last + 2, 1)[..., None]
    parts = np.split(solution, curves, axis=1)
    zero = np.zeros((solution.shape[0], 1, solution.shape[2]))
    return np.concatenate([np.concatenate([zero, part], axis=1) for part in parts], axis=1), reach


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
