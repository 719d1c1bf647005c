"""A camera's test chart: dark tilted squares on a light ground (as MTF
Mapper's charts), seen through a lens whose blur grows from the optical
centre outwards and differs between the sagittal and meridional
directions: what a lens profile is measured from, with its truth known.

Each edge of each square is blurred by a Gaussian of its own width, the
sagittal or meridional width at its square's distance from the centre
(its normal across or along the radius, :mod:`imgmtf.estimate.field`); the
pixels are the blurred scene sampled at their centres, so the MTF along an
edge's normal is exactly ``exp(-2 pi^2 sigma^2 f^2)``, MTF50
``sqrt(ln 2 / 2) / (pi sigma)`` cy/px.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr

from ..errors import ParameterError

#: MTF50 (cy/px) of a Gaussian LSF of sigma 1 px
GAUSSIAN_MTF50_PX = math.sqrt(math.log(2.0) / 2.0) / math.pi


@dataclass(frozen=True)
class FieldBlur:
    """A lens's Gaussian blur across its field: sigma (px) at the centre
    and at ``reference_px`` from it, sagittal and meridional, growing with
    the square of the radius between.

    Examples
    --------
    >>> FieldBlur(0.6, 0.9, 1.5, 200.0).sigma_px(200.0, "meridional")
    1.5
    """

    centre_sigma_px: float = 0.6
    sagittal_sigma_px: float = 0.9
    meridional_sigma_px: float = 1.4
    reference_px: float = 200.0

    def __post_init__(self):
        for name in ("centre_sigma_px", "sagittal_sigma_px", "meridional_sigma_px", "reference_px"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ParameterError(f"{name} must be finite and > 0, got {value!r}")

    def sigma_px(self, radius_px: float, field_direction: str) -> float:
        """The blur's sigma (px) at ``radius_px`` from the centre in the
        sagittal or meridional direction."""
        edge = self.sagittal_sigma_px if field_direction == "sagittal" else self.meridional_sigma_px
        return self.centre_sigma_px + (edge - self.centre_sigma_px) * (radius_px / self.reference_px) ** 2

    def mtf50_cy_px(self, radius_px: float, field_direction: str) -> float:
        """The true MTF50 (cy/px) there."""
        return GAUSSIAN_MTF50_PX / self.sigma_px(radius_px, field_direction)


def square_chart(shape: tuple[int, int] = (300, 400), blur: FieldBlur | None = None, *, grid: tuple[int, int] = (3, 4),
                 side_px: float = 44.0, tilt_deg: float = 5.0, levels_dn: tuple[float, float] = (1500.0, 9000.0),
                 noise_dn: float = 0.0, seed: int = 0) -> np.ndarray:
    """A chart of ``grid`` (rows, columns) dark squares, each tilted
    ``tilt_deg``, evenly spread over an image of ``shape`` (rows, cols),
    blurred by ``blur`` about the image's centre.

    Parameters
    ----------
    shape : (int, int), optional
        The image's rows and columns, px.
    blur : FieldBlur, optional
        The lens's blur across the field (default :class:`FieldBlur`'s).
    grid : (int, int), optional
        Rows and columns of squares.
    side_px : float, optional
        A square's side, px.
    tilt_deg : float, optional
        Each square's rotation, deg (a few degrees: slanted edges).
    levels_dn : (float, float), optional
        The squares' and the ground's levels, DN.
    noise_dn : float, optional
        Gaussian noise's standard deviation, DN.
    seed : int, optional
        The noise's seed.

    Returns
    -------
    numpy.ndarray of float64
        The chart, DN.

    Raises
    ------
    ParameterError
        Squares that do not fit in their cells.

    Examples
    --------
    >>> chart = square_chart((120, 160), grid=(1, 2), side_px=40.0)
    >>> chart.shape, round(float(chart.max())), round(float(chart[60, 40]))
    ((120, 160), 9000, 1500)
    """
    blur = blur or FieldBlur()
    rows, cols = shape
    cell = min(rows / grid[0], cols / grid[1])
    if side_px * math.sqrt(2.0) + 8 * max(blur.meridional_sigma_px, blur.sagittal_sigma_px) > cell:
        raise ParameterError(f"squares of {side_px:g} px do not fit in cells of {cell:.0f} px")
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    centre = ((cols - 1) / 2, (rows - 1) / 2)
    dark, light = levels_dn
    image = np.full(shape, light)
    for i in range(grid[0]):
        for j in range(grid[1]):
            cx, cy = (j + 0.5) * cols / grid[1] - 0.5, (i + 0.5) * rows / grid[0] - 0.5
            inside = _blurred_square(x, y, (cx, cy), side_px, tilt_deg, centre, blur)
            image -= (light - dark) * inside
    if noise_dn:
        image += np.random.default_rng(seed).normal(0.0, noise_dn, shape)
    return image


def _blurred_square(x, y, square_centre, side_px, tilt_deg, centre, blur: FieldBlur) -> np.ndarray:
    """1 inside the square, 0 outside, each edge blurred by its own sigma
    (the product of four blurred half-planes: exact along each edge away
    from the corners, where a scan does not measure)."""
    from ..estimate.field import field_position
    cx, cy = square_centre
    reach_px = side_px * 0.75 + 8 * max(blur.sagittal_sigma_px, blur.meridional_sigma_px, blur.centre_sigma_px)
    near = (slice(max(int(cy - reach_px), 0), int(cy + reach_px) + 1),
            slice(max(int(cx - reach_px), 0), int(cx + reach_px) + 1))
    full = np.zeros_like(x)
    x, y = x[near], y[near]
    out = np.ones_like(x)
    for k in range(4):
        angle = math.radians(tilt_deg + 90.0 * k)
        nx, ny = math.cos(angle), math.sin(angle)
        mid = (cx + nx * side_px / 2, cy + ny * side_px / 2)
        place = field_position(mid[0], mid[1], math.degrees(angle), centre)
        sigma = blur.sigma_px(float(place["radial_distance_px"]), str(place["field_direction"] or "sagittal"))
        outward = (x - cx) * nx + (y - cy) * ny - side_px / 2
        out *= ndtr(-outward / sigma)
    full[near] = out
    return full
