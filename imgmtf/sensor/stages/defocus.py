"""The Defocus stage ('defocus'): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import FitSpec, Stage, param, register


@register
@dataclass(frozen=True)
class Defocus(Stage):
    """Defocus as a uniform disk PSF (geometric optics):
    T = 2 J1(2 pi r f) / (2 pi r f), f the radial frequency.

    Parameters
    ----------
    radius_m : float
        The disk's radius r, metres on the ground, >= 0 (default 0.5).

    Raises
    ------
    ParameterError
        A radius that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Defocus
    >>> round(float(Defocus(0.5).transfer(0.5, 0.0, 1.0)), 4)
    0.7217
    """

    name: ClassVar[str] = "defocus"
    title: ClassVar[str] = "defocus disk"
    radius_m: float = param(0.5, "m", FitSpec(rank=2))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        from scipy.special import j1
        z = 2.0 * np.pi * self.radius_m * np.hypot(np.asarray(fx, float), np.asarray(fy, float))
        safe = np.where(z == 0, 1.0, z)
        return np.where(z == 0, 1.0, 2.0 * j1(safe) / safe)

    def support_radius_m(self, gsd_m: float) -> float:
        return self.radius_m
