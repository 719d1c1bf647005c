"""The 2-D MTF's across- and along-track sections from MTFs measured
along two or more normals, without a sensor model.

An edge whose normal makes the angle theta with the across-track axis
measures the central section of the 2-D MTF along that normal (the Fourier
slice theorem): m(f) = M(f cos theta, f sin theta), f in cy/px along the
normal.  Two sections do not fix a 2-D function; each named assumption
does:

``separable`` (M(u, v) = Mx(u) My(v)) or ``elliptical`` (the square pixel
times g(sqrt(u^2 + v^2 / a^2))), each inverted by :mod:`.inversion`.

Across track is u (theta = 0), along track v (theta = 90 deg); with rows
along track those are the image's x and y.  Any two sections fit the
separable assumption; the elliptical one only if their remainders are one
curve stretched (:mod:`.assumptions` tests it).  When it fits, two
orientations cannot tell the assumptions apart: :func:`mtf2d_from_sections`
then gives both and the ``bracket`` spanning them.  A third orientation is
predicted from the two nearest the axes under each assumption and compared
with its measurement; the assumption it does not reject is chosen.

Many targets' sections are inverted together
(:func:`mtf2d_from_sections_many`; one target's is a batch of one): every
step takes a leading target axis, each target's numbers those it gives
alone.

Intervals: each section's uncertainty (one standard deviation per
frequency) is drawn as a whole-curve shift (the noise of one edge's MTF is
correlated across frequency), every draw inverted, and the percentiles
taken.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..._blas import one_blas_thread
from ...errors import ParameterError
from .assumptions import (
    ASSUMPTIONS,
    BRACKET,
    ELLIPTICAL,
    SEPARABLE,
    base_pair,
    decision,
    overlay_tests,
    pair_decision,
    prediction_tests,
)
from .curves import mtf50_rows, transfers
from .inversion import (
    REACH_CY_PX,
    EllipticalModel,
    EllipticalProblem,
    SeparableProblem,
    model_row,
    prepared,
    stacked_inputs,
)

_GRID = np.round(np.arange(0.0, REACH_CY_PX + 1e-9, 0.01), 2)
#: targets inverted together (a target's draws take some 2 MB through the inversion)
BATCH_TARGETS = 16
_FWHM_X = np.linspace(0.0, 4.0, 801)       # where the LSF is evaluated for its FWHM, px
# the across (u, 0) then the along (0, v) section's points, cy/px
_ACROSS_ALONG = (np.concatenate([_GRID, 0.0 * _GRID]), np.concatenate([0.0 * _GRID, _GRID]))


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
        orientations it was not fitted to; with two orientations, the
        elliptical model's fit to them.

    Examples
    --------
    >>> f = np.linspace(0, 1, 101)
    >>> gaussian = [np.sinc(f) * np.exp(-2 * f ** 2)] * 2          # the same along both normals
    >>> result = mtf2d_from_sections([0.0, 90.0], f, gaussian)
    >>> result.assumption, round(float(result.transfer(0.5, 0.0)), 3), round(result.along.mtf_nyquist, 3)
    ('bracket', 0.386, 0.386)
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
        is the mean of the two assumptions'.  NaN beyond the data's reach.

        Parameters
        ----------
        fx_cy_px, fy_cy_px : array_like
            Across-track (u) and along-track (v) frequencies, cy/px
            (broadcast together).

        Returns
        -------
        numpy.ndarray
            The MTF (1 at zero frequency).
        """
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
        The chosen assumption, why, its across/along sections with their
        intervals, every assumption's, and the 2-D MTF (``transfer``).

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
    result = mtf2d_from_sections_many([(normals_deg, frequencies_cy_px, mtfs, sd)], assumption=assumption,
                                      draws=draws, confidence=confidence, seed=seed)[0]
    if isinstance(result, ParameterError):
        raise result
    return result


