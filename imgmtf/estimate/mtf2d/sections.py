"""The 2-D MTF's across- and along-track sections from MTFs measured
along two or more normals, without a sensor model.

An edge whose normal makes the angle theta with the across-track axis
measures the central section of the 2-D MTF along that normal (the Fourier
slice theorem): m(f) = M(f cos theta, f sin theta), f in cy/px along the
normal.  Two sections do not fix a 2-D function; each named assumption
does:

- **separable**: M(u, v) = Mx(u) My(v).  In logs every measured point is
  a sum, log m(f) = log Mx(f |cos|) + log My(f |sin|): one linear least
  squares for both curves on a node grid (:func:`separable_model`).
- **elliptical**: M(u, v) = sinc(u) sinc(v) g(sqrt(u^2 + v^2 / a^2)), the
  square pixel times an elliptical remainder.  With the pixel divided out
  every section is g stretched: r(f) = g(f sqrt(cos^2 + sin^2 / a^2)); the
  aspect ``a`` is the one that lays the sections onto one curve
  (:func:`elliptical_model`).

Across track is u (theta = 0), along track v (theta = 90 deg); with rows
along track those are the image's x and y.  Two (near-)perpendicular
sections fit either assumption exactly, so the data cannot tell them
apart: :func:`mtf2d_from_sections` then gives both and the ``bracket``
spanning them.  A third orientation is predicted from the two nearest the
axes under each assumption and compared with its measurement; the
assumption it does not reject is chosen.

Intervals: each section's uncertainty (one standard deviation per
frequency) is drawn as a whole-curve shift (the noise of one edge's MTF is
correlated across frequency), every draw inverted, and the percentiles
taken.
"""
from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ParameterError

SEPARABLE, ELLIPTICAL, BRACKET = "separable", "elliptical", "bracket"
ASSUMPTIONS = (SEPARABLE, ELLIPTICAL)
NODE_STEP_CY_PX = 0.025     # the curves' node spacing
REACH_CY_PX = 0.8           # the sections are inverted up to this frequency on each axis
MIN_MTF = 0.02              # below it a measured MTF is noise in logs: not used
SD_FLOOR = 0.005            # what a measured MTF cannot be trusted to better (edge estimator bias)
MIN_SEPARATION_DEG = 30.0   # two normals closer than this hardly tell the axes apart
SMOOTHING = 3.0             # weight of the curves' second differences (per node, log units)
ASPECT_BOUNDS = (0.25, 4.0)  # the elliptical remainder's along/across width ratio searched
TEST_ALPHA = 0.05           # a prediction whose p-value falls below is rejected
TEST_DRAWS = 30             # draws for a prediction's own spread
_GRID = np.round(np.arange(0.0, REACH_CY_PX + 1e-9, 0.01), 2)


@dataclass(frozen=True)
class TrackSection:
    """One section of a 2-D MTF (across- or along-track) and its interval.

    Attributes
    ----------
    direction : str
        "across-track" (u) or "along-track" (v).
    frequencies_cy_px, mtf, low, high : numpy.ndarray
        The section (MTF 1 at zero frequency) and its pointwise interval;
        NaN beyond what the measured sections reach.
    mtf_nyquist, mtf50_cy_px, fwhm_px : float
        MTF at 0.5 cy/px, where it falls to 0.5, the LSF's full width at
        half maximum (px).
    mtf_nyquist_ci, mtf50_ci_cy_px : (float, float)
        Their intervals (NaN without uncertainties).
    """

    direction: str
    frequencies_cy_px: np.ndarray = field(repr=False)
    mtf: np.ndarray = field(repr=False)
    low: np.ndarray = field(repr=False)
    high: np.ndarray = field(repr=False)
    mtf_nyquist: float
    mtf_nyquist_ci: tuple[float, float]
    mtf50_cy_px: float
    mtf50_ci_cy_px: tuple[float, float]
    fwhm_px: float


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


