"""The Detector stage ('detector'): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from ..lines import sinc
from .base import FitSpec, Stage, param, register


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
