"""Where a Siemens star is and what it is: its centre (sub-pixel), its
number of cycles and its profile (sinusoidal or binary).

The centre is found twice.  First by symmetry: a star seen through a
point-symmetric PSF is its own 180-degree rotation about its centre
(inverted when N is odd), so the phase correlation of the chip with its
rotation peaks at twice the centre's offset from the chip's middle.  Then
by the pattern itself: on an annulus where the star is well resolved, the
centre is the one about which the pixels are best a sum of angular
harmonics ``cos(k N theta)``, ``sin(k N theta)`` (with a linear change of
their amplitude with radius, an anisotropy of period 180 deg and a
gradient of the illumination), a variable-projection least-squares fit of
the two coordinates.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import TargetNotFoundError, UnsuitableTargetError

#: the smallest share of the angular variance the star's fundamental must hold on its outer circles
MIN_FUNDAMENTAL_SHARE = 0.3
#: a sinusoid spends 29 % of its period within a tenth of its range from its extremes, a square wave most of its
#: period: the share on the outermost circle above which a star is binary
BINARY_PLATEAU_SHARE = 0.45
#: a chip refused as a line is said to hold a star when the same harmonic, of at least so many cycles, holds
#: at least this share of the angular variance on its outer and its middle circles
MIN_SEEN_CYCLES = 8
MIN_SEEN_SHARE = 0.5
#: the annulus the centre is refined on: the fundamental's local frequency between these, cy/px
REFINE_BAND_CY_PX = (0.06, 0.3)
#: at most so many of the annulus' pixels enter the centre's fit
REFINE_PIXELS = 6000


@dataclass(frozen=True)
class StarGeometry:
    """A star's centre, cycles and profile.

    Attributes
    ----------
    x_px, y_px : float
        The centre, px (pixel centres at integers).
    cycles : int
        N, periods around the centre.
    profile : str
        "sinusoidal" or "binary".
    phase_rad : float
        The fundamental's phase: the pattern is ``cos(N theta - phase)``
        about its mean at low frequency.
    outer_radius_px : float
        The largest radius read: the nearest chip border less a margin.
    centre_rms_px : float
        The refined centre's standard error, px (from the fit's residuals).
    """

    x_px: float
    y_px: float
    cycles: int
    profile: str
    phase_rad: float
    outer_radius_px: float
    centre_rms_px: float

    @property
    def nyquist_radius_px(self) -> float:
        """Where the star's frequency ``N / (2 pi r)`` is 0.5 cy/px."""
        return self.cycles / math.pi


def rough_centre(image: np.ndarray) -> tuple[float, float]:
    """The centre of the chip's point symmetry, px: the phase correlation of
    the chip with its 180-degree rotation (its peak's magnitude, so that an
    inverted rotation counts) peaks at twice the centre's offset."""
    data = image - image.mean()
    rows, cols = data.shape
    taper = np.outer(np.hanning(rows), np.hanning(cols))  # symmetric about the chip's middle: no bias of its own
    a = np.fft.fft2(data * taper)
    b = np.fft.fft2(data[::-1, ::-1] * taper)
    cross = a * np.conj(b)
    surface = np.abs(np.fft.ifft2(cross / np.maximum(np.abs(cross), 1e-12 * np.abs(cross).max())))
    py, px = np.unravel_index(int(np.argmax(surface)), surface.shape)
    shifts = []
    for peak, n, axis in ((px, cols, 1), (py, rows, 0)):
        around = [surface[(py + (d if axis == 0 else 0)) % rows, (px + (d if axis == 1 else 0)) % cols]
                  for d in (-1, 0, 1)]
        denominator = around[0] - 2 * around[1] + around[2]
        sub = 0.5 * (around[0] - around[2]) / denominator if denominator < 0 else 0.0
        shift = peak + sub
        shifts.append(shift - n if shift > n / 2 else shift)
    return ((cols - 1 + shifts[0]) / 2.0, (rows - 1 + shifts[1]) / 2.0)


def angular_spectrum(image: np.ndarray, x: float, y: float, radii: np.ndarray, samples: int = 2048) -> np.ndarray:
    """The magnitudes of the angular harmonics 0 to ``samples / 2`` of the
    chip on circles of ``radii`` about (x, y), averaged over the circles."""
    from scipy.ndimage import map_coordinates
    theta = np.arange(samples) * (2.0 * math.pi / samples)
    xs = x + radii[:, None] * np.cos(theta)[None, :]
    ys = y + radii[:, None] * np.sin(theta)[None, :]
    values = map_coordinates(np.asarray(image, float), [ys.ravel(), xs.ravel()], order=1).reshape(xs.shape)
    return np.abs(np.fft.rfft(values - values.mean(axis=1, keepdims=True), axis=1)).mean(axis=0) * (2.0 / samples)


