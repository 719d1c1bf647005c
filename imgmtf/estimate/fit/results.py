"""What a sensor fit returns: each parameter, each edge and the whole fit."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ...sensor.model import Sensor
from .bands import model_mtf_band
from .model import Model
from .record import write_fitted_sensor

if TYPE_CHECKING:
    from ..edge import EdgeResult
    from .choice import ModelChoice

#: misfit warning: binned residuals significant at this level ...
MISFIT_P = 1e-3
#: ... and their systematic part larger than this fraction of the step
MISFIT_FRACTION = 5e-4


@dataclass(frozen=True)
class FittedParameter:
    """One stage parameter after the fit.

    ``status`` is "fitted", "held" (at its starting value: ``note`` says
    why) or "tied" (equal to its other-axis twin: ``note`` names it).
    ``standard_error`` is in the parameter's unit (NaN unless fitted).
    """

    stage: str
    name: str
    value: float
    standard_error: float
    unit: str
    status: str
    note: str = ""

    @property
    def key(self) -> str:
        return f"{self.stage}.{self.name}"

    def to_dict(self) -> dict:
        return {"stage": self.stage, "name": self.name, "value": json_value(self.value),
                "standard_error": json_value(self.standard_error), "unit": self.unit,
                "status": self.status, "note": self.note}


@dataclass(frozen=True, eq=False)
class EdgeFit:
    """One input edge: the model's MTF along its normal and how well the
    model fits its profile.

    Attributes
    ----------
    source : str
        The file (or "array 1", ... for arrays).
    normal_angle_deg : float
        Angle of the edge normal from the x axis (the edge's tilt from the column axis).
    direction : str
        "across-track" or "along-track" when the normal lies within 10 deg
        of that axis, else "oblique": the label :func:`imgmtf.measure_edge`
        gives with rows along track (``track_azimuth_deg=0``), the geometry
        the fit assumes.
    constrains : str
        "across" (|angle| < 45 deg) or "along": the image axis whose
        parameters the edge mostly constrains.
    gsd_m : float
        The edge's pixel, m (1 when unknown: parameters then in pixels).
    rows_used : int
        The rows of the edge measured.
    snr : float
        Its contrast over its noise.
    mtf_nyquist, mtf_nyquist_ci : float, (float, float)
        The fitted model's MTF at 0.5 cy/px along the normal, and its interval.
    mtf50_cy_px : float
        The model's MTF50 along the normal, cycles per pixel.
    measured_mtf_nyquist : float
        The non-parametric estimate of the same edge, for comparison.
    noise_dn, step_dn : float
        Noise (measured without the model) and fitted step R - L, DN.
    levels_dn : (float, float)
        The fitted levels (L, R), DN.
    offset_px : float
        The edge's fitted sub-pixel offset, px.
    reduced_chi_square : float
        Of this edge's samples' residuals against its noise (not its
        bins'), over its samples less its share of the parameters.
    misfit_p, misfit_fraction : float
        P-value of the structure of the samples' residuals (each profile
        sample's, not the fit's bins') averaged in 0.25 px bins along the
        normal from the fitted edge (small: structure), and the size of
        that structure, RMS as a fraction of the step.
    samples_x_px, residuals_dn, bin_counts : numpy.ndarray
        Per bin of the fit, not per sample (the profile samples binned
        along the normal, :data:`imgmtf.estimate.fit.data.FIT_BIN_PX` wide
        on their distances before the fitted offset): its samples' mean
        distance to the edge before the offset (px; ``samples_x_px -
        offset_px`` from the fitted edge), their mean value less the
        model's mean over them (DN; its noise is ``noise_dn /
        sqrt(bin_counts)``) and their count.  What the residual panel
        (:func:`imgmtf.plot.plot_fit_residuals`) averages in 0.25 px bins,
        each fit bin wholly in the one its mean distance falls in: where
        the offset puts a fit bin across a 0.25 px bin's edge its samples
        count on one side, so the panel's means are close to, not exactly,
        those the misfit test takes from the samples.
    measurement : EdgeResult
        The non-parametric measurement of the edge.
    """

    source: str
    normal_angle_deg: float
    direction: str
    constrains: str
    gsd_m: float
    rows_used: int
    snr: float
    mtf_nyquist: float
    mtf_nyquist_ci: tuple[float, float]
    mtf50_cy_px: float
    measured_mtf_nyquist: float
    noise_dn: float
    step_dn: float
    levels_dn: tuple[float, float]
    offset_px: float
    reduced_chi_square: float
    misfit_p: float
    misfit_fraction: float
    samples_x_px: np.ndarray = field(repr=False)
    residuals_dn: np.ndarray = field(repr=False)
    bin_counts: np.ndarray = field(repr=False)
    measurement: EdgeResult = field(repr=False)

    @property
    def misfit(self) -> bool:
        """Whether the model does not fit this edge: its residuals are
        structured beyond the noise (p below :data:`MISFIT_P`) and beyond
        :data:`MISFIT_FRACTION` of the step."""
        # bool(): the statistics may be NumPy floats, whose comparison JSON cannot write
        return bool(self.misfit_p < MISFIT_P and self.misfit_fraction > MISFIT_FRACTION)

    @property
    def misfit_tested(self) -> bool:
        """Whether the misfit test ran (its residuals filled a bin): an
        edge it could not test is neither a fit nor a misfit."""
        return math.isfinite(self.misfit_p)

    def to_dict(self) -> dict:
        return {"path": self.source, "normal_angle_deg": self.normal_angle_deg, "direction": self.direction,
                "constrains": self.constrains, "gsd_m": self.gsd_m, "rows_used": self.rows_used,
                "snr": json_value(self.snr),
                "mtf_nyquist": self.mtf_nyquist, "mtf_nyquist_ci": [json_value(v) for v in self.mtf_nyquist_ci],
                "mtf50_cy_px": json_value(self.mtf50_cy_px),
                "measured_mtf_nyquist": json_value(self.measured_mtf_nyquist), "noise_dn": self.noise_dn,
                "step_dn": self.step_dn, "levels_dn": list(self.levels_dn), "offset_px": self.offset_px,
                "reduced_chi_square": self.reduced_chi_square, "misfit_p": json_value(self.misfit_p),
                "misfit_fraction": json_value(self.misfit_fraction), "misfit": self.misfit,
                "misfit_test": ("failed" if self.misfit else "passed") if self.misfit_tested else "not-run"}


@dataclass(frozen=True, eq=False)
class SensorFit:
    """The fitted sensor and everything said about it (see the module
    docstring for the method).

    Attributes
    ----------
    sensor, start : Sensor
        The fitted sensor (its TOML is what ``imgmtf fit --out`` writes) and
        the one the fit started from.
    parameters : tuple of FittedParameter
        Every parameter with its value, standard error and unit; held and
        tied ones say why in their ``note``.
    correlations : tuple of (str, str, float)
        Fitted parameter pairs correlated beyond 0.9: the data constrain a
        combination of them better than each.
    reduced_chi_square : float
        Of the samples' residuals (each profile sample's value against the
        fitted model, weighted by its edge's noise), not the fit's bins':
        their chi-square over samples - parameters degrees of freedom (1
        for a model that fits to the noise).
    edges : tuple of EdgeFit
        Per input edge: the model's MTF at Nyquist along its normal (cy/px)
        with an interval, the measured one, and the misfit statistics.
    directions : dict
        "across" and "along": the model's MTF at Nyquist and MTF50 (cy/px)
        with intervals, and whether an edge constrains that axis.
    confidence : float
        Of the intervals.
    warnings : tuple of str
        Where the model does not fit an edge, and which direction no edge
        constrains.
    choice : ModelChoice or None
        With ``stages="auto"``: the candidate stage sets fitted, their
        information criterion and verdicts, and why this one was kept.
    pixel_units : bool
        True when no input had a GSD (a camera's images): lengths are in
        px (the model's metres at a 1 m GSD) and directions the image's
        axes, "horizontal" (across its columns: ``directions["across"]``)
        and "vertical" (``directions["along"]``).

    Examples
    --------
    >>> import imgmtf
    >>> fit = imgmtf.fit_sensor([imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60).image])
    >>> fit.directions["across"]["constrained"], fit.misfit
    (True, False)
    """

    sensor: Sensor
    start: Sensor
    parameters: tuple[FittedParameter, ...]
    correlations: tuple[tuple[str, str, float], ...]
    reduced_chi_square: float
    edges: tuple[EdgeFit, ...]
    directions: dict
    confidence: float
    warnings: tuple[str, ...]
    _model: Model = field(repr=False)
    _u: np.ndarray = field(repr=False)
    _covariance: np.ndarray = field(repr=False)
    choice: ModelChoice | None = None
    pixel_units: bool = False

    @property
    def misfit(self) -> bool:
        """True when the model does not fit: an edge's residuals are
        structured, or a fitted parameter sits at the bound of its range."""
        return any(e.misfit for e in self.edges) or any(
            p.note == "at the bound of its range" for p in self.parameters)

    def mtf_band(self, f_cy_px: ArrayLike, angle_deg: float,
                 gsd_m: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The model's MTF along the normal of an edge tilted ``angle_deg``,
        at ``f_cy_px`` cycles per pixel of ``gsd_m`` (default the sensor's),
        with its lower and upper confidence bounds: ``(mtf, low, high)``.

        Parameters
        ----------
        f_cy_px : array_like
            Frequencies along the normal, cy/px.
        angle_deg : float
            The edge's tilt from the column axis, deg.
        gsd_m : float, optional
            The pixel, m (default the fitted sensor's).

        Returns
        -------
        mtf, low, high : numpy.ndarray
            The model's MTF and the ends of its interval at each frequency.
        """
        gsd = self.sensor.gsd_m if gsd_m is None else gsd_m
        return model_mtf_band(self._model, self._u, self._covariance, np.asarray(f_cy_px, float),
                         angle_deg, gsd, self.confidence)

    def to_toml(self, path: str | os.PathLike, comment: str = "", sources: list[str] | None = None) -> None:
        """Write the fitted sensor as TOML with a ``[fit]`` table saying
        whether the model fits (:mod:`imgmtf.estimate.fit.record`):
        :meth:`imgmtf.Sensor.from_toml` reads the sensor, ``imgmtf
        restore`` refuses a misfit one.

        Parameters
        ----------
        path : str or pathlib.Path
            The file (replaced if it exists).
        comment : str, optional
            Lines written as TOML comments on top.
        sources : list of str, optional
            What the edges were (default the edges' names).

        Raises
        ------
        FileWriteError
            The file cannot be written.
        """
        write_fitted_sensor(path, self, comment=comment, sources=sources)

    def to_dict(self) -> dict:
        """JSON-ready: one object holding the sensor, parameters, fit
        quality, directions and a record per input edge (``edges``)."""
        from ...version import __version__
        return {"imgmtf_version": __version__, "method": "fit",
                "stages": [s.name for s in self.sensor.stages], "gsd_m": self.sensor.gsd_m,
                "length_unit": "px" if self.pixel_units else "m",
                "direction_names": (dict(zip(("across", "along"), ("horizontal", "vertical"))) if self.pixel_units
                                    else {"across": "across-track", "along": "along-track"}),
                "confidence": self.confidence, "reduced_chi_square": self.reduced_chi_square,
                "misfit": self.misfit,
                "parameters": [p.to_dict() for p in self.parameters],
                "correlations": [{"a": a, "b": b, "r": r} for a, b, r in self.correlations],
                "directions": {k: {kk: json_value(vv) if not isinstance(vv, (list, tuple))
                                   else [json_value(x) for x in vv] for kk, vv in v.items()}
                               for k, v in self.directions.items()},
                "warnings": list(self.warnings), "sensor": self.sensor.to_dict(),
                "model_choice": self.choice.to_dict() if self.choice is not None else None,
                "edges": [e.to_dict() for e in self.edges]}



def json_value(value):
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None
