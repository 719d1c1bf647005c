"""Sub-pixel edge geometry: a Fermi fit per row, a robust least-squares
line through the row locations, and every pixel's signed distance to it.

Works in the *vertical frame*: the edge runs roughly down the rows
(|tilt| < 45 deg) and each row crosses it once.  A near-horizontal edge is
handled by transposing the image first; :class:`EdgeGeometry` remembers
that and reports angles in the original image.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import TargetNotFoundError
from .fermi import fit_fermi


@dataclass(frozen=True, eq=False)
class EdgeGeometry:
    """The fitted edge line x = slope * y + intercept in the vertical frame.

    ``rows`` are the rows that were fitted, ``locations`` their Fermi edge
    positions (px), ``kept`` which of them the line fit accepted;
    ``transposed`` is True when the vertical frame is the image transposed.
    """

    slope: float
    intercept: float
    rows: np.ndarray
    locations: np.ndarray
    kept: np.ndarray
    transposed: bool

    @property
    def angle_deg(self) -> float:
        """Tilt of the edge from the column axis of the original image, in
        (-90, 90] (the angle of its normal from the x axis)."""
        vertical = -math.degrees(math.atan(self.slope))
        if not self.transposed:
            return vertical
        angle = 90.0 - vertical
        return angle - 180.0 if angle > 90.0 else angle

    def distance(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Signed perpendicular distance (px) from the line, positive to the
        right (+x) in the vertical frame."""
        return (x - self.slope * y - self.intercept) / math.hypot(1.0, self.slope)


def locate_edge(image: np.ndarray, seed_x: np.ndarray, half_window: int = 10,
                transposed: bool = False) -> EdgeGeometry:
    """Fit the Fermi model in every row around ``seed_x`` (the seed edge
    column per row) and a robust line through the locations.

    Rows whose fit fails are dropped; the line is refitted after discarding
    locations more than 4 robust standard deviations (and 0.05 px) off it.
    """
    rows_n, cols_n = image.shape
    rows = np.arange(rows_n)
    centre = np.rint(seed_x).astype(int)
    cols = centre[:, None] + np.arange(-half_window, half_window + 1)[None, :]
    inside = (cols >= 0) & (cols < cols_n)
    values = image[rows[:, None], np.clip(cols, 0, cols_n - 1)]
    usable = inside.sum(axis=1) >= half_window + 4
    if usable.sum() < 5:
        raise TargetNotFoundError("the edge does not cross enough rows of the image")
    fit = fit_fermi(cols[usable].astype(float), values[usable], inside[usable].astype(float),
                    seed_x[usable])
    y = rows[usable][fit.ok]
    x = fit.location[fit.ok]
    if y.size < 5:
        raise TargetNotFoundError("the per-row edge fits failed: no clear edge profile in the rows")
    keep = np.ones(y.size, bool)
    for _ in range(4):
        slope, intercept = np.polyfit(y[keep], x[keep], 1)
        resid = x - (slope * y + intercept)
        mad = 1.4826 * np.median(np.abs(resid[keep] - np.median(resid[keep])))
        new_keep = np.abs(resid) <= max(4.0 * mad, 0.05)
        if np.array_equal(new_keep, keep) or new_keep.sum() < 5:
            break
        keep = new_keep
    slope, intercept = np.polyfit(y[keep], x[keep], 1)
    return EdgeGeometry(float(slope), float(intercept), y, x, keep, transposed)
