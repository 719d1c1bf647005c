"""What every MTF estimate returns: the common part of edge and pulse
results, and its JSON form."""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from ..safe_json import finite_values
from ..version import __version__
from .geometry import TargetGeometry
from .intervals import Interval


@dataclass(frozen=True, eq=False, kw_only=True)
class MTFResult:
    """An MTF estimate and what it was computed from.

    Conventions: distances in pixels along the target's normal, frequencies
    in cycles per pixel along the normal (cycles per metre when ``gsd_m``
    is known); the MTF is 1 at zero frequency.

    Attributes
    ----------
    method : str
        The resampling method (:data:`imgmtf.METHODS`).
    params : dict
        The settings the estimate was made with (JSON-ready).
    normal_angle_deg : float
        Angle of the target's normal from the image's x (column) axis,
        towards +y (down), in (-90, 90]: the tilt of the target from the
        column axis.  The MTF is measured along this normal.
    tilt_deg : float
        Angle between the target and the nearest image axis (0 to 45).
    direction : str
        "across-track" or "along-track" when the normal lies within 10 deg
        of the ground track's perpendicular or of the track (rows along
        track unless a track azimuth was given), "oblique" otherwise,
        "unknown" for a map-projected image without a track azimuth.
    orientation : str
        "vertical" when the target runs nearer the columns, "horizontal"
        (its frame transposed) nearer the rows.
    polarity : str
        An edge's "rising" or "falling" (along +x of its frame), a bar's
        "bright" or "dark".
    rows_used, rows_total : int
        The rows (of the target's frame) measured, and all it crosses.
    snr, noise_dn : float
        Contrast over the sides' noise (quantisation included), and that
        noise (DN).
    mtf_nyquist, mtf50_cy_px : float
        MTF at 0.5 cy/px, and the frequency where it falls to 0.5.
    mtf_nyquist_ci, mtf50_ci_cy_px : Interval
        Their confidence intervals (NaN when switched off).
    fwhm_px : float
        Full width at half maximum of the recovered LSF.
    mtfa : float
        The area under the MTF from 0 to Nyquist, cy/px.
    gsd_m : float or None
        The pixel on the ground, m, when known.
    frequencies_cy_px, mtf : numpy.ndarray
        The MTF along the normal and its frequencies, cy/px.
    lsf_x_px, lsf : numpy.ndarray
        The recovered LSF (1/px) and its positions along the normal, px.
    samples_x_px, samples_dn : numpy.ndarray
        Every pixel used: its signed distance to the target's line, px, and
        its value, DN (the over-sampled profile).
    geometry : imgmtf.estimate.geometry.TargetGeometry
        Where the target lies: the per-row locations and the fitted line.
    roi : (int, int, int, int)
        (x, y, width, height) of the window measured, px.
    noise_limit_cy_px : float
        Above it the MTF is within 3 standard deviations of its noise.
    lsf_half_width_px, tail_fraction : float
        The LSF window's flat core, and the share of the LSF's area the
        tail model supplies beyond it.
    checks : tuple of imgmtf.estimate.gate.Check
        Every quality check and its outcome (passed, failed, or not run
        and why), in the JSON form too.
    warnings : tuple of str
        What the user should know (low SNR, forced checks...).
    mtf_function : callable or None
        The corrected MTF at any frequency (:meth:`mtf_at`).
    mtf_peak, mtf_peak_cy_px : float
        The MTF's largest value up to the noise limit (1 at zero frequency
        for an unsharpened system) and its frequency, cy/px.
    sharpened : bool
        The MTF rises above 1 as a sharpening kernel raises it (MTF
        compensation of a delivered product): the figures are the
        product's, not the sensor's (said in the warnings).
    """

    target: ClassVar[str] = ""
    method: str
    params: dict
    normal_angle_deg: float
    tilt_deg: float
    direction: str
    orientation: str
    polarity: str
    rows_used: int
    rows_total: int
    snr: float
    noise_dn: float
    mtf_nyquist: float
    mtf50_cy_px: float
    mtf_nyquist_ci: Interval
    mtf50_ci_cy_px: Interval
    fwhm_px: float
    mtfa: float
    gsd_m: float | None
    frequencies_cy_px: np.ndarray = field(repr=False)
    mtf: np.ndarray = field(repr=False)
    lsf_x_px: np.ndarray = field(repr=False)
    lsf: np.ndarray = field(repr=False)
    samples_x_px: np.ndarray = field(repr=False)
    samples_dn: np.ndarray = field(repr=False)
    geometry: TargetGeometry = field(repr=False)
    roi: tuple[int, int, int, int]
    noise_limit_cy_px: float
    lsf_half_width_px: float
    tail_fraction: float
    checks: tuple = field(default=(), repr=False)
    warnings: tuple[str, ...] = ()
    mtf_function: Callable | None = field(default=None, repr=False)
    mtf_peak: float = math.nan
    mtf_peak_cy_px: float = math.nan
    sharpened: bool = False

    def __repr__(self) -> str:
        ci = self.mtf_nyquist_ci
        interval = f" [{ci.low:.4f}, {ci.high:.4f}]" if math.isfinite(ci.low) else ""
        return (f"{type(self).__name__}(MTF@Nyquist {self.mtf_nyquist:.4f}{interval}, MTF50 "
                f"{self.mtf50_cy_px:.4f} cy/px, FWHM {self.fwhm_px:.3f} px, SNR {self.snr:.0f}, "
                f"normal {self.normal_angle_deg:.2f} deg, {self.direction}, {self.rows_used} rows, "
                f"method {self.method!r}{f', {len(self.warnings)} warning(s)' if self.warnings else ''})")

    @property
    def mtf50_cy_m(self) -> float | None:
        return self.mtf50_cy_px / self.gsd_m if self.gsd_m else None

    @property
    def fwhm_m(self) -> float | None:
        return self.fwhm_px * self.gsd_m if self.gsd_m else None

    def mtf_at(self, f_cy_px: ArrayLike) -> np.ndarray:
        """The corrected MTF at frequencies ``f_cy_px`` (cy/px): even in f,
        NaN beyond the transform's reach (4 cy/px) and near a divisor's zeros."""
        if self.mtf_function is None:
            raise ValueError("this result carries no MTF function")
        return self.mtf_function(f_cy_px)

    @property
    def width_px(self) -> float:
        """The target's width along its normal, px (0: a target without
        one, an edge)."""
        return 0.0

    def normalised_profile(self) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
        """The profile across the target (an edge's ESF, a bar's pulse
        response) normalised to run from 0 to 1, its positions along the
        normal (px), and the levels (DN) it is normalised between: each
        target's result says which."""
        raise NotImplementedError

    def lsf_like(self) -> tuple[np.ndarray, np.ndarray, float]:
        """The LSF-like profile the MTF is the transform of (an edge's LSF,
        a bar's pulse response), its positions along the normal (px) and
        its FWHM (px)."""
        raise NotImplementedError

    def _specific(self) -> dict:
        return {}

    def summaries(self, curves: bool = True) -> list[dict]:
        """The records' figures: one summary (:meth:`to_dict`), as every
        kind's result gives a list (points give one per direction)."""
        return [self.to_dict(curves)]

    def to_dict(self, curves: bool = True) -> dict:
        """JSON-ready summary (units in the names); ``curves`` adds the MTF."""
        out = {
            "target": self.target, "method": self.method, "normal_angle_deg": finite(self.normal_angle_deg),
            "tilt_deg": finite(self.tilt_deg), "direction": self.direction,
            "orientation": self.orientation, "polarity": self.polarity, "rows_used": self.rows_used,
            "snr": finite(self.snr), "noise_dn": finite(self.noise_dn),
            "mtf_nyquist": finite(self.mtf_nyquist),
            "mtf_nyquist_ci": [finite(self.mtf_nyquist_ci.low), finite(self.mtf_nyquist_ci.high)],
            "mtf50_cy_px": finite(self.mtf50_cy_px),
            "mtf50_ci_cy_px": [finite(self.mtf50_ci_cy_px.low), finite(self.mtf50_ci_cy_px.high)],
            "fwhm_px": finite(self.fwhm_px), "mtfa": finite(self.mtfa), "gsd_m": self.gsd_m,
            "mtf50_cy_m": finite(self.mtf50_cy_m), "fwhm_m": finite(self.fwhm_m),
            "noise_limit_cy_px": finite(self.noise_limit_cy_px),
            "mtf_peak": finite(self.mtf_peak), "mtf_peak_cy_px": finite(self.mtf_peak_cy_px),
            "sharpened": bool(self.sharpened),
            "lsf_half_width_px": finite(self.lsf_half_width_px), "tail_fraction": finite(self.tail_fraction),
            **self._specific(),
            "roi": list(self.roi), "warnings": list(self.warnings),
            "checks": [c.to_dict() for c in self.checks],
            "params": self.params, "imgmtf_version": __version__,
        }
        if curves:
            out["frequencies_cy_px"] = [float(f) for f in self.frequencies_cy_px]
            out["mtf"] = finite_values(self.mtf)
        return out


def finite(value: Any) -> float | None:
    """A float rounded to 6 decimals for JSON, None for None/NaN/inf."""
    if value is None:
        return None
    value = float(value)
    return round(value, 6) if math.isfinite(value) else None
