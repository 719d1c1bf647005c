"""Confidence intervals for MTF figures: a registry of methods
(:data:`METHODS`, name -> function) behind one dispatcher,
:func:`intervals`, and their settings (:class:`Intervals`).

A method is a function ``method(estimate, **options) -> FigureIntervals``
taking the :class:`Estimate` (the pipeline's records of the estimate) and
any of the options ``confidence``, ``replicates`` and ``seed`` it names;
adding one is a module beside :mod:`.influence` and :mod:`.bootstrap` and
one entry in :data:`METHODS` (the CLI's ``--intervals`` choices follow it,
a test checks).

``none`` gives no intervals (NaN ends).

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

import inspect
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from ...errors import ParameterError
from .bootstrap import bootstrap_intervals
from .influence import influence_intervals
from .interval import Estimate, FigureIntervals, Interval

__all__ = ["MAX_REPLICATES", "METHODS", "NO_INTERVALS", "Bootstrap", "Estimate", "FigureIntervals", "Interval",
           "Intervals", "as_intervals", "intervals", "no_intervals"]


def no_intervals(estimate: Estimate) -> FigureIntervals:
    """No intervals: the method ``none``.

    Parameters
    ----------
    estimate : Estimate
        The estimate (unread).

    Returns
    -------
    FigureIntervals
        NaN ends for both figures.

    Examples
    --------
    >>> no_intervals(None).mtf_nyquist              # it reads nothing of the estimate
    Interval(low=nan, high=nan)
    """
    return FigureIntervals.none()


#: the interval methods by name: linearised (row influence), a bootstrap over rows, none
METHODS: dict[str, Callable[..., FigureIntervals]] = {
    "influence": influence_intervals,
    "bootstrap": bootstrap_intervals,
    "none": no_intervals,
}
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


def intervals(estimate: Estimate, method: str = "influence", *, confidence: float = 0.95, replicates: int = 200,
              seed: int = 0) -> FigureIntervals:
    """The intervals of an estimate's MTF at Nyquist and MTF50 by ``method``.

    The options are checked as :class:`Intervals` checks them and each
    method is given those it names (``none`` none, ``influence`` the
    confidence, ``bootstrap`` all three).  Ends below 0 are raised to 0:
    an MTF (a modulus) and a frequency are never negative.

    Parameters
    ----------
    estimate : Estimate
        The estimate (:attr:`imgmtf.estimate.pipeline.Measurement.estimate`).
    method : str, optional
        A key of :data:`METHODS`: "influence" (default), "bootstrap" or "none".
    confidence : float, optional
        Coverage the intervals aim at, in (0, 1).
    replicates : int, optional
        Bootstrap replicates (20 to 5000).
    seed : int, optional
        The bootstrap's random seed.

    Returns
    -------
    FigureIntervals
        The intervals of the MTF at Nyquist and of MTF50 (cy/px), and what
        the method says of them.

    Raises
    ------
    ParameterError
        An unknown method or an option out of range.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=5.0, seed=1)
    >>> estimate = run(EdgeKind(), chip.image, make_settings(intervals="none")).estimate
    >>> linear, none = intervals(estimate), intervals(estimate, "none")
    >>> float(chip.true_mtf(0.5)) in linear.mtf_nyquist, none.mtf_nyquist
    (True, Interval(low=nan, high=nan))
    """
    chosen = Intervals(method, confidence, replicates, seed)
    function = METHODS[chosen.method]
    named = inspect.signature(function).parameters
    options = {name: value for name, value in asdict(chosen).items() if name != "method" and name in named}
    return function(estimate, **options).clipped_at_zero()
