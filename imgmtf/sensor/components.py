"""Stages of the imaging chain, each with its analytic transfer function.

All functions take spatial frequencies in cycles per metre and parameters in
metres (or cycles per metre), and return the real transfer function
normalised to 1 at zero frequency.  ``fx`` is across track (image columns,
x), ``fy`` along track (image rows, y).

A parameter of 0 means the stage is absent (transfer 1 everywhere).
"""
from __future__ import annotations

import numpy as np


def gaussian_ft(fx, fy, sigma_x_m: float, sigma_y_m: float) -> np.ndarray:
    """Optics: transfer of a 2-D Gaussian PSF of standard deviations
    ``sigma_x_m``, ``sigma_y_m`` (metres): exp(-2 pi^2 (sx^2 fx^2 + sy^2 fy^2))."""
    fx, fy = np.asarray(fx, float), np.asarray(fy, float)
    return np.exp(-2.0 * np.pi**2 * (sigma_x_m**2 * fx**2 + sigma_y_m**2 * fy**2))


def pixel_ft(fx, fy, width_x_m: float, width_y_m: float) -> np.ndarray:
    """Detector: transfer of a rect aperture (the GIFOV) of the given widths
    (metres): sinc(fx wx) sinc(fy wy), with sinc(t) = sin(pi t) / (pi t)."""
    fx, fy = np.asarray(fx, float), np.asarray(fy, float)
    return np.sinc(fx * width_x_m) * np.sinc(fy * width_y_m)


def smear_ft(fy, length_m: float) -> np.ndarray:
    """Motion: transfer of a rect of ``length_m`` metres along track only
    (the ground distance travelled during integration): sinc(fy S)."""
    return np.sinc(np.asarray(fy, float) * length_m)


def butterworth_ft(fx, fy, cutoff_cy_m: float) -> np.ndarray:
    """Electronics: first-order 2-D Butterworth low-pass,
    1 / (1 + (D / D0)^2) with D = sqrt(fx^2 + fy^2) and D0 = ``cutoff_cy_m``
    (cycles per metre).  ``cutoff_cy_m = 0`` means no filter."""
    fx, fy = np.asarray(fx, float), np.asarray(fy, float)
    if cutoff_cy_m == 0:
        return np.ones(np.broadcast(fx, fy).shape)
    return 1.0 / (1.0 + (fx**2 + fy**2) / cutoff_cy_m**2)