def mtf2d_from_sections_many(sections: Sequence[tuple], *, assumption: str = "auto", draws: int = 100,
                             confidence: float = 0.95, seed: int = 0) -> list[MTF2D | ParameterError]:
    """:func:`mtf2d_from_sections` of many targets' sections at once: each
    result what the target alone gives, their arrays stacked along a
    leading target axis through every step (one target's work is a few
    hundred small array operations; a dense chart has hundreds of targets).

    Parameters
    ----------
    sections : sequence of tuple
        Each target's (normals_deg, frequencies_cy_px, mtfs[, sd]), as
        :func:`mtf2d_from_sections` takes them.  Targets of different
        shapes (normals, frequencies) or with and without ``sd`` are
        inverted in groups of one shape.
    assumption : str, optional
        As :func:`mtf2d_from_sections`, for every target ("auto" default).
    draws : int, optional
        Draws of each target's sections for its intervals (default 100).
    confidence : float, optional
        Of the intervals (default 0.95).
    seed : int, optional
        Of the draws (each target's the same as alone).

    Returns
    -------
    list of MTF2D or ParameterError
        Per target, in order: its result, or the error that refuses its
        sections (too few normals, shapes that do not agree).

    Raises
    ------
    ParameterError
        An unknown assumption.

    Examples
    --------
    >>> f = np.linspace(0, 1, 101)
    >>> gaussian = [np.sinc(f) * np.exp(-2 * f ** 2)] * 2
    >>> results = mtf2d_from_sections_many([([0.0, 90.0], f, gaussian), ([16.8], f, gaussian[:1])])
    >>> round(results[0].along.mtf_nyquist, 3), type(results[1]).__name__
    (0.386, 'ParameterError')
    """
    if assumption not in ("auto", BRACKET, *ASSUMPTIONS):
        raise ParameterError(f"assumption must be auto, separable, elliptical or bracket, got {assumption!r}")
    out: list[MTF2D | ParameterError | None] = [None] * len(sections)
    checked: dict[int, tuple] = {}
    groups: dict[tuple, list[int]] = {}
    for k, (normals_deg, frequencies_cy_px, mtfs, *rest) in enumerate(sections):
        sd = rest[0] if rest else None
        try:
            theta, f, m, _ = prepared(normals_deg, frequencies_cy_px, mtfs, sd)
        except ParameterError as exc:
            out[k] = exc
            continue
        spread = np.zeros_like(m) if sd is None else np.broadcast_to(np.asarray(sd, float), m.shape)
        checked[k] = (np.degrees(theta), f, m, spread)
        groups.setdefault((m.shape, sd is not None), []).append(k)
    # small matrices: BLAS threads cost more than they save (on a busy machine, a third of the time)
    with one_blas_thread():
        for (_, drawn), members in groups.items():
            for start in range(0, len(members), BATCH_TARGETS):
                part = members[start: start + BATCH_TARGETS]
                inputs = tuple(np.stack([checked[k][i] for k in part]) for i in range(4))
                for k, result in zip(part, _inverted(inputs, drawn, assumption, draws, confidence, seed)):
                    out[k] = result
    return out  # type: ignore[return-value]


def _inverted(inputs: tuple, drawn: bool, assumption: str, draws: int, confidence: float,
              seed: int) -> list[MTF2D]:
    """:func:`mtf2d_from_sections_many`'s work on targets of one shape, their
    arguments checked and stacked (normals (T, n) deg, f (T, F), m and sd
    (T, n, F))."""
    normals, _, m, spread = inputs
    separable, elliptical = SeparableProblem(*stacked_inputs(*inputs)), EllipticalProblem(*stacked_inputs(*inputs))
    central: dict[str, Any] = {SEPARABLE: separable.models(), ELLIPTICAL: elliptical.model(elliptical.search())}
    count, n = normals.shape
    models = [{a: model_row(central[a], t) for a in ASSUMPTIONS} for t in range(count)]
    aspects = [float(a) for a in np.asarray(central[ELLIPTICAL].aspect).tolist()]
    chosen = _chosen(inputs, central[ELLIPTICAL], assumption, draws, seed)
    shifts = np.random.default_rng(seed).standard_normal((draws, n)) if drawn and draws > 0 else None
    again: dict[str, Any] = dict.fromkeys(ASSUMPTIONS)
    if shifts is not None:
        many = m[:, None] + shifts[None, :, :, None] * spread[:, None]
        again[SEPARABLE] = separable.models(many)
        again[ELLIPTICAL] = elliptical.models(many, np.array([math.log(a) for a in aspects]))
    sections = {a: _sections(central[a], again[a], confidence) for a in ASSUMPTIONS}
    out = []
    for t in range(count):
        alternatives = {a: sections[a][t] for a in ASSUMPTIONS}
        (sep_across, sep_along), (ell_across, ell_along) = alternatives[SEPARABLE], alternatives[ELLIPTICAL]
        alternatives[BRACKET] = (_bracket(sep_across, ell_across), _bracket(sep_along, ell_along))
        name, because, tests = chosen[t]
        across, along = alternatives[name]
        out.append(MTF2D(name, because, across, along, alternatives, models[t], aspects[t],
                         tuple(float(x) for x in normals[t]), tests))
    return out


def _chosen(inputs: tuple, elliptical: EllipticalModel, assumption: str, draws: int,
            seed: int) -> list[tuple[str, str, dict]]:
    """Each target's assumption, why, and its tests' p-values: asked for,
    else a third orientation's prediction tests, else (two orientations)
    the elliptical model's overlay test, every target's at once."""
    normals, f, m, spread = inputs
    count, n = normals.shape
    if assumption != "auto":
        return [(assumption, "asked for", {})] * count
    if n == 2:
        return [(*pair_decision(p), {ELLIPTICAL: p}) for p in overlay_tests(inputs, elliptical, seed).tolist()]
    out = []
    for t in range(count):
        base = base_pair(normals[t])
        others = [k for k in range(n) if k not in base]
        tests = prediction_tests((normals[t], f[t], m[t], spread[t]), base, others, draws, seed)
        out.append((*decision(tests, normals[t][others]), tests))
    return out


