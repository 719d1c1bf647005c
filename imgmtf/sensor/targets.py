"""Synthetic targets: a straight edge, a pulse (bar) or a double bar.

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
response along the normal, the pulse's the difference of two edges',
a double bar's the sum of two pulses' (:meth:`Target.image_values`).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import ParameterError
from ..kinds import get_kind, kinds_with_width


@dataclass(frozen=True)
class Target:
    """A straight edge or a bar (pulse) on a uniform background.

    Parameters
    ----------
    kind : {"edge", "pulse"}
        An edge (a step between two levels) or a bar of ``width_px``: a
        name in :data:`imgmtf.kinds.KINDS`.
    angle_deg : float
        Angle of the target's normal from the image's x (column) axis,
        towards +y (down), in (-90, 90] degrees: the tilt of the edge from
        vertical.  0 is a vertical edge (its MTF is across track), 90 a
        horizontal one (along track).  ``imgmtf measure`` reports the same
        angle as ``normal_angle_deg``.
    low_dn, high_dn : float
        Scene levels, DN: ``high_dn`` on the side the normal points to (an
        edge) or inside the bar (a pulse), ``low_dn`` elsewhere; swap them
        to flip the polarity.
    offset_px : float
        Position along the normal from the chip's centre, px.
    width_px : float
        The bar's width along the normal, px (> 0 for a pulse, 0 for an
        edge); each bar's, for a double bar.
    gap_px : float
        A double bar's gap between its two bars (edge to edge) along the
        normal, px (> 0 for a double bar, 0 for the others); the pair is
        centred on the target's line.

    Raises
    ------
    ParameterError
        An unknown kind, a value that is not a finite number, an angle
        outside (-90, 90], a pulse without width or an edge with one.

    Examples
    --------
    >>> from imgmtf import Target
    >>> Target("pulse", angle_deg=84.0, width_px=1.5).kind
    'pulse'
    >>> Target("double-bar", angle_deg=5.0, width_px=1.0, gap_px=2.0).gap_px
    2.0
    >>> Target("edge", angle_deg=120.0)
    Traceback (most recent call last):
    imgmtf.errors.ParameterError: target angle must be in (-90, 90] degrees, got 120.0
    """

    kind: str = "edge"
    angle_deg: float = 6.0
    low_dn: float = 200.0
    high_dn: float = 1200.0
    offset_px: float = 0.0
    width_px: float = 0.0
    gap_px: float = 0.0

    def __post_init__(self):
        kind = get_kind(self.kind)
        if kind.scene_response is None:
            raise ParameterError(f"a {kind.name} target is no straight line: {kind.renderer} renders it")
        for name in ("angle_deg", "low_dn", "high_dn", "offset_px", "width_px", "gap_px"):
            value = getattr(self, name)
            if isinstance(value, (bool, np.bool_)) or not isinstance(
                    value, (int, float, np.integer, np.floating)) or not math.isfinite(value):
                raise ParameterError(f"target {name} must be a finite number, got {value!r}")
            object.__setattr__(self, name, float(value))
        if not -90.0 < self.angle_deg <= 90.0:
            raise ParameterError(f"target angle must be in (-90, 90] degrees, got {self.angle_deg}")
        if kind.has_width and self.width_px <= 0:
            raise ParameterError(f"{kind.name} width must be > 0 pixels, got {self.width_px}")
        if not kind.has_width and self.width_px != 0:
            wide = " or ".join(f"kind={other.name!r}" for other in kinds_with_width())
            raise ParameterError(f"an {kind.name} target has no width; use {wide}")
        if kind.gap_keyword is not None and self.gap_px <= 0:
            raise ParameterError(f"{kind.name} gap must be > 0 pixels, got {self.gap_px}")
        if kind.gap_keyword is None and self.gap_px != 0:
            raise ParameterError(f"a {kind.name} target has no gap; a gap is a double bar's")

    def to_dict(self) -> dict:
        return asdict(self)

    def signed_distance(self, x: np.ndarray, y: np.ndarray, center: tuple[float, float]) -> np.ndarray:
        """Signed distance (px) of points (x, y) from the edge (pulse centre line).

        Parameters
        ----------
        x, y : numpy.ndarray
            The points' columns and rows, px.
        center : (float, float)
            The (x, y) point, px, the target is placed about.

        Returns
        -------
        numpy.ndarray
            The distances, px, along the normal (cos a, sin a): an edge is
            ``high_dn`` where they are positive.
        """
        a = math.radians(self.angle_deg)
        return (x - center[0]) * math.cos(a) + (y - center[1]) * math.sin(a) - self.offset_px

    def image_values(self, d_px: np.ndarray, esf: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """DN of the target seen through a sensor whose edge response along
        this target's normal is ``esf(d)`` (rising from 0 to 1), at signed
        distances ``d_px`` (px) from the edge (the pulse's centre line).

        Parameters
        ----------
        d_px : numpy.ndarray
            Signed distances from the edge, px.
        esf : callable
            The edge response ``esf(d)``, d in px.

        Returns
        -------
        numpy.ndarray
            The target's values there, DN.
        """
        response = get_kind(self.kind).scene_response
        assert response is not None, "a target is a line (checked when it was made)"
        gap = {kind.gap_keyword: self.gap_px} if (kind := get_kind(self.kind)).gap_keyword else {}
        inside = response(d_px, esf, self.width_px, **gap)
        return self.low_dn + (self.high_dn - self.low_dn) * inside
