"""Render targets through a sensor into quantised image chips.

Each output pixel is a point sample, at its centre, of the scene convolved
with the system PSF (which holds the detector aperture, so the aperture is
applied exactly once).  A target is a straight edge or bar, so by linearity
its part of every pixel is the sensor's edge response along the target's
normal at the pixel's signed distance from it
(:meth:`imgmtf.sensor.model.Sensor.line_response`): exact for every stage,
long-tailed diffraction included, with no grid to truncate and no border to
hide.  Ground noise (if any) is a field on a grid ``oversampling`` times
finer than the output GSD; it is convolved with the sampled PSF by OpenCV
(the PSF with the sub-pixel cell's box divided out, so that the cells add
no blur of their own), point-sampled and added.  System noise is added
after sampling, then the values are rounded and clipped to 8 or 16 bits.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import ArrayLike

from ..errors import ParameterError
from ..metrics import first_crossing, fwhm
from ..version import __version__
from .model import MAX_GRID_CELLS, SampledPSF, Sensor, check_gsd
from .noise import GroundNoise, add_system_noise
from .targets import Target

BITS = (8, 16)


@dataclass(frozen=True, eq=False)
class Chip:
    """A rendered chip and everything needed to reproduce it (what
    :func:`render` and :class:`Renderer` return).

    Attributes
    ----------
    image : numpy.ndarray of uint8 or uint16, shape (rows, cols)
        The chip, DN.
    sensor : Sensor
        The sensor it was rendered through.
    target : Target
        The edge or bar.
    gsd_m : float
        Its ground sample distance, m.
    oversampling : int
        Sub-pixel cells per pixel of the ground-noise field.
    bits : int
        8 or 16.
    noise_std_dn : float
        Standard deviation of the white system noise, DN.
    ground_noise : GroundNoise or None
        The ground noise added before the PSF, if any.
    seed : int or None
        The noise's random seed.
    clipped_fraction : float
        Fraction of pixels that hit 0 or the top of the range.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 100)
    >>> round(float(chip.true_mtf(0.5)), 4), round(chip.true_mtf50_cy_px(), 4), round(chip.true_fwhm_px(), 4)
    (0.2667, 0.3644, 1.2392)
    """

    image: np.ndarray
    sensor: Sensor
    target: Target
    gsd_m: float
    oversampling: int
    bits: int
    noise_std_dn: float
    ground_noise: GroundNoise | None
    seed: int | None
    clipped_fraction: float

    def true_mtf(self, f_cy_px: ArrayLike) -> np.ndarray:
        """The sensor's MTF along the target's normal at ``f_cy_px``
        (cycles per pixel of this chip): what an ideal estimator returns.

        Parameters
        ----------
        f_cy_px : array_like
            Frequencies along the normal, cy/px.

        Returns
        -------
        numpy.ndarray
            The true MTF at each frequency (1 at zero).
        """
        return np.abs(self.sensor.normal_transfer(f_cy_px, self.target.angle_deg, self.gsd_m))

    def true_fwhm_px(self) -> float:
        """FWHM (px) of the sensor's LSF along the target's normal."""
        return fwhm(*self.sensor.normal_lsf(self.target.angle_deg, self.gsd_m))

    def true_mtf50_cy_px(self) -> float:
        """Frequency (cy/px) where the true MTF along the normal falls to 0.5."""
        f = np.linspace(0.0, 2.0, 20001)
        return first_crossing(f, self.true_mtf(f), 0.5)

    def provenance(self) -> dict:
        """JSON-ready description of how the chip was made: version,
        sensor (GSD and stages), target, GSD, oversampling, bits, noise and
        seed (what :func:`imgmtf.write_geotiff` stores in its ``IMGMTF``
        tag)."""
        return {
            "imgmtf_version": __version__,
            "sensor": self.sensor.to_dict(),
            "target": self.target.to_dict(),
            "gsd_m": self.gsd_m,
            "oversampling": self.oversampling,
            "bits": self.bits,
            "noise_std_dn": self.noise_std_dn,
            "ground_noise": self.ground_noise.to_dict() if self.ground_noise else None,
            "seed": self.seed,
        }


class Renderer:
    """Set up once (sensor, chip size), render many targets: calling it
    with a :class:`Target` returns a :class:`Chip`.

    Each pixel is the sensor's exact edge response along the target's
    normal at the pixel centre's distance from it (no scene grid, no
    border), plus noise, rounded and clipped to ``bits``.  Calling it takes
    the target and, keyword-only, the noise and its seed (:meth:`__call__`).

    Parameters
    ----------
    sensor : Sensor, optional
        The sensor (default the paper's generic sensor).
    shape : int or (int, int), optional
        Chip size (rows, cols) in pixels, or one int for a square (default
        50; at least 2, at most 16 Mpx).
    gsd_m : float, optional
        Output ground sample distance, m (default the sensor's).
    oversampling : int, optional
        Sub-pixel cells per output pixel in each axis, for the ground-noise
        field (default 20).
    bits : {8, 16}, optional
        The output integer depth (default 16).

    Raises
    ------
    ParameterError
        A bad size, depth, oversampling or GSD, or a sensor whose blur would
        need more than 16 M grid cells at this GSD.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.Renderer(imgmtf.Sensor(), 40)(imgmtf.Target("edge", 6.0))
    >>> chip.image.shape, chip.image.dtype.name
    ((40, 40), 'uint16')
    """

    def __init__(self, sensor: Sensor = Sensor(), shape: int | tuple[int, int] = 50, *,
                 gsd_m: float | None = None, oversampling: int = 20, bits: int = 16):
        if not isinstance(sensor, Sensor):
            raise ParameterError(f"sensor must be an imgmtf.Sensor, got {sensor!r}")
        size = (shape, shape) if isinstance(shape, (int, np.integer)) else tuple(np.atleast_1d(shape))
        if len(size) != 2 or any(isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer))
                                 or n < 2 for n in size):
            raise ParameterError(f"chip size must be at least 2 x 2 pixels, got {shape!r}")
        rows, cols = (int(n) for n in size)
        if rows * cols > MAX_GRID_CELLS:
            raise ParameterError(f"a {rows} x {cols} px chip is over the {MAX_GRID_CELLS}-pixel limit")
        if bits not in BITS:
            raise ParameterError(f"bits must be 8 or 16, got {bits}")
        if isinstance(oversampling, (bool, np.bool_)) or not (
                isinstance(oversampling, (int, np.integer)) and oversampling >= 1):
            raise ParameterError(f"oversampling must be a positive integer, got {oversampling!r}")
        self.gsd_m = sensor.gsd_m if gsd_m is None else check_gsd("gsd_m", gsd_m)
        self.sensor, self.oversampling, self.bits = sensor, int(oversampling), bits
        self.shape: tuple[int, int] = (rows, cols)
        self._y, self._x = np.mgrid[0:rows, 0:cols].astype(float)
        self._responses: dict[float, tuple[float, object]] = {}     # angle -> (reach px, response)

    @functools.cached_property
    def psf(self) -> SampledPSF:
        """The sampled PSF, with the sub-pixel cell's box divided out, that
        blurs the ground noise."""
        return self.sensor.psf(self.oversampling, gsd_m=self.gsd_m, deconvolve_cell=True)

    def __call__(self, target: Target, *, noise_std_dn: float = 0.0,
                 ground_noise: GroundNoise | None = None, seed: int | None = None) -> Chip:
        """Render ``target`` into a chip.

        Parameters
        ----------
        target : Target
            The edge or bar.
        noise_std_dn : float, optional
            White system noise added after sampling, DN (default 0).
        ground_noise : GroundNoise, optional
            Ground noise added to the scene before the PSF.
        seed : int, optional
            Seed of the noise (>= 0), for a reproducible chip.

        Returns
        -------
        Chip
            The image and how it was made, with its true MTF.

        Raises
        ------
        ParameterError
            A bad target, noise level or seed, or a ground-noise grid over
            the size limit.
        """
        if not isinstance(target, Target):
            raise ParameterError(f"target must be an imgmtf.Target, got {target!r}")
        if ground_noise is not None and not isinstance(ground_noise, GroundNoise):
            raise ParameterError(f"ground_noise must be an imgmtf.GroundNoise or None, got {ground_noise!r}")
        if seed is not None and (isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer))
                                 or seed < 0):
            raise ParameterError(f"seed must be an integer >= 0 or None, got {seed!r}")
        rng = np.random.default_rng(seed)
        rows, cols = self.shape
        d = target.signed_distance(self._x, self._y, ((cols - 1) / 2.0, (rows - 1) / 2.0))
        sampled = target.image_values(d, self._response(target).esf)
        if ground_noise is not None:
            sampled = sampled + self._blurred_ground_noise(ground_noise, rng)
        sampled = add_system_noise(sampled, noise_std_dn, rng)
        top = 2**self.bits - 1
        rounded = np.rint(sampled)
        clipped = float(np.mean((rounded <= 0) | (rounded >= top)))
        image = np.clip(rounded, 0, top).astype(np.uint8 if self.bits == 8 else np.uint16)
        return Chip(image, self.sensor, target, self.gsd_m, self.oversampling, self.bits,
                    float(noise_std_dn), ground_noise, seed, clipped)

    def _response(self, target: Target):
        """The sensor's line response along the target's normal, kept per
        angle (and made anew where a target needs it to reach further)."""
        rows, cols = self.shape
        half_diagonal = math.hypot(rows, cols) / 2.0
        if abs(target.offset_px) > half_diagonal + target.width_px:
            raise ParameterError(f"a target offset of {target.offset_px:g} px puts the {target.kind} outside "
                                 f"the {rows} x {cols} px chip (at most {half_diagonal:.1f} px from its centre)")
        reach = half_diagonal + abs(target.offset_px) + 2 * target.width_px + target.gap_px + 2.0
        kept = self._responses.get(target.angle_deg)
        if kept is None or kept[0] < reach:
            kept = (reach, self.sensor.line_response(target.angle_deg, self.gsd_m, reach_px=reach))
            self._responses[target.angle_deg] = kept
        return kept[1]

    def _blurred_ground_noise(self, ground_noise: GroundNoise, rng: np.random.Generator) -> np.ndarray:
        """Ground noise on the sub-pixel grid (with a margin of the PSF's
        radius), convolved with the PSF and sampled at the pixel centres."""
        rows, cols = self.shape
        os_, margin = self.oversampling, self.psf.data.shape[0] // 2
        shape = ((rows - 1) * os_ + 1 + 2 * margin, (cols - 1) * os_ + 1 + 2 * margin)
        if shape[0] * shape[1] > MAX_GRID_CELLS:
            raise ParameterError(f"ground noise on a {rows} x {cols} px chip at {os_} sub-pixels per pixel "
                                 f"needs a {shape[0]} x {shape[1]} grid (over {MAX_GRID_CELLS} cells); "
                                 "render a smaller chip or lower the oversampling")
        field = ground_noise.sample(shape, rng)
        # cv2.filter2D correlates; flipping the kernel makes it a convolution
        kernel = np.ascontiguousarray(self.psf.data[::-1, ::-1])
        blurred = cv2.filter2D(field, cv2.CV_64F, kernel, borderType=cv2.BORDER_REFLECT)
        return blurred[margin: field.shape[0] - margin: os_, margin: field.shape[1] - margin: os_]


def render(sensor: Sensor, target: Target, shape: int | tuple[int, int] = 50, *,
           gsd_m: float | None = None, oversampling: int = 20, bits: int = 16,
           noise_std_dn: float = 0.0, ground_noise: GroundNoise | None = None,
           seed: int | None = None) -> Chip:
    """Render one target through a sensor into an 8/16-bit chip (one call
    of a :class:`Renderer`; make one to render many chips of a sensor).

    Parameters
    ----------
    sensor : Sensor
        The sensor.
    target : Target
        The edge or bar.
    shape : int or (int, int), optional
        Chip size in pixels (default 50 x 50).
    gsd_m : float, optional
        Output GSD, m (default the sensor's).
    oversampling : int, optional
        Sub-pixel cells per pixel of the ground-noise field (default 20).
    bits : {8, 16}, optional
        Output depth (default 16).
    noise_std_dn : float, optional
        White system noise added after sampling, DN (default 0).
    ground_noise : GroundNoise, optional
        Ground noise added to the scene before the PSF.
    seed : int, optional
        Seed of the noise (>= 0), for a reproducible chip.

    Returns
    -------
    Chip
        The image and how it was made, with its true MTF.

    Raises
    ------
    ParameterError
        A bad sensor, target, size, depth, oversampling, GSD, noise level
        or seed.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 100, noise_std_dn=5.0, seed=1)
    >>> chip.image.shape, chip.image.dtype.name, round(float(chip.true_mtf(0.5)), 4)
    ((100, 100), 'uint16', 0.2667)
    """
    return Renderer(sensor, shape, gsd_m=gsd_m, oversampling=oversampling, bits=bits)(
        target, noise_std_dn=noise_std_dn, ground_noise=ground_noise, seed=seed)
