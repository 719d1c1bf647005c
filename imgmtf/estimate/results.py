"""What every MTF estimate returns: the common part of edge and pulse
results, and its JSON form."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, ClassVar

import numpy as np

from ..version import __version__
from .geometry import TargetGeometry
from .intervals import Interval


@dataclass(frozen=True, eq=False, kw_only=True)
class MTFResult:
    """An MTF estimate and what it was computed from.

    Distances are in pixels along the target's normal, frequencies in cycles
    per pixel along the normal; the MTF is normalised to 1 at zero
    frequency.  ``lsf`` integrates to 1 (1/px).  ``noise_limit_cy_px`` is
    the frequency above which the MTF is within 3 standard deviations of
    its noise (inf for a noise-free chip): the curve beyond it is not
    signal.  ``samples_x_px``/``samples_dn`` are the over-sampled profile's
    raw samples; ``geometry`` the fitted target line.
    """

    target: ClassVar[str] = ""
    method: str
    params: dict
    angle_deg: float
    orientation: str
    polarity: str
    rows_used: int
    rows_total: int
    snr: float
    mtf_nyquist: float
    mtf50_cy_px: float
    mtf_nyquist_ci: Interval
    mtf50_ci_cy_px: Interval
    fwhm_px: float
    mtfa: float
    gsd_m: float | None
    frequencies_cy_px: np.ndarray
    mtf: np.ndarray
    lsf_x_px: np.ndarray
    lsf: np.ndarray
    samples_x_px: np.ndarray
    samples_dn: np.ndarray
    geometry: TargetGeometry
    roi: tuple[int, int, int, int]
    noise_limit_cy_px: float
    warnings: tuple[str, ...] = ()
    mtf_function: Callable | None = None

    @property
    def direction(self) -> str:
        """Which MTF this target measures on a pushbroom image: rows are
        along track, so a near-vertical target gives the across-track MTF."""
        return "across-track" if self.orientation == "vertical" else "along-track"

    @property
    def mtf50_cy_m(self) -> float | None:
        return self.mtf50_cy_px / self.gsd_m if self.gsd_m else None

    @property
    def fwhm_m(self) -> float | None:
        return self.fwhm_px * self.gsd_m if self.gsd_m else None

    def mtf_at(self, f_cy_px) -> np.ndarray:
        """The corrected MTF at any frequencies (cycles/pixel)."""
        return self.mtf_function(f_cy_px)

    def _specific(self) -> dict:
        return {}

    def to_dict(self, curves: bool = True) -> dict:
        """JSON-ready summary (units in the names); ``curves`` adds the MTF."""
        out = {
            "target": self.target, "method": self.method, "angle_deg": self.angle_deg,
            "orientation": self.orientation, "direction": self.direction,
            "polarity": self.polarity, "rows_used": self.rows_used, "snr": finite(self.snr),
            "mtf_nyquist": finite(self.mtf_nyquist),
            "mtf_nyquist_ci": [finite(self.mtf_nyquist_ci.low), finite(self.mtf_nyquist_ci.high)],
            "mtf50_cy_px": finite(self.mtf50_cy_px),
            "mtf50_ci_cy_px": [finite(self.mtf50_ci_cy_px.low), finite(self.mtf50_ci_cy_px.high)],
            "fwhm_px": finite(self.fwhm_px), "mtfa": finite(self.mtfa), "gsd_m": self.gsd_m,
            "mtf50_cy_m": finite(self.mtf50_cy_m), "fwhm_m": finite(self.fwhm_m),
            "noise_limit_cy_px": finite(self.noise_limit_cy_px),
            **self._specific(),
            "roi": list(self.roi), "warnings": list(self.warnings),
            "params": self.params, "imgmtf_version": __version__,
        }
        if curves:
            out["frequencies_cy_px"] = [float(f) for f in self.frequencies_cy_px]
            out["mtf"] = [finite(m) for m in self.mtf]
        return out


def finite(value):
    """A float rounded to 6 decimals for JSON, None for None/NaN/inf."""
    if value is None:
        return None
    value = float(value)
    return round(value, 6) if math.isfinite(value) else None