@dataclass(frozen=True)
class MTF2D:
    """The 2-D MTF from measured sections, under a named assumption.

    Attributes
    ----------
    assumption : str
        "separable", "elliptical" or "bracket" (the data cannot tell the
        two apart: the interval spans both).
    because : str
        Why that assumption (a short phrase).
    across, along : TrackSection
        The chosen assumption's across-track (u, cy/px) and along-track
        (v) sections.
    alternatives : dict
        Every assumption's (``across``, ``along``) sections, the bracket's
        among them.
    models : dict
        Each assumption's fitted model (:class:`SeparableModel`,
        :class:`EllipticalModel`).
    aspect : float
        The elliptical remainder's aspect a (along/across widths).
    normals_deg : tuple of float
        The sections' normals from the across-track axis, deg.
    tests : dict
        For each assumption, the p-value of its prediction of the
        orientations it was not fitted to (absent with two orientations).
    """

    assumption: str
    because: str
    across: TrackSection
    along: TrackSection
    alternatives: dict = field(repr=False)
    models: dict = field(repr=False)
    aspect: float
    normals_deg: tuple
    tests: dict

    def transfer(self, fx_cy_px: ArrayLike, fy_cy_px: ArrayLike) -> np.ndarray:
        """The 2-D MTF at (across, along) frequencies, cy/px; the bracket's
        is the mean of the two assumptions'.  NaN beyond the data's reach."""
        if self.assumption == BRACKET:
            return 0.5 * sum(self.models[a].transfer(fx_cy_px, fy_cy_px) for a in ASSUMPTIONS)
        return self.models[self.assumption].transfer(fx_cy_px, fy_cy_px)


def sd_from_nyquist(sd_nyquist: ArrayLike, frequencies_cy_px: ArrayLike) -> np.ndarray:
    """Per-frequency standard deviations of sections from theirs at Nyquist
    (n,), growing in proportion to frequency (0 at 0, where an MTF is 1 by
    construction): (n, len(frequencies)).

    Examples
    --------
    >>> sd_from_nyquist([0.01], [0.0, 0.25, 0.5]).tolist()
    [[0.0, 0.005, 0.01]]
    """
    return np.outer(np.asarray(sd_nyquist, float), np.asarray(frequencies_cy_px, float) / 0.5)


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
    return _SeparableProblem(*_prepared(normals_deg, frequencies_cy_px, mtfs, sd)).models()[0]


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
    problem = _EllipticalProblem(*_prepared(normals_deg, frequencies_cy_px, mtfs, sd))
    log_aspect = problem.search() if aspect is None else math.log(aspect)
    return problem.model(log_aspect, problem.log_r)


class _SeparableProblem:
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
        log_x, log_y = solution[: self.nodes.size], solution[self.nodes.size:]
        return [SeparableModel(self.nodes, np.where(reach[0], log_x[:, k], np.nan),
                               np.where(reach[1], log_y[:, k], np.nan)) for k in range(many.shape[0])]


class _EllipticalProblem:
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
            costs = np.array([float(self._fit(x, self.log_r)[0]) for x in trials])
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
        costs = np.array([self._fit(x, targets)[0] for x in trials])
        return [self.model(_vertex(trials, costs[:, k]), targets[:, k]) for k in range(targets.shape[1])]


def _vertex(trials: np.ndarray, costs: np.ndarray) -> float:
    """Where the parabola through the lowest cost and its neighbours has
    its minimum (at most a step from the lowest; the lowest at an end)."""
    i = int(np.argmin(costs))
    if i == 0 or i == trials.size - 1:
        return float(trials[i])
    step = trials[1] - trials[0]
    left, mid, right = costs[i - 1:i + 2]
    curvature = left - 2 * mid + right
    shift = 0.5 * step * (left - right) / curvature if curvature > 0 else 0.0
    return float(trials[i] + np.clip(shift, -step, step))


