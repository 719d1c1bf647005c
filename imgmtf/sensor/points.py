"""Arrays of point targets rendered exactly through a sensor: points of
light (stars, convex mirrors, lamps) or squares of ``size_px`` (Rauchmiller's
black squares on white sand), each at its own sub-pixel offset.

Each output pixel is a point sample, at its centre, of the scene convolved
with the system PSF, which holds the pixel's aperture (the Detector stage),
so each pixel holds the PSF integrated over it.  The samples are made in the
frequency domain, exactly: a target at sub-pixel phase ``p`` has the pixel
values ``h(n - p)``, whose transform on a ``K`` px window is the sensor's
transfer (times a square's ``W^2 sinc(W fx) sinc(W fy)``) at every frequency
``f + j``, ``j`` an integer, phase-shifted and summed over ``j`` (the
aliases).  The sum runs until the transfer is negligible (< 1e-9), so the
only approximation is the window ``K``, sized from the PSF's support, and
aliases beyond ``MAX_ALIAS_ORDER`` cy/px for a sensor without optics.

Geometry as in :mod:`imgmtf.sensor.targets`: pixel centres at integer
coordinates, x along columns (across track), y along rows (along track).
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

#: the highest alias order (cy/px) the renderer sums; a sensor whose transfer is still above
#: ``ALIAS_TOLERANCE`` there (no optics: the pixel's sinc alone) is rendered with that small error
MAX_ALIAS_ORDER = 16
ALIAS_TOLERANCE = 1e-9
BITS = (8, 16)


def quarter_pixel_offsets(rows: int = 4, cols: int = 4) -> np.ndarray:
    """Distinct sub-pixel offsets for an array of ``rows`` x ``cols``
    targets: column ``c`` shifted ``c / cols`` px in x, row ``r`` shifted
    ``r / rows`` px in y (quarter pixels for a 4 x 4 array), so that the
    targets' phases tile the pixel evenly, as Rauchmiller laid out his
    squares.

    Parameters
    ----------
    rows, cols : int, optional
        The array's shape (default 4 x 4).

    Returns
    -------
    numpy.ndarray, shape (rows * cols, 2)
        (dx, dy) per target, px, row by row.

    Examples
    --------
    >>> quarter_pixel_offsets(2, 2).tolist()
    [[0.0, 0.0], [0.5, 0.0], [0.0, 0.5], [0.5, 0.5]]
    """
    r, c = np.mgrid[0:rows, 0:cols]
    return np.column_stack([(c / cols).ravel(), (r / rows).ravel()]).astype(float)


@dataclass(frozen=True)
class PointArray:
    """A ``rows`` x ``cols`` array of point targets (``size_px`` 0) or of
    squares ``size_px`` wide, centred on the chip.

    Parameters
    ----------
    rows, cols : int
        The array's shape.
    spacing_px : float
        Distance between neighbouring targets' centres, px.
    size_px : float
        The side of each square, px (0: a point).
    low_dn : float
        The background, DN.
    high_dn : float
        Inside a square, DN; a point carries the light of a 1 px square at
        this level (its integral is ``high_dn - low_dn`` DN px^2).  Below
        ``low_dn``: dark targets on a bright field.
    offsets_px : tuple of (float, float), optional
        Each target's sub-pixel (dx, dy), px, row by row; default
        :func:`quarter_pixel_offsets`.

    Raises
    ------
    ParameterError
        A non-finite or negative size, a spacing under 2 px, offsets that do
        not match the array.

    Examples
    --------
    >>> array = PointArray(2, 2, spacing_px=10.0)
    >>> array.centres_px((40, 40)).tolist()
    [[14.0, 14.0], [24.5, 14.0], [14.0, 24.5], [24.5, 24.5]]
    """

    rows: int = 4
    cols: int = 4
    spacing_px: float = 12.0
    size_px: float = 0.0
    low_dn: float = 200.0
    high_dn: float = 1200.0
    offsets_px: tuple[tuple[float, float], ...] | None = None

    def __post_init__(self):
        for name in ("rows", "cols"):
            value = getattr(self, name)
            if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < 1:
                raise ParameterError(f"point array {name} must be a positive integer, got {value!r}")
        for name in ("spacing_px", "size_px", "low_dn", "high_dn"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not math.isfinite(value):
                raise ParameterError(f"point array {name} must be a finite number, got {value!r}")
            object.__setattr__(self, name, float(value))
        if self.spacing_px < 2.0:
            raise ParameterError(f"point array spacing must be at least 2 px, got {self.spacing_px}")
        if not 0.0 <= self.size_px < self.spacing_px:
            raise ParameterError(f"point size must be >= 0 px and under the spacing, got {self.size_px}")
        if self.offsets_px is not None:
            offsets = np.asarray(self.offsets_px, float)
            if offsets.shape != (self.rows * self.cols, 2) or not np.isfinite(offsets).all():
                raise ParameterError(f"offsets must be {self.rows * self.cols} finite (dx, dy) pairs, px")
            object.__setattr__(self, "offsets_px", tuple(map(tuple, offsets.tolist())))

    @property
    def count(self) -> int:
        """The number of targets."""
        return self.rows * self.cols

    def offsets(self) -> np.ndarray:
        """Each target's (dx, dy) sub-pixel offset, px, shape (count, 2)."""
        if self.offsets_px is None:
            return quarter_pixel_offsets(self.rows, self.cols)
        return np.asarray(self.offsets_px, float)

    def centres_px(self, shape: tuple[int, int]) -> np.ndarray:
        """The targets' centres (x, y), px, on a chip of ``shape`` (rows,
        cols): the array centred, each target at its offset.

        Parameters
        ----------
        shape : (int, int)
            The chip's rows and columns.

        Returns
        -------
        numpy.ndarray, shape (count, 2)
            (x, y) per target, px, pixel centres at integers.
        """
        r, c = np.mgrid[0:self.rows, 0:self.cols]
        x0 = (shape[1] - 1) / 2.0 - (self.cols - 1) * self.spacing_px / 2.0
        y0 = (shape[0] - 1) / 2.0 - (self.rows - 1) * self.spacing_px / 2.0
        grid = np.column_stack([x0 + c.ravel() * self.spacing_px, y0 + r.ravel() * self.spacing_px])
        return np.floor(grid) + self.offsets()

    def to_dict(self) -> dict:
        return {"kind": "points", "rows": self.rows, "cols": self.cols, "spacing_px": self.spacing_px,
                "size_px": self.size_px, "low_dn": self.low_dn, "high_dn": self.high_dn,
                "offsets_px": self.offsets().tolist()}


