"""The Lag stage ('lag'): a one-sided response along each axis (detector
lag, a readout's RC tail): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import FitSpec, Stage, exponential_radius, param, register


@register
@dataclass(frozen=True)
class Lag(Stage):
    """A one-sided exponential response per axis: the LSF across track
    exp(-x / Lx) / |Lx| on the side of x that has the sign of Lx (0 on the
    other), along track likewise with Ly, so
    T = 1 / ((1 + 2 pi i Lx fx) (1 + 2 pi i Ly fy)) with the transform
    T(f) = integral of h(x) exp(-2 pi i f x) dx.

    The transfer is complex: the sensor gains a phase transfer function and
    its PSF leans one way, as a detector's lag or a readout's RC tail makes
    it lean along the direction it reads.  Its MTF per axis is
    1 / sqrt(1 + (2 pi L f)^2); its phase, -atan(2 pi L f), holds a shift by
    L (which an edge's location takes up) and the asymmetry.  Positive
    lengths point the tail toward increasing column (x) and row (y).

    Parameters
    ----------
    length_x_m, length_y_m : float
        The signed e-folding lengths Lx (across track, along image columns)
        and Ly (along track, rows), metres on the ground (default 0: no
        lag, where a fit starts; the data then choose the tail's side).

    Raises
    ------
    ParameterError
        A parameter that is not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Lag
    >>> stage = Lag(length_x_m=0.0, length_y_m=0.5)
    >>> t = complex(stage.transfer(0.0, 0.5, 1.0))
    >>> round(abs(t), 4), round(t.imag, 4)                        # 1 / sqrt(1 + (pi / 2)^2)
    (0.537, -0.453)
    """

    name: ClassVar[str] = "lag"
    title: ClassVar[str] = "one-sided lag"
    length_x_m: float = param(0.0, "m", FitSpec(kind="length", power=1, axis="x", upper_px=4.0, rank=2,
                                                signed=True), signed=True)
    length_y_m: float = param(0.0, "m", FitSpec(kind="length", power=1, axis="y", upper_px=4.0, rank=2,
                                                signed=True), signed=True)

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        fx, fy = np.asarray(fx, float), np.asarray(fy, float)
        return 1.0 / ((1.0 + 2j * np.pi * self.length_x_m * fx) * (1.0 + 2j * np.pi * self.length_y_m * fy))

    def support_radius_m(self, gsd_m: float) -> float:
        return exponential_radius(self.length_x_m, self.length_y_m)
