"""A confidence interval: the value type every interval method returns."""
from __future__ import annotations

import math
from dataclasses import dataclass


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
