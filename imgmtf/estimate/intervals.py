"""Confidence intervals for MTF figures: a bootstrap over the target's rows.

The rows of an edge or bar chip are the independent units of its noise
(and of ground texture, which is correlated along a row but not from one
row to the next in the vertical frame), so a replicate draws as many rows
as the chip has, with replacement, and weights every profile sample by how
often its row was drawn.  The resampling methods take a stack of such
weights at once (:func:`imgmtf.resampling.resample_profile`), and every
replicate's spectrum is one row of a matrix product, so the replicates
cost no Python loop (the smoothing spline excepted: one fit per replicate).

What a replicate re-estimates: the smoothed profile, its derivative (for
an edge), the background (for a bar) and so the MTF.  What it keeps fixed:
the fitted target line, the LSF window and the corrections, whose own
variability is far below the noise's (a line-slope error of 0.01 px over
the chip blurs the profile by less than 1e-4 in MTF at Nyquist).

The interval is the percentile interval of the replicates.  Its coverage
was measured on noisy synthetic chips of known MTF (``bench/coverage.py``,
docs/accuracy.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..metrics import first_crossing
from .spectrum import MIN_TRANSFER, NYQUIST

FREQUENCY_STEP_CY_PX = 0.0025   # MTF50 is read on this grid, linearly interpolated


@dataclass(frozen=True)
class Bootstrap:
    """Bootstrap settings.

    replicates : number of row resamplings; 0 switches intervals off.
    confidence : coverage the interval aims at (0.95 for 95 %).
    seed : random seed, so that the same image gives the same interval.
    """

    replicates: int = 200
    confidence: float = 0.95
    seed: int = 0

    def __post_init__(self):
        if not (isinstance(self.replicates, int) and self.replicates >= 0):
            raise ParameterError(f"bootstrap replicates must be an integer >= 0, got {self.replicates!r}")
        if self.replicates and self.replicates < 20:
            raise ParameterError(f"a bootstrap needs at least 20 replicates for an interval, "
                                 f"got {self.replicates}")
        if not 0 < self.confidence < 1:
            raise ParameterError(f"confidence must be in (0, 1), got {self.confidence}")

    def as_dict(self) -> dict:
        return {"replicates": self.replicates, "confidence": self.confidence, "seed": self.seed}


NO_BOOTSTRAP = Bootstrap(0)


@dataclass(frozen=True)
class Interval:
    """A confidence interval [low, high] (units of the figure)."""

    low: float
    high: float

    @classmethod
    def none(cls) -> "Interval":
        return cls(math.nan, math.nan)

    def __contains__(self, value: float) -> bool:
        return self.low <= value <= self.high

    @property
    def width(self) -> float:
        return self.high - self.low


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
    :func:`imgmtf.mtf.corrected_mtf` does for one profile."""
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


def bootstrap_figures(settings: Bootstrap, distance: np.ndarray, rows: np.ndarray, span_px: float,
                      resample, windowed_profile, step: float,
                      divisor) -> tuple[Interval, Interval]:
    """Intervals for MTF at Nyquist and MTF50 (cy/px) by resampling rows.

    Parameters
    ----------
    settings : the bootstrap's settings.
    distance : every profile sample's distance from the target line (px).
    rows : every sample's row.
    span_px : the profile is needed within +-span_px of the line.
    resample : ``resample(keep, weights, half_range)`` -> Resampled, the
        estimator's own resampling of the samples selected by ``keep``
        under a stack of ``weights``.
    windowed_profile : ``(grid, values, weights_of) -> profile`` the
        estimator's windowed LSF (or PRF) of each replicate, shape
        (replicates, n); ``weights_of(mask)`` gives the replicates' weights
        of the samples selected by ``mask`` (see :func:`row_weights`).
    step : the profile's sample step (px).
    divisor : the estimator's transfer correction (see :mod:`imgmtf.mtf`).
    """
    if settings.replicates == 0:
        return Interval.none(), Interval.none()
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