@dataclass(frozen=True, eq=False)
class PointChip:
    """A rendered chip of point targets and how it was made (what
    :func:`render_points` returns).

    Attributes
    ----------
    image : numpy.ndarray, shape (rows, cols)
        The chip, DN: float64 (``bits`` None) or uint8/uint16.
    sensor : Sensor
        The sensor it was rendered through.
    array : PointArray
        The targets.
    centres_px : numpy.ndarray, shape (n, 2)
        Each target's true (x, y), px.
    gsd_m : float
        Its ground sample distance, m.
    bits : int or None
        8 or 16, or None (floats, no rounding).
    noise_std_dn : float
        Standard deviation of the white system noise, DN.
    seed : int or None
        The noise's random seed.
    clipped_fraction : float
        Fraction of pixels that hit 0 or the top of the range.
    """

    image: np.ndarray
    sensor: Sensor
    array: PointArray
    centres_px: np.ndarray
    gsd_m: float
    bits: int | None
    noise_std_dn: float
    seed: int | None
    clipped_fraction: float

    def true_mtf(self, f_cy_px: ArrayLike, direction: str = "across") -> np.ndarray:
        """The sensor's MTF across (x) or along (y) track at ``f_cy_px``
        (cy/px of this chip): what an ideal estimator returns once the
        squares' size is divided out.

        Parameters
        ----------
        f_cy_px : array_like
            Frequencies, cy/px.
        direction : {"across", "along"}, optional
            Across track (x, default) or along track (y).

        Returns
        -------
        numpy.ndarray
            The MTF (1 at zero).
        """
        angle = 0.0 if direction in ("across", "across-track") else 90.0
        return np.abs(self.sensor.normal_transfer(f_cy_px, angle, self.gsd_m))

    def true_mtf50_cy_px(self, direction: str = "across") -> float:
        """Frequency (cy/px) where the true MTF falls to 0.5."""
        f = np.linspace(0.0, 2.0, 20001)
        return first_crossing(f, self.true_mtf(f, direction), 0.5)

    def provenance(self) -> dict:
        """JSON-ready description of how the chip was made (what
        :func:`imgmtf.write_geotiff` stores in its ``IMGMTF`` tag): the
        truth is the sensor's transfer at this GSD."""
        return {"imgmtf_version": __version__, "sensor": self.sensor.to_dict(), "target": self.array.to_dict(),
                "gsd_m": self.gsd_m, "bits": self.bits, "noise_std_dn": self.noise_std_dn, "seed": self.seed,
                "centres_px": self.centres_px.tolist(),
                "mtf_nyquist_across": float(self.true_mtf(0.5, "across")),
                "mtf_nyquist_along": float(self.true_mtf(0.5, "along"))}


