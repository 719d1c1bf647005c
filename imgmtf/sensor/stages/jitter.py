"""The Jitter stage ('jitter'): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .base import FitSpec, Stage, param, register
from .optics import GaussianOptics


@register
@dataclass(frozen=True)
class Jitter(Stage):
    """Random line-of-sight jitter during integration, a Gaussian.  Its
    transfer has the form of the Gaussian optics', so a fit cannot tell
    the two apart: it holds one of them.

    Parameters
    ----------
    sigma_x_m, sigma_y_m : float
        Standard deviations across and along track, metres on the ground,
        >= 0 (default 0.1).

    Raises
    ------
    ParameterError
        A parameter that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Jitter
    >>> round(float(Jitter(0.0, 0.2).transfer(0.0, 0.5, 1.0)), 4)
    0.8209
    """

    name: ClassVar[str] = "jitter"
    title: ClassVar[str] = "jitter"
    sigma_x_m: float = param(0.1, "m", FitSpec(axis="x", rank=3))
    sigma_y_m: float = param(0.1, "m", FitSpec(axis="y", pair="sigma_x_m", rank=3))

    transfer = GaussianOptics.transfer
    support_radius_m = GaussianOptics.support_radius_m
