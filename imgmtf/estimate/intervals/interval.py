"""What an interval method reads (:class:`Estimate`: the estimate's
samples, profile, window, tails and spectrum) and what it returns
(:class:`FigureIntervals`: an :class:`Interval` per figure)."""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..resampling import Resampled
from ..state import Profile, Samples, Spectrum, TailedLSF, Window
from .width import WidthReading


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


@dataclass(frozen=True)
class FigureIntervals:
    """The intervals of an estimate's figures, as an interval method gives them.

    Parameters
    ----------
    mtf_nyquist : Interval
        Of the MTF at Nyquist (0.5 cy/px).
    mtf50_cy_px : Interval
        Of MTF50, cy/px.
    warnings : tuple of str
        What the method must say of its intervals (what they leave out).

    Examples
    --------
    >>> FigureIntervals(Interval(-0.01, 0.02), Interval.none()).clipped_at_zero().mtf_nyquist
    Interval(low=0.0, high=0.02)
    """

    mtf_nyquist: Interval
    mtf50_cy_px: Interval
    warnings: tuple[str, ...] = ()

    @classmethod
    def none(cls) -> FigureIntervals:
        """No intervals (NaN ends)."""
        return cls(Interval.none(), Interval.none())

    def clipped_at_zero(self) -> FigureIntervals:
        """Both intervals with their ends below 0 raised to 0: an MTF (a
        modulus) and a frequency are never negative (see
        :meth:`Interval.clipped_at_zero`)."""
        return FigureIntervals(self.mtf_nyquist.clipped_at_zero(), self.mtf50_cy_px.clipped_at_zero(), self.warnings)


@dataclass(frozen=True, eq=False)
class Estimate:
    """What an interval method reads of an MTF estimate: the pipeline's
    records of it (:mod:`imgmtf.estimate.state`) and the few things its
    target kind supplies.

    Parameters
    ----------
    samples : Samples
        The profile's samples (distances, values, rows).
    profile : Profile
        The resampled profile the LSF was taken from.
    shape_profile : Profile
        The resampled profile the target's shape (and a width) was read
        from; ``profile`` may reach farther.
    centre_px : float
        The target's middle along the normal, px.
    window : Window
        The LSF window.
    lsf : TailedLSF
        The windowed LSF-like profile and its tails.
    spectrum : Spectrum
        The MTF and its figures.
    tail_power : int
        The power p of the sides' tail model, level + A / |s|^p.
    subtracts_background : bool
        Whether the LSF-like profile is the profile above a fitted
        background (a bar) rather than a derivative (an edge).
    lsf_of : callable
        The kind's LSF-like profile, ``(grid, values, background) -> (x,
        lsf, adjoint)``, for profiles stacked in rows.
    resample : callable
        ``(keep, weights, half_range_px) -> Resampled``: the estimate's own
        resampling of the samples ``keep`` selects under a stack of
        ``weights`` (one row a replicate).
    width : WidthReading or None
        The width the divisor rests on where it was read off the profile;
        None where the divisor is known.
    target : str
        The target as a user names it ("edge", "bar"), for messages.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60)
    >>> estimate = run(EdgeKind(), chip.image, make_settings()).estimate
    >>> estimate.tail_power, estimate.spectrum.mtf_nyquist == float(estimate.spectrum.mtf(0.5)[0])
    (1, True)
    """

    samples: Samples
    profile: Profile
    shape_profile: Profile
    centre_px: float
    window: Window
    lsf: TailedLSF
    spectrum: Spectrum
    tail_power: int
    subtracts_background: bool
    lsf_of: Callable[..., tuple[np.ndarray, np.ndarray, Callable[[np.ndarray], np.ndarray]]]
    resample: Callable[[np.ndarray, np.ndarray, float], Resampled]
    width: WidthReading | None
    target: str
