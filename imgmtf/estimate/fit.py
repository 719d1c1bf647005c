"""Fit a sensor's stages to the edge profiles of one or more images.

The parametric estimate.  Each edge is measured as usual
(:func:`imgmtf.measure_edge`) for its geometry only: every pixel's signed
distance from the edge along its normal and its value.  The model of the
edge is then

    DN = L + (R - L) ESF(x - x0),

where ESF is the sensor's exact edge response along that edge's normal
(:meth:`imgmtf.Sensor.line_response`), and L, R (levels) and x0 (sub-pixel
offset) are the edge's own nuisance parameters.  All edges share the
stages' parameters, so an across-track and an along-track edge together
constrain both axes.  The parameters are fitted by bounded least squares
(``scipy.optimize.least_squares``, :meth:`_Model.solve`), each edge
weighted by the inverse of its noise, measured without the model (each
sample against the line through its two neighbours, :func:`profile_noise`).

Identifiability, in three steps:

1. Axes.  An edge constrains only its own normal.  When no edge lies
   within 45 deg of the along-track axis, every along-track parameter that
   has an across-track twin is tied to it (a symmetric optic) and the
   others (motion) are held; likewise the other way round.
2. Coordinates.  Each parameter is fitted as its blur length in pixels
   raised to the power to which the low-frequency MTF responds (the square
   for widths, the length itself for diffraction), bounded from 0 (stage
   absent) to a few pixels; see :class:`imgmtf.sensor.stages.FitSpec`.
3. Holding.  After a fit, a parameter whose one-standard-error range is
   wider than ``DETERMINED_RELATIVE`` (50 %) of its blur length and than
   ``DETERMINED_PX`` (0.2 px) is not determined by the data: the best-known
   of those (detector first, optics last) is held at its starting value,
   and the fit is redone, until every free parameter is determined.  Then,
   best-known first, a parameter is held when freeing it gains less than
   ``LIKELIHOOD_RATIO`` in chi-square, keeping one free parameter on each
   axis an edge sees.  Optics sigma, electronics cut-off and detector
   width shape the MTF alike, and such pairs are reported with their
   correlation.

The result reports each parameter with its standard error (from the
Jacobian, scaled up by the reduced chi-square when that exceeds 1), the
reduced chi-square, the model's MTF at Nyquist along each edge's normal
with a delta-method interval, the across- and along-track MTF at Nyquist
and MTF50, and a misfit warning when the residuals, binned along the
normal, show structure the noise cannot explain.
"""
from __future__ import annotations

import importlib
import math
from dataclasses import dataclass, field
from pathlib import Path
from statistics import NormalDist
from typing import TYPE_CHECKING

import numpy as np

from .._blas import one_blas_thread
from ..errors import ImgmtfError, ParameterError
from ..inputs import check_number
from ..metrics import first_crossing
from ..sensor.model import DIRECTIONS, PAPER_STAGES, Sensor, direction_angle
from ..sensor.stages import STAGES, Stage
from .geometry import direction_label

if TYPE_CHECKING:
    from .edge import EdgeResult

