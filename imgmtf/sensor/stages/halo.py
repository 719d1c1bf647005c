"""The Halo stage ('halo'): a share of the energy scattered into a broad
isotropic kernel: see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import FitSpec, Stage, param, register


@register
@dataclass(frozen=True)
class Halo(Stage):
    """A scatter halo: a fraction eta of the energy spread by a broad 2-D
    exponential kernel exp(-r / R) / (2 pi R^2), the rest left in place:
    T = 1 - eta + eta (1 + (2 pi R f)^2)^(-3/2), f the radial frequency.

    Stray light and scatter in the optics and the focal plane put a few
    per cent of an edge's step several pixels from it, a broad foot that
    no core stage explains: the MTF drops by about eta at the lowest
    frequencies and then runs flat.

    Parameters
    ----------
    fraction : float
        The share eta of the energy in the halo, in [0, 1] (default 0: no
        halo, where a fit starts, so that a halo the data do not need is
        held at none).
    radius_m : float
        The kernel's e-folding radius R, metres on the ground, >= 0 (default
        3); its LSF has standard deviation sqrt(3) R.

    Raises
    ------
    ParameterError
        A fraction outside [0, 1], or a parameter that is negative, not
        finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Halo
    >>> stage = Halo(fraction=0.1, radius_m=3.0)
    >>> round(float(stage.transfer(0.5, 0.0, 1.0)), 4)               # past the kernel: 1 - eta
    0.9001
    >>> float(stage.transfer(0.0, 0.0, 1.0))
    1.0
    """

    name: ClassVar[str] = "halo"
    title: ClassVar[str] = "scatter halo"
    fraction: float = param(0.0, "", FitSpec(kind="fraction", power=1, upper_px=0.5, rank=2), high=1.0)
    radius_m: float = param(3.0, "m", FitSpec(upper_px=12.0, rank=4))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        f2 = np.asarray(fx, float) ** 2 + np.asarray(fy, float) ** 2
        kernel = (1.0 + (2.0 * np.pi * self.radius_m) ** 2 * f2) ** -1.5
        return 1.0 - self.fraction + self.fraction * kernel

    def support_radius_m(self, gsd_m: float) -> float:
        # the kernel leaves (1 + r / R) exp(-r / R) of its energy beyond r: solve for 1e-9 / eta
        if self.fraction == 0.0 or self.radius_m == 0.0:
            return 0.0
        target = math.log(self.fraction / 1e-9) if self.fraction > 1e-9 else 0.0
        u = max(target, 1.0)
        for _ in range(6):
            u = target + math.log1p(u)
        return u * self.radius_m
