"""Scalar figures read off sampled curves: half-maximum widths and level
crossings.  Shared by the sensor model and the estimators so that the truth
and the estimate are read off in the same way."""
from __future__ import annotations

import numpy as np


def fwhm(x: np.ndarray, y: np.ndarray) -> float:
    """Full width at half maximum of a single-peaked curve ``y(x)``.

    The half-maximum crossings nearest the peak on each side are found by
    linear interpolation.  Returns NaN when a side never falls below half
    the peak.  The result is in the units of ``x``.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    peak = int(np.argmax(y))
    half = y[peak] / 2.0
    below_right = np.nonzero(y[peak:] < half)[0]
    below_left = np.nonzero(y[: peak + 1] < half)[0]
    if below_right.size == 0 or below_left.size == 0:
        return float("nan")
    r = peak + below_right[0]
    left = below_left[-1]
    x_right = x[r - 1] + (y[r - 1] - half) / (y[r - 1] - y[r]) * (x[r] - x[r - 1])
    x_left = x[left] + (half - y[left]) / (y[left + 1] - y[left]) * (x[left + 1] - x[left])
    return float(x_right - x_left)


def first_crossing(x: np.ndarray, y: np.ndarray, level: float):
    """First ``x`` at which a curve starting above ``level`` falls below it
    (linear interpolation between samples); NaN if it never does.  ``y`` may
    stack curves on its leading axes (..., len(x)): one crossing each."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    below = y < level
    if y.ndim == 1:
        # one curve (a report reads thousands): the same arithmetic on its two samples, without the
        # stacked path's gathers
        k = int(np.argmax(below))
        if k == 0:                           # never below, or below from the start
            return float("nan")
        y0, y1 = y[k - 1], y[k]
        return float(x[k - 1] + (y0 - level) / (y0 - y1) * (x[k] - x[k - 1]))
    i = np.argmax(below, axis=-1)
    found = below.any(axis=-1) & (i > 0)
    i = np.clip(i, 1, x.size - 1)[..., None]
    y0 = np.take_along_axis(y, i - 1, axis=-1)[..., 0]
    y1 = np.take_along_axis(y, i, axis=-1)[..., 0]
    i = i[..., 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        crossing = x[i - 1] + (y0 - level) / (y0 - y1) * (x[i] - x[i - 1])
    return np.where(found, crossing, np.nan)