def mtf2d_from_sections(normals_deg: ArrayLike, frequencies_cy_px: ArrayLike, mtfs: ArrayLike,
                        sd: ArrayLike | None = None, *, assumption: str = "auto", draws: int = 100,
                        confidence: float = 0.95, seed: int = 0) -> MTF2D:
    """The across- and along-track sections of the 2-D MTF from MTFs
    measured along two or more normals.

    Parameters
    ----------
    normals_deg : sequence of float
        Each section's normal from the across-track axis (deg; 180 apart
        is the same section), at least two of them ``MIN_SEPARATION_DEG``
        apart.
    frequencies_cy_px : array_like
        The sections' common frequencies along their normals, cy/px.
    mtfs : array_like
        (n, len(frequencies)): the measured MTFs (1 at zero frequency).
    sd : array_like, optional
        (n, len(frequencies)): their standard deviations
        (:func:`sd_from_nyquist`); without, no intervals and the tests
        assume ``SD_FLOOR``.
    assumption : str, optional
        "auto" (default: chosen as the module says), "separable",
        "elliptical" or "bracket".
    draws : int, optional
        Draws of the sections within their uncertainty for the intervals.
    confidence : float, optional
        Of the intervals (default 0.95).
    seed : int, optional
        Of the draws: the same inputs give the same intervals.

    Returns
    -------
    MTF2D

    Raises
    ------
    ParameterError
        Shapes that do not agree, fewer than two distinct normals, or an
        unknown assumption.

    Examples
    --------
    >>> f = np.linspace(0, 1, 101)
    >>> truth = lambda u, v: np.sinc(u) * np.sinc(v) * np.exp(-2 * u ** 2 - 4 * v ** 2)
    >>> t = np.radians([16.8, -73.2])
    >>> result = mtf2d_from_sections([16.8, -73.2], f, [truth(f * np.cos(a), f * np.sin(a)) for a in t])
    >>> result.assumption, round(result.across.mtf_nyquist, 3), round(float(truth(0.5, 0)), 3)
    ('bracket', 0.386, 0.386)
    """
    if assumption not in ("auto", BRACKET, *ASSUMPTIONS):
        raise ParameterError(f"assumption must be auto, separable, elliptical or bracket, got {assumption!r}")
    theta, f, m, _ = _prepared(normals_deg, frequencies_cy_px, mtfs, sd)
    normals = np.degrees(theta)
    spread = np.zeros_like(m) if sd is None else np.broadcast_to(np.asarray(sd, float), m.shape)
    base = _base_pair(normals)
    inputs = (normals, f, m, spread)
    models = {a: _model(a, normals, f, m, spread) for a in ASSUMPTIONS}
    tests: dict[str, float] = {}
    if assumption == "auto":
        others = [k for k in range(normals.size) if k not in base]
        if others:
            tests = _tests(inputs, base, others, draws, seed)
            assumption, because = _decision(tests, normals[list(others)])
        else:
            tests = {ELLIPTICAL: _overlay_test(inputs, models[ELLIPTICAL], seed)}
            assumption, because = _pair_decision(tests[ELLIPTICAL])
    else:
        because = "asked for"
    rng = np.random.default_rng(seed)
    shifts = rng.standard_normal((draws, normals.size)) if sd is not None and draws > 0 else None
    alternatives = {a: _sections(a, models[a], inputs, shifts, confidence) for a in ASSUMPTIONS}
    (sep_across, sep_along), (ell_across, ell_along) = alternatives[SEPARABLE], alternatives[ELLIPTICAL]
    alternatives[BRACKET] = (_bracket(sep_across, ell_across), _bracket(sep_along, ell_along))
    across, along = alternatives[assumption]
    return MTF2D(assumption, because, across, along, alternatives, models, models[ELLIPTICAL].aspect,
                 tuple(float(n) for n in normals), tests)


def _model(assumption: str, normals, f, m, sd):
    if assumption == SEPARABLE:
        return separable_model(normals, f, m, sd)
    return elliptical_model(normals, f, m, sd)


def _prepared(normals_deg, frequencies_cy_px, mtfs, sd):
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


def _interp(x: ArrayLike, nodes: np.ndarray, values: np.ndarray) -> np.ndarray:
    x = np.asarray(x, float)
    inside = (x >= 0) & (x <= nodes[-1] + 1e-12)
    return np.where(inside, np.interp(x, nodes, values), np.nan)


def _base_pair(normals: np.ndarray) -> tuple[int, int]:
    """The two normals to invert from: at least ``MIN_SEPARATION_DEG``
    apart, nearest the axes, then farthest apart."""
    best, key = (0, 1), (math.inf, math.inf)
    for i in range(normals.size):
        for j in range(i + 1, normals.size):
            apart = abs((normals[i] - normals[j] + 90.0) % 180.0 - 90.0)
            if apart < MIN_SEPARATION_DEG:
                continue
            off_axis = sum(min(n % 90.0, 90.0 - n % 90.0) for n in (normals[i], normals[j]))
            if (off_axis, -apart) < key:
                best, key = (i, j), (off_axis, -apart)
    return best


