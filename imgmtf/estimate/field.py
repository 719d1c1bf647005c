"""Where an edge lies in a camera's field: its distance from the optical
centre and whether it measures the sagittal or the meridional MTF, as MTF
Mapper reports them.

The meridional (tangential) MTF is the one along the radial direction from
the optical centre: an edge whose normal lies within 45 deg of the radial
direction (the edge itself tangential, across the radius) measures it.  The
sagittal MTF is the one across the radius: an edge whose normal lies within
45 deg of the tangential direction (the edge pointing at the centre).
Coordinates are pixels of the image, x right and y down, pixel centres at
integers (as a scan's ``x0_px``...); the normal angle is measured from +x
towards +y, as :attr:`imgmtf.EdgeResult.normal_angle_deg` is.
"""
from __future__ import annotations

import math
from typing import Any

from ..errors import ParameterError

#: an edge within this distance of the optical centre has no radial direction
MIN_RADIUS_PX = 1.0
SAGITTAL, MERIDIONAL = "sagittal", "meridional"


def image_centre(width: int, height: int) -> tuple[float, float]:
    """The centre of an image of ``width`` x ``height`` px, in pixel-centre
    coordinates (the optical centre taken for a photo).

    Examples
    --------
    >>> image_centre(640, 480)
    (319.5, 239.5)
    """
    return (width - 1) / 2, (height - 1) / 2


def field_position(x_px: float, y_px: float, normal_angle_deg: float,
                   centre: tuple[float, float]) -> dict[str, Any]:
    """An edge's place in the field of a lens whose optical centre is
    ``centre``.

    Parameters
    ----------
    x_px, y_px : float
        The edge's centre, px (pixel centres at integers).
    normal_angle_deg : float
        The angle of its normal from +x towards +y (down), deg.
    centre : (float, float)
        The optical centre (x, y), px.

    Returns
    -------
    dict
        ``radial_distance_px`` (from the centre), ``radial_angle_deg`` (0
        to 90 deg between the normal and the radial direction),
        ``field_direction`` ("meridional" under 45 deg, "sagittal" from 45
        deg; None within ``MIN_RADIUS_PX`` of the centre, where no radial
        direction is defined) and the ``optical_centre_px`` used.

    Raises
    ------
    ParameterError
        A coordinate that is not finite.

    Examples
    --------
    >>> p = field_position(400.0, 300.0, 0.0, (300.0, 300.0))   # right of the centre, normal along x
    >>> p["radial_distance_px"], p["field_direction"]
    (100.0, 'meridional')
    >>> field_position(300.0, 400.0, 0.0, (300.0, 300.0))["field_direction"]   # below it
    'sagittal'
    """
    values = (x_px, y_px, normal_angle_deg, *centre)
    if not all(math.isfinite(float(v)) for v in values):
        raise ParameterError(f"an edge's field position needs finite coordinates, got {values}")
    dx, dy = x_px - centre[0], y_px - centre[1]
    radius = math.hypot(dx, dy)
    out: dict[str, Any] = {"radial_distance_px": round(radius, 2),
                           "optical_centre_px": [round(float(c), 3) for c in centre]}
    if radius < MIN_RADIUS_PX:
        return {**out, "radial_angle_deg": None, "field_direction": None}
    radial = math.degrees(math.atan2(dy, dx))
    between = abs((normal_angle_deg - radial + 90.0) % 180.0 - 90.0)
    return {**out, "radial_angle_deg": round(between, 2),
            "field_direction": MERIDIONAL if between < 45.0 else SAGITTAL}


def parse_centre(text: str) -> tuple[float, float] | str:
    """``--optical-centre``'s value: "X,Y" (px) or "centre" (the image's).

    Examples
    --------
    >>> parse_centre("1024,768.5"), parse_centre("centre")
    ((1024.0, 768.5), 'centre')
    """
    if text.strip().lower() in ("centre", "center"):
        return "centre"
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise ParameterError(f"expected X,Y (two numbers, px) or 'centre', got {text!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise ParameterError(f"expected finite X,Y, got {text!r}")
    return x, y


def resolve_centre(centre: tuple[float, float] | str | None, width: int, height: int) -> tuple[float, float] | None:
    """The optical centre of an image: the one given, its centre for
    "centre", None for none."""
    if centre is None:
        return None
    if isinstance(centre, str):
        return image_centre(width, height)
    return float(centre[0]), float(centre[1])
