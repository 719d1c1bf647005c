"""Synthetic targets: a straight edge or a pulse (bar), rendered area-exact
on a sub-pixel grid.

Geometry, in output-pixel units with pixel centres at integer coordinates
(x along columns, y along rows, origin at the centre of the top-left pixel):
the target's normal is n = (cos a, sin a) for a tilt ``a`` of the edge from
the column axis, and the signed distance of a point from the edge is
d = (x - xc) cos a + (y - yc) sin a - offset, with (xc, yc) the chip centre.
An edge is ``high_dn`` where d > 0 and ``low_dn`` where d < 0; a pulse is
``high_dn`` where |d| < width / 2 and ``low_dn`` elsewhere.  So a = 0 is a
vertical edge (its MTF is across track), a = 90 a horizontal one (along
track); swapping ``low_dn`` and ``high_dn`` flips the polarity.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import ParameterError

KINDS = ("edge", "pulse")


@dataclass(frozen=True)
class Target:
    """An edge or pulse target.

    Attributes
    ----------
    kind : "edge" or "pulse".
    angle_deg : tilt of the edge (bar) from the column axis, in (-90, 90].
    low_dn, high_dn : scene levels (DN) on either side, see module docstring.
    offset_px : position along the normal relative to the chip centre (px).
    width_px : pulse width along the normal (px); only for pulses.
    """

    kind: str = "edge"
    angle_deg: float = 6.0
    low_dn: float = 200.0
    high_dn: float = 1200.0
    offset_px: float = 0.0
    width_px: float = 0.0

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ParameterError(f"target kind must be one of {KINDS}, got {self.kind!r}")
        for name in ("angle_deg", "low_dn", "high_dn", "offset_px", "width_px"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ParameterError(f"target {name} must be a finite number, got {value!r}")
        if not -90.0 < self.angle_deg <= 90.0:
            raise ParameterError(f"target angle must be in (-90, 90] degrees, got {self.angle_deg}")
        if self.kind == "pulse" and self.width_px <= 0:
            raise ParameterError(f"pulse width must be > 0 pixels, got {self.width_px}")
        if self.kind == "edge" and self.width_px != 0:
            raise ParameterError("an edge target has no width; use kind='pulse'")

    def to_dict(self) -> dict:
        return asdict(self)

    def signed_distance(self, x: np.ndarray, y: np.ndarray, center: tuple[float, float]) -> np.ndarray:
        """Signed distance (px) of points (x, y) from the edge (pulse centre line)."""
        a = math.radians(self.angle_deg)
        return (x - center[0]) * math.cos(a) + (y - center[1]) * math.sin(a) - self.offset_px

    def scene(self, shape: tuple[int, int], oversampling: int, margin: int) -> np.ndarray:
        """Area-exact scene on the sub-pixel grid that serves an output chip of
        ``shape`` (rows, cols) pixels.

        Cell (i, j) of the returned array has its centre at output-pixel
        coordinates ((j - margin) / oversampling, (i - margin) / oversampling),
        so output pixel (r, c) sits on cell (margin + r * os, margin + c * os),
        and ``margin`` extra cells surround the chip on every side.  Each cell
        holds its covered fraction of the target, scaled to DN.
        """
        rows, cols = shape
        step = 1.0 / oversampling
        y = (np.arange((rows - 1) * oversampling + 1 + 2 * margin) - margin) * step
        x = (np.arange((cols - 1) * oversampling + 1 + 2 * margin) - margin) * step
        center = ((cols - 1) / 2.0, (rows - 1) / 2.0)
        d = self.signed_distance(x[None, :], y[:, None], center) / step
        a = math.radians(self.angle_deg)
        c, s = abs(math.cos(a)), abs(math.sin(a))
        if self.kind == "edge":
            inside = cell_coverage(d, c, s)
        else:
            half = self.width_px / 2.0 / step
            inside = cell_coverage(d + half, c, s) - cell_coverage(d - half, c, s)
        return self.low_dn + (self.high_dn - self.low_dn) * inside


def cell_coverage(t: np.ndarray, c: float, s: float) -> np.ndarray:
    """Fraction of a unit square cell lying on the positive side of a line.

    ``t`` is the signed distance of the cell centre from the line, in cell
    units, and (c, s) = (|cos a|, |sin a|) the absolute components of the
    line's unit normal.  The fraction is the CDF at ``t`` of c U + s V with
    U, V uniform on [-1/2, 1/2]: a trapezoidal distribution, written with the
    ramp R(x) = max(x, 0)^2 / 2 as
    [R(t + (c+s)/2) - R(t + (c-s)/2) - R(t - (c-s)/2) + R(t - (c+s)/2)] / (c s).
    """
    p, q = max(c, s), min(c, s)
    if q < 1e-6:  # the trapezoid has become a box of width p
        return np.clip(t / p + 0.5, 0.0, 1.0)

    def ramp(x):
        return np.square(np.maximum(x, 0.0)) / 2.0

    return (ramp(t + (p + q) / 2) - ramp(t + (p - q) / 2)
            - ramp(t - (p - q) / 2) + ramp(t - (p + q) / 2)) / (p * q)
