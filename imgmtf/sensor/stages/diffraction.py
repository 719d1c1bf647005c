"""The Diffraction stage ('diffraction'): see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import FitSpec, Stage, param, register


@register
@dataclass(frozen=True)
class Diffraction(Stage):
    """Diffraction by an aberration-free circular aperture, incoherent light.

    The cut-off is 1 / (wavelength x f-number) cycles per metre in the
    focal plane, ``pixel_pitch_m`` / (wavelength x f-number) cycles per
    pixel, and so pitch / (wavelength x N x GSD) cycles per metre on the
    ground.  T = (2/pi) (acos v - v sqrt(1 - v^2)) for v = f / f_c <= 1, 0
    beyond; f is the radial frequency.

    Parameters
    ----------
    f_number : float
        The working f-number N, > 0 (default 8).
    wavelength_m : float
        The wavelength, metres, > 0 (default 550e-9).
    pixel_pitch_m : float
        The detector pitch in the focal plane, metres, > 0 (default 5e-6):
        it maps the focal plane onto the GSD.

    Raises
    ------
    ParameterError
        A parameter that is not > 0 or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Diffraction
    >>> stage = Diffraction(f_number=8.0, wavelength_m=550e-9, pixel_pitch_m=5e-6)
    >>> round(stage.cutoff_cy_m(gsd_m=1.0), 4)                   # cy/m on the ground at a 1 m GSD
    1.1364
    """

    name: ClassVar[str] = "diffraction"
    title: ClassVar[str] = "diffraction"
    f_number: float = param(8.0, "", FitSpec(kind="f-number", power=1, upper_px=10.0, rank=2), positive=True)
    wavelength_m: float = param(550e-9, "m", positive=True)
    pixel_pitch_m: float = param(5e-6, "m", positive=True)

    def cutoff_cy_m(self, gsd_m: float) -> float:
        """Incoherent cut-off on the ground, cycles per metre."""
        return self.pixel_pitch_m / (self.wavelength_m * self.f_number * gsd_m)

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        v = np.minimum(np.hypot(np.asarray(fx, float), np.asarray(fy, float)) / self.cutoff_cy_m(gsd_m), 1.0)
        return (2.0 / np.pi) * (np.arccos(v) - v * np.sqrt(1.0 - v * v))

    def support_radius_m(self, gsd_m: float) -> float:
        # energy outside r: J0^2 + J1^2 of x = pi r f_c ~ 2 / (pi x) = 2 / (pi^2 r f_c);
        # the 1 % core, 20 lambda N; the line responses add the tails in closed form
        return 2.0 / (math.pi**2 * 0.01 * self.cutoff_cy_m(gsd_m))

    def tail_length_m(self, gsd_m: float) -> float:
        # T = 1 - (4 / pi) f / f_c + O(f^3) = 1 - 2 pi b |f|
        return 2.0 / (math.pi**2 * self.cutoff_cy_m(gsd_m))

    def fit_coordinates(self, gsd_m: float) -> dict[str, float]:
        # the blur length 1 / f_c in pixels: the MTF responds linearly to it (the cusp)
        return {"f_number": self.wavelength_m * self.f_number / self.pixel_pitch_m}

    def with_fit_coordinates(self, coordinates: dict[str, float], gsd_m: float) -> Stage:
        u = max(coordinates["f_number"], 1e-6)
        return self._replaced({"f_number": u * self.pixel_pitch_m / self.wavelength_m})