def target_transfer(sensor: Sensor, fx: np.ndarray, fy: np.ndarray, gsd_m: float, size_px: float) -> np.ndarray:
    """The transfer of the sensor and of one target (a square of ``size_px``
    with its area as gain, or a point of unit light) at (``fx``, ``fy``)
    cy/px: complex where the sensor's is."""
    t = sensor.transfer(fx / gsd_m, fy / gsd_m)
    if size_px > 0:
        t = t * (size_px ** 2) * np.sinc(size_px * fx) * np.sinc(size_px * fy)
    return t


def alias_order(sensor: Sensor, gsd_m: float, size_px: float) -> int:
    """The alias order (cy/px) beyond which the target's transfer is below
    :data:`ALIAS_TOLERANCE` on both axes, at most :data:`MAX_ALIAS_ORDER`."""
    f = np.linspace(0.0, MAX_ALIAS_ORDER + 0.5, 64 * MAX_ALIAS_ORDER + 33)
    zero = np.zeros_like(f)
    gain = max(size_px ** 2, 1.0)
    level = np.maximum(np.abs(target_transfer(sensor, f, zero, gsd_m, size_px)),
                       np.abs(target_transfer(sensor, zero, f, gsd_m, size_px))) / gain
    # the envelope from f on, so that a sinc's zero does not stop the sum early
    envelope = np.maximum.accumulate(level[::-1])[::-1]
    above = np.nonzero(envelope >= ALIAS_TOLERANCE)[0]
    reach = f[above[-1]] if above.size else 0.0
    return int(min(MAX_ALIAS_ORDER, math.ceil(reach + 0.5)))


def target_kernels(sensor: Sensor, phases_px: np.ndarray, window_px: int, gsd_m: float,
                   size_px: float = 0.0) -> np.ndarray:
    """The pixel values of one target at each sub-pixel phase, exactly: the
    PSF (pixel aperture included) integrated over each pixel of a
    ``window_px`` square window, the target's integer position at the
    window's centre pixel.

    Parameters
    ----------
    sensor : Sensor
        The sensor.
    phases_px : numpy.ndarray, shape (n, 2)
        (dx, dy) of each target from its centre pixel, px.
    window_px : int
        The window's side, px (odd).
    gsd_m : float
        The pixel, m.
    size_px : float, optional
        A square's side, px (0: a point).

    Returns
    -------
    numpy.ndarray, shape (n, window_px, window_px)
        Each target's pixel values (a point's sum to 1, a square's to its
        area, less what falls outside the window).
    """
    order = alias_order(sensor, gsd_m, size_px)
    m = 2 * order + 1                                  # samples per pixel of the fine grid
    f = np.fft.fftfreq(window_px * m, d=1.0 / m)       # cy/px, to +-(order + 1/2)
    t = target_transfer(sensor, f[None, :], f[:, None], gsd_m, size_px)
    half = window_px // 2
    out = np.empty((len(phases_px), window_px, window_px))
    for k, (dx, dy) in enumerate(np.asarray(phases_px, float)):
        # shifted to the window's centre pixel and by the phase; the fine grid decimated at the pixel centres
        shift = np.exp(-2j * np.pi * (f[None, :] * (dx + half) + f[:, None] * (dy + half)))
        fine = np.fft.ifft2(t * shift)
        out[k] = (m * m) * fine[::m, ::m].real
    return out


