"""Pulse-target MTF estimator: bridges, tarp strips, painted lines.

Pipeline (Choi and Helder, Figure 8), sharing the edge estimator's stages:

1. seed: Canny + Hough finds the bar's direction (:mod:`imgmtf.detection`);
2. the bar's centre in every row is the centroid of its background-
   subtracted profile, re-centred twice on the fitted line; a robust
   least-squares line goes through the centres (:mod:`imgmtf.profile`);
3. every pixel's signed distance to that line gives the over-sampled pulse
   response function (PRF), smoothed and resampled by the same methods as
   an ESF (:mod:`imgmtf.resampling`);
4. MTF = |FT(PRF)| / (|sinc(f W)| H_method(f)), normalised at zero, for a bar
   W px wide; frequencies where |sinc(f W)| < 0.1 are masked (NaN).

No derivative is taken, so there is no central-difference correction.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .detection import bar_contrast, find_lines, robust_noise
from .edge import SNR_THRESHOLD
from ..errors import ParameterError, TargetNotFoundError, UnsuitableTargetError
from ..inputs import prepare_image
from ..metrics import fwhm
from .spectrum import (MIN_TRANSFER, NYQUIST, corrected_mtf, flat_top_window, mtf50,
                  mtf_area, noise_limited_frequency, restore_lsf, with_transfer)
from .geometry import (ProfileEstimator, check_angle, fit_line, profile_samples, row_windows,
                      vertical_frame)
from .resampling import resample_profile
from .results import MTFResult, finite
from .intervals import bootstrap_figures

MIN_FIRST_ZERO_CY_PX = 0.1      # a wider bar leaves too little usable band
RESTORE_MIN_SINC = 0.02         # below this |sinc| the LSF spectrum is interpolated
MAX_ZERO_SEARCH_CY_PX = 0.9     # a pixel aperture has its first zero at 1 cy/px or above


@dataclass(frozen=True, eq=False, kw_only=True)
class PulseResult(MTFResult):
    """MTF from one bar (see :class:`imgmtf.results.MTFResult`).

    ``prf`` is the pulse response normalised to a unit peak above the
    background (positive for dark bars too); ``pulse_width_px`` the bar
    width used (``width_estimated`` when it came from the profile);
    ``usable_band_cy_px`` the frequency below which the bar's sinc stays
    above 0.1, so that dividing by it is meaningful; ``fwhm_px`` is the
    recovered LSF's, ``prf_fwhm_px`` the PRF's."""

    target: ClassVar[str] = "pulse"
    pulse_width_px: float
    width_estimated: bool
    usable_band_cy_px: float
    prf_x_px: np.ndarray
    prf: np.ndarray
    prf_fwhm_px: float
    background_dn: float
    peak_dn: float

    def _specific(self) -> dict:
        return {"pulse_width_px": finite(self.pulse_width_px), "width_estimated": self.width_estimated,
                "usable_band_cy_px": finite(self.usable_band_cy_px),
                "prf_fwhm_px": finite(self.prf_fwhm_px), "background_dn": finite(self.background_dn),
                "peak_dn": finite(self.peak_dn)}


class PulseEstimator(ProfileEstimator):
    """A configured pulse estimator: set up once, apply to many chips.

    Takes the settings of :class:`imgmtf.profile.ProfileEstimator`;
    ``snr_threshold=None`` uses the paper's 100 (the reproduction study
    measured edges only).
    """

    def __call__(self, image, *, width_px: float | None = None, roi=None,
                 gsd_m: float | None = None) -> PulseResult:
        """Measure the bar in ``image`` (2-D array, DN), ``width_px`` wide
        (estimated from the profile when None)."""
        if width_px is not None:
            check_width(width_px)
        data, (x0, y0) = prepare_image(image, roi)
        lines = find_lines(data)
        if not lines:
            raise TargetNotFoundError("no bar found: no straight line of strong contrast")
        noise = robust_noise(data)
        lines = [ln for ln in lines if bar_contrast(data, ln) >= 3.0 * noise]
        if not lines:
            raise TargetNotFoundError("no bar found: no straight line stands out of the noise")
        work, seed_x, transposed = vertical_frame(data, lines[0])
        geometry = locate_pulse(work, seed_x, transposed)
        check_angle(geometry, "bar")
        d, v, row, half_range = profile_samples(work, geometry, "bar")
        prf = resample_profile(d, v, method=self.method, step=self.step_px,
                               half_range=half_range - 0.6, **self.method_options)
        grid, values = prf.grid, prf.values
        good = np.isfinite(values)
        grid, values = grid[good], values[good]
        n_side = max(len(values) // 6, 2)
        left, right = values[:n_side].mean(), values[-n_side:].mean()
        background = (left + right) / 2
        centre = np.argmin(np.abs(grid))
        sign = 1.0 if values[centre] >= background else -1.0
        peak = sign * (values - background)
        height = peak[centre - 20: centre + 21].max()
        if height < 5 * noise:
            raise TargetNotFoundError(f"no bar found: the profile peaks {height:.1f} DN above "
                                      f"its background, within the noise ({noise:.1f} DN)")
        if abs(left - right) > 0.25 * height:
            raise UnsuitableTargetError("the profile is a step, not a bar (its two sides differ "
                                        "by more than a quarter of its height): measure it as an edge",
                                        reason="not-a-bar")
        prf01 = peak / height
        h10 = _half_width_at(grid, prf01, 0.1)
        outer = np.abs(d) > min(1.5 * h10 + 1.0, half_range - 1.0)
        snr = _pulse_snr(height, v[outer])
        width_estimated = width_px is None
        if width_estimated:
            width_px = estimate_width(grid, prf01)
            check_width(width_px)
        if width_px / 2 + 2.0 > half_range:
            raise UnsuitableTargetError(
                f"the bar ({width_px:.1f} px) is too wide for the chip: it needs "
                f"{width_px / 2 + 2:.1f} px of background on each side of its centre")
        half_width = max(1.6 * h10, width_px / 2 + 1.0)
        taper = 0.5 * half_width
        prf_w = prf01 * flat_top_window(grid, 0.0, half_width, taper)
        transfer = prf.transfer if self.correct else None
        divisor = pulse_divisor(width_px, transfer)
        mtf = corrected_mtf(prf_w, prf.step, divisor)
        density = d.size / (2.0 * half_range)
        noise_limit = noise_limited_frequency(mtf, snr, 2.0 * half_width + taper, density)
        band = usable_band(width_px)
        # the division is bridged only right at the sinc's zeros: between them
        # even a small sinc carries LSF content the FWHM needs
        x_c, lsf_c = restore_lsf(prf_w, grid, divisor, noise_limit, min_divisor=RESTORE_MIN_SINC)
        # a replicate's background moves as the mean of its outer samples does
        outer_band = np.abs(d) >= min(-grid[n_side - 1], grid[-n_side])

        def windowed_prf(grid_b, values_b, weights_of):
            weights = weights_of(outer_band)
            shift = weights @ v[outer_band] / weights.sum(axis=1)
            background_b = background + shift - v[outer_band].mean()
            return (values_b - background_b[:, None]) * flat_top_window(grid_b, 0.0, half_width, taper)
        nyquist_ci, mtf50_ci = bootstrap_figures(
            self.bootstrap, d, row, half_width + taper + 2 * prf.step,
            self._resampler(d, v), windowed_prf, prf.step, divisor)
        warnings = []
        threshold = self.snr_threshold or SNR_THRESHOLD
        if snr < threshold:
            warnings.append(f"SNR {snr:.0f} is below {threshold:.0f}: the estimate is not confident")
        if band < NYQUIST:
            warnings.append(f"the bar's sinc falls below {MIN_TRANSFER} at {band:.3f} cy/px, before "
                            "Nyquist: MTF values near its zeros are masked (NaN)")
        params = {"method": self.method, **prf.params, "correct": self.correct,
                  "window_half_width_px": half_width, "window_taper_px": taper,
                  "bootstrap": self.bootstrap.as_dict()}
        return PulseResult(
            method=self.method, params=params, angle_deg=geometry.angle_deg,
            orientation="horizontal" if transposed else "vertical",
            polarity="bright" if sign > 0 else "dark",
            rows_used=int(geometry.kept.sum()), rows_total=int(work.shape[0]), snr=snr,
            mtf_nyquist=float(mtf(NYQUIST)[0]), mtf50_cy_px=mtf50(mtf), fwhm_px=fwhm(x_c, lsf_c),
            mtf_nyquist_ci=nyquist_ci, mtf50_ci_cy_px=mtf50_ci,
            mtfa=mtf_area(mtf), gsd_m=gsd_m, frequencies_cy_px=self.frequencies_cy_px,
            mtf=mtf(self.frequencies_cy_px), lsf_x_px=x_c, lsf=lsf_c, samples_x_px=d,
            samples_dn=v, geometry=geometry, roi=(x0, y0, data.shape[1], data.shape[0]),
            noise_limit_cy_px=noise_limit, warnings=tuple(warnings), mtf_function=mtf,
            pulse_width_px=float(width_px), width_estimated=width_estimated,
            usable_band_cy_px=band, prf_x_px=grid, prf=prf01, prf_fwhm_px=fwhm(grid, prf01),
            background_dn=float(background), peak_dn=float(background + sign * height))


def measure_pulse(image, *, width_px: float | None = None, roi=None, method: str = "msg",
                  gsd_m: float | None = None, **options) -> PulseResult:
    """Measure the MTF from the bar (pulse) in ``image``.

    Parameters
    ----------
    image : 2-D array (DN) with one straight bar, bright or dark.
    width_px : the bar's width along its normal (px); estimated from the
        first zero of the PRF's spectrum when None.
    roi : optional (x, y, width, height) crop, pixels.
    method : "msg" (default), "sliding", "spline" or "iso".
    gsd_m : ground sample distance (m), to report cycles/m and metres.
    **options : see :class:`PulseEstimator`.
    """
    return PulseEstimator(method, **options)(image, width_px=width_px, roi=roi, gsd_m=gsd_m)


def pulse_divisor(width_px: float, transfer):
    """Transfer between the system LSF and the resampled PRF: the bar's
    sinc(f W) (signed) times the resampling method's transfer."""
    return with_transfer(lambda f: np.sinc(f * width_px), transfer)


