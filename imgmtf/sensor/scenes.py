"""Scenes of several targets with a known MTF at every edge: what a scan
is tested on.

A four-quadrant target (a 2 x 2 checkerboard, as at the Baotou and
Salon-de-Provence calibration sites) is two straight lines crossing at right
angles, each quadrant at its own level, on a field.  Its image is composed
from the sensor's exact edge responses along each line's normal
(:meth:`imgmtf.sensor.model.Sensor.line_response`): a quadrant's weight in a
pixel is the product of the two lines' edge responses, exact wherever the
pixel is farther from one line than the PSF reaches (everywhere but the
few pixels around the centre), so each half-edge away from the centre is
the exact edge of :mod:`.rendering`, and its true MTF is the sensor's along
its normal.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ParameterError
from ..metrics import first_crossing
from .model import Sensor
from .noise import add_system_noise


@dataclass(frozen=True)
class QuadrantTarget:
    """A four-quadrant target.

    Attributes
    ----------
    centre_px : (x, y) of the crossing, pixel coordinates (pixel centres at
        integers, x right, y down).
    angle_deg : tilt of the first line from the column axis (the angle of
        its normal from the x axis, as :class:`imgmtf.Target`); the second
        line is perpendicular to it.
    levels_dn : the four quadrants' levels (DN), going round the centre:
        (d1 > 0, d2 > 0), (d1 < 0, d2 > 0), (d1 < 0, d2 < 0), (d1 > 0, d2 < 0),
        with d1, d2 the signed distances from the first and second line.
        A checkerboard alternates bright and dark.
    half_size_px : the target is a square reaching this far from the
        centre along both lines (px); beyond it lies the field.
    """

    centre_px: tuple[float, float]
    angle_deg: float = 16.8
    levels_dn: tuple[float, float, float, float] = (9000.0, 2500.0, 9000.0, 4500.0)
    half_size_px: float = 40.0

    def __post_init__(self):
        values = (*self.centre_px, self.angle_deg, *self.levels_dn, self.half_size_px)
        if len(self.centre_px) != 2 or len(self.levels_dn) != 4 or not all(
                isinstance(v, (int, float, np.integer, np.floating)) and math.isfinite(v) for v in values):
            raise ParameterError("a quadrant target needs a centre (x, y), an angle, four levels and a "
                                 "half-size, all finite numbers")
        if not self.half_size_px > 4:
            raise ParameterError(f"the target's half-size must exceed 4 px, got {self.half_size_px}")

    def normals_deg(self) -> tuple[float, float]:
        """Normal angles (deg from the x axis, in (-90, 90]) of the two lines."""
        second = self.angle_deg + 90.0
        return float(self.angle_deg), float(second - 180.0 if second > 90.0 else second)

    def half_edges(self) -> list[dict]:
        """The four inner half-edges, each from the centre to the target's
        border: ``x0_px``, ``y0_px`` (the centre), ``x1_px``, ``y1_px``, and
        ``normal_angle_deg`` of its line."""
        cx, cy = self.centre_px
        out = []
        for normal in self.normals_deg():
            a = math.radians(normal)
            ux, uy = -math.sin(a), math.cos(a)          # along the line
            for sign in (1.0, -1.0):
                out.append({"x0_px": cx, "y0_px": cy, "x1_px": cx + sign * self.half_size_px * ux,
                            "y1_px": cy + sign * self.half_size_px * uy, "normal_angle_deg": normal})
        return out


@dataclass(frozen=True, eq=False)
class QuadrantScene:
    """A rendered scene with one four-quadrant target: ``image`` (uint16),
    the ``target``, the ``sensor``, and ``fill`` (True when everything
    outside the target was set to 0, as in an L0R chip)."""

    image: np.ndarray
    target: QuadrantTarget
    sensor: Sensor
    fill: bool
    noise_std_dn: float
    seed: int | None
    provenance: dict = field(default_factory=dict)

    def true_mtf(self, f_cy_px: ArrayLike, normal_angle_deg: float) -> np.ndarray:
        """The sensor's MTF (cycles/pixel) along a normal at ``normal_angle_deg``."""
        return np.abs(self.sensor.normal_transfer(f_cy_px, normal_angle_deg))

    def true_mtf50_cy_px(self, normal_angle_deg: float) -> float:
        f = np.linspace(0.0, 2.0, 20001)
        return first_crossing(f, self.true_mtf(f, normal_angle_deg), 0.5)


