"""The Diffusion stage ('diffusion'): exponential wings per axis (charge
diffusion, an RC readout's symmetric part): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import FitSpec, Stage, exponential_radius, param, register


@register
@dataclass(frozen=True)
class Diffusion(Stage):
    """Exponential-winged blur per axis, separable: the LSF across track
    exp(-|x| / Lx) / (2 Lx), along track likewise with Ly, so
    T = 1 / (1 + (2 pi Lx fx)^2) / (1 + (2 pi Ly fy)^2), a Lorentzian
    transfer on each axis.

    This is the tent-shaped core with straight wings on a log scale that
    real L0R edges show (charge diffusion between detectors, the symmetric
    part of a readout's response): a Gaussian of the same width leaves
    0.1 % of the step beyond +-2 px where these leave 10-20 %.  Unlike the
    isotropic Butterworth ``electronics`` stage, each axis has its own
    length, and the fit lets it reach several pixels.

    Parameters
    ----------
    length_x_m, length_y_m : float
        The e-folding lengths Lx (across track) and Ly (along track) of the
        LSF's wings, metres on the ground, >= 0; the LSF's
        standard deviation is sqrt(2) L (default 0: no wings, where a fit
        starts, so that a length the data do not need is held at none).

    Raises
    ------
    ParameterError
        A parameter that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Diffusion
    >>> stage = Diffusion(length_x_m=0.5, length_y_m=0.0)
    >>> round(float(stage.transfer(0.5, 0.0, 1.0)), 4)           # 1 / (1 + (pi / 2)^2)
    0.2884
    >>> float(stage.transfer(0.0, 0.5, 1.0))
    1.0
    """

    name: ClassVar[str] = "diffusion"
    title: ClassVar[str] = "diffusion (exponential wings)"
    length_x_m: float = param(0.0, "m", FitSpec(axis="x", upper_px=6.0, rank=3))
    length_y_m: float = param(0.0, "m", FitSpec(axis="y", upper_px=6.0, pair="length_x_m", rank=3))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        fx, fy = np.asarray(fx, float), np.asarray(fy, float)
        ax = (2.0 * np.pi * self.length_x_m) ** 2
        ay = (2.0 * np.pi * self.length_y_m) ** 2
        return 1.0 / ((1.0 + ax * fx * fx) * (1.0 + ay * fy * fy))

    def support_radius_m(self, gsd_m: float) -> float:
        return exponential_radius(self.length_x_m, self.length_y_m)