def _sections(central, drawn, confidence: float) -> list[tuple[TrackSection, TrackSection]]:
    """Each target's across and along sections of its ``central`` model
    (stacked, one row per target), with intervals from its ``drawn``
    redrawn models (stacked, targets x draws; None: no intervals)."""
    curves = transfers(central, *_ACROSS_ALONG)
    count, size = curves.shape[0], _GRID.size
    directions = ("across-track", "along-track")
    if drawn is None:
        return [tuple(_section(d, curves[t, k * size: (k + 1) * size])  # type: ignore[misc]
                      for k, d in enumerate(directions)) for t in range(count)]
    # every target's draws in one pass (a call per draw was a third of a dense chart's sections), across
    # and along together (u then v): one interpolation, one quantile, one MTF50 search for all
    both = transfers(drawn, *_ACROSS_ALONG).reshape(count, -1, 2 * size)
    tail = (1 - confidence) / 2
    low, high = np.quantile(both, [tail, 1 - tail], axis=1)
    fifty = mtf50_rows(_GRID, both.reshape(count, -1, 2, size).swapaxes(1, 2).reshape(-1, size))
    # every section's intervals at Nyquist and of its MTF50 in one pass (a quantile call each was a tenth of
    # a dense chart's sections): rows (target, direction) of draws
    nyquist = both[:, :, _GRID.searchsorted(0.5) + size * np.arange(2)].swapaxes(1, 2).reshape(count * 2, -1)
    centres = curves.reshape(count * 2, size)
    nyq_ci = _interval_rows(nyquist, tail, centres[:, _GRID.searchsorted(0.5)]).reshape(count, 2, 2)
    fifty_ci = _interval_rows(fifty.reshape(count * 2, -1), tail, np.array([_mtf50(c) for c in centres]))
    fifty_ci = fifty_ci.reshape(count, 2, 2)
    return [tuple(_section(d, curves[t, k * size: (k + 1) * size],  # type: ignore[misc]
                           (low[t, k * size: (k + 1) * size], high[t, k * size: (k + 1) * size],
                            nyq_ci[t, k], fifty_ci[t, k]))
                  for k, d in enumerate(directions)) for t in range(count)]


def _section(direction: str, curve: np.ndarray, spread: tuple | None = None) -> TrackSection:
    """One section and its intervals from its redraws' ``spread``: their
    pointwise quantiles (low, high) and its intervals at Nyquist and of
    its MTF50 (None: no intervals)."""
    if spread is None:
        low = high = np.full_like(curve, np.nan)
        nyq_ci = fifty_ci = (math.nan, math.nan)
    else:
        # NaN where a draw does not reach (beyond the sections' reach)
        low, high, nyquist, fifty = spread
        low, high = np.minimum(low, curve), np.maximum(high, curve)
        nyq_ci, fifty_ci = (float(nyquist[0]), float(nyquist[1])), (float(fifty[0]), float(fifty[1]))
    return TrackSection(direction, _GRID.copy(), curve, low, high, float(curve[_GRID.searchsorted(0.5)]), nyq_ci,
                        _mtf50(curve), fifty_ci, _fwhm(curve))


def _interval_rows(values: np.ndarray, tail: float, central: np.ndarray) -> np.ndarray:
    """Each row's interval from its draws ``values`` (rows x draws): the
    quantiles ``tail`` and 1 - ``tail`` of its finite values (the same
    arithmetic as :func:`numpy.quantile`'s linear method), widened to take
    in its ``central`` value (rows,): (rows, 2); NaN for a row with no
    finite value or no finite centre."""
    rows = np.arange(values.shape[0])[:, None]
    ordered = np.sort(np.where(np.isfinite(values), values, np.nan), axis=1)      # the finite first
    count = np.isfinite(ordered).sum(axis=1)[:, None]
    virtual = (count - 1) * np.array([tail, 1 - tail])
    previous = np.floor(virtual)
    gamma = virtual - previous
    last = np.maximum(count - 1, 0)
    a = ordered[rows, np.clip(previous.astype(int), 0, last)]
    b = ordered[rows, np.clip(previous.astype(int) + 1, 0, last)]
    with np.errstate(invalid="ignore"):
        difference = b - a
        out = np.where(gamma >= 0.5, b - difference * (1 - gamma), a + difference * gamma)
        out = np.stack([np.minimum(out[:, 0], central), np.maximum(out[:, 1], central)], axis=1)
    return np.where(((count > 0) & np.isfinite(central)[:, None]), out, np.nan)


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
    mtf = curve[:reach]
    weights = np.full(reach, 0.01)
    weights[[0, -1]] = 0.005
    lsf = 2.0 * (_cosines(reach) @ (mtf * weights))
    half = lsf[0] / 2
    below = np.flatnonzero(lsf < half)
    if not below.size:
        return math.nan
    k, x = below[0], _FWHM_X
    return float(2 * (x[k - 1] + (lsf[k - 1] - half) / (lsf[k - 1] - lsf[k]) * (x[k] - x[k - 1])))


@functools.lru_cache(maxsize=16)
def _cosines(reach: int) -> np.ndarray:
    """The cosine transform's matrix from the first ``reach`` grid
    frequencies to the LSF at ``_FWHM_X`` (px): the same few reaches recur
    for every target of a scan."""
    out = np.cos(2 * np.pi * np.outer(_FWHM_X, _GRID[:reach]))
    out.flags.writeable = False
    return out

