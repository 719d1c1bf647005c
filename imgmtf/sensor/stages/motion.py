"""The Motion stage ('motion'): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import FitSpec, Stage, param, register


@register
@dataclass(frozen=True)
class Motion(Stage):
    """Along-track smear during integration, a rect along y only:
    T = sinc(fy S).

    Parameters
    ----------
    length_m : float
        The smear S, metres on the ground, >= 0 (default 0.25, the
        paper's).

    Raises
    ------
    ParameterError
        A parameter that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Motion
    >>> stage = Motion(0.25)
    >>> float(stage.transfer(0.5, 0.0, 1.0)), round(float(stage.transfer(0.0, 0.5, 1.0)), 4)
    (1.0, 0.9745)
    """

    name: ClassVar[str] = "motion"
    title: ClassVar[str] = "along-track motion"
    length_m: float = param(0.25, "m", FitSpec(axis="y", upper_px=3.0, rank=2))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        fy = np.asarray(fy, float)
        return np.broadcast_to(np.sinc(fy * self.length_m), np.broadcast(np.asarray(fx), fy).shape)

    def support_radius_m(self, gsd_m: float) -> float:
        return self.length_m / 2.0
