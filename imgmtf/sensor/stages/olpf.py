"""The OLPF stage ('olpf'): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import FitSpec, Stage, param, register


@register
@dataclass(frozen=True)
class OLPF(Stage):
    """Four-spot birefringent optical low-pass filter, four equal points at
    (+-d/2, +-d/2): T = cos(pi d fx) cos(pi d fy).

    Parameters
    ----------
    split_m : float
        The split d, metres on the ground, >= 0 (default 0.5).

    Raises
    ------
    ParameterError
        A split that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import OLPF
    >>> round(float(OLPF(1.0).transfer(0.5, 0.0, 1.0)), 12)      # a 1-px split nulls Nyquist
    0.0
    """

    name: ClassVar[str] = "olpf"
    title: ClassVar[str] = "4-spot OLPF"
    has_width: ClassVar[bool] = False
    split_m: float = param(0.5, "m", FitSpec(upper_px=2.0, rank=5))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        d = self.split_m
        return np.cos(np.pi * d * np.asarray(fx, float)) * np.cos(np.pi * d * np.asarray(fy, float))

    def support_radius_m(self, gsd_m: float) -> float:
        return self.split_m / math.sqrt(2.0)
