"""Where a fit starts a one-sided stage: the lag read off the edges' own
line spread functions.

A lag's likelihood is not convex in its length: started on the wrong side,
or at none (where the profile's asymmetry has no slope), the fit stays
there.  Cumulants add over independent blurs and every other stage is
symmetric, so the third cumulant of an edge's measured LSF along its
profile direction (cos a, sin a) is that of the lag alone: a one-sided
exponential of length L has 2 L^3, and the lag's projection onto the
direction is two of them, of lengths Lx cos a and Ly sin a.  Over the
edges, kappa3 = 2 (cos^3 a) Lx^3 + 2 (sin^3 a) Ly^3 is linear in Lx^3 and
Ly^3: a least-squares solve gives the start.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...sensor.model import Sensor
from ...sensor.stages import Lag, Stage
from .data import EdgeData

#: half-width (px) of the LSF about its centroid read for its third
#: cumulant: the lag's mass within a few lengths, the noisy far tails out
CUMULANT_HALF_WIDTH_PX = 5.0
#: the start's lengths are clipped to this (px), inside the fit's bounds
MAX_SEED_PX = 2.0


def third_cumulant(x_px: np.ndarray, lsf: np.ndarray, half_width_px: float = CUMULANT_HALF_WIDTH_PX) -> float:
    """Third central moment (px^3) of a sampled LSF within ``half_width_px``
    of its centroid (the same as its third cumulant).

    Examples
    --------
    >>> x = np.linspace(0.0, 40.0, 40001)
    >>> round(third_cumulant(x - 0.5, np.exp(-x / 0.5), 40.0), 4)      # 2 L^3 for L = 0.5
    0.25
    """
    x, lsf = np.asarray(x_px, float), np.asarray(lsf, float)
    mean = float(np.sum(x * lsf) / np.sum(lsf))
    near = np.abs(x - mean) <= half_width_px
    x, lsf = x[near], lsf[near]
    mean = float(np.sum(x * lsf) / np.sum(lsf))
    return float(np.sum((x - mean) ** 3 * lsf) / np.sum(lsf))


def lag_seed_px(data: Sequence[EdgeData]) -> tuple[float, float]:
    """The lag's lengths (px, signed, across and along) the edges' LSFs'
    third cumulants give (0 on an axis no edge sees)."""
    rows, kappa = [], []
    for d in data:
        angle = math.radians(d.profile_angle_deg)
        rows.append([2 * math.cos(angle) ** 3, 2 * math.sin(angle) ** 3])
        kappa.append(third_cumulant(d.measurement.lsf_x_px, d.measurement.lsf))
    cubes = np.linalg.lstsq(np.array(rows), np.array(kappa), rcond=None)[0]
    return tuple(float(np.clip(np.cbrt(c), -MAX_SEED_PX, MAX_SEED_PX)) for c in cubes)  # type: ignore[return-value]


def seeded(stages: list[Stage], data: Sequence[EdgeData], gsd: float, start: Sensor | None) -> list[Stage]:
    """``stages`` with a lag the starting sensor does not give started from
    the edges' asymmetry (:func:`lag_seed_px`)."""
    given = {s.name for s in start.stages} if start is not None else set()
    if "lag" in given or not any(isinstance(s, Lag) for s in stages):
        return stages
    lx, ly = lag_seed_px(data)
    return [Lag(lx * gsd, ly * gsd) if isinstance(s, Lag) else s for s in stages]
