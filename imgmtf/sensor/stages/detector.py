"""The Detector stage ('detector'): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import FitSpec, Stage, param, register

#: below this |pi t| every sine rounds to its argument (glibc returns it for |x| < 2^-26), so sinc(t)
#: is 1 exactly: an axis's frequencies along a normal at 0 or 90 deg (0, or f cos 90 deg ~ 6e-17 f)
SINC_ONE_BELOW = 2.0 ** -27
#: what np.sinc puts for a zero argument (looked up once: a fit's every detector transfer asked np.finfo)
_EPS = float(np.finfo(float).eps)


def sinc(t: ArrayLike) -> np.ndarray:
    """``np.sinc(t)``, sin(pi t) / (pi t), the same numbers, in fewer
    passes: the product and the quotient written in place, and all ones
    when every |pi t| is below :data:`SINC_ONE_BELOW` (the sine of each
    then its argument: a detector's factor along the axis a normal does
    not lean on, whose sines were half a report's FWHM transfer).

    Examples
    --------
    >>> t = np.array([0.0, 1e-30, 0.25, -1.5, 3.0, np.nan])
    >>> bool(np.array_equal(sinc(t), np.sinc(t), equal_nan=True))
    True
    >>> sinc(np.full(3, 1e-17)).tolist()
    [1.0, 1.0, 1.0]
    """
    y = np.multiply(t, np.pi, out=np.empty(t.shape if isinstance(t, np.ndarray) else np.shape(t)), dtype=float)
    if y.size and np.abs(y).max() < SINC_ONE_BELOW:           # (NaN compares False: computed)
        return np.ones(y.shape)[()]
    y[y == 0] = _EPS                          # as np.sinc: sin(eps) / eps, 1
    out = np.sin(y)
    out /= y
    return out[()] if out.ndim == 0 else out


@register
@dataclass(frozen=True)
class Detector(Stage):
    """Detector aperture (the GIFOV) as a rect: T = sinc(fx wx) sinc(fy wy),
    sinc(t) = sin(pi t) / (pi t).

    Parameters
    ----------
    width_x_m, width_y_m : float
        Widths of the aperture across and along track, metres on the
        ground, >= 0 (default 1, the paper's GIFOV).

    Raises
    ------
    ParameterError
        A parameter that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Detector
    >>> round(float(Detector(1.0, 1.0).transfer(0.5, 0.0, 1.0)), 4)         # 2 / pi at Nyquist
    0.6366
    """

    name: ClassVar[str] = "detector"
    title: ClassVar[str] = "detector aperture"
    width_x_m: float = param(1.0, "m", FitSpec(axis="x", upper_px=3.0, rank=6))
    width_y_m: float = param(1.0, "m", FitSpec(axis="y", upper_px=3.0, pair="width_x_m", rank=6))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        out = sinc(np.asarray(fx, float) * self.width_x_m)
        out = out * sinc(np.asarray(fy, float) * self.width_y_m)          # (broadcast: not in place)
        return out

    def support_radius_m(self, gsd_m: float) -> float:
        return math.hypot(self.width_x_m, self.width_y_m) / 2.0
