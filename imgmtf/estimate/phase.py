"""A row locator's bias with the sub-pixel phase: where a target falls
within a pixel shifts where a per-row fit places it, most for a sharp or
sharpened target (aliasing: up to 0.3 px on a sharpened edge of MTF 0.6 at
Nyquist).  The bias repeats with the phase, where texture, noise or a bend
do not, so that the rows' scatter about their line, and which rows the line
keeps, are judged beyond it.
"""
from __future__ import annotations

import numpy as np

from ._order import median

PHASE_HARMONICS = 2             # the bias as a function of sub-pixel phase: this many harmonics
MIN_PHASE_ROWS = 20


def phase_bias(resid: np.ndarray, line: np.ndarray, fit: np.ndarray | None = None) -> np.ndarray:
    """The part of the per-row locations' residuals ``resid`` (px) about
    their line that the rows' sub-pixel phase explains (the fractional
    part of the line's position ``line``, px): ``PHASE_HARMONICS``
    harmonics fitted robustly (a few wild rows must not take the model)
    to the rows ``fit`` selects (all by default), evaluated at every row;
    zeros for fewer than ``MIN_PHASE_ROWS`` rows.

    Examples
    --------
    >>> line = 0.1 * np.arange(100.0)
    >>> bias = 0.3 * np.sin(2 * np.pi * line)
    >>> float(np.abs(phase_bias(bias, line) - bias).max()) < 1e-9
    True
    """
    fit = np.ones(resid.size, bool) if fit is None else fit
    if fit.sum() < MIN_PHASE_ROWS:
        return np.zeros_like(resid)
    phase = 2 * np.pi * np.mod(line, 1.0)
    design = np.column_stack([np.ones_like(phase)] + [f(k * phase) for k in range(1, PHASE_HARMONICS + 1)
                                                      for f in (np.cos, np.sin)])
    weights = np.ones(int(fit.sum()))
    for _ in range(3):
        coef, *_ = np.linalg.lstsq(design[fit] * weights[:, None], resid[fit] * weights, rcond=None)
        out = resid[fit] - design[fit] @ coef
        scale = max(1.4826 * float(median(np.abs(out))), 1e-9)
        weights = 1.0 / np.sqrt(np.maximum(1.0, np.abs(out) / (1.5 * scale)))
    return design @ coef


def without_phase_bias(resid: np.ndarray, line: np.ndarray) -> np.ndarray:
    """The residuals ``resid`` (px) less their :func:`phase_bias`.

    Examples
    --------
    >>> line = 0.1 * np.arange(100.0)
    >>> float(np.abs(without_phase_bias(0.3 * np.sin(2 * np.pi * line), line)).max()) < 1e-9
    True
    """
    return resid - phase_bias(resid, line)
