"""Siemens stars rendered exactly through a sensor: ISO 12233:2017's
sinusoidal star (the s-SFR target: intensity varying as ``cos(N theta)``
around the centre, ``N`` cycles) and the binary (bar) star, black and white
wedges.

The star fills the chip, so that no outline enters the rings a measurement
reads.  A pixel holds the scene convolved with the system PSF (the pixel's
aperture among its stages), sampled at its centre, as every chip of
:mod:`imgmtf.sensor` does.  The convolution is made in the frequency
domain on a grid ``m`` times finer than the pixels, tile by tile (each with
a halo wider than the PSF): the pattern's part above the mean, sampled on
the fine grid, times the sensor's 2-D transfer, transformed back and read
at the pixel centres.

That is exact where the fine grid holds the pattern: a star's angular
harmonic ``k N`` has the local frequency ``f_k(r) = k N / (2 pi r)``
cy/px, tangential, which grows without bound towards the centre.  Each
harmonic is therefore kept where ``f_k <= f_keep``, the frequency beyond
which the sensor's transfer is below :data:`TRANSFER_TOLERANCE` (where it
would be blurred away anyway), and tapered to zero by ``1.5 f_keep``, which
the fine grid (``m / 2 >= 1.5 f_keep + 0.5``) samples without aliasing.  A
binary star is its square wave's Fourier series, ``(4 / pi) sum (-1)^j /
(2j+1) cos((2j+1) N theta)``, each harmonic windowed so (the windowed sum
tabulated once against the angle and the local frequency).  The only
approximations are then the transfer beyond ``f_keep`` (below the
tolerance, or, for a sensor whose transfer decays slower than
:data:`MAX_KEEP_CY_PX` allows, what lies above that) and the table's
interpolation (a binary star's values within 0.01 DN of a brute-force
quadrature, a sinusoidal star's within 1e-4 DN, on a 1000 DN range).

Geometry as in :mod:`imgmtf.sensor.targets`: pixel centres at integer
coordinates, x along columns (across track), y along rows (along track,
down); angles from the x axis towards y.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ParameterError
from ..metrics import first_crossing
from ..version import __version__
from .model import Sensor, check_gsd
from .noise import add_system_noise

#: the transfer below which the star's finer harmonics are left out (they are blurred away)
TRANSFER_TOLERANCE = 1e-6
#: the highest frequency (cy/px) a harmonic is kept to, for sensors whose transfer decays slowly
MAX_KEEP_CY_PX = 3.0
#: the star's profiles around the centre
PROFILES = ("sinusoidal", "binary")
#: the smallest chip a star is rendered on, px
MIN_STAR_PX = 32
#: a harmonic is tapered from the frequency it is kept to (1x) to this multiple of it
TAPER = 1.5
#: the binary star's square-wave table: samples a cycle and rows of local frequency
WAVE_SAMPLES = 8192
WAVE_ROWS = 384
TILE_PX = 256
BITS = (8, 16)


@dataclass(frozen=True)
class SiemensStar:
    """A Siemens star of ``cycles`` periods around its centre, filling the
    chip.

    Parameters
    ----------
    cycles : int
        N, the periods around the centre (ISO 12233:2017's s-SFR chart has
        144 on a large print; a 200 px chip reads best with 24 to 64).
    profile : {"sinusoidal", "binary"}
        Intensity ``cos(N theta)`` (ISO 12233's s-SFR) or black and white
        wedges (its sign).
    low_dn, high_dn : float
        The darkest and brightest DN of the pattern (the sinusoid's troughs
        and crests, or the wedges).
    centre_offset_px : (float, float)
        The centre's (dx, dy) from the chip's middle, px.
    phase_deg : float
        The pattern's rotation, deg: a crest along ``theta = phase_deg``.

    Raises
    ------
    ParameterError
        Fewer than 4 cycles, an unknown profile, a non-finite value.

    Examples
    --------
    >>> star = SiemensStar(cycles=32)
    >>> star.centre_px((201, 201))
    (100.3, 99.8)
    >>> round(star.nyquist_radius_px, 3)             # where N / (2 pi r) is 0.5 cy/px
    10.186
    """

    cycles: int = 32
    profile: str = "sinusoidal"
    low_dn: float = 200.0
    high_dn: float = 1200.0
    centre_offset_px: tuple[float, float] = (0.3, -0.2)
    phase_deg: float = 0.0

    def __post_init__(self):
        if not isinstance(self.cycles, (int, np.integer)) or isinstance(self.cycles, bool) or self.cycles < 4:
            raise ParameterError(f"a star needs an integer number of cycles >= 4, got {self.cycles!r}")
        object.__setattr__(self, "cycles", int(self.cycles))
        if self.profile not in PROFILES:
            raise ParameterError(f"star profile must be one of {PROFILES}, got {self.profile!r}")
        for name in ("low_dn", "high_dn", "phase_deg"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not math.isfinite(value):
                raise ParameterError(f"star {name} must be a finite number, got {value!r}")
            object.__setattr__(self, name, float(value))
        offset = tuple(float(v) for v in self.centre_offset_px)
        if len(offset) != 2 or not all(math.isfinite(v) for v in offset):
            raise ParameterError(f"star centre offset must be two finite numbers, px, got {self.centre_offset_px!r}")
        object.__setattr__(self, "centre_offset_px", offset)

    @property
    def nyquist_radius_px(self) -> float:
        """The radius (px) where the star's frequency ``N / (2 pi r)`` is
        Nyquist's, 0.5 cy/px."""
        return self.cycles / math.pi

    def centre_px(self, shape: tuple[int, int]) -> tuple[float, float]:
        """The centre (x, y), px, on a chip of ``shape``.

        Parameters
        ----------
        shape : (int, int)
            The chip's rows and columns.

        Returns
        -------
        (float, float)
            x and y, px (pixel centres at integers).
        """
        return ((shape[1] - 1) / 2.0 + self.centre_offset_px[0], (shape[0] - 1) / 2.0 + self.centre_offset_px[1])

    def to_dict(self) -> dict:
        return {"kind": "star", "cycles": self.cycles, "profile": self.profile, "low_dn": self.low_dn,
                "high_dn": self.high_dn, "centre_offset_px": list(self.centre_offset_px),
                "phase_deg": self.phase_deg}


@dataclass(frozen=True, eq=False)
class StarChip:
    """A rendered Siemens star and how it was made (what
    :func:`render_star` returns).

    Attributes
    ----------
    image : numpy.ndarray, shape (rows, cols)
        The chip, DN: float64 (``bits`` None) or uint8/uint16.
    sensor : Sensor
        The sensor it was rendered through.
    star : SiemensStar
        The target.
    centre_px : (float, float)
        The star's true centre (x, y), px.
    gsd_m : float
        The pixel, m.
    bits : int or None
        8 or 16, or None (floats).
    noise_std_dn : float
        White system noise, DN.
    seed : int or None
        The noise's seed.
    clipped_fraction : float
        Fraction of pixels at 0 or the top of the range.
    keep_cy_px : float
        The frequency above which the pattern was left out (see the module).
    """

    image: np.ndarray
    sensor: Sensor
    star: SiemensStar
    centre_px: tuple[float, float]
    gsd_m: float
    bits: int | None
    noise_std_dn: float
    seed: int | None
    clipped_fraction: float
    keep_cy_px: float

    def true_mtf(self, f_cy_px: ArrayLike, angle_deg: float = 0.0) -> np.ndarray:
        """The sensor's MTF at ``f_cy_px`` along the direction ``angle_deg``
        from the x axis (0: across track, 90: along track)."""
        return np.abs(self.sensor.normal_transfer(f_cy_px, angle_deg, self.gsd_m))

    def true_mtf50_cy_px(self, angle_deg: float = 0.0) -> float:
        """Frequency (cy/px) where the true MTF along ``angle_deg`` falls to 0.5."""
        f = np.linspace(0.0, 2.0, 20001)
        return first_crossing(f, self.true_mtf(f, angle_deg), 0.5)

    def provenance(self) -> dict:
        """JSON-ready description of how the chip was made (the GeoTIFF's
        ``IMGMTF`` tag), the truth across and along track among it."""
        return {"imgmtf_version": __version__, "sensor": self.sensor.to_dict(), "target": self.star.to_dict(),
                "gsd_m": self.gsd_m, "bits": self.bits, "noise_std_dn": self.noise_std_dn, "seed": self.seed,
                "centre_px": list(self.centre_px), "keep_cy_px": self.keep_cy_px,
                "mtf_nyquist_across": float(self.true_mtf(0.5, 0.0)),
                "mtf_nyquist_along": float(self.true_mtf(0.5, 90.0))}


def default_cycles(size_px: int, profile: str = "sinusoidal") -> int:
    """The cycles (even) of a star filling a ``size_px`` chip whose
    outermost ring reads about 0.125 cy/px (a sinusoidal star: low enough to
    extrapolate its full contrast, and its Nyquist radius far enough out
    that its wavefronts' curvature leaves the MTF at Nyquist within 0.005),
    or 0.075 cy/px (a binary star: wedges wide enough at the rim to read
    their levels 2.5 px from any edge).

    Examples
    --------
    >>> default_cycles(201), default_cycles(201, "binary")
    (76, 46)
    """
    radius = (size_px - 1) / 2.0 - 2.0
    f = 0.075 if profile == "binary" else 0.125
    return max(8, 2 * round(math.pi * radius * f))


def keep_frequency(sensor: Sensor, gsd_m: float) -> float:
    """The frequency (cy/px) beyond which the sensor's transfer stays below
    :data:`TRANSFER_TOLERANCE` in every direction, at most
    :data:`MAX_KEEP_CY_PX`."""
    f = np.linspace(0.0, MAX_KEEP_CY_PX, 601)
    angles = np.radians(np.arange(0.0, 180.0, 15.0))
    level = np.abs(sensor.transfer(f[:, None] * np.cos(angles) / gsd_m, f[:, None] * np.sin(angles) / gsd_m))
    envelope = np.maximum.accumulate(level.max(axis=1)[::-1])[::-1]
    above = np.nonzero(envelope >= TRANSFER_TOLERANCE)[0]
    return float(max(f[above[-1]] if above.size else 0.5, 0.5))


def _window(f_local: np.ndarray, keep: float) -> np.ndarray:
    """1 where a harmonic's local frequency is at most ``keep``, 0 from
    ``TAPER * keep``, a smooth step between."""
    u = np.clip((TAPER * keep - f_local) / ((TAPER - 1.0) * keep), 0.0, 1.0)
    return u * u * u * (10.0 + u * (6.0 * u - 15.0))


def _square_wave_table(keep: float, lowest: float) -> tuple[np.ndarray, np.ndarray]:
    """The binary star's windowed square wave ``sum_k a_k W(k b) cos(k psi)``
    tabulated against ``psi`` (:data:`WAVE_SAMPLES` a cycle) and ``log b``
    (``b`` the fundamental's local frequency, ``lowest`` to ``TAPER * keep``
    cy/px): the sum, up to a thousand harmonics at the chip's rim, costs one
    inverse FFT a row instead of one pass over the fine grid a harmonic."""
    log_b = np.linspace(math.log(lowest), math.log(TAPER * keep), WAVE_ROWS)
    k = np.arange(WAVE_SAMPLES // 2 + 1)
    amplitude = np.where(k % 2 == 1, 4.0 / math.pi * (-1.0) ** ((k - 1) // 2) / np.maximum(k, 1), 0.0)
    coefficients = amplitude[None, :] * _window(k[None, :] * np.exp(log_b)[:, None], keep)
    return log_b, np.fft.irfft(coefficients * (WAVE_SAMPLES / 2.0), n=WAVE_SAMPLES, axis=1)


def _pattern(star: SiemensStar, x: np.ndarray, y: np.ndarray, keep: float) -> np.ndarray:
    """The star's pattern above its mean, relative to half its range (-1 to
    1), on the fine grid (x, y px from the centre), each harmonic windowed."""
    r = np.hypot(x, y)
    psi = star.cycles * (np.arctan2(y, x) - math.radians(star.phase_deg))
    with np.errstate(divide="ignore"):
        base = star.cycles / (2.0 * math.pi * r)          # the fundamental's local frequency, cy/px
    if star.profile == "sinusoidal":
        return _window(base, keep) * np.cos(psi)
    from scipy.ndimage import map_coordinates
    lowest = 0.5 * float(base.min())
    log_b, table = _square_wave_table(keep, lowest)
    inside = base < TAPER * keep
    rows = (np.log(base[inside]) - log_b[0]) / (log_b[1] - log_b[0])
    columns = np.mod(psi[inside], 2.0 * math.pi) * (WAVE_SAMPLES / (2.0 * math.pi))
    out = np.zeros_like(r)
    out[inside] = map_coordinates(table, [rows, columns], order=1, mode="grid-wrap")
    return out


def render_star(sensor: Sensor, star: SiemensStar, shape: int | tuple[int, int] = 201, *,
                gsd_m: float | None = None, bits: int | None = 16, noise_std_dn: float = 0.0,
                seed: int | None = None) -> StarChip:
    """Render a Siemens star through ``sensor``, exactly (see the module).

    Parameters
    ----------
    sensor : Sensor
        The sensor.
    star : SiemensStar
        The star.
    shape : int or (int, int), optional
        The chip's side or (rows, cols), px (default 201), at least 32.
    gsd_m : float, optional
        The pixel, m (default the sensor's).
    bits : {8, 16} or None, optional
        Round and clip to this depth (default 16); None keeps floats.
    noise_std_dn : float, optional
        White system noise, DN (default 0).
    seed : int, optional
        The noise's seed.

    Returns
    -------
    StarChip
        The chip and its truth.

    Raises
    ------
    ParameterError
        A chip under 32 px, or a bad depth.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.sensor.star import SiemensStar, render_star
    >>> from imgmtf.sensor.stages import Detector, GaussianOptics
    >>> sensor = imgmtf.Sensor(stages=[GaussianOptics(0.45, 0.6), Detector(1.0, 1.0)])
    >>> chip = render_star(sensor, SiemensStar(cycles=32), 64, bits=None)
    >>> chip.image.shape, round(float(chip.true_mtf(0.5, 90.0)), 4)
    ((64, 64), 0.1077)
    """
    rows, cols = (shape, shape) if isinstance(shape, (int, np.integer)) else tuple(shape)
    if not (rows >= MIN_STAR_PX and cols >= MIN_STAR_PX):
        raise ParameterError(f"a star chip must be at least {MIN_STAR_PX} x {MIN_STAR_PX} px, got {shape!r}")
    if bits not in (*BITS, None):
        raise ParameterError(f"bits must be 8, 16 or None, got {bits!r}")
    gsd = sensor.gsd_m if gsd_m is None else check_gsd("gsd_m", gsd_m)
    keep = keep_frequency(sensor, gsd)
    m = math.ceil(2.0 * (TAPER * keep + 0.5))             # its Nyquist above the finest harmonic kept
    m += 1 - m % 2                                         # odd: every pixel centre a fine sample
    halo = int(math.ceil(sensor.support_radius_m() / gsd)) + 3
    cx, cy = star.centre_px((rows, cols))
    tile = min(TILE_PX, max(rows, cols))
    n = (tile + 2 * halo) * m
    f = np.fft.fftfreq(n, d=1.0 / m)
    fr = np.fft.rfftfreq(n, d=1.0 / m)
    transfer = sensor.transfer(fr[None, :] / gsd, f[:, None] / gsd)
    offsets = (np.arange(n) - (m - 1) / 2.0) / m - halo    # fine positions from a tile's first pixel
    pattern = np.empty((rows, cols))
    for y0 in range(0, rows, tile):
        for x0 in range(0, cols, tile):
            fine = _pattern(star, x0 + offsets[None, :] - cx, y0 + offsets[:, None] - cy, keep)
            blurred = np.fft.irfft2(np.fft.rfft2(fine) * transfer, s=(n, n))
            samples = blurred[(m - 1) // 2::m, (m - 1) // 2::m][halo: halo + tile, halo: halo + tile]
            h, w = min(tile, rows - y0), min(tile, cols - x0)
            pattern[y0: y0 + h, x0: x0 + w] = samples[:h, :w]
    mean, half = (star.high_dn + star.low_dn) / 2.0, (star.high_dn - star.low_dn) / 2.0
    image = add_system_noise(mean + half * pattern, noise_std_dn, np.random.default_rng(seed))
    clipped = 0.0
    if bits is not None:
        top = 2 ** bits - 1
        image = np.rint(image)
        clipped = float(np.mean((image <= 0) | (image >= top)))
        image = np.clip(image, 0, top).astype(np.uint8 if bits == 8 else np.uint16)
    return StarChip(image, sensor, star, (cx, cy), gsd, bits, float(noise_std_dn), seed, clipped, keep)