def usable_band(width_px: float) -> float:
    """First frequency (cy/px) where |sinc(f W)| falls to ``MIN_TRANSFER``."""
    f = np.linspace(0.0, 1.0 / width_px, 2001)
    return float(f[np.argmax(np.abs(np.sinc(f * width_px)) < MIN_TRANSFER)])


def check_width(width_px: float) -> None:
    """Refuse a non-positive width and one whose sinc has its first zero
    below ``MIN_FIRST_ZERO_CY_PX``."""
    if not (isinstance(width_px, (int, float)) and math.isfinite(width_px) and width_px > 0):
        raise ParameterError(f"the pulse width must be > 0 px, got {width_px}")
    if 1.0 / width_px < MIN_FIRST_ZERO_CY_PX:
        raise ParameterError(
            f"a {width_px:g} px wide bar puts the first zero of its sinc at {1 / width_px:.3f} cy/px, "
            f"below {MIN_FIRST_ZERO_CY_PX} cy/px: too little of the MTF can be recovered")


def estimate_width(grid: np.ndarray, prf01: np.ndarray) -> float:
    """Bar width from the first zero of the PRF's spectrum: |FT(PRF)| =
    |sinc(f W)| MTF(f), so its first zero is at 1/W as long as the MTF is
    still above the noise there.  Zeros are only sought below
    ``MAX_ZERO_SEARCH_CY_PX``: the pixel aperture's own zero near 1 cy/px
    would otherwise pass for a bar's.  The zero is located as the sign change
    of the spectrum referenced to the bar's centre (real for a symmetric
    bar)."""
    f = np.arange(0.005, MAX_ZERO_SEARCH_CY_PX, 0.0025)
    step = grid[1] - grid[0]
    real = np.cos(2 * np.pi * f[:, None] * grid[None, :]) @ prf01 * step
    area = prf01.sum() * step
    change = np.nonzero(np.sign(real[:-1]) != np.sign(real[1:]))[0]
    if change.size == 0 or area <= 0:
        raise UnsuitableTargetError(
            f"the bar width cannot be estimated from this profile (no zero in its spectrum below "
            f"{MAX_ZERO_SEARCH_CY_PX} cy/px, so the bar is narrower than "
            f"{1 / MAX_ZERO_SEARCH_CY_PX:.2f} px); give it with --pulse-width")
    i = change[0]
    zero = f[i] - real[i] * (f[i + 1] - f[i]) / (real[i + 1] - real[i])
    return float(1.0 / zero)