def cycles_and_profile(image: np.ndarray, x: float, y: float, outer: float) -> tuple[int, str, float]:
    """The star's cycles, profile and its fundamental's amplitude (DN) on
    its outer circles about (x, y).

    Raises
    ------
    UnsuitableTargetError
        (reason ``not-a-star``) no angular harmonic dominates: no star
        about that centre.
    """
    radii = np.linspace(0.75 * outer, outer, 6)
    spectrum = angular_spectrum(image, x, y, radii)
    spectrum[:3] = 0.0                                     # the mean and illumination, not a star's cycles
    n = int(np.argmax(spectrum))
    share = spectrum[n] ** 2 / max(float(np.sum(spectrum ** 2)), 1e-300)
    if n < 4:
        raise UnsuitableTargetError(
            f"no Siemens star about ({x:.1f}, {y:.1f}): the strongest angular variation around it has {n} cycles "
            "(a star has at least 4): an edge, a bar or a uniform field", reason="not-a-star")
    if share < MIN_FUNDAMENTAL_SHARE:
        raise UnsuitableTargetError(
            f"no Siemens star about ({x:.1f}, {y:.1f}): its strongest angular harmonic ({n} cycles) holds "
            f"{100 * share:.0f} % of the variance around the centre (a star's holds over "
            f"{100 * MIN_FUNDAMENTAL_SHARE:.0f} %)", reason="not-a-star")
    # wedges dwell on their two levels, a sinusoid passes through: on the outermost circle, the least blurred
    circle = angular_values(image, x, y, outer)
    low, high = np.percentile(circle, [1, 99])
    near_extremes = float(np.mean(np.abs(circle - 0.5 * (low + high)) > 0.4 * (high - low)))
    profile = "binary" if near_extremes > BINARY_PLATEAU_SHARE else "sinusoidal"
    return n, profile, float(spectrum[n])


def angular_values(image: np.ndarray, x: float, y: float, radius: float, samples: int = 2048) -> np.ndarray:
    """The chip on a circle of ``radius`` about (x, y), bilinear."""
    from scipy.ndimage import map_coordinates
    theta = np.arange(samples) * (2.0 * math.pi / samples)
    return map_coordinates(np.asarray(image, float), [y + radius * np.sin(theta), x + radius * np.cos(theta)],
                           order=1)


def harmonic_design(dx: np.ndarray, dy: np.ndarray, cycles: int, profile: str, radius: float) -> np.ndarray:
    """The columns the centre's fit explains the annulus with (see the
    module): the mean and an illumination gradient; each harmonic ``k N``
    (1, and 3 and 5 for a binary star) as cos and sin, their change with
    radius and their anisotropy (harmonics ``k N +- 2``)."""
    r = np.hypot(dx, dy)
    theta = np.arctan2(dy, dx)
    rho = (r - radius) / radius
    columns = [np.ones_like(r), dx / radius, dy / radius]
    for k in ((1, 3, 5) if profile == "binary" else (1,)):
        psi = k * cycles * theta
        for phase in (psi, psi + 2 * theta, psi - 2 * theta):
            columns += [np.cos(phase), np.sin(phase)]
        columns += [rho * np.cos(psi), rho * np.sin(psi)]
    return np.column_stack(columns)