#: a free parameter is undetermined when its 1-SE range of blur length is
#: wider than this fraction of the length ...
DETERMINED_RELATIVE = 0.5
#: ... and than this many pixels
DETERMINED_PX = 0.2
#: residual bins along the normal (px) for the misfit test
MISFIT_BIN_PX = 0.25
#: misfit warning: binned residuals significant at this level ...
MISFIT_P = 1e-3
#: ... and their systematic part larger than this fraction of the step
MISFIT_FRACTION = 5e-4
#: a parameter stays free only if holding it costs this much chi-square
#: (in units of the reduced chi-square): p = 0.001 for one degree of freedom
LIKELIHOOD_RATIO = 10.8
#: parameter pairs reported when their correlation exceeds this
HIGH_CORRELATION = 0.9


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
        return {"stage": self.stage, "name": self.name, "value": _json(self.value),
                "standard_error": _json(self.standard_error), "unit": self.unit,
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
    mtf_nyquist, mtf_nyquist_ci : float, (float, float)
        The fitted model's MTF at 0.5 cy/px along the normal, and its interval.
    mtf50_cy_px : float
        The model's MTF50 along the normal, cycles per pixel.
    measured_mtf_nyquist : float
        The non-parametric estimate of the same edge, for comparison.
    noise_dn, step_dn, levels_dn, offset_px :
        Noise (measured without the model), fitted step R - L, levels (L, R)
        and sub-pixel offset of the edge.
    reduced_chi_square : float
        Of this edge's residuals against its noise.
    misfit_p, misfit_fraction : float
        P-value of the residuals binned along the normal (small: structure),
        and the size of that structure, RMS as a fraction of the step.
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
    measurement: EdgeResult = field(repr=False)

    def to_dict(self) -> dict:
        return {"path": self.source, "normal_angle_deg": self.normal_angle_deg, "direction": self.direction,
                "constrains": self.constrains, "gsd_m": self.gsd_m, "rows_used": self.rows_used, "snr": _json(self.snr),
                "mtf_nyquist": self.mtf_nyquist, "mtf_nyquist_ci": [_json(v) for v in self.mtf_nyquist_ci],
                "mtf50_cy_px": _json(self.mtf50_cy_px),
                "measured_mtf_nyquist": _json(self.measured_mtf_nyquist), "noise_dn": self.noise_dn,
                "step_dn": self.step_dn, "levels_dn": list(self.levels_dn), "offset_px": self.offset_px,
                "reduced_chi_square": self.reduced_chi_square, "misfit_p": self.misfit_p,
                "misfit_fraction": self.misfit_fraction}


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
        Of the residuals, each edge weighted by its noise (1 for a model
        that fits to the noise).
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
    _model: _Model = field(repr=False)
    _u: np.ndarray = field(repr=False)
    _covariance: np.ndarray = field(repr=False)

    @property
    def misfit(self) -> bool:
        """True when the model does not fit: an edge's residuals are
        structured, or a fitted parameter sits at the bound of its range."""
        return any(e.misfit_p < MISFIT_P and e.misfit_fraction > MISFIT_FRACTION for e in self.edges) or any(
            p.note == "at the bound of its range" for p in self.parameters)

    def mtf_band(self, f_cy_px, angle_deg: float, gsd_m: float | None = None):
        """The model's MTF along the normal of an edge tilted ``angle_deg``,
        at ``f_cy_px`` cycles per pixel of ``gsd_m`` (default the sensor's),
        with its lower and upper confidence bounds: ``(mtf, low, high)``."""
        gsd = self.sensor.gsd_m if gsd_m is None else gsd_m
        return _mtf_band(self._model, self._u, self._covariance, np.asarray(f_cy_px, float),
                         angle_deg, gsd, self.confidence)

    def to_dict(self) -> dict:
        """JSON-ready: one object holding the sensor, parameters, fit
        quality, directions and a record per input edge (``edges``)."""
        from ..version import __version__
        return {"imgmtf_version": __version__, "method": "fit",
                "stages": [s.name for s in self.sensor.stages], "gsd_m": self.sensor.gsd_m,
                "confidence": self.confidence, "reduced_chi_square": self.reduced_chi_square,
                "misfit": self.misfit,
                "parameters": [p.to_dict() for p in self.parameters],
                "correlations": [{"a": a, "b": b, "r": r} for a, b, r in self.correlations],
                "directions": {k: {kk: _json(vv) if not isinstance(vv, (list, tuple)) else [_json(x) for x in vv]
                                   for kk, vv in v.items()} for k, v in self.directions.items()},
                "warnings": list(self.warnings), "sensor": self.sensor.to_dict(),
                "edges": [e.to_dict() for e in self.edges]}


def fit_sensor(edges, *, stages=None, start: Sensor | None = None, hold=(), gsd_m: float | None = None,
               band: int | None = None, roi: tuple[int, int, int, int] | None = None,
               confidence: float = 0.95) -> SensorFit:
    """Fit a sensor's stages to the profiles of one or more edges.

    Parameters
    ----------
    edges : sequence
        Each an image file path, a 2-D array (DN) or an
        :class:`imgmtf.EdgeResult` already measured; one edge per image.
    stages : str or sequence of str, optional
        Stage names to fit (comma-separated or a list; see
        :data:`imgmtf.sensor.stages.STAGES`); default the stages of
        ``start``, or the paper's four.
    start : Sensor, optional
        Starting (and held) values of the stages it has; other stages
        start from their defaults scaled to the GSD.
    hold : sequence of str
        Parameters held at their starting values: "stage" or "stage.name".
    gsd_m : float, optional
        Ground sample distance (m); default the first file's, else 1
        (parameters then in pixels).
    band : int, optional
        1-based band of multi-band files (default: the only band or the
        luminance).
    roi : (int, int, int, int), optional
        (x, y, width, height) window, px, taken from every file or array
        (only it is read from a file); not for EdgeResults.
    confidence : float
        Of the intervals, in (0, 1).

    Returns
    -------
    SensorFit

    Raises
    ------
    ParameterError
        Unknown stage or parameter names, no edges, bad ``confidence``, a
        ``roi`` outside an input.
    ImgmtfError
        An input that cannot be read or has no measurable edge (the
        message names it), or a fit that does not converge.

    Examples
    --------
    >>> import imgmtf
    >>> chips = [imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", a), 60).image for a in (6.0, 84.0)]
    >>> fit = imgmtf.fit_sensor(chips)
    >>> abs(fit.edges[0].mtf_nyquist - 0.2667) < 0.002
    True
    """
    if not (isinstance(confidence, (int, float, np.floating)) and 0 < confidence < 1):
        raise ParameterError(f"confidence must be in (0, 1), got {confidence!r}")
    if gsd_m is not None:
        gsd_m = check_number("gsd_m", gsd_m, positive=True)
    if start is not None and not isinstance(start, Sensor):
        raise ParameterError(f"start must be a Sensor, got {start!r}")
    names = _stage_names(stages, start)
    from .edge import EdgeResult
    if isinstance(edges, (str, Path, np.ndarray, EdgeResult)):
        edges = [edges]
    items = _listed("edges", edges, "files, arrays or EdgeResults")
    data = [_edge_data(item, k, gsd_m, band, roi) for k, item in enumerate(items)]
    if not data:
        raise ParameterError("no edges to fit")
    gsd = gsd_m if gsd_m is not None else next((d.gsd_m for d in data if d.gsd_known), 1.0)
    importlib.import_module("scipy.optimize")      # (its BLAS loaded before the next line limits it)
    with one_blas_thread():
        return _fit(_Model(gsd, _initial_stages(names, start, gsd), data), hold, confidence)


def _fit(model: _Model, hold, confidence: float) -> SensorFit:
    """Fit ``model``, holding what the data do not determine or need (see
    the module's notes), and report."""
    notes = model.screen_axes(_hold_keys(hold, model.keys))
    z = model.initial_vector()
    while True:
        z, jacobian = model.solve(z)
        scale = max(model.chi_square(z) / max(model.dof, 1), 1.0)
        covariance = _covariance(jacobian, scale)
        undetermined = model.undetermined(z, covariance)
        if not undetermined:
            break
        worst = max(undetermined, key=lambda i: (model.specs[model.free[i]].rank, undetermined[i]))
        notes[model.free[worst]] = ("held", f"not determined by the data (within one standard error its blur "
                                            f"length spans {undetermined[worst]:.2g} px); "
                                            "held at its starting value")
        z = model.hold(z, worst)
    # hold, best-known first, each parameter the data do not need (holding it
    # at its starting value costs less than the likelihood-ratio threshold),
    # but keep one free parameter on each axis an edge sees
    for key in sorted(model.free, key=lambda k: -model.specs[k].rank):
        if not model.covers_axes([k for k in model.free if k != key]):
            continue            # the last free parameter of an axis: its uncertainty belongs in the intervals
        index = model.free.index(key)
        trial = model.copy()
        z_held = trial.hold(z, index)
        try:
            z_held, jacobian_held = trial.solve(z_held)
        except ImgmtfError:
            continue
        cost = (trial.chi_square(z_held) - model.chi_square(z)) / scale
        if cost < LIKELIHOOD_RATIO:
            notes[key] = ("held", f"the data do not need it (freeing it gains chi-square {max(cost, 0):.1f} "
                                  f"< {LIKELIHOOD_RATIO:g}); held at its starting value")
            model, z = trial, z_held
            scale = max(model.chi_square(z) / max(model.dof, 1), 1.0)
            covariance = _covariance(jacobian_held, scale)
    return _report(model, z, covariance, notes, confidence)


# -- the data -------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class _EdgeData:
    source: str
    x: np.ndarray
    y: np.ndarray
    normal_angle_deg: float
    gsd_m: float
    gsd_known: bool
    noise: float
    levels: tuple[float, float]
    measurement: EdgeResult


def _edge_data(item, k: int, gsd_m, band, roi) -> _EdgeData:
    from ..inputs import check_roi, saturation_levels
    from .edge import EdgeResult, measure_edge
    from .intervals import Bootstrap
    from .results import MTFResult
    if isinstance(item, MTFResult) and not isinstance(item, EdgeResult):
        raise ParameterError(f"edge {k + 1}: a {type(item).__name__}; the fit takes edges (an EdgeResult, "
                             "an image array or a file)")
    if isinstance(item, EdgeResult):
        if roi is not None:
            raise ParameterError(f"edge {k + 1}: an EdgeResult is already measured: a roi applies to "
                                 "files and arrays")
        source, result, integer = f"edge {k + 1}", item, False
    else:
        if isinstance(item, (str, Path)):
            from ..io import read_raster
            raster = read_raster(item, band, window=roi)
            source, image, gsd, dtype = str(item), raster.data, raster.gsd_m, np.dtype(raster.dtype)
        else:
            image = np.asarray(item)
            source, gsd, dtype = f"array {k + 1}", None, image.dtype
            if roi is not None:
                left, top, width, height = check_roi(roi, image.shape[:2], source)
                image = image[top: top + height, left: left + width]
        try:
            result = measure_edge(image, gsd_m=gsd_m if gsd_m is not None else gsd,
                                  saturation=saturation_levels(dtype), bootstrap=Bootstrap(0))
        except ImgmtfError as exc:
            # name the input, keeping the error's class, reason and checks
            exc.args = (f"{source}: {exc}",)
            raise
        integer = np.issubdtype(dtype, np.integer)
    x = np.asarray(result.samples_x_px, float)
    y = np.asarray(result.samples_dn, float)
    order = np.argsort(x, kind="stable")
    x, y = x[order], y[order]
    levels = (float(result.levels_dn[0]), float(result.levels_dn[1]))
    step = abs(levels[1] - levels[0])
    if x.size < 20 or not step > 0:
        raise ImgmtfError(f"{source}: too few edge samples to fit", reason="unsuitable")
    # quantisation (1 DN) for integer data, else a floor for noise-free floats
    floor = 1 / math.sqrt(12) if integer else 1e-5 * step
    noise = max(profile_noise(x, y), floor)
    gsd = result.gsd_m if result.gsd_m else (gsd_m or 1.0)
    return _EdgeData(source, x, y, float(result.normal_angle_deg), float(gsd), bool(result.gsd_m), noise,
                     levels, result)


def profile_noise(x: np.ndarray, y: np.ndarray) -> float:
    """Noise standard deviation (DN) of profile samples ``y`` at sorted
    positions ``x``, without a model: each sample against the straight line
    through its two neighbours, robust (median absolute deviation), so the
    few samples where the profile curves do not count."""
    left, right = x[1:-1] - x[:-2], x[2:] - x[1:-1]
    span = left + right
    ok = span > 0
    w = np.where(ok, right / np.where(ok, span, 1.0), 0.5)
    misfit = y[1:-1] - (w * y[:-2] + (1 - w) * y[2:])
    scale = np.sqrt(1 + w**2 + (1 - w) ** 2)
    return float(1.4826 * np.median(np.abs(misfit / scale)))


# -- the model --------------------------------------------------------------------
def _stage_names(names, start: Sensor | None) -> list[str]:
    if names is None:
        names = [s.name for s in start.stages] if start is not None else list(PAPER_STAGES)
    elif isinstance(names, str):
        names = [n.strip() for n in names.split(",") if n.strip()]
    names = _listed("stages", names)
    if not names:
        raise ParameterError("no stages to fit")
    for name in names:
        if name not in STAGES:
            raise ParameterError(f"unknown stage {name!r}; known: {', '.join(STAGES)}")
    if len(set(names)) != len(names):
        raise ParameterError(f"a stage is named twice in {', '.join(names)}")
    return names


def _listed(name: str, values, kinds: str = "names, or one comma-separated string") -> list:
    """``values`` as a list; a ParameterError naming ``name`` when it is no collection (None, 3)."""
    try:
        return list(values)
    except TypeError:
        raise ParameterError(f"{name} must be a list of {kinds}, got {values!r}") from None


def _initial_stages(names: list[str], start: Sensor | None, gsd: float) -> list[Stage]:
    given = {s.name: s for s in (start.stages if start is not None else ())}
    out = []
    for name in names:
        if name in given:
            out.append(given[name])
        else:  # the defaults are for a 1 m GSD: the same blur in pixels
            default = STAGES[name]()
            out.append(default.with_fit_coordinates(default.fit_coordinates(1.0), gsd))
    return out


def check_names(stages=None, hold=(), start: Sensor | None = None) -> list[str]:
    """The stages a fit frees, and the parameters it holds, checked before
    any data are read (the CLI's --stages and --hold: a usage error).

    Parameters
    ----------
    stages, hold, start
        As :func:`fit_sensor` takes them.

    Returns
    -------
    list of str
        The stages' names.

    Raises
    ------
    ParameterError
        An unknown stage, one named twice, or a held name that is no
        fitted stage or parameter.

    Examples
    --------
    >>> check_names("optics,detector", "detector.width_x_m")
    ['optics', 'detector']
    """
    names = _stage_names(stages, start)
    _hold_keys(hold, [f"{name}.{parameter}" for name in names for parameter in STAGES[name].fit_specs()])
    return names


def _hold_keys(hold, fitted: list[str]) -> set[str]:
    if isinstance(hold, str):
        hold = [h.strip() for h in hold.split(",") if h.strip()]
    keys = set()
    for item in _listed("hold", hold):
        matches = [k for k in fitted if k == item or k.split(".")[0] == item]
        if not matches:
            raise ParameterError(f"cannot hold {item!r}: not a fitted stage or parameter; "
                                 f"fitted: {', '.join(fitted)}")
        keys.update(matches)
    return keys


class _Model:
    """The shared stage parameters and each edge's nuisance parameters as
    one vector z = [free stage coordinates, then L, R, x0 per edge]."""

    def __init__(self, gsd: float, stages: list[Stage], data: list[_EdgeData]):
        self.gsd, self.stages, self.data = gsd, stages, data
        self.specs, self.keys, self.units = {}, [], {}
        for stage in stages:
            for name, spec in stage.fit_specs().items():
                key = f"{stage.name}.{name}"
                self.specs[key] = spec
                self.keys.append(key)
                self.units[key] = stage.units()[name]
        self.start = {k: v for s in stages for k, v in _coordinates(s, gsd).items()}
        self.values = dict(self.start)           # coordinates of held parameters live here
        self.ties: dict[str, str] = {}
        self.free = list(self.keys)
        self._last_responses: tuple = (None, [])

    # -- which parameters are free ------------------------------------------------
    def screen_axes(self, held: set[str]) -> dict[str, tuple[str, str]]:
        """Tie or hold what no edge's axis constrains; hold ``held``."""
        notes = {k: ("held", "held by request at its starting value") for k in held}
        seen = {"across" if axis == "x" else "along" for axis in self.seen_axes()}
        axis_of = {"x": "across", "y": "along"}
        for key, spec in self.specs.items():
            if key in held or spec.axis == "xy" or axis_of[spec.axis] in seen:
                continue
            twin = f"{key.split('.')[0]}.{spec.pair}" if spec.pair else next(
                (k for k, s in self.specs.items() if s.pair and f"{k.split('.')[0]}.{s.pair}" == key), None)
            if twin and twin not in held:
                self.ties[key] = twin
                notes[key] = ("tied", f"no {axis_of[spec.axis]}-track edge: taken equal to {twin}")
            else:
                notes[key] = ("held", f"no {axis_of[spec.axis]}-track edge: held at its starting value")
        self.free = [k for k in self.keys if k not in notes]
        return notes

    def copy(self) -> _Model:
        other = object.__new__(_Model)
        other.__dict__.update(self.__dict__)
        other.values, other.ties, other.free = dict(self.values), dict(self.ties), list(self.free)
        return other

    def seen_axes(self) -> set[str]:
        """Image axes some edge mostly constrains: "x" (across), "y" (along)."""
        return {"x" if abs(d.normal_angle_deg) < 45 else "y" for d in self.data}

    def covers_axes(self, free: list[str]) -> bool:
        """Whether parameters ``free`` (with those tied to them) act on every
        axis an edge sees."""
        axes: set[str] = set()
        for key in free:
            for k in [key] + [t for t, source in self.ties.items() if source == key]:
                axes.update(("x", "y") if self.specs[k].axis == "xy" else (self.specs[k].axis,))
        return self.seen_axes() <= axes

    def hold(self, z: np.ndarray, index: int) -> np.ndarray:
        key = self.free.pop(index)
        self.values[key] = self.start[key]
        return np.delete(z, index)

    @property
    def n_free(self) -> int:
        return len(self.free)

    @property
    def dof(self) -> int:
        return sum(d.x.size for d in self.data) - self.n_free - 3 * len(self.data)

    def initial_vector(self) -> np.ndarray:
        nuisance = [v for d in self.data for v in (*d.levels, 0.0)]
        return np.array([self.start[k] for k in self.free] + nuisance, float)

    def bounds(self):
        upper = [self.specs[k].upper_px ** self.specs[k].power for k in self.free]
        big = np.inf
        lower = [0.0] * self.n_free + [-big] * (3 * len(self.data))
        return np.array(lower), np.array(upper + [big] * (3 * len(self.data)))

    def sensor(self, u: np.ndarray) -> Sensor:
        coords = dict(self.values)
        coords.update(zip(self.free, u))
        for key, twin in self.ties.items():
            coords[key] = coords[twin]
        stages = []
        for stage in self.stages:
            own = {k.split(".", 1)[1]: v for k, v in coords.items() if k.split(".")[0] == stage.name}
            stages.append(stage.with_fit_coordinates(own, self.gsd) if own else stage)
        return Sensor(self.gsd, stages)

    def responses(self, u: np.ndarray):
        """Each edge's line response for stage coordinates ``u``; the last
        ones kept, since the solver asks for the residuals and then the
        Jacobian at the same point."""
        key = (tuple(self.free), u.tobytes())
        if self._last_responses[0] != key:
            sensor = self.sensor(u)
            self._last_responses = (key, [sensor.line_response(d.normal_angle_deg, d.gsd_m,
                                                               reach_px=float(np.abs(d.x).max()) + 2.0)
                                          for d in self.data])
        return self._last_responses[1]

    # -- least squares ------------------------------------------------------------
    def residuals(self, z: np.ndarray, responses=None) -> np.ndarray:
        u = z[: self.n_free]
        responses = responses or self.responses(u)
        out = []
        for e, (d, r) in enumerate(zip(self.data, responses)):
            lo, hi, x0 = z[self.n_free + 3 * e: self.n_free + 3 * e + 3]
            out.append((d.y - (lo + (hi - lo) * r.esf(d.x - x0))) / d.noise)
        return np.concatenate(out)

    def jacobian(self, z: np.ndarray):
        u = z[: self.n_free]
        base = self.responses(u)
        offsets = [z[self.n_free + 3 * e + 2] for e in range(len(self.data))]
        base_esf = [r.esf(d.x - x0) for d, r, x0 in zip(self.data, base, offsets)]
        _, upper = self.bounds()
        columns = []
        for k in range(self.n_free):
            h = 1e-3 * max(u[k], 0.05 * upper[k] ** 0.5)
            h = -h if u[k] + h > upper[k] else h
            shifted = u.copy()
            shifted[k] += h
            moved = self.responses(shifted)
            columns.append(np.concatenate([
                -(z[self.n_free + 3 * e + 1] - z[self.n_free + 3 * e]) / d.noise
                * (m.esf(d.x - x0) - esf) / h
                for e, (d, m, x0, esf) in enumerate(zip(self.data, moved, offsets, base_esf))]))
        # each edge's levels and offset act on its own samples only: a sparse
        # Jacobian, whose size grows with the edges, not with their square
        from scipy import sparse
        n = sum(d.x.size for d in self.data)
        stage = np.stack(columns, axis=1) if columns else np.zeros((n, 0))
        blocks = []
        for e, (d, b, esf) in enumerate(zip(self.data, base, base_esf)):
            lo, hi, x0 = z[self.n_free + 3 * e: self.n_free + 3 * e + 3]
            blocks.append(np.stack([-(1 - esf), -esf, (hi - lo) * b.lsf(d.x - x0)], axis=1) / d.noise)
        return sparse.hstack([sparse.csr_array(stage), sparse.block_diag(blocks)], format="csr")

    def solve(self, z: np.ndarray, max_iterations: int = 200):
        """Bounded least squares from ``z`` (SciPy's trust-region
        reflective ``least_squares``, with :meth:`jacobian`, sparse, the
        columns scaled by their norms, the steps by LSMR).  Returns the
        solution and its Jacobian.

        Raises
        ------
        ImgmtfError
            No convergence within ``max_iterations`` Jacobians.
        """
        from scipy.optimize import least_squares
        lower, upper = self.bounds()
        z = np.clip(z, lower, upper)
        if max_iterations > 0:
            result = least_squares(self.residuals, z, jac=self.jacobian, bounds=(lower, upper), method="trf",
                                   x_scale="jac", ftol=1e-9, xtol=1e-10, gtol=1e-10, max_nfev=max_iterations,
                                   tr_solver="lsmr", tr_options={"atol": 1e-12, "btol": 1e-12})
            if result.status > 0:
                return result.x, result.jac
        raise ImgmtfError(f"the fit of {', '.join(s.name for s in self.stages)} did not converge in "
                          f"{max_iterations} iterations; try fewer stages (--stages) or hold some (--hold)",
                          reason="fit")

    def chi_square(self, z: np.ndarray) -> float:
        return float(np.sum(self.residuals(z) ** 2))

    def undetermined(self, z: np.ndarray, covariance: np.ndarray) -> dict[int, float]:
        """Index -> 1-SE range (px of blur length) of each free parameter
        the data do not determine."""
        out = {}
        for i, key in enumerate(self.free):
            power = self.specs[key].power
            u, se = z[i], math.sqrt(max(covariance[i, i], 0.0))
            length = u ** (1 / power)
            width = ((u + se) ** (1 / power) - max(u - se, 0.0) ** (1 / power)) / 2
            if not np.isfinite(width) or width > max(DETERMINED_RELATIVE * length, DETERMINED_PX):
                out[i] = width if np.isfinite(width) else math.inf
        return out


def _other_stages(stages) -> str:
    """What to try when the model misfits: the long-tailed stages it lacks,
    or, with all of them in, the non-parametric estimate."""
    have = {s.name for s in stages}
    missing = [name for name in ("diffraction", "defocus", "olpf") if name not in have]
    if missing:
        return f"try other stages (e.g. {', '.join(missing)})"
    return "compare with the non-parametric estimate (imgmtf measure), which assumes no form of blur"


def _coordinates(stage: Stage, gsd: float) -> dict[str, float]:
    return {f"{stage.name}.{k}": v for k, v in stage.fit_coordinates(gsd).items()}


def _covariance(jacobian, reduced_chi_square: float) -> np.ndarray:
    """Parameter covariance from the weighted (sparse) Jacobian, scaled up by
    the reduced chi-square when the residuals exceed the noise (never down:
    on noise-free integer chips the noise is the quantisation's, 1/sqrt(12)
    DN, which flat plateaus do not show)."""
    return np.linalg.pinv((jacobian.T @ jacobian).toarray()) * max(reduced_chi_square, 1.0)


# -- the report -------------------------------------------------------------------
def _mtf_band(model: _Model, u: np.ndarray, covariance: np.ndarray, f: np.ndarray, angle_deg: float,
              gsd: float, confidence: float):
    sensor = model.sensor(u)
    value = np.abs(sensor.normal_transfer(f, angle_deg, gsd))
    n = model.n_free
    if n == 0:
        return value, value, value
    _, upper = model.bounds()
    grads = []
    for k in range(n):
        h = 1e-4 * max(u[k], 0.05 * upper[k] ** 0.5)
        h = -h if u[k] + h > upper[k] else h
        shifted = u.copy()
        shifted[k] += h
        grads.append((np.abs(model.sensor(shifted).normal_transfer(f, angle_deg, gsd)) - value) / h)
    g = np.stack(grads, axis=-1)
    se = np.sqrt(np.maximum(np.einsum("...i,ij,...j->...", g, covariance[:n, :n], g), 0.0))
    z = NormalDist().inv_cdf(0.5 + confidence / 2)
    return value, np.clip(value - z * se, 0.0, 1.0), np.clip(value + z * se, 0.0, 1.0)


def _mtf50_band(model, u, covariance, angle_deg, gsd, confidence):
    f = np.linspace(0.0, 2.0, 4001)
    value, low, high = _mtf_band(model, u, covariance, f, angle_deg, gsd, confidence)
    return first_crossing(f, value, 0.5), (first_crossing(f, low, 0.5), first_crossing(f, high, 0.5))


def _report(model: _Model, z: np.ndarray, covariance: np.ndarray, notes: dict, confidence: float) -> SensorFit:
    n = model.n_free
    u = z[:n]
    sensor = model.sensor(u)
    start = model.sensor(np.array([model.start[k] for k in model.free]))
    responses = model.responses(u)
    residuals = model.residuals(z, responses)
    reduced = float(np.sum(residuals**2) / max(model.dof, 1))
    warnings = []

    parameters = []
    _, upper = model.bounds()
    for stage in sensor.stages:
        units = stage.units()
        for name, value in stage.to_dict(include_name=False).items():
            key = f"{stage.name}.{name}"
            if key in model.free:
                i = model.free.index(key)
                se = _value_error(stage, name, u[i], math.sqrt(max(covariance[i, i], 0.0)), model.gsd)
                status, note = "fitted", ""
                if u[i] >= upper[i] * (1 - 1e-6):
                    note = "at the bound of its range"
                    warnings.append(f"{key} is at the bound of its range ({value:.4g} {units[name]}): the model "
                                    "strains to fit the edges, whose blur may have another form; its MTF may be "
                                    f"biased: {_other_stages(model.stages)}")
            elif key in notes:
                se, (status, note) = math.nan, notes[key]
            else:  # a parameter the fit does not touch (wavelength, pitch)
                se, status, note = math.nan, "held", "not fitted"
            parameters.append(FittedParameter(stage.name, name, float(value), float(se), units[name], status, note))

    correlations = []
    if n > 1:
        sd = np.sqrt(np.maximum(np.diag(covariance)[:n], 1e-300))
        corr = covariance[:n, :n] / np.outer(sd, sd)
        for i in range(n):
            for j in range(i + 1, n):
                if abs(corr[i, j]) > HIGH_CORRELATION:
                    correlations.append((model.free[i], model.free[j], float(corr[i, j])))

    edges, start_row = [], 0
    for e, (d, r) in enumerate(zip(model.data, responses)):
        lo, hi, x0 = z[n + 3 * e: n + 3 * e + 3]
        res = residuals[start_row: start_row + d.x.size] * d.noise
        start_row += d.x.size
        chi = float(np.sum((res / d.noise) ** 2) / max(d.x.size - 3 - n / len(model.data), 1))
        p, fraction = _misfit(d.x - x0, res, d.noise, abs(hi - lo), r)
        value, low, high = _mtf_band(model, u, covariance, np.array(0.5), d.normal_angle_deg, d.gsd_m, confidence)
        f = np.linspace(0.0, 2.0, 4001)
        measured = d.measurement
        edge = EdgeFit(d.source, d.normal_angle_deg, direction_label(d.normal_angle_deg, 0.0),
                       "across" if abs(d.normal_angle_deg) < 45 else "along", d.gsd_m,
                       int(measured.rows_used), float(measured.snr), float(value), (float(low), float(high)),
                       first_crossing(f, np.abs(sensor.normal_transfer(f, d.normal_angle_deg, d.gsd_m)), 0.5),
                       float(np.interp(0.5, measured.frequencies_cy_px, measured.mtf)), d.noise, float(hi - lo),
                       (float(lo), float(hi)), float(x0), chi, p, fraction, d.x, res, measured)
        edges.append(edge)
        if p < MISFIT_P and fraction > MISFIT_FRACTION:
            warnings.append(f"{d.source}: the model does not fit this edge: its residuals are structured "
                            f"along the normal ({100 * fraction:.2f} % of the step, p = {p:.1g}); its MTF may be "
                            f"biased: {_other_stages(model.stages)}")

    if not model.covers_axes(model.free):
        warnings.append("no parameter acting on every axis an edge sees could be determined: the MTF there is "
                        "the starting sensor's; give more or sharper edges, or other stages")
    seen = {e.constrains for e in edges}
    directions = {}
    for direction in DIRECTIONS:
        angle = direction_angle(direction)
        value, low, high = _mtf_band(model, u, covariance, np.array(0.5), angle, model.gsd, confidence)
        mtf50, mtf50_ci = _mtf50_band(model, u, covariance, angle, model.gsd, confidence)
        directions[direction] = {"mtf_nyquist": float(value), "mtf_nyquist_ci": [float(low), float(high)],
                                 "mtf50_cy_px": mtf50, "mtf50_cy_px_ci": list(mtf50_ci),
                                 "constrained": direction in seen}
        if direction not in seen:
            warnings.append(f"no {direction}-track edge: the {direction}-track MTF is an extrapolation "
                            "of the model (tied and held parameters)")
    if not any(d.gsd_known for d in model.data):
        warnings.append(f"no GSD in the inputs: lengths are in units of {model.gsd:g} m per pixel "
                        "(at 1 m, metres are pixels); give the GSD (--gsd, gsd_m=) for lengths on the ground")
    return SensorFit(sensor, start, tuple(parameters), tuple(correlations), reduced, tuple(edges), directions,
                     confidence, tuple(warnings), model, u, covariance)


def _value_error(stage: Stage, name: str, u: float, se_u: float, gsd: float) -> float:
    """Standard error of a parameter in its own unit, from that of its fit
    coordinate (linearised; one-sided at the coordinate's zero)."""
    def value(coordinate):
        return getattr(stage.with_fit_coordinates({name: max(coordinate, 0.0)}, gsd), name)
    if u > se_u:
        return abs(value(u + se_u) - value(u - se_u)) / 2
    return abs(value(u + se_u) - value(u))


def _misfit(x: np.ndarray, residuals: np.ndarray, noise: float, step: float, response):
    """P-value and size (RMS fraction of the step, noise removed) of the
    residuals' structure: their means in bins along the normal, over the
    transition (where the model's edge response is between 0.1 % and 99.9 %,
    and at least +-3 px)."""
    grid = np.arange(-50.0, 50.0, MISFIT_BIN_PX / 4)
    esf = response.esf(grid)
    inside = grid[(esf > 1e-3) & (esf < 1 - 1e-3)]
    reach = max(3.0, float(np.abs(inside).max()) if inside.size else 3.0)
    keep = np.abs(x) <= reach
    bins = np.floor(x[keep] / MISFIT_BIN_PX).astype(int)
    bins -= bins.min() if bins.size else 0
    count = np.bincount(bins)
    total = np.bincount(bins, weights=residuals[keep])
    used = count >= 3
    if not used.any():
        return 1.0, 0.0
    means, count = total[used] / count[used], count[used]
    statistic = float(np.sum(count * means**2) / noise**2)
    from scipy.special import chdtrc  # (scipy.stats, for this one tail, costs most of a second to import)
    p = float(chdtrc(used.sum(), statistic))
    systematic = max(float(np.mean(means**2 - noise**2 / count)), 0.0)
    return p, math.sqrt(systematic) / step


def _json(value):
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None
