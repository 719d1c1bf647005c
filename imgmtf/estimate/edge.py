"""Slanted-edge MTF estimator.

Pipeline (Choi and Helder, with the corrections of :mod:`imgmtf.mtf`):

1. seed: Canny + Hough finds the edge and its rough angle
   (:mod:`imgmtf.detection`); a near-horizontal edge is measured in the
   transposed image (along-track MTF);
2. a Fermi fit in every row gives sub-pixel edge locations, all rows solved
   at once (:mod:`imgmtf.fermi`); a robust least-squares line goes through
   them (:mod:`imgmtf.profile`);
3. every pixel's signed distance to that line gives the over-sampled ESF;
4. the ESF is smoothed and resampled onto a uniform grid by the chosen
   method (:mod:`imgmtf.resampling`);
5. the LSF is its central difference, cut to its support by a flat-topped
   window, and the MTF the corrected modulus of its Fourier transform.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .detection import find_edge
from ..errors import ImageContentError, UnsuitableTargetError
from ..inputs import prepare_image, saturation_levels
from ..metrics import fwhm
from .spectrum import (NYQUIST, central_difference, corrected_mtf, edge_divisor, flat_top_window, mtf50, mtf_area,
                  noise_limited_frequency, relative_edge_response, restore_lsf, rise_distance)
from .geometry import (ProfileEstimator, TargetGeometry, check_angle, locate_edge, profile_samples,
                      vertical_frame)
from .resampling import resample_profile
from .results import MTFResult, finite
from .intervals import bootstrap_figures

SNR_THRESHOLD = 100.0          # the paper's threshold for a confident estimate
# Measured by `imgmtf reproduce` (docs/reproduction.md): on the paper's 40-row
# edge chips, 95 % of msg estimates fall within +-5 % of the true MTF at
# Nyquist from SNR 125 on.  The noise falls as 1 / (SNR sqrt(rows)), so the
# threshold for an edge of n rows is 125 sqrt(40 / n).
CONFIDENT_SNR_40_ROWS = 125.0
WINDOW_FACTOR_CLEAN = 1.35     # LSF window half-width / 10-90 % rise, high SNR
WINDOW_FACTOR_NOISY = 1.0      # ... and at SNR <= 30


@dataclass(frozen=True, eq=False, kw_only=True)
class EdgeResult(MTFResult):
    """MTF of one edge and everything it was computed from (see
    :class:`imgmtf.results.MTFResult`).  ``esf`` is normalised to rise from
    0 to 1 whatever the edge's polarity; ``levels_dn`` are the dark and
    bright levels; ``rer`` the relative edge response."""

    target: ClassVar[str] = "edge"
    rer: float
    esf_x_px: np.ndarray
    esf: np.ndarray
    levels_dn: tuple[float, float]
    window_half_width_px: float

    def _specific(self) -> dict:
        return {"rer": finite(self.rer), "levels_dn": list(self.levels_dn)}


class EdgeEstimator(ProfileEstimator):
    """A configured slanted-edge estimator: set up once, apply to many chips.

    Takes the settings of :class:`imgmtf.profile.ProfileEstimator`, where
    ``snr_threshold=None`` uses the measured threshold for the edge's length
    (:func:`confident_snr`), and:

    lsf_half_width_px : half-width of the flat part of the LSF window (px);
        None chooses it from the measured edge width.
    lsf_window_factor : that half-width in units of the 10-90 % rise
        distance; None adapts it to the SNR (:func:`window_factor`).
    """

    def __init__(self, method: str = "msg", *, lsf_half_width_px: float | None = None,
                 lsf_window_factor: float | None = None, **settings):
        super().__init__(method, **settings)
        self.lsf_half_width_px = lsf_half_width_px
        self.lsf_window_factor = lsf_window_factor

    def __call__(self, image, *, roi=None, gsd_m: float | None = None,
                 saturation: tuple[float, float] | None = None) -> EdgeResult:
        """Measure the edge in ``image`` (2-D array, DN), optionally within
        ``roi`` = (x, y, width, height).  ``saturation`` is the (min, max)
        the sensor can record; it defaults to an integer dtype's range."""
        data, (x0, y0) = prepare_image(image, roi)
        if saturation is None:
            saturation = saturation_levels(np.asarray(image).dtype)
        work, seed_x, transposed = vertical_frame(data, find_edge(data))
        geometry = locate_edge(work, seed_x, transposed=transposed)
        check_angle(geometry, "edge")
        return self._profile(work, geometry, (x0, y0, data.shape[1], data.shape[0]),
                             gsd_m, saturation)

    def _profile(self, work, geometry: TargetGeometry, roi, gsd_m, saturation) -> EdgeResult:
        d, v, row, half_range = profile_samples(work, geometry, "edge")
        esf = resample_profile(d, v, method=self.method, step=self.step_px,
                               half_range=half_range - 0.6, **self.method_options)
        grid, values = esf.grid, esf.values
        good = np.isfinite(values)
        if not good[len(good) // 2 - 5: len(good) // 2 + 6].all():
            raise UnsuitableTargetError("the edge profile has gaps at the edge: too few "
                                        "sub-pixel samples (edge too short or angle unsuitable)")
        grid, values = grid[good], values[good]
        n_side = max(len(values) // 8, 2)
        left, right = values[:n_side].mean(), values[-n_side:].mean()
        if left == right:
            raise ImageContentError("the two sides of the edge have the same level")
        _check_saturation(v, d, left, right, saturation)
        esf01 = (values - left) / (right - left)
        x, lsf = central_difference(grid, esf01)
        centre = _crossing_nearest(grid, esf01)
        rise = rise_distance(grid, esf01, centre)
        if not rise > 0:
            raise UnsuitableTargetError("the edge profile does not rise cleanly from 10 % to 90 %: "
                                        "no usable edge (noise or a second feature?)")
        plateau = np.abs(d - centre) >= max(3.0 * rise, 2.0)
        snr = _edge_snr(v[plateau & (d < centre)], v[plateau & (d > centre)])
        factor = self.lsf_window_factor or window_factor(snr)
        half_width = self.lsf_half_width_px or factor * rise
        taper = 0.5 * half_width
        lsf_w = lsf * flat_top_window(x, centre, half_width, taper)
        divisor = edge_divisor(esf.step, esf.transfer if self.correct else None)
        mtf = corrected_mtf(lsf_w, esf.step, divisor)
        warnings = []
        rows_used = int(geometry.kept.sum())
        threshold = self.snr_threshold or confident_snr(rows_used)
        if snr < threshold:
            warnings.append(f"SNR {snr:.0f} is below {threshold:.0f}, the lowest at which 95 % of "
                            f"estimates from a {rows_used}-row edge fall within 5 % of the truth")
        density = d.size / (2.0 * half_range)
        noise_limit = noise_limited_frequency(mtf, snr, 2.0 * half_width + taper, density)
        x_c, lsf_c = restore_lsf(lsf_w, x, divisor, noise_limit)

        def windowed_lsf(grid_b, esf_b, weights_of):
            x_b, lsf_b = central_difference(grid_b, esf_b)
            return lsf_b * flat_top_window(x_b, centre, half_width, taper)
        nyquist_ci, mtf50_ci = bootstrap_figures(
            self.bootstrap, d, row, abs(centre) + half_width + taper + 2 * esf.step,
            self._resampler(d, v), windowed_lsf, esf.step, divisor)
        params = {"method": self.method, **esf.params, "correct": self.correct,
                  "lsf_half_width_px": half_width, "lsf_taper_px": taper,
                  "bootstrap": self.bootstrap.as_dict()}
        return EdgeResult(
            method=self.method, params=params, angle_deg=geometry.angle_deg,
            orientation="horizontal" if geometry.transposed else "vertical",
            polarity="rising" if right > left else "falling",
            rows_used=rows_used, rows_total=int(work.shape[0]), snr=snr,
            mtf_nyquist=float(mtf(NYQUIST)[0]), mtf50_cy_px=mtf50(mtf),
            mtf_nyquist_ci=nyquist_ci, mtf50_ci_cy_px=mtf50_ci,
            fwhm_px=fwhm(x_c, lsf_c), rer=relative_edge_response(grid, esf01, centre),
            mtfa=mtf_area(mtf), gsd_m=gsd_m,
            frequencies_cy_px=self.frequencies_cy_px, mtf=mtf(self.frequencies_cy_px),
            esf_x_px=grid, esf=esf01, lsf_x_px=x_c, lsf=lsf_c,
            samples_x_px=d, samples_dn=v, levels_dn=(float(left), float(right)),
            geometry=geometry, roi=roi, window_half_width_px=half_width,
            noise_limit_cy_px=noise_limit,
            warnings=tuple(warnings), mtf_function=mtf)


def measure_edge(image, *, roi=None, method: str = "msg", gsd_m: float | None = None,
                 saturation: tuple[float, float] | None = None, **options) -> EdgeResult:
    """Measure the MTF of the straight edge in ``image``.

    Parameters
    ----------
    image : 2-D array (DN), one edge crossing it.
    roi : optional (x, y, width, height) crop, pixels.
    method : "msg" (default), "sliding", "spline" or "iso".
    gsd_m : ground sample distance (m), to report cycles/m and metres.
    saturation : (min, max) DN the sensor records; default an integer
        image's dtype range, none for float images.
    **options : see :class:`EdgeEstimator`.

    Returns
    -------
    EdgeResult
    """
    return EdgeEstimator(method, **options)(image, roi=roi, gsd_m=gsd_m, saturation=saturation)


def _check_saturation(v, d, left, right, saturation) -> None:
    if saturation is None:
        return
    low, high = saturation
    for name, side, level in (("dark", d < 0 if left < right else d > 0, min(left, right)),
                              ("bright", d > 0 if left < right else d < 0, max(left, right))):
        at_limit = np.mean((v[side] <= low) | (v[side] >= high)) if side.any() else 0.0
        if at_limit > 0.2:
            raise UnsuitableTargetError(
                f"the {name} side of the edge is saturated ({100 * at_limit:.0f} % of its "
                f"pixels at {low:g} or {high:g} DN): its true level is unknown", reason="saturated")


def _crossing_nearest(grid, esf01) -> float:
    """Position of the 0.5 crossing of the normalised ESF closest to 0."""
    s = np.sign(esf01 - 0.5)
    idx = np.nonzero(s[:-1] * s[1:] <= 0)[0]
    if idx.size == 0:
        return 0.0
    i = idx[np.argmin(np.abs(grid[idx]))]
    y0, y1 = esf01[i], esf01[i + 1]
    return float(grid[i] + (0.5 - y0) / (y1 - y0) * (grid[i + 1] - grid[i])) if y1 != y0 else float(grid[i])


def confident_snr(rows: int) -> float:
    """Lowest SNR at which an edge of ``rows`` rows gives 95 % of its MTF at
    Nyquist estimates within 5 % of the truth (measured for MTF ~0.27)."""
    return CONFIDENT_SNR_40_ROWS * math.sqrt(40.0 / max(rows, 1))


def window_factor(snr: float) -> float:
    """Half-width of the flat LSF window in units of the 10-90 % rise.

    A bias-variance trade measured on exact chips (docs/accuracy.md): 1.35
    rises (plus a taper of half that) keeps the truncation bias at Nyquist
    below 0.0005 for Gaussian, pixel and Butterworth blurs, and is used at
    SNR >= 100; the noise of the flat tails grows with the window, so at
    SNR <= 30 the window shrinks to 1 rise (bias up to 0.002, noise 20 %
    lower), log-linearly in between."""
    if not math.isfinite(snr):
        return WINDOW_FACTOR_CLEAN
    t = min(max(math.log(snr / 30.0) / math.log(100.0 / 30.0), 0.0), 1.0)
    return WINDOW_FACTOR_NOISY + t * (WINDOW_FACTOR_CLEAN - WINDOW_FACTOR_NOISY)


def _edge_snr(v_left, v_right) -> float:
    """Paper's edge SNR: difference of the side means over the mean of the
    side standard deviations."""
    if v_left.size < 3 or v_right.size < 3:
        return float("nan")
    noise = (v_left.std(ddof=1) + v_right.std(ddof=1)) / 2.0
    signal = abs(v_right.mean() - v_left.mean())
    return float(signal / noise) if noise > 0 else float("inf")