def refine_centre(image: np.ndarray, x: float, y: float, cycles: int, profile: str,
                  outer: float) -> tuple[float, float, float, float]:
    """The centre (x, y) about which the annulus is best a sum of the
    star's harmonics, its standard error (px) and the fundamental's phase.

    Raises
    ------
    TargetNotFoundError
        The annulus where the star is resolved does not fit on the chip.
    """
    from scipy.optimize import least_squares
    low, high = REFINE_BAND_CY_PX
    r_in = max(cycles / (2 * math.pi * high), 4.0)
    r_out = min(cycles / (2 * math.pi * low), outer)
    if r_out < r_in + 4.0:
        raise TargetNotFoundError(
            f"the star's {cycles} cycles are resolved only beyond {r_in:.0f} px from its centre, and the chip "
            f"reaches {outer:.0f} px: a larger chip, or a star of fewer cycles")
    rows, cols = image.shape
    yy, xx = np.mgrid[0:rows, 0:cols]
    r0 = np.hypot(xx - x, yy - y)
    keep = (r0 >= r_in - 1.0) & (r0 <= r_out + 1.0)
    stride = max(1, int(np.count_nonzero(keep)) // REFINE_PIXELS)   # an even spread of pixels is as good as all
    px, py = xx[keep][::stride].astype(float), yy[keep][::stride].astype(float)
    values = np.asarray(image, float)[keep][::stride]
    radius = 0.5 * (r_in + r_out)

    def explained(centre):
        design = harmonic_design(px - centre[0], py - centre[1], cycles, profile, radius)
        # the normal equations: the columns are nearly orthogonal, and an SVD of every trial costs 100 times more
        beta = np.linalg.solve(design.T @ design, design.T @ values)
        return design, beta

    def residuals(centre):
        design, beta = explained(centre)
        return design @ beta - values
    fit = least_squares(residuals, np.array([x, y]), x_scale=0.1, diff_step=1e-4, xtol=1e-6, ftol=1e-8)
    cx, cy = (float(v) for v in fit.x)
    design, beta = explained(fit.x)
    dof = max(values.size - design.shape[1] - 2, 1)
    variance = float(np.sum(fit.fun ** 2)) / dof
    try:
        covariance = np.linalg.inv(fit.jac.T @ fit.jac) * variance
        rms = float(np.sqrt(np.trace(covariance)))
    except np.linalg.LinAlgError:
        rms = math.nan
    phase = float(np.arctan2(beta[4], beta[3]))              # cos(psi) and sin(psi) of the fundamental
    return cx, cy, rms, phase


def star_seen(image: np.ndarray) -> str | None:
    """What a chip refused as an edge or a bar shows if a Siemens star fills
    it: "a sinusoidal Siemens star of 46 cycles about (60.3, 59.8)", or
    None (its strongest angular harmonic about its centre of symmetry is
    no star's: an edge's or a bar's has one or two cycles).

    Parameters
    ----------
    image : numpy.ndarray
        The chip, DN.

    Returns
    -------
    str or None
        The words naming what was seen.

    Examples
    --------
    >>> star_seen(np.zeros((40, 40))) is None
    True
    """
    data = np.asarray(image, float)
    if data.ndim != 2 or min(data.shape) < 32 or not np.isfinite(data).all() or np.ptp(data) == 0:
        return None
    x, y = rough_centre(data)
    outer = min(x, y, data.shape[1] - 1 - x, data.shape[0] - 1 - y) - 2.0
    if outer < 12.0:
        return None
    try:
        n, profile, _ = cycles_and_profile(data, x, y, outer)
    except UnsuitableTargetError:
        return None
    # a star's cycles are the same on every circle, and hold most of its variance; a wide bar's are neither
    inner = angular_spectrum(data, x, y, np.linspace(0.5 * outer, 0.6 * outer, 4))
    inner[:3] = 0.0
    share = inner[n] ** 2 / max(float(np.sum(inner ** 2)), 1e-300)
    if n < MIN_SEEN_CYCLES or int(np.argmax(inner)) != n or share < MIN_SEEN_SHARE:
        return None
    return f"a {profile} Siemens star of {n} cycles about ({x:.1f}, {y:.1f})"


def locate_star(image: np.ndarray, *, profile: str = "auto", cycles: int | None = None,
                margin_px: float = 2.0) -> StarGeometry:
    """The star's centre, cycles and profile (see the module).

    Parameters
    ----------
    image : numpy.ndarray, shape (rows, cols)
        The chip, DN, linear in light.
    profile : {"auto", "sinusoidal", "binary"}, optional
        The star's profile, or found from its outer circles (default).
    cycles : int, optional
        N, when known (default: the strongest angular harmonic).
    margin_px : float, optional
        Kept from the chip's border, px (default 2).

    Returns
    -------
    StarGeometry
        Where the star is and what it is.

    Raises
    ------
    UnsuitableTargetError
        (reason ``not-a-star``) no star about the chip's centre of symmetry.
    TargetNotFoundError
        The star's resolved rings do not fit on the chip.
    """
    rows, cols = image.shape
    x, y = rough_centre(image)
    outer = min(x, y, cols - 1 - x, rows - 1 - y) - margin_px
    if outer < 8.0:
        raise UnsuitableTargetError(f"the chip's centre of symmetry ({x:.1f}, {y:.1f}) lies within 10 px of its "
                                    "border: no Siemens star fills it", reason="not-a-star")
    found, seen, _ = cycles_and_profile(image, x, y, outer)
    n = found if cycles is None else int(cycles)
    shape = seen if profile == "auto" else profile
    x, y, rms, phase = refine_centre(image, x, y, n, shape, outer)
    outer = min(x, y, cols - 1 - x, rows - 1 - y) - margin_px
    return StarGeometry(x, y, n, shape, phase, outer, rms)
