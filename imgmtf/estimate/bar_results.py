"""What a bar's measurement and a double bar's share: the bars' width and
the pulse response the MTF is the transform of (:class:`BarProfileResult`,
the base of :class:`imgmtf.PulseResult` and :class:`imgmtf.DoubleBarResult`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .results import MTFResult, finite


@dataclass(frozen=True, eq=False, kw_only=True, repr=False)
class BarProfileResult(MTFResult):
    """An MTF measured from the pulse response of one bar or two (see
    :class:`imgmtf.estimate.results.MTFResult` for the fields every
    measurement has).

    Attributes
    ----------
    pulse_width_px : float
        Each bar's width used, px.
    prf_x_px, prf : numpy.ndarray
        The pulse response, normalised to a unit peak above the background
        (positive for dark bars too), and its positions along the normal, px.
    prf_fwhm_px : float
        The pulse response's FWHM, px.
    background_dn, peak_dn : float
        The background's level and the profile's peak, DN.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("pulse", 6.0, width_px=1.5), 60)
    >>> result = imgmtf.measure_pulse(chip.image, width_px=1.5)
    >>> isinstance(result, BarProfileResult), result.width_px
    (True, 1.5)
    >>> x, prf, (background, peak) = result.normalised_profile()
    >>> round(float(prf.max()), 2), bool(peak > background)
    (1.0, True)
    """

    pulse_width_px: float
    prf_x_px: np.ndarray
    prf: np.ndarray
    prf_fwhm_px: float
    background_dn: float
    peak_dn: float

    @property
    def width_px(self) -> float:
        """Each bar's width, px (``pulse_width_px``)."""
        return self.pulse_width_px

    def normalised_profile(self) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
        """The pulse response (0 to a unit peak), its positions along the
        normal (px), and the background and peak levels (DN)."""
        return self.prf_x_px, self.prf, (self.background_dn, self.peak_dn)

    def lsf_like(self) -> tuple[np.ndarray, np.ndarray, float]:
        """The pulse response (peak 1), its positions along the normal (px)
        and its FWHM (px)."""
        return self.prf_x_px, self.prf, self.prf_fwhm_px

    def _profile_figures(self) -> dict:
        """The pulse response's figures in a record: its FWHM (px) and its
        two levels (DN)."""
        return {"prf_fwhm_px": finite(self.prf_fwhm_px), "background_dn": finite(self.background_dn),
                "peak_dn": finite(self.peak_dn)}