def locate_pulse(work: np.ndarray, seed_x: np.ndarray, transposed: bool, half_window: int = 12):
    """Per-row bar centres (centroids of the background-subtracted profile
    within ``half_window`` px), re-centred twice on the fitted line."""
    background = np.median(work, axis=1)
    rows = np.arange(work.shape[0])
    centre_x = seed_x
    for _ in range(3):
        cols, values, inside = row_windows(work, centre_x, half_window)
        excess = (values - background[:, None]) * inside
        sign = 1.0 if excess.sum() >= 0 else -1.0
        weight = sign * excess
        total = weight.sum(axis=1)
        usable = (inside.sum(axis=1) == 2 * half_window + 1) & (total > 0)
        if usable.sum() < 5:
            raise UnsuitableTargetError(
                f"fewer than 5 rows hold the bar with {half_window} px of background on both "
                "sides: the chip is too narrow, or the bar too wide or too close to its border")
        centres = (weight * cols).sum(axis=1)[usable] / total[usable]
        geometry = fit_line(rows[usable], centres, transposed)
        centre_x = geometry.slope * rows + geometry.intercept
    return geometry


def _half_width_at(grid: np.ndarray, prf01: np.ndarray, level: float) -> float:
    """Half of the PRF's width at ``level`` of its peak."""
    above = np.nonzero(prf01 >= level)[0]
    if above.size == 0:
        return 0.0
    return float(max(-grid[above[0]], grid[above[-1]]))


def _pulse_snr(height: float, background: np.ndarray) -> float:
    """Paper's pulse SNR: PRF peak above the mean background over the
    background's standard deviation (pulse excluded)."""
    if background.size < 3:
        return float("nan")
    sd = background.std(ddof=1)
    return float(height / sd) if sd > 0 else float("inf")