def _tests(inputs, base, others, draws: int, seed: int) -> dict[str, float]:
    """Each assumption's p-value for the orientations ``others``: its
    prediction from the ``base`` pair against their measurement, at the
    frequency where the two assumptions' predictions differ most."""
    normals, f, m, sd = inputs
    pair = list(base)
    rng = np.random.default_rng(seed + 1)
    shifts = rng.standard_normal((TEST_DRAWS, 2))
    chi2 = dict.fromkeys(ASSUMPTIONS, 0.0)
    for k in others:
        theta = math.radians(normals[k])
        u, v = f * abs(math.cos(theta)), f * abs(math.sin(theta))
        predictions, spreads = {}, {}
        for a in ASSUMPTIONS:
            central = _model(a, normals[pair], f, m[pair], sd[pair])
            predictions[a] = central.transfer(u, v)
            drawn = np.array([again.transfer(u, v) for again in
                              _drawn_models(a, central, normals[pair], f, m[pair], sd[pair], shifts)]) \
                if sd.any() else None
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)       # all-NaN beyond the reach
                spreads[a] = np.zeros_like(f) if drawn is None else np.nanstd(drawn, axis=0)
        total = {a: np.sqrt(spreads[a] ** 2 + sd[k] ** 2 + SD_FLOOR ** 2) for a in ASSUMPTIONS}
        gap = np.abs(predictions[SEPARABLE] - predictions[ELLIPTICAL]) / np.maximum(total[SEPARABLE],
                                                                                    total[ELLIPTICAL])
        usable = np.isfinite(gap) & (f > 0) & (m[k] >= MIN_MTF) & (f <= REACH_CY_PX)
        if not usable.any():
            continue
        at = int(np.flatnonzero(usable)[np.argmax(gap[usable])])
        for a in ASSUMPTIONS:
            chi2[a] += float(((predictions[a][at] - m[k, at]) / total[a][at]) ** 2)
    from scipy.special import chdtrc  # here only: a scan with two orientations never loads it
    return {a: float(chdtrc(len(others), chi2[a])) for a in ASSUMPTIONS}


def _decision(tests: dict[str, float], others) -> tuple[str, str]:
    where = "/".join(f"{n:.0f}" for n in others) + " deg"
    fits = [a for a in ASSUMPTIONS if tests[a] >= TEST_ALPHA]
    p = ", ".join(f"{a} p={tests[a]:.2g}" for a in ASSUMPTIONS)
    if len(fits) == 2:
        return BRACKET, f"the {where} section agrees with both ({p})"
    if len(fits) == 1:
        return fits[0], f"the {where} section rejects the other ({p})"
    closer = max(ASSUMPTIONS, key=lambda a: tests[a])
    return closer, f"the {where} section rejects both; {closer} is closer ({p})"


def _pair_decision(elliptical_p: float) -> tuple[str, str]:
    """Two orientations: a separable model fits any two sections, an
    elliptical one only sections whose remainders are one curve stretched."""
    if elliptical_p < TEST_ALPHA:
        return SEPARABLE, (f"the two sections are not one curve stretched (elliptical p={elliptical_p:.2g}); "
                           "separable fits any two")
    return BRACKET, f"two orientations cannot tell separable from elliptical (elliptical p={elliptical_p:.2g})"


def _overlay_test(inputs, model: EllipticalModel, seed: int, draws: int = 100) -> float:
    """The p-value of the elliptical model's fit to the sections: how often
    sections drawn from the fitted model (within their uncertainty and
    ``SD_FLOOR``, as whole-curve shifts) lay onto one curve worse than the
    measured ones do."""
    normals, f, m, sd = inputs
    problem = _EllipticalProblem(*_prepared(normals, f, m, sd))
    log_aspect = math.log(model.aspect)
    observed = float(problem._fit(log_aspect, problem.log_r)[0])
    theta = np.radians(normals)
    predicted = np.array([model.transfer(f * abs(math.cos(t)), f * abs(math.sin(t))) for t in theta])
    predicted = np.where(np.isfinite(predicted), predicted, m)
    spread = np.hypot(sd, SD_FLOOR * f / 0.5)
    shifts = np.random.default_rng(seed + 2).standard_normal((draws, normals.size))
    null = _EllipticalProblem(*_prepared(normals, f, predicted, sd))
    targets = null.remainders(predicted[None] + shifts[:, :, None] * spread[None])
    costs = np.min([null._fit(x, targets)[0] for x in log_aspect + np.linspace(-0.3, 0.3, 13)], axis=0)
    return float(np.mean(costs >= observed))


def _sections(assumption: str, model, inputs, shifts, confidence: float) -> tuple[TrackSection, TrackSection]:
    """The model's across and along sections, with intervals from the
    sections redrawn by ``shifts`` (draws x sections) and inverted again."""
    normals, f, m, sd = inputs
    curves = np.stack([model.transfer(_GRID, 0.0 * _GRID), model.transfer(0.0 * _GRID, _GRID)])
    drawn = None
    if shifts is not None:
        drawn = np.array([[again.transfer(_GRID, 0.0 * _GRID), again.transfer(0.0 * _GRID, _GRID)]
                          for again in _drawn_models(assumption, model, normals, f, m, sd, shifts)])
    return (_section("across-track", curves[0], None if drawn is None else drawn[:, 0], confidence),
            _section("along-track", curves[1], None if drawn is None else drawn[:, 1], confidence))


