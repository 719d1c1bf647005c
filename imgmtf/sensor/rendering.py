"""Render targets through the generic sensor into quantised image chips.

The scene is built area-exact on a grid ``oversampling`` times finer than
the output GSD, ground noise (if any) is added, the scene is convolved with
the sampled system PSF by OpenCV (the PSF with the sub-pixel cell's box
divided out, so that cell averaging adds no blur of its own), and the result is point-sampled at the
output pixel centres.  The detector aperture is part of the PSF, so it is
applied exactly once (point sampling adds no second aperture).  System
noise is added after sampling, then the values are rounded and clipped to
8 or 16 bits.

The scene carries a margin of the PSF's radius on every side, so every
output pixel sees a complete neighbourhood of the analytic scene and the
image border never creates a false edge.
"""
from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ..version import __version__
from ..errors import ParameterError
from ..metrics import first_crossing, fwhm
from .noise import GroundNoise, add_system_noise
from .model import Sensor
from .targets import Target

BITS = (8, 16)


@dataclass(frozen=True, eq=False)
class Chip:
    """A rendered chip and everything needed to reproduce it.

    ``image`` is uint8 or uint16, rows x cols; ``clipped_fraction`` is the
    fraction of pixels that hit 0 or the top of the range.
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

    def true_mtf(self, f_cy_px) -> np.ndarray:
        """The sensor's MTF along the target's normal (cycles/pixel)."""
        return np.abs(self.sensor.normal_transfer(f_cy_px, self.target.angle_deg, self.gsd_m))

    def true_fwhm_px(self) -> float:
        """FWHM (px) of the sensor's LSF along the target's normal."""
        return fwhm(*self.sensor.normal_lsf(self.target.angle_deg, self.gsd_m))

    def true_mtf50_cy_px(self) -> float:
        """Frequency (cy/px) where the true MTF along the normal falls to 0.5."""
        f = np.linspace(0.0, 2.0, 20001)
        return first_crossing(f, self.true_mtf(f), 0.5)

    def provenance(self) -> dict:
        """JSON-ready description of how the chip was made."""
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
    """Set up once (sensor, chip size, PSF), render many targets.

    Parameters
    ----------
    sensor : the generic sensor.
    shape : output chip size (rows, cols) in pixels, or one int for a square.
    gsd_m : output ground sample distance (m); default the sensor's.
    oversampling : sub-pixel samples per output pixel in each axis.
    bits : 8 or 16, the output integer depth.
    """

    def __init__(self, sensor: Sensor = Sensor(), shape: int | tuple[int, int] = 50, *,
                 gsd_m: float | None = None, oversampling: int = 20, bits: int = 16):
        shape = (shape, shape) if isinstance(shape, (int, np.integer)) else tuple(shape)
        if len(shape) != 2 or any(not isinstance(n, (int, np.integer)) or n < 2 for n in shape):
            raise ParameterError(f"chip size must be at least 2 x 2 pixels, got {shape}")
        if bits not in BITS:
            raise ParameterError(f"bits must be 8 or 16, got {bits}")
        self.gsd_m = sensor.gsd_m if gsd_m is None else float(gsd_m)
        if not self.gsd_m > 0:
            raise ParameterError(f"GSD must be > 0 m, got {gsd_m}")
        self.sensor, self.shape, self.oversampling, self.bits = sensor, shape, oversampling, bits
        self.psf = sensor.psf(oversampling, gsd_m=self.gsd_m, deconvolve_cell=True)
        # cv2.filter2D correlates; flipping the kernel makes it a convolution
        self._kernel = np.ascontiguousarray(self.psf.data[::-1, ::-1])
        self._margin = self.psf.data.shape[0] // 2

    def __call__(self, target: Target, *, noise_std_dn: float = 0.0,
                 ground_noise: GroundNoise | None = None, seed: int | None = None) -> Chip:
        rng = np.random.default_rng(seed)
        scene = target.scene(self.shape, self.oversampling, self._margin)
        if ground_noise is not None:
            scene = scene + ground_noise.sample(scene.shape, rng)
        blurred = cv2.filter2D(scene, cv2.CV_64F, self._kernel, borderType=cv2.BORDER_REFLECT)
        m, os_ = self._margin, self.oversampling
        sampled = blurred[m: scene.shape[0] - m: os_, m: scene.shape[1] - m: os_]
        sampled = add_system_noise(sampled, noise_std_dn, rng)
        top = 2**self.bits - 1
        rounded = np.rint(sampled)
        clipped = float(np.mean((rounded <= 0) | (rounded >= top)))
        image = np.clip(rounded, 0, top).astype(np.uint8 if self.bits == 8 else np.uint16)
        return Chip(image, self.sensor, target, self.gsd_m, self.oversampling, self.bits,
                    float(noise_std_dn), ground_noise, seed, clipped)


def render(sensor: Sensor, target: Target, shape: int | tuple[int, int] = 50, *,
           gsd_m: float | None = None, oversampling: int = 20, bits: int = 16,
           noise_std_dn: float = 0.0, ground_noise: GroundNoise | None = None,
           seed: int | None = None) -> Chip:
    """Render one target through ``sensor``; see :class:`Renderer`."""
    return Renderer(sensor, shape, gsd_m=gsd_m, oversampling=oversampling, bits=bits)(
        target, noise_std_dn=noise_std_dn, ground_noise=ground_noise, seed=seed)
