"""A row locator's bias with the sub-pixel phase: where a target falls
within a pixel shifts where a per-row fit places it, most for a sharp or
sharpened target (aliasing: up to 0.3 px on a sharpened edge of MTF 0.6 at
Nyquist).  The bias repeats with the phase, where texture, noise or a bend
do not, so that the rows' scatter about their line, and which rows the line
keeps, are judged beyond it.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .ragged import Groups, least_squares

PHASE_HARMONICS = 2             # the bias as a function of sub-pixel phase: this many harmonics
MIN_PHASE_ROWS = 20


def phase_bias(resid: np.ndarray, line: np.ndarray, fit: np.ndarray | None = None) -> np.ndarray:
    """The part of the per-row locations' residuals ``resid`` (px) about
    their line that the rows' sub-pixel phase explains (the fractional
    part of the line's position ``line``, px): ``PHASE_HARMONICS``
    harmonics fitted robustly (a few wild rows must not take the model)
    to the rows ``fit`` selects (all by default), evaluated at every row;
    zeros for fewer than ``MIN_PHASE_ROWS`` rows.  A batch of one of
    :func:`phase_bias_many`.

    Examples
    --------
    >>> line = 0.1 * np.arange(100.0)
    >>> bias = 0.3 * np.sin(2 * np.pi * line)
    >>> float(np.abs(phase_bias(bias, line) - bias).max()) < 1e-9
    True
    """
    return phase_bias_many([(resid, line, fit)])[0]


def phase_bias_many(calls: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray | None]]) -> list[np.ndarray]:
    """:func:`phase_bias` of many targets' rows, fitted together
    (:mod:`.ragged`): each target's bias the same, to the bit, as alone.

    Parameters
    ----------
    calls : sequence of (numpy.ndarray, numpy.ndarray, numpy.ndarray or None)
        Each target's ``resid``, ``line`` and ``fit`` of :func:`phase_bias`.

    Returns
    -------
    list of numpy.ndarray
        Each target's bias at its every row (px).

    Examples
    --------
    >>> line = 0.1 * np.arange(100.0)
    >>> a, b = phase_bias_many([(0.3 * np.sin(2 * np.pi * line), line, None), (np.zeros(10), line[:10], None)])
    >>> float(np.abs(a - 0.3 * np.sin(2 * np.pi * line)).max()) < 1e-9, b.tolist() == [0.0] * 10
    (True, True)
    """
    fits = [np.ones(resid.size, bool) if fit is None else fit for resid, _, fit in calls]
    used = [k for k, fit in enumerate(fits) if fit.sum() >= MIN_PHASE_ROWS]
    out = [np.zeros_like(resid) for resid, _, _ in calls]
    if not used:
        return out
    rows = Groups([calls[k][1].size for k in used])
    phase = 2 * np.pi * np.mod(np.concatenate([calls[k][1] for k in used]), 1.0)
    design = [np.ones_like(phase)] + [f(k * phase) for k in range(1, PHASE_HARMONICS + 1) for f in (np.cos, np.sin)]
    take = np.concatenate([fits[k] for k in used])
    groups = Groups([int(fits[k].sum()) for k in used])
    resid = np.concatenate([calls[k][0] for k in used])[take]
    columns = [column[take] for column in design]
    weights = np.ones(resid.size)
    for _ in range(3):
        coef, _ = least_squares(groups, [column * weights for column in columns], resid * weights)
        residual = resid - sum(column * groups.spread(coef[:, i]) for i, column in enumerate(columns))
        scale = np.maximum(1.4826 * groups.median(np.abs(residual)), 1e-9)
        weights = 1.0 / np.sqrt(np.maximum(1.0, np.abs(residual) / groups.spread(1.5 * scale)))
    bias = sum(column * rows.spread(coef[:, i]) for i, column in enumerate(design))
    for j, k in enumerate(used):
        out[k] = bias[rows.starts[j]: rows.starts[j] + rows.sizes[j]]
    return out


def without_phase_bias(resid: np.ndarray, line: np.ndarray) -> np.ndarray:
    """The residuals ``resid`` (px) less their :func:`phase_bias`.

    Examples
    --------
    >>> line = 0.1 * np.arange(100.0)
    >>> float(np.abs(without_phase_bias(0.3 * np.sin(2 * np.pi * line), line)).max()) < 1e-9
    True
    """
    return resid - phase_bias(resid, line)