def _drawn_models(assumption: str, model, normals, f, m, sd, shifts: np.ndarray) -> list:
    """The models of the sections redrawn by ``shifts`` (draws x sections,
    in standard deviations ``sd``), each inverted again."""
    prepared = _prepared(normals, f, m, sd)
    many = m[None] + shifts[:, :, None] * sd[None]
    if assumption == SEPARABLE:
        return _SeparableProblem(*prepared).models(many)
    return _EllipticalProblem(*prepared).models(many, math.log(model.aspect))


def _section(direction: str, curve: np.ndarray, drawn: np.ndarray | None, confidence: float) -> TrackSection:
    tail = (1 - confidence) / 2
    if drawn is None:
        low = high = np.full_like(curve, np.nan)
        nyq_ci = fifty_ci = (math.nan, math.nan)
    else:
        # NaN where a draw does not reach (beyond the sections' reach)
        low, high = np.quantile(drawn, [tail, 1 - tail], axis=0)
        low, high = np.minimum(low, curve), np.maximum(high, curve)
        nyquist = drawn[:, _GRID.searchsorted(0.5)]
        fifty = np.array([_mtf50(c) for c in drawn])
        nyq_ci = _quantiles(nyquist, tail, curve[_GRID.searchsorted(0.5)])
        fifty_ci = _quantiles(fifty, tail, _mtf50(curve))
    return TrackSection(direction, _GRID.copy(), curve, low, high, float(curve[_GRID.searchsorted(0.5)]), nyq_ci,
                        _mtf50(curve), fifty_ci, _fwhm(curve))


def _quantiles(values: np.ndarray, tail: float, central: float) -> tuple[float, float]:
    values = values[np.isfinite(values)]
    if not values.size or not math.isfinite(central):
        return (math.nan, math.nan)
    low, high = np.quantile(values, [tail, 1 - tail])
    return (float(min(low, central)), float(max(high, central)))


def _bracket(first: TrackSection, second: TrackSection) -> TrackSection:
    """The section spanning two assumptions': their mean, and an interval
    from the lower's low to the higher's high (each at least its value)."""
    def span(a: float, b: float, ia, ib) -> tuple[float, float]:
        lows = [x for x in (a, b, ia[0], ib[0]) if math.isfinite(x)]
        highs = [x for x in (a, b, ia[1], ib[1]) if math.isfinite(x)]
        return (min(lows, default=math.nan), max(highs, default=math.nan))

    curve = 0.5 * (first.mtf + second.mtf)
    low = np.fmin(np.fmin(first.low, second.low), np.fmin(first.mtf, second.mtf))
    high = np.fmax(np.fmax(first.high, second.high), np.fmax(first.mtf, second.mtf))
    return TrackSection(first.direction, first.frequencies_cy_px, curve, low, high,
                        0.5 * (first.mtf_nyquist + second.mtf_nyquist),
                        span(first.mtf_nyquist, second.mtf_nyquist, first.mtf_nyquist_ci, second.mtf_nyquist_ci),
                        0.5 * (first.mtf50_cy_px + second.mtf50_cy_px),
                        span(first.mtf50_cy_px, second.mtf50_cy_px, first.mtf50_ci_cy_px, second.mtf50_ci_cy_px),
                        0.5 * (first.fwhm_px + second.fwhm_px))


def _mtf50(curve: np.ndarray) -> float:
    """Where a section first falls to 0.5 (linear between samples), cy/px."""
    below = np.flatnonzero(curve < 0.5)
    if not below.size or below[0] == 0 or not np.isfinite(curve[: below[0] + 1]).all():
        return math.nan
    k = below[0]
    return float(_GRID[k - 1] + (curve[k - 1] - 0.5) / (curve[k - 1] - curve[k]) * (_GRID[k] - _GRID[k - 1]))


def _fwhm(curve: np.ndarray) -> float:
    """The FWHM of the LSF whose MTF is ``curve`` (even, real): its cosine
    transform over the section's reach, which must reach MTF 0.1 (else
    NaN: a transform truncated higher is not the LSF's width)."""
    finite = np.isfinite(curve)
    reach = int(np.argmin(finite)) if not finite.all() else curve.size
    if reach < 3 or curve[reach - 1] > 0.1:
        return math.nan
    f, mtf = _GRID[:reach], curve[:reach]
    x = np.linspace(0.0, 4.0, 801)
    weights = np.full(reach, 0.01)
    weights[[0, -1]] = 0.005
    lsf = 2.0 * (np.cos(2 * np.pi * np.outer(x, f)) @ (mtf * weights))
    half = lsf[0] / 2
    below = np.flatnonzero(lsf < half)
    if not below.size:
        return math.nan
    k = below[0]
    return float(2 * (x[k - 1] + (lsf[k - 1] - half) / (lsf[k - 1] - lsf[k]) * (x[k] - x[k - 1])))