def texture(shape: tuple[int, int], std_dn: float, seed: int | None = None,
            scales_px: tuple[float, ...] = (1.0, 3.0, 9.0, 27.0)) -> np.ndarray:
    """A ground texture of standard deviation ``std_dn`` (DN) about 0:
    Gaussian-smoothed white noise at each of ``scales_px`` (smoothing
    sigma, px), equally strong, summed.

    Examples
    --------
    >>> t = texture((64, 64), 100.0, seed=1)
    >>> t.shape, round(float(t.std()))
    ((64, 64), 100)
    """
    import cv2
    rng = np.random.default_rng(seed)
    out = np.zeros(shape)
    for sigma in scales_px:
        layer = cv2.GaussianBlur(rng.standard_normal(shape, dtype=np.float32), (0, 0), sigma).astype(float)
        out = out + layer / max(float(layer.std()), 1e-12)
    return out * (std_dn / max(float(out.std()), 1e-12))


def render_quadrants(sensor: Sensor, shape: tuple[int, int], target: QuadrantTarget, *,
                     field_dn: float | np.ndarray = 3000.0, fill: bool = False, noise_std_dn: float = 0.0,
                     seed: int | None = None) -> QuadrantScene:
    """Render a four-quadrant target on a field through ``sensor`` into a
    16-bit image of ``shape`` (rows, cols).

    Parameters
    ----------
    sensor : Sensor
        The sensor (its GSD is the pixel size).
    shape : (int, int)
        The image's (rows, cols), px.
    target : QuadrantTarget
        The target.
    field_dn : float or numpy.ndarray, optional
        The field around the target: a level (DN, default 3000) or an image
        of ``shape`` (a :func:`texture` plus a level), already as blurred as
        it should look.
    fill : bool, optional
        Set every pixel whose centre lies outside the target's square to 0,
        as an L0R product cuts a target out of its scene (default False).
    noise_std_dn : float, optional
        White system noise (DN), added before rounding (default 0).
    seed : int, optional
        The noise's seed.

    Returns
    -------
    QuadrantScene
        The 16-bit image with the target and sensor it was rendered from.

    Raises
    ------
    ParameterError
        A bad shape, field or noise level.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.sensor.scenes import QuadrantTarget, render_quadrants
    >>> scene = render_quadrants(imgmtf.Sensor(), (101, 101), QuadrantTarget((50.0, 50.0)), fill=True)
    >>> int(scene.image[0, 0]), int(scene.image[50, 50]) > 0
    (0, True)
    """
    rows, cols = shape
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    cx, cy = target.centre_px
    reach = math.hypot(rows, cols) + target.half_size_px
    distances, inside = [], np.ones(shape)
    for normal in target.normals_deg():
        a = math.radians(normal)
        d = (x - cx) * math.cos(a) + (y - cy) * math.sin(a)
        esf = sensor.line_response(normal, reach_px=reach).esf
        distances.append((d, esf(d)))
        # the square's extent along this normal: a pulse of width 2 half-size
        inside *= esf(d + target.half_size_px) - esf(d - target.half_size_px)
    (d1, e1), (d2, e2) = distances
    weights = (e1 * e2, (1 - e1) * e2, (1 - e1) * (1 - e2), e1 * (1 - e2))
    quadrants = sum(level * w for level, w in zip(target.levels_dn, weights))
    field = np.broadcast_to(np.asarray(field_dn, float), shape)
    image = inside * quadrants + (1.0 - inside) * field
    image = add_system_noise(image, noise_std_dn, np.random.default_rng(seed))
    image = np.clip(np.rint(image), 0, 65535)
    if fill:
        image[(np.abs(d1) > target.half_size_px) | (np.abs(d2) > target.half_size_px)] = 0
    provenance = {"target": asdict(target), "sensor": sensor.to_dict(), "fill": fill,
                  "noise_std_dn": noise_std_dn, "seed": seed}
    return QuadrantScene(image.astype(np.uint16), target, sensor, fill, float(noise_std_dn), seed, provenance)