def render_points(sensor: Sensor, array: PointArray, shape: int | tuple[int, int] = 64, *,
                  gsd_m: float | None = None, bits: int | None = 16, noise_std_dn: float = 0.0,
                  seed: int | None = None) -> PointChip:
    """Render an array of point targets (or squares) through ``sensor``,
    exactly: each pixel holds the PSF integrated over it (see the module).

    Parameters
    ----------
    sensor : Sensor
        The sensor.
    array : PointArray
        The targets.
    shape : int or (int, int), optional
        The chip's side or (rows, cols), px (default 64).
    gsd_m : float, optional
        The pixel, m (default the sensor's).
    bits : {8, 16} or None, optional
        Round and clip to this depth (default 16); None keeps floats.
    noise_std_dn : float, optional
        White system noise added after sampling, DN (default 0).
    seed : int, optional
        The noise's random seed.

    Returns
    -------
    PointChip
        The chip and its truth.

    Raises
    ------
    ParameterError
        A bad shape or depth, or an array that does not fit on the chip.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.sensor.points import PointArray, render_points
    >>> from imgmtf.sensor.stages import Detector, GaussianOptics
    >>> sensor = imgmtf.Sensor(stages=[GaussianOptics(0.45, 0.55), Detector(1.0, 1.0)])
    >>> chip = render_points(sensor, PointArray(4, 4, spacing_px=12.0), 64, bits=None)
    >>> round(float(chip.image.sum() - 200.0 * 64 * 64), 6)      # 16 points of 1000 DN px^2
    16000.0
    >>> round(float(chip.true_mtf(0.5, "along")), 4)
    0.1431
    """
    rows, cols = (shape, shape) if isinstance(shape, (int, np.integer)) else tuple(shape)
    if not (rows >= 2 and cols >= 2):
        raise ParameterError(f"chip shape must be at least 2 x 2 px, got {shape!r}")
    if bits not in (*BITS, None):
        raise ParameterError(f"bits must be 8, 16 or None, got {bits!r}")
    gsd = sensor.gsd_m if gsd_m is None else check_gsd("gsd_m", gsd_m)
    centres = array.centres_px((rows, cols))
    reach = (array.size_px / 2.0 + 0.5) * math.sqrt(2.0)
    if (centres.min(axis=0) < reach).any() or (centres[:, 0] > cols - 1 - reach).any() \
            or (centres[:, 1] > rows - 1 - reach).any():
        raise ParameterError(f"a {array.rows} x {array.cols} array at {array.spacing_px:g} px does not fit on a "
                             f"{rows} x {cols} px chip")
    window = 2 * int(math.ceil(3.0 * sensor.support_radius_m() / gsd + array.size_px)) + 3
    whole = np.floor(centres).astype(int)
    kernels = target_kernels(sensor, centres - whole, window, gsd, array.size_px)
    half = window // 2
    padded = np.zeros((rows + 2 * half, cols + 2 * half))
    for (x, y), kernel in zip(whole, kernels):
        padded[y: y + window, x: x + window] += kernel
    image = array.low_dn + (array.high_dn - array.low_dn) * padded[half: half + rows, half: half + cols]
    rng = np.random.default_rng(seed)
    image = add_system_noise(image, noise_std_dn, rng)
    clipped = 0.0
    if bits is not None:
        top = 2 ** bits - 1
        image = np.rint(image)
        clipped = float(np.mean((image <= 0) | (image >= top)))
        image = np.clip(image, 0, top).astype(np.uint8 if bits == 8 else np.uint16)
    return PointChip(image, sensor, array, centres, gsd, bits, float(noise_std_dn), seed, clipped)
