"""The generic pushbroom sensor of Choi and Helder.

PSF = optics Gaussian * detector rect * along-track motion rect *
first-order Butterworth electronics.  Parameters are in metres on the
ground (cycles per metre for the electronics cut-off); the image's row
direction (y) is along track, the column direction (x) across track.

The system transfer function is the product of the analytic component
transfer functions (:mod:`imgmtf.components`).  The sampled PSF is the
convolution of the components, evaluated through the convolution theorem
(inverse FFT of that product): the Butterworth PSF has a logarithmic
singularity at its centre, which a point-sampled spatial convolution cannot
represent, whereas the band-limited samples obtained this way have exactly
the analytic transfer function at every DFT frequency.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

import numpy as np

from . import components
from ..errors import ConfigError, FileWriteError, ParameterError
from ..metrics import fwhm

DIRECTIONS = ("across", "along")


@dataclass(frozen=True)
class Sensor:
    """Parameters of the generic sensor; the defaults are the paper's.

    Attributes
    ----------
    gsd_m : ground sample distance (metres per pixel).
    optics_sigma_x_m, optics_sigma_y_m : optics Gaussian standard deviations (m).
    detector_width_x_m, detector_width_y_m : detector GIFOV (m).
    motion_m : along-track smear during integration (m); 0 for none.
    electronics_cutoff_cy_m : Butterworth cut-off D0 (cycles/m); 0 for none.
    """

    gsd_m: float = 1.0
    optics_sigma_x_m: float = 0.39
    optics_sigma_y_m: float = 0.39
    detector_width_x_m: float = 1.0
    detector_width_y_m: float = 1.0
    motion_m: float = 0.25
    electronics_cutoff_cy_m: float = 1.4

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(f"sensor parameter {f.name} must be a number, got {value!r}")
            if not math.isfinite(value) or value < 0:
                raise ParameterError(f"sensor parameter {f.name} must be finite and >= 0, got {value}")
        if self.gsd_m <= 0:
            raise ParameterError(f"sensor parameter gsd_m must be > 0, got {self.gsd_m}")

    # -- transfer functions -------------------------------------------------
    def transfer(self, fx, fy) -> np.ndarray:
        """System transfer function at (``fx``, ``fy``) in cycles per metre,
        the product of the component transfer functions (1 at zero)."""
        return (components.gaussian_ft(fx, fy, self.optics_sigma_x_m, self.optics_sigma_y_m)
                * components.pixel_ft(fx, fy, self.detector_width_x_m, self.detector_width_y_m)
                * components.smear_ft(fy, self.motion_m)
                * components.butterworth_ft(fx, fy, self.electronics_cutoff_cy_m))

    def normal_transfer(self, f_cy_px, angle_deg: float, gsd_m: float | None = None) -> np.ndarray:
        """Transfer along the normal of an edge tilted ``angle_deg`` from the
        column axis, at ``f_cy_px`` cycles per pixel of ``gsd_m`` (default the
        sensor's): T(f cos a / gsd, f sin a / gsd).  This is the MTF an ideal
        slanted-edge estimator returns for that edge."""
        gsd = self.gsd_m if gsd_m is None else gsd_m
        a = math.radians(angle_deg)
        f = np.asarray(f_cy_px, float) / gsd
        return self.transfer(f * math.cos(a), f * math.sin(a))

    def mtf(self, f_cy_px, direction: str = "across") -> np.ndarray:
        """MTF across track (x) or along track (y) at ``f_cy_px`` cycles/pixel."""
        return np.abs(self.normal_transfer(f_cy_px, _direction_angle(direction)))

    def mtf_nyquist(self, direction: str = "across") -> float:
        """MTF at the Nyquist frequency, 0.5 cycles/pixel."""
        return float(self.mtf(0.5, direction))

    # -- spatial functions --------------------------------------------------
    def normal_lsf(self, angle_deg: float, gsd_m: float | None = None,
                   samples_per_px: int = 400) -> tuple[np.ndarray, np.ndarray]:
        """LSF along the normal of an edge tilted ``angle_deg`` from the
        column axis: ``(x_px, lsf)``, positions in pixels of ``gsd_m`` and the
        LSF in 1/px (it integrates to 1), by inverse FFT of the 1-D transfer
        function on a grid of ``samples_per_px`` per pixel."""
        gsd = self.gsd_m if gsd_m is None else gsd_m
        step = 1.0 / samples_per_px
        n = 2 * int(math.ceil(4 * self.support_radius_m() / gsd / step)) + 1
        f = np.fft.fftfreq(n, d=step)
        values = np.fft.fftshift(np.fft.ifft(self.normal_transfer(f, angle_deg, gsd)).real) / step
        return (np.arange(n) - n // 2) * step, values

    def lsf(self, direction: str = "across") -> tuple[np.ndarray, np.ndarray]:
        """Line spread function across or along track: ``(x_m, lsf)``,
        positions in metres centred on 0 and the LSF in 1/m."""
        x, values = self.normal_lsf(_direction_angle(direction))
        return x * self.gsd_m, values / self.gsd_m

    def fwhm_m(self, direction: str = "across") -> float:
        """FWHM of the line spread function across or along track (metres)."""
        return fwhm(*self.lsf(direction))

    def support_radius_m(self) -> float:
        """A generous radius (m) outside which the PSF is negligible; used to
        size grids before they are trimmed to the actual energy."""
        r = (6 * max(self.optics_sigma_x_m, self.optics_sigma_y_m)
             + max(self.detector_width_x_m, self.detector_width_y_m) / 2
             + self.motion_m / 2)
        if self.electronics_cutoff_cy_m:
            # the electronics LSF decays as exp(-2 pi D0 r): 1e-9 of it is left at this r
            r += math.log(1e9) / (2 * math.pi * self.electronics_cutoff_cy_m)
        return max(r, self.gsd_m)

    def psf(self, oversampling: int = 20, tolerance: float = 1e-7,
            gsd_m: float | None = None, deconvolve_cell: bool = False) -> "SampledPSF":
        """System PSF sampled ``oversampling`` times per GSD (``gsd_m``, default
        the sensor's) in each axis.

        With ``deconvolve_cell`` the samples are those of the PSF divided (in
        frequency) by the sub-pixel cell's own box transfer: the kernel that,
        convolved with a scene of cell averages and point-sampled, gives the
        continuous scene convolved with the PSF.  The renderer uses it so that
        the area-exact scene adds no blur of its own.

        The grid is square with an odd side, centred on the PSF, and trimmed
        to the smallest square outside which less than ``tolerance`` of the
        energy lies; samples are renormalised to sum to 1.
        """
        if not (isinstance(oversampling, (int, np.integer)) and oversampling >= 1):
            raise ParameterError(f"oversampling must be a positive integer, got {oversampling!r}")
        step = (self.gsd_m if gsd_m is None else gsd_m) / oversampling
        half = int(math.ceil(self.support_radius_m() / step))
        n = 2 * half + 1
        f = np.fft.fftfreq(n, d=step)
        t = self.transfer(f[None, :], f[:, None])
        if deconvolve_cell:
            t = t / (np.sinc(f * step)[None, :] * np.sinc(f * step)[:, None])
        grid = np.fft.fftshift(np.fft.ifft2(t).real)
        # mass inside the centred square of half-side k, for every k at once
        idx = np.abs(np.arange(n) - half)
        ring = np.maximum(idx[:, None], idx[None, :])
        inner = np.cumsum(np.bincount(ring.ravel(), weights=grid.ravel()))
        keep = int(np.argmax(np.abs(1.0 - inner) < tolerance)) if np.any(np.abs(1.0 - inner) < tolerance) else half
        data = grid[half - keep: half + keep + 1, half - keep: half + keep + 1]
        return SampledPSF(data / data.sum(), step)

    def components(self) -> dict[str, "Sensor"]:
        """Each stage alone, as a sensor with every other stage removed."""
        none = dict(optics_sigma_x_m=0.0, optics_sigma_y_m=0.0, detector_width_x_m=0.0,
                    detector_width_y_m=0.0, motion_m=0.0, electronics_cutoff_cy_m=0.0)
        keep = {
            "optics": ("optics_sigma_x_m", "optics_sigma_y_m"),
            "detector": ("detector_width_x_m", "detector_width_y_m"),
            "motion": ("motion_m",),
            "electronics": ("electronics_cutoff_cy_m",),
        }
        return {name: replace(self, **{**none, **{k: getattr(self, k) for k in names}})
                for name, names in keep.items()}

    # -- files --------------------------------------------------------------
    def to_dict(self) -> dict[str, float]:
        return asdict(self)

    def to_toml(self, path: str | Path) -> None:
        """Write the parameters as a ``[sensor]`` TOML table."""
        lines = ["# imgmtf generic sensor: metres on the ground, cycles/metre for the cut-off",
                 "[sensor]"]
        lines += [f"{k} = {float(v)!r}" for k, v in self.to_dict().items()]
        try:
            Path(path).write_text("\n".join(lines) + "\n")
        except OSError as exc:
            raise FileWriteError(f"{path}: cannot write sensor file: {exc.strerror or exc}") from None

    @classmethod
    def from_toml(cls, path: str | Path) -> "Sensor":
        """Read a sensor from TOML: keys at the top level or in a ``[sensor]``
        table; missing keys take the paper's defaults; unknown keys are errors."""
        try:
            with open(path, "rb") as fh:
                doc = tomllib.load(fh)
        except OSError as exc:
            raise ConfigError(f"{path}: cannot read sensor file: {exc.strerror or exc}") from None
        except tomllib.TOMLDecodeError as exc:
            raise ConfigError(f"{path}: malformed TOML: {exc}") from None
        table = doc.get("sensor", doc)
        if not isinstance(table, dict):
            raise ConfigError(f"{path}: [sensor] must be a table")
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(table) - known)
        if unknown:
            raise ConfigError(f"{path}: unknown sensor parameter(s) {', '.join(unknown)}; "
                              f"known: {', '.join(sorted(known))}")
        try:
            return cls(**table)
        except ParameterError as exc:
            raise ConfigError(f"{path}: {exc}") from None


@dataclass(frozen=True, eq=False)
class SampledPSF:
    """A PSF on a square grid: ``data`` sums to 1, ``step_m`` is the sample
    spacing in metres, the centre sample is the PSF's origin."""

    data: np.ndarray
    step_m: float

    @property
    def coordinates_m(self) -> np.ndarray:
        n = self.data.shape[0]
        return (np.arange(n) - n // 2) * self.step_m


def _direction_angle(direction: str) -> float:
    """Angle (deg from the column axis) of the edge whose normal points in
    ``direction``: across track is x (a vertical edge), along track is y."""
    if direction not in DIRECTIONS:
        raise ParameterError(f"direction must be one of {DIRECTIONS}, got {direction!r}")
    return 0.0 if direction == "across" else 90.0
