"""A bar's width read off its pulse response: the first zero of the
profile's spectrum (:func:`estimate_width`), only where it stands out of
the noise, and how that reading moves with the profile's values, for the
intervals (:func:`width_reading`).  The bar's own estimator is
:mod:`.pulse`."""
from __future__ import annotations

import math

import numpy as np

from ..errors import UnsuitableTargetError
from ..metrics import fwhm
from .intervals.width import WidthReading
from .spectrum import NYQUIST

ZERO_SET_SPAN = (0.5, 1.6)       # a read width's zero is judged over this span of f0 (W / 1.6 to 2 W)...
ZERO_SET_STEP_CY_PX = 0.02       # ...on this grid (its crossings interpolated)
MAX_ZERO_SEARCH_CY_PX = 0.9     # a pixel aperture has its first zero at 1 cy/px or above
ZERO_EVIDENCE_SD = 2.5          # the spectrum beyond a read zero must average this many sd below nil


def width_reading(grid: np.ndarray, prf01: np.ndarray, width_px: float, contrast_dn: float,
                  background_sides: tuple[np.ndarray, ...] = ()) -> WidthReading:
    """How :func:`estimate_width` read ``width_px`` off ``prf01``, the
    profile normalised by ``contrast_dn`` (its values minus the background,
    over the peak's height in DN): R(f) and its pull on the profile's
    values and background at the zero f0 and over ``ZERO_SET_SPAN`` of f0
    about it, for the intervals (:class:`imgmtf.estimate.intervals.width.WidthReading`);
    ``background_sides`` the masks of the samples the background is the
    mean of the two sides' means of.

    Examples
    --------
    A 1.5 px bar through a Gaussian PSF (sigma 0.5 px), made 0.02 px wider:

    >>> from scipy.special import erf
    >>> x = np.arange(-400, 401) * 0.05
    >>> def bar(w):
    ...     return 0.5 * (erf((x + w / 2) / 0.7071) - erf((x - w / 2) / 0.7071))
    >>> reading = width_reading(x, bar(1.5), estimate_width(x, bar(1.5)), 1.0)
    >>> round(float(reading.width_change(reading.on_grid[0] @ (bar(1.52) - bar(1.5)))), 3)
    0.02
    """
    f_zero = 1.0 / width_px
    low, high = (f * f_zero for f in ZERO_SET_SPAN)
    freqs = np.concatenate([[f_zero], np.arange(low, min(high, MAX_ZERO_SEARCH_CY_PX), ZERO_SET_STEP_CY_PX)])
    step = float(grid[1] - grid[0])
    cosines = np.cos(2 * np.pi * freqs[:, None] * grid[None, :]) * step
    slope = -float(np.sum(2 * np.pi * grid * np.sin(2 * np.pi * f_zero * grid) * prf01)) * step
    on_grid = cosines / contrast_dn             # prf01 = (values - background) / contrast
    return WidthReading(width_px, freqs, on_grid, -on_grid.sum(axis=1), cosines @ prf01, slope,
                        lambda f: sinc_log_slope(f, width_px), background_sides)


