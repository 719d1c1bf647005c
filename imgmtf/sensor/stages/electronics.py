"""The Electronics stage ('electronics'): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import FitSpec, Stage, param, register


@register
@dataclass(frozen=True)
class Electronics(Stage):
    """First-order 2-D Butterworth low-pass of the detector electronics:
    T = 1 / (1 + (D / D0)^2), D = sqrt(fx^2 + fy^2).

    Parameters
    ----------
    cutoff_cy_m : float
        The cut-off D0, cycles per metre on the ground, > 0; ``math.inf``
        for no filter (default 1.4, the paper's).

    Raises
    ------
    ParameterError
        A cut-off that is not > 0 or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Electronics
    >>> round(float(Electronics(1.4).transfer(0.5, 0.0, 1.0)), 4)
    0.8869
    """

    name: ClassVar[str] = "electronics"
    title: ClassVar[str] = "electronics (Butterworth)"
    cutoff_cy_m: float = param(1.4, "cy/m", FitSpec(kind="frequency", upper_px=3.0, rank=4),
                                positive=True, allow_inf=True)

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        fx, fy = np.asarray(fx, float), np.asarray(fy, float)
        return 1.0 / (1.0 + (fx**2 + fy**2) / self.cutoff_cy_m**2)

    def support_radius_m(self, gsd_m: float) -> float:
        # the PSF is 2 pi D0^2 K0(2 pi D0 r); the energy outside r is u K1(u),
        # u = 2 pi D0 r, below sqrt(pi u / 2) exp(-u) (1 + 3 / 8u): solve for 1e-9
        if math.isinf(self.cutoff_cy_m):
            return 0.0
        u = math.log(1e9)
        for _ in range(4):
            u = math.log(1e9 * math.sqrt(math.pi * u / 2.0) * (1.0 + 3.0 / (8.0 * u)))
        return u / (2.0 * math.pi * self.cutoff_cy_m)
