"""What a Siemens star measures: the MTF in each direction (:class:`StarDirection`)
and the star's geometry (:class:`StarResult`), one record per direction."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ParameterError
from ...safe_json import finite_values
from ...version import __version__
from ..intervals import Interval
from ..results import finite


@dataclass(frozen=True, eq=False)
class StarDirection:
    """The MTF along one direction of the frequency.

    Attributes
    ----------
    direction : str
        Its name: "across-track", "along-track", or its angle ("22.5deg").
    angle_deg : float
        The frequency's direction, deg from the x axis (0 to 180; 90 along
        the rows, down).
    frequencies_cy_px, mtf, standard_error : numpy.ndarray
        The smoothed curve, 0 to the highest ring read (MTF 1 at zero).
    ring_frequencies_cy_px, ring_mtf, ring_errors : numpy.ndarray
        Each ring's own value (before smoothing) and standard error.
    mtf_nyquist : float
        At 0.5 cy/px.
    mtf_nyquist_ci : Interval
        Its confidence interval.
    mtf50_cy_px : float
        Where the curve first falls to 0.5, cy/px.
    mtf50_ci_cy_px : Interval
        Its confidence interval.
    scatter : float
        The rings' reduced chi-square about the curve.
    """

    direction: str
    angle_deg: float
    frequencies_cy_px: np.ndarray
    mtf: np.ndarray
    standard_error: np.ndarray
    ring_frequencies_cy_px: np.ndarray
    ring_mtf: np.ndarray
    ring_errors: np.ndarray
    mtf_nyquist: float
    mtf_nyquist_ci: Interval
    mtf50_cy_px: float
    mtf50_ci_cy_px: Interval
    scatter: float


@dataclass(frozen=True, eq=False)
class StarResult:
    """The MTF of a Siemens star in each direction.

    Attributes
    ----------
    directions : tuple of StarDirection
        The directions, from the across-track one (or the image's x).
    centre_px : (float, float)
        The star's centre (x, y), px, in the chip measured.
    centre_error_px : float
        Its standard error, px.
    cycles : int
        N.
    profile : str
        "sinusoidal" or "binary".
    contrast : float
        The full-contrast modulation the rings were divided by.
    contrast_method : str
        "extrapolated" (to zero frequency) or "levels" (a binary star's
        wedges, with the square wave's 4/pi).
    inner_radius_px, outer_radius_px : float
        The radii read, px.
    unresolved_radius_px : float
        The radius inside which the star is not resolved: where the MTF,
        averaged over the directions, falls to 0.1 (NaN when it does not
        within the rings read).
    noise_dn : float
        The chip's noise, DN (the rings' residuals at large radius).
    snr : float
        The star's range over the noise.
    gsd_m : float or None
        The pixel on the ground, m.
    roi : (int, int, int, int)
        (x, y, width, height) of the chip measured, px.
    params : dict
        The settings.
    warnings : tuple of str
        What the reader should know.
    method, target : str
        "star": its own estimator, and the kind.
    checks : tuple
        Empty: a star has no gate of line checks.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render_star(imgmtf.Sensor(), imgmtf.SiemensStar(cycles=32), 101)
    >>> result = imgmtf.measure_star(chip.image, intervals="none")
    >>> len(result.directions), result.directions[4].direction, result.cycles
    (8, 'along-track', 32)
    """

    directions: tuple[StarDirection, ...]
    centre_px: tuple[float, float]
    centre_error_px: float
    cycles: int
    profile: str
    contrast: float
    contrast_method: str
    inner_radius_px: float
    outer_radius_px: float
    unresolved_radius_px: float
    noise_dn: float
    snr: float
    gsd_m: float | None = None
    roi: tuple[int, int, int, int] = (0, 0, 0, 0)
    params: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    method: str = "star"
    target: str = "star"
    checks: tuple = ()

    @property
    def nyquist_radius_px(self) -> float:
        """Where the star's frequency ``N / (2 pi r)`` is 0.5 cy/px, px."""
        return self.cycles / math.pi

    def direction(self, name: str) -> StarDirection:
        """The direction called ``name``.

        Parameters
        ----------
        name : str
            "across-track", "along-track", "22.5deg"... (or "image-x",
            "image-y" when the track is unknown).

        Returns
        -------
        StarDirection
            That direction's MTF and its figures.

        Raises
        ------
        ParameterError
            No direction of that name.
        """
        for section in self.directions:
            if section.direction == name:
                return section
        raise ParameterError(f"direction must be one of {[d.direction for d in self.directions]}, got {name!r}")

    def summaries(self, curves: bool = True) -> list[dict]:
        """One JSON-ready summary per direction (the records' figures).

        Parameters
        ----------
        curves : bool, optional
            Include the MTF curve (default True).

        Returns
        -------
        list of dict
            Keys with units in their names.
        """
        out = []
        for d in self.directions:
            row: dict[str, Any] = {
                "target": self.target, "method": self.method, "direction": d.direction,
                "direction_deg": finite(d.angle_deg), "normal_angle_deg": finite(d.angle_deg),
                "snr": finite(self.snr), "noise_dn": finite(self.noise_dn),
                "mtf_nyquist": finite(d.mtf_nyquist),
                "mtf_nyquist_ci": [finite(d.mtf_nyquist_ci.low), finite(d.mtf_nyquist_ci.high)],
                "mtf50_cy_px": finite(d.mtf50_cy_px),
                "mtf50_ci_cy_px": [finite(d.mtf50_ci_cy_px.low), finite(d.mtf50_ci_cy_px.high)],
                "gsd_m": self.gsd_m,
                "mtf50_cy_m": finite(d.mtf50_cy_px / self.gsd_m) if self.gsd_m else None,
                "star_cycles": self.cycles, "star_profile": self.profile,
                "centre_x_px": finite(self.centre_px[0] + self.roi[0]),
                "centre_y_px": finite(self.centre_px[1] + self.roi[1]),
                "nyquist_radius_px": finite(self.nyquist_radius_px),
                "unresolved_radius_px": finite(self.unresolved_radius_px),
                "star_contrast": finite(self.contrast), "contrast_method": self.contrast_method,
                "roi": list(self.roi), "warnings": list(self.warnings), "params": dict(self.params),
                "imgmtf_version": __version__,
            }
            if curves:
                row["frequencies_cy_px"] = [round(float(f), 4) for f in d.frequencies_cy_px]
                row["mtf"] = finite_values(d.mtf)
            out.append(row)
        return out

    def to_dict(self, curves: bool = True) -> dict:
        """The first direction's summary (:meth:`summaries` gives them all).

        Parameters
        ----------
        curves : bool, optional
            Include the MTF curve (default True).

        Returns
        -------
        dict
            The across-track (or image-x) summary.
        """
        return self.summaries(curves)[0]

