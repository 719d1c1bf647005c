"""Synthetic targets: a straight edge or a pulse (bar).

Geometry, in output-pixel units with pixel centres at integer coordinates
(x along columns, y along rows, origin at the centre of the top-left pixel):
the target's normal is n = (cos a, sin a) for a tilt ``a`` of the edge from
the column axis, and the signed distance of a point from the edge is
d = (x - xc) cos a + (y - yc) sin a - offset, with (xc, yc) the chip centre.
An edge is ``high_dn`` where d > 0 and ``low_dn`` where d < 0; a pulse is
``high_dn`` where |d| < width / 2 and ``low_dn`` elsewhere.  So a = 0 is a
vertical edge (its MTF is across track), a = 90 a horizontal one (along
track); swapping ``low_dn`` and ``high_dn`` flips the polarity.

A target is a straight line (or two) of infinite length, so its image
through any PSF depends on d alone: the edge's is the sensor's edge
response along the normal, the pulse's the difference of two edges'
(:meth:`Target.image_values`).
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
            if isinstance(value, (bool, np.bool_)) or not isinstance(
                    value, (int, float, np.integer, np.floating)) or not math.isfinite(value):
                raise ParameterError(f"target {name} must be a finite number, got {value!r}")
            object.__setattr__(self, name, float(value))
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

    def image_values(self, d_px: np.ndarray, esf) -> np.ndarray:
        """DN of the target seen through a sensor whose edge response along
        this target's normal is ``esf(d)`` (rising from 0 to 1), at signed
        distances ``d_px`` (px) from the edge (the pulse's centre line)."""
        if self.kind == "edge":
            inside = esf(d_px)
        else:
            inside = esf(d_px + self.width_px / 2.0) - esf(d_px - self.width_px / 2.0)
        return self.low_dn + (self.high_dn - self.low_dn) * inside