def sinc_log_slope(f, width_px: float):
    """d ln|sinc(f W)| / dW at ``f`` (cy/px) for a bar of width W (px):
    pi f cot(pi f W) - 1 / W (0 at f = 0)."""
    f = np.asarray(f, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.pi * f / np.tan(np.pi * f * width_px) - 1.0 / width_px
    return np.where(f == 0, 0.0, slope)


def estimate_width(grid: np.ndarray, prf01: np.ndarray, noise_per_px: float = 0.0) -> float:
    """Bar width from the first zero of the PRF's spectrum: |FT(PRF)| =
    |sinc(f W)| MTF(f), so its first zero is at 1/W as long as the MTF is
    still above the noise there.  Zeros are only sought below
    ``MAX_ZERO_SEARCH_CY_PX``: the pixel aperture's own zero near 1 cy/px
    would otherwise pass for a bar's.  The zero is located as the sign change
    of the spectrum referenced to the bar's centre (real for a symmetric
    bar).

    A zero is read only where it stands out of the noise: beyond a bar's
    zero its spectrum turns negative (the sinc's negative lobe), beyond a
    zero the noise made where the spectrum has faded it stays about nil.
    ``noise_per_px`` (the profile's noise over its peak's height, times the
    square root of a pixel over the samples per pixel: the sd of a linear
    functional sum(k * prf01) * step is noise_per_px * sqrt(sum(k^2) * step))
    judges it: the spectrum's mean over the lobe, from the zero f0 to 2 f0
    (or ``MAX_ZERO_SEARCH_CY_PX``), must lie ``ZERO_EVIDENCE_SD`` of its sd
    below nil; 0 (the default) takes
    any zero.

    Raises
    ------
    UnsuitableTargetError
        (reason ``bar-width``) no zero below ``MAX_ZERO_SEARCH_CY_PX``, or
        none that stands out of the noise: the message says how wide the bar
        may be and how far that moves the MTF at Nyquist.

    Examples
    --------
    >>> x = np.arange(-10, 10.0001, 0.05)
    >>> round(estimate_width(x, (np.abs(x) <= 1.25).astype(float)), 2)    # a bare 2.5 px box
    2.5
    """
    f = np.arange(0.005, MAX_ZERO_SEARCH_CY_PX, 0.0025)
    step = grid[1] - grid[0]
    cosines = np.cos(2 * np.pi * f[:, None] * grid[None, :])
    real = cosines @ prf01 * step
    area = prf01.sum() * step
    if area <= 0:
        raise UnsuitableTargetError("the bar width cannot be estimated from this profile: it has no area above "
                                    "its background; give its width", reason="bar-width")
    change = np.nonzero(np.sign(real[:-1]) != np.sign(real[1:]))[0]
    if change.size == 0:
        raise UnsuitableTargetError(
            f"the bar width cannot be estimated from this profile: its spectrum has no zero below "
            f"{MAX_ZERO_SEARCH_CY_PX} cy/px, so {_width_range(grid, prf01, f, real, cosines, noise_per_px)}; "
            "give its width", reason="bar-width")
    i = change[0]
    zero = f[i] - real[i] * (f[i + 1] - f[i]) / (real[i + 1] - real[i])
    lobe_sd = _lobe_sd(f, real, cosines, step, zero, noise_per_px) if noise_per_px > 0 else -math.inf
    if lobe_sd > -ZERO_EVIDENCE_SD:
        raise UnsuitableTargetError(
            f"the bar width cannot be told from the noise: its spectrum's zero at {zero:.3f} cy/px "
            f"({1 / zero:.2f} px) has no negative lobe beyond it (its mean to "
            f"{min(2 * zero, MAX_ZERO_SEARCH_CY_PX):.2f} cy/px is {lobe_sd:+.1f} sd, "
            f"{-ZERO_EVIDENCE_SD:g} needed) and may be the noise's, so "
            f"{_width_range(grid, prf01, f, real, cosines, noise_per_px)}; give its width", reason="bar-width")
    return float(1.0 / zero)


def _lobe_sd(f: np.ndarray, real: np.ndarray, cosines: np.ndarray, step: float, zero: float,
             noise_per_px: float) -> float:
    """The spectrum's mean over the sinc's first negative lobe beyond the
    zero (f0 to 2 f0, below ``MAX_ZERO_SEARCH_CY_PX``), in sd of that mean
    under white noise of ``noise_per_px``; 0 where the lobe holds no grid
    frequency (nothing shows it)."""
    beyond = (f > zero) & (f < 2.0 * zero)
    if not beyond.any():
        return 0.0
    sd = noise_per_px * math.sqrt(float(np.sum(cosines[beyond].mean(axis=0) ** 2)) * step)
    return float(real[beyond].mean()) / sd


def _width_range(grid: np.ndarray, prf01: np.ndarray, f: np.ndarray, real: np.ndarray, cosines: np.ndarray,
                 noise_per_px: float) -> str:
    """What a width that cannot be read leaves open, for a refusal: the
    widest bar whose zero the noise could hide (1 / the frequency where
    the spectrum ``real`` at ``f`` first falls within ``ZERO_EVIDENCE_SD``
    sd of nil, at most ``MAX_ZERO_SEARCH_CY_PX``; and no wider than the
    profile's FWHM), and the MTF at Nyquist a
    line and that bar would give (the profile's spectrum at Nyquist over
    its area within twice its half-width at 10 % and 2 px: about what
    the estimate would read)."""
    step = float(grid[1] - grid[0])
    sd = noise_per_px * np.sqrt(np.sum(cosines ** 2, axis=1) * step)
    faded = np.nonzero(real <= ZERO_EVIDENCE_SD * sd)[0]
    # a bar is no wider than its pulse response's FWHM (a symmetric, unimodal blur keeps its edges above half)
    widest = min(1.0 / (float(f[faded[0]]) if faded.size else MAX_ZERO_SEARCH_CY_PX), fwhm(grid, prf01))
    # the profile's spectrum at Nyquist over its area within a few of its widths: the far samples add only
    # noise and the background's error
    near = np.abs(grid) <= 2.0 * half_width_at(grid, prf01, 0.1) + 2.0
    line = float(np.cos(np.pi * grid[near]) @ prf01[near]) / float(prf01[near].sum())
    if NYQUIST * widest >= 1.0:
        return (f"the bar may be anything up to {widest:.2f} px wide, which puts the MTF at Nyquist anywhere "
                f"above about {line:.2f} (a line): a bar 2 px wide hides Nyquist in its sinc's zero")
    return (f"the bar may be anything up to {widest:.2f} px wide, which puts the MTF at Nyquist anywhere from "
            f"about {line:.2f} (a line) to {line / np.sinc(NYQUIST * widest):.2f} (a {widest:.2f} px bar)")


def half_width_at(grid: np.ndarray, prf01: np.ndarray, level: float) -> float:
    """Half of the PRF's width at ``level`` of its peak."""
    above = np.nonzero(prf01 >= level)[0]
    if above.size == 0:
        return 0.0
    return float(max(-grid[above[0]], grid[above[-1]]))
