"""A line response: the edge and line spread functions along one normal,
a closed-form reference plus a remainder sampled on a fine grid (what
:meth:`imgmtf.sensor.model.Sensor.line_response` returns)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True, eq=False)
class LineResponse:
    """Edge (ESF) and line (LSF) spread functions along one normal, in
    pixels: a closed-form reference (a Cauchy LSF b / pi (b^2 + x^2) for a
    sensor with diffraction, else a Gaussian of about the LSF's width) plus
    a remainder sampled every ``step_px`` from ``start_px``, zero beyond its
    grid.  The ESF rises from 0 to 1; both are exact to about 1e-7."""

    start_px: float
    step_px: float
    esf_remainder: np.ndarray
    lsf_remainder: np.ndarray
    reference: tuple[str, float]

    def esf(self, d_px: ArrayLike) -> np.ndarray:
        """Edge response at signed distances ``d_px`` (cubic Hermite between
        grid samples, whose slopes are the LSF)."""
        d = np.asarray(d_px, float)
        t = (d - self.start_px) / self.step_px
        n = self.esf_remainder.size
        k = np.clip(np.floor(t).astype(np.intp), 0, n - 2)
        u = np.clip(t - k, 0.0, 1.0)
        y, s, h = self.esf_remainder, self.lsf_remainder, self.step_px
        value = ((1 + 2 * u) * (1 - u) ** 2 * y[k] + u * (1 - u) ** 2 * h * s[k]
                 + u * u * (3 - 2 * u) * y[k + 1] + u * u * (u - 1) * h * s[k + 1])
        value = np.where((t < 0) | (t > n - 1), 0.0, value)
        kind, width = self.reference
        if kind == "cauchy":
            return value + 0.5 + np.arctan(d / width) / np.pi
        from scipy.special import ndtr
        return value + ndtr(d / width)

    def lsf(self, d_px: ArrayLike) -> np.ndarray:
        """Line spread function (1/px) at signed distances ``d_px``."""
        d = np.asarray(d_px, float)
        grid = self.start_px + self.step_px * np.arange(self.lsf_remainder.size)
        value = np.interp(d, grid, self.lsf_remainder, left=0.0, right=0.0)
        kind, width = self.reference
        if kind == "cauchy":
            return value + width / (np.pi * (width**2 + d**2))
        return value + np.exp(-0.5 * (d / width) ** 2) / (width * math.sqrt(2 * math.pi))


def reference_transfer(reference: tuple[str, float], f: np.ndarray) -> np.ndarray:
    """Transfer (1 at zero) of a line response's closed-form reference at
    ``f`` cy/px: a Cauchy LSF's exp(-2 pi b f), a Gaussian's
    exp(-2 pi^2 s^2 f^2)."""
    kind, width = reference
    if kind == "cauchy":
        return np.exp(-2 * np.pi * width * f)
    return np.exp(-2 * np.pi**2 * width**2 * f**2)
