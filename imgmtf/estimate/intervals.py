"""Confidence intervals for MTF figures.

Two methods behind one setting (:class:`Intervals`):

``influence`` (the default) linearises the estimate: with the target line,
the LSF window and the corrections held fixed, every stage from the pixel
values to the MTF (resampling, differentiation, tail fit, Fourier
transform) is linear, so the MTF at a frequency is a smooth function of
the samples whose gradient costs one pass backwards through the stages
(:attr:`imgmtf.estimate.resampling.Resampled.adjoint`).  Each row's
influence is the sum over its samples of gradient times residual; the
variance is that of the row influences (the infinitesimal jackknife),
with the covariances of neighbouring rows added (a Bartlett-weighted sum
over a few lags, as Newey and West) so that ground texture spanning
several rows is not counted as independent.  The interval is the estimate
plus or minus Student's t times the standard error, widened in quadrature
by the estimator's own systematic error budget.  It costs about one fit.

``bootstrap`` redraws the rows with replacement (``replicates`` times) and
takes the percentile interval of the re-estimates; the local polynomial
and binning fit every replicate in one vectorised pass, the spline one fit
each.

The interval's coverage is measured on noisy chips of known MTF by
``bench/coverage.py`` (docs/accuracy.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._stats import t_quantile
from ..errors import ParameterError
from ..metrics import first_crossing
from .spectrum import MIN_TRANSFER, NYQUIST

FREQUENCY_STEP_CY_PX = 0.0025   # a bootstrap replicate's MTF50 is read on this grid
METHODS = ("influence", "bootstrap", "none")
MAX_REPLICATES = 5000           # 200 are plenty; more only costs memory and time


@dataclass(frozen=True)
class Intervals:
    """How confidence intervals are computed.

    Parameters
    ----------
    method : {"influence", "bootstrap", "none"}
        Linearised (row influence) intervals, a bootstrap over rows, or none.
    confidence : float
        Coverage the interval aims at, in (0, 1) (0.95 for 95 %).
    replicates : int
        Bootstrap replicates (20 to 5000); ignored by the other methods.
    seed : int
        Bootstrap random seed, so that one image always gets one interval.

    Raises
    ------
    ParameterError
        For an unknown method or a value out of range.

    Examples
    --------
    >>> Intervals()                                  # doctest: +ELLIPSIS
    Intervals(method='influence', confidence=0.95, ...)
    >>> Intervals("bootstrap", replicates=500).replicates
    500
    """

    method: str = "influence"
    confidence: float = 0.95
    replicates: int = 200
    seed: int = 0

    def __post_init__(self):
        if self.method not in METHODS:
            raise ParameterError(f"interval method must be one of {', '.join(METHODS)}, got {self.method!r}")
        if (isinstance(self.replicates, bool) or not isinstance(self.replicates, (int, np.integer))
                or not 20 <= self.replicates <= MAX_REPLICATES):
            raise ParameterError(f"bootstrap replicates must be an integer from 20 to {MAX_REPLICATES}, "
                                 f"got {self.replicates!r}")
        if (isinstance(self.confidence, bool) or not isinstance(self.confidence, (int, float, np.floating))
                or not 0 < self.confidence < 1):
            raise ParameterError(f"confidence must be a number in (0, 1), got {self.confidence!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0:
            raise ParameterError(f"the interval seed must be an integer >= 0, got {self.seed!r}")
        object.__setattr__(self, "replicates", int(self.replicates))
        object.__setattr__(self, "confidence", float(self.confidence))
        object.__setattr__(self, "seed", int(self.seed))

    def as_dict(self) -> dict:
        out = {"method": self.method, "confidence": self.confidence}
        if self.method == "bootstrap":
            out.update(replicates=self.replicates, seed=self.seed)
        return out


NO_INTERVALS = Intervals("none")


def Bootstrap(replicates: int = 200, confidence: float = 0.95, seed: int = 0) -> Intervals:
    """Bootstrap interval settings: ``replicates`` row resamplings (0: no
    intervals at all).

    Parameters
    ----------
    replicates : int, optional
        Bootstrap replicates, 20 to 5000, or 0 for no intervals (default 200).
    confidence : float, optional
        Coverage the interval aims at, in (0, 1) (default 0.95).
    seed : int, optional
        Random seed of the row resampling (default 0).

    Returns
    -------
    Intervals
        Method "bootstrap", or "none" for 0 replicates.

    Raises
    ------
    ParameterError
        A number of replicates or a confidence out of range.

    Examples
    --------
    >>> Bootstrap(0).method
    'none'
    >>> Bootstrap(300).replicates
    300
    """
    if isinstance(replicates, (int, np.integer)) and not isinstance(replicates, bool) and replicates == 0:
        return Intervals("none", confidence)
    return Intervals("bootstrap", confidence, replicates, seed)


def as_intervals(value) -> Intervals:
    """Interval settings from what a caller gives: None (the default
    influence intervals), an :class:`Intervals`, a method's name as the
    CLI's ``--intervals`` takes it ("influence", "bootstrap": 200
    replicates, "none"), an int N (a bootstrap of N replicates; 0 for
    none), or False (none).

    Examples
    --------
    >>> as_intervals("bootstrap").replicates, as_intervals("none").method
    (200, 'none')
    """
    if value is None or value is True:
        return Intervals()
    if value is False:
        return NO_INTERVALS
    if isinstance(value, Intervals):
        return value
    if isinstance(value, str):
        return Intervals(value)
    if isinstance(value, (int, np.integer)):
        return Bootstrap(int(value))
    raise ParameterError(f"intervals must be None, an Intervals, one of {', '.join(map(repr, METHODS))}, or a "
                         f"number of bootstrap replicates; got {value!r}")


@dataclass(frozen=True)
class Interval:
    """A confidence interval [low, high] (units of the figure).

    Parameters
    ----------
    low, high : float
        The ends, in the figure's unit (NaN for no interval).

    Examples
    --------
    >>> from imgmtf import Interval
    >>> 0.26 in Interval(0.25, 0.27), Interval.none()
    (True, Interval(low=nan, high=nan))
    """

    low: float
    high: float

    @classmethod
    def none(cls) -> Interval:
        return cls(math.nan, math.nan)

    def __contains__(self, value: float) -> bool:
        return self.low <= value <= self.high

    def clipped_at_zero(self) -> Interval:
        """The interval of a figure that cannot be negative (an MTF, a
        modulus; a frequency): ends below 0 raised to 0.  It covers the
        truth whenever the unclipped interval did, so its coverage is
        unchanged; [0, h] says only that the figure is below h.

        Examples
        --------
        >>> Interval(-0.0124, 0.0273).clipped_at_zero()
        Interval(low=0.0, high=0.0273)
        """
        return Interval(max(self.low, 0.0), max(self.high, 0.0)) if self.low < 0 else self

    @property
    def width(self) -> float:
        return self.high - self.low


# -- linearised (influence) intervals -------------------------------------------
def influence_sd(influence: np.ndarray, rows: np.ndarray) -> tuple[float, int]:
    """Standard error of a linearised estimate from per-sample influences
    (gradient times residual) and each sample's row: the rows' summed
    influences, their variance plus Bartlett-weighted covariances of
    neighbouring rows (lags up to 4 (n / 100)^(2/9)).  Returns (sd, number
    of rows)."""
    sds, n = influence_sds(np.asarray(influence, float)[None, :], rows)
    return float(sds[0]), n


def influence_sds(influences: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, int]:
    """:func:`influence_sd` of every row of ``influences`` (estimates,
    samples) at once.  Returns (sds, number of rows)."""
    ids, inverse = np.unique(rows, return_inverse=True)
    n, m = ids.size, influences.shape[0]
    bins = (inverse[None, :] + n * np.arange(m)[:, None]).ravel()
    per_row = np.bincount(bins, weights=influences.ravel(), minlength=m * n).reshape(m, n)
    if n < 3:
        return np.full(m, math.nan), n
    centred = per_row - per_row.mean(axis=1, keepdims=True)
    variance = np.einsum("ij,ij->i", centred, centred)
    lags = int(math.ceil(4 * (n / 100.0) ** (2.0 / 9.0)))
    for lag in range(1, min(lags, n - 1) + 1):
        variance += 2.0 * (1.0 - lag / (lags + 1.0)) * np.einsum("ij,ij->i", centred[:, lag:], centred[:, :-lag])
    return np.sqrt(np.maximum(variance, 0.0) * n / (n - 1)), n


def linearised_interval(value: float, sd: float, rows: int, confidence: float,
                        systematic: float = 0.0) -> Interval:
    """``value`` plus or minus Student's t (rows - 1 degrees of freedom)
    times the standard error ``sd`` widened by a ``systematic`` standard
    deviation in quadrature."""
    if not (math.isfinite(value) and math.isfinite(sd)) or rows < 3:
        return Interval.none()
    half = t_quantile(0.5 + confidence / 2, rows - 1) * math.hypot(sd, systematic)
    return Interval(value - half, value + half)


# -- bootstrap ----------------------------------------------------------------
def row_weights(rows: np.ndarray, replicates: int, rng: np.random.Generator):
    """Bootstrap weights: ``weights_of(mask)`` -> array (replicates,
    mask.sum()), each selected sample weighted by how often its row
    (``rows`` labels each sample's row) was drawn when as many rows as there
    are were drawn with replacement, the same draws for every mask."""
    ids, inverse = np.unique(rows, return_inverse=True)
    n = ids.size
    draws = rng.integers(0, n, size=(replicates, n)) + n * np.arange(replicates)[:, None]
    counts = np.bincount(draws.ravel(), minlength=replicates * n).reshape(replicates, n).astype(float)

    def weights_of(mask: np.ndarray) -> np.ndarray:
        return counts[:, inverse[mask]]
    return weights_of


def spectral_figures(profiles: np.ndarray, step: float, divisor) -> tuple[np.ndarray, np.ndarray]:
    """MTF at Nyquist and MTF50 (cy/px) of every windowed profile (rows of
    ``profiles``, sampled every ``step`` px): |DFT| normalised at zero,
    divided by |divisor(f)| (NaN where it is below ``MIN_TRANSFER``), as
    :func:`imgmtf.estimate.spectrum.corrected_mtf` does for one profile."""
    f = np.arange(0.0, 1.0 + 1e-9, FREQUENCY_STEP_CY_PX)
    x = np.arange(profiles.shape[-1]) * step
    modulus = np.abs(profiles @ np.exp(-2j * np.pi * x[:, None] * f[None, :]))
    div = np.abs(divisor(f) / divisor(np.zeros(1)))
    with np.errstate(invalid="ignore", divide="ignore"):
        mtf = np.where(div >= MIN_TRANSFER, modulus / modulus[:, :1] / np.where(div > 0, div, 1), np.nan)
    nyquist = mtf[:, int(round(NYQUIST / FREQUENCY_STEP_CY_PX))]
    return nyquist, first_crossing(f, mtf, 0.5)


def percentile_interval(samples: np.ndarray, confidence: float) -> Interval:
    """Central percentile interval of the finite ``samples``; NaN when fewer
    than 90 % of them are finite (the figure is not defined often enough
    for an interval to mean anything)."""
    samples = np.asarray(samples, float)
    finite = samples[np.isfinite(samples)]
    if finite.size < 0.9 * samples.size or finite.size == 0:
        return Interval.none()
    tail = 50.0 * (1.0 - confidence)
    low, high = np.percentile(finite, [tail, 100.0 - tail])
    return Interval(float(low), float(high))


def bootstrap_figures(settings: Intervals, distance: np.ndarray, rows: np.ndarray, span_px: float,
                      resample, windowed_profile, step: float, divisor) -> tuple[Interval, Interval]:
    """Intervals for MTF at Nyquist and MTF50 (cy/px) by resampling rows.

    Parameters
    ----------
    settings : Intervals
        The interval settings (method "bootstrap").
    distance : numpy.ndarray
        Every profile sample's distance from the target line (px).
    rows : numpy.ndarray
        Every sample's row.
    span_px : float
        The profile is needed within +-span_px of the line.
    resample : callable
        ``resample(keep, weights, half_range)`` -> Resampled, the
        estimator's own resampling of the samples selected by ``keep``
        under a stack of ``weights``.
    windowed_profile : callable
        ``(grid, values, weights_of) -> profiles``: the estimator's
        windowed LSF (or PRF) of each replicate, shape (replicates, n);
        ``weights_of(mask)`` gives the replicates' weights of the samples
        selected by ``mask`` (see :func:`row_weights`).
    step : float
        The profile's sample step (px).
    divisor : callable
        The estimator's transfer correction (see :mod:`.spectrum`).

    Returns
    -------
    mtf_nyquist_ci, mtf50_ci_cy_px : Interval
        The intervals of the MTF at Nyquist and of MTF50 (cy/px).
    """
    rng = np.random.default_rng(settings.seed)
    keep = np.abs(distance) <= span_px + 2.0
    weights_of = row_weights(rows, settings.replicates, rng)
    resampled = resample(keep, weights_of(keep), span_px)
    profiles = windowed_profile(resampled.grid, resampled.values, weights_of)
    complete = np.isfinite(profiles).all(axis=1)
    nyquist, fifty = spectral_figures(np.where(complete[:, None], profiles, 0.0), step, divisor)
    nyquist[~complete] = np.nan
    fifty[~complete] = np.nan
    return (percentile_interval(nyquist, settings.confidence),
            percentile_interval(fifty, settings.confidence))
