"""A width read off the profile (a bar's), as the intervals need it: how
the reading moves with the profile's values, so that the width's own noise
joins the intervals of the figures its divisor corrects."""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class WidthReading:
    """A width W (px) read off the profile as the first zero f0 = 1 / W of
    R(f), a linear functional of the profile's values (a bar's spectrum
    about its centre).  ``freqs`` (cy/px): f0, then a grid about it;
    ``on_grid``: dR(f) / d value, one row per frequency over the profile's
    grid; ``per_background``: dR(f) / d background level; ``values``: R at
    ``freqs``; ``slope``: R'(f0); ``log_slope(f)``: d ln|divisor(f)| / dW;
    ``background_sides``: masks of the samples whose two sides' means the
    background level is the mean of (none: no background)."""

    width_px: float
    freqs: np.ndarray
    on_grid: np.ndarray
    per_background: np.ndarray
    values: np.ndarray
    slope: float
    log_slope: Callable[[np.ndarray], np.ndarray]
    background_sides: tuple[np.ndarray, ...] = ()

    def sample_pull(self, adjoint: Callable[[np.ndarray], np.ndarray], grid_size: int,
                    span: tuple[int, int]) -> np.ndarray:
        """dR(f) / dv for every sample v, one row per frequency of ``freqs``:
        through the adjoint of the resampling (onto ``grid_size`` points,
        of which ``span`` is the profile the width was read from) and
        through the background level."""
        return self.background_pull(adjoint(self.grid_weights(grid_size, span)))

    def grid_weights(self, grid_size: int, span: tuple[int, int]) -> np.ndarray:
        """dR(f) / d value over a resampling's whole grid of ``grid_size``
        points, ``span`` the profile's run of it (zero beyond)."""
        full = np.zeros((self.freqs.size, grid_size))
        full[:, span[0]: span[1]] = self.on_grid
        return full

    def background_pull(self, pull: np.ndarray) -> np.ndarray:
        """``pull`` (dR(f) / dv through the resampling, one row per
        frequency) with the background level's share added (in place):
        each side's samples pull it by half their mean."""
        for side in self.background_sides:
            pull[:, side] += 0.5 * self.per_background[:, None] / max(int(side.sum()), 1)
        return pull

    def width_change(self, spectrum_change_at_zero):
        """The change of W (px) a change dR of R at f0 makes: the zero moves
        by -dR / R'(f0), and W = 1 / f0 by dR / (R'(f0) f0^2)."""
        f_zero = float(self.freqs[0])
        return spectrum_change_at_zero / (self.slope * f_zero * f_zero)

    def spread_px(self, spectrum_sd: np.ndarray, t: float) -> float:
        """Half the width (px) of the set of W whose zero 1 / W the data
        cannot tell from f0: the run of the grid about f0 where
        |R(f)| <= t sd(R(f)) (Fieller's interval for a zero, which stays
        honest where R is shallow and the linearised one is not); inf when
        the run reaches the grid's low end (no zero is read at all)."""
        f, margin = self.freqs[1:], t * spectrum_sd - np.abs(self.values[1:])
        inside = margin >= 0
        k = int(np.clip(np.searchsorted(f, self.freqs[0]), 1, f.size - 1))
        k = k if inside[k] else k - 1
        if not inside[k]:
            return 0.0
        outside = np.flatnonzero(~inside)
        below, above = outside[outside < k], outside[outside > k]
        if below.size == 0:
            return math.inf

        def edge(i, j):      # where the margin crosses 0 between grid points i (inside) and j (outside)
            return f[i] + (f[j] - f[i]) * margin[i] / (margin[i] - margin[j])
        f_low = edge(below[-1] + 1, below[-1])
        f_high = edge(above[0] - 1, above[0]) if above.size else f[-1]
        return 0.5 * (1.0 / f_low - 1.0 / f_high)
