"""The sensor model fitted to bars' and double bars' profiles (Storey's
method for the Lake Pontchartrain Causeway, Landsat 7 ETM+).

A bar W wide seen through the sensor is the difference of two edge
responses; a double bar, two such bars whose centres lie W + G apart.
Each profile's model is

    DN(x) = B + A sum_c [ESF(x - x0 - c + W/2) - ESF(x - x0 - c - W/2)],

c over its bars' centres (0; or -+(W + G)/2), ESF the sensor's exact edge
response along the profile's normal (:meth:`imgmtf.Sensor.line_response`),
B, A and x0 the profile's own background, amplitude and offset.  All
profiles share the stages' parameters, in the coordinates of the edges'
fit (:class:`imgmtf.sensor.stages.FitSpec`: blur lengths in px raised to
the power the low-frequency MTF responds to, bounded), each other-axis
twin tied to its fitted parameter where no profile sees its axis (a
symmetric optic), as :mod:`.model` does for edges.  The samples are binned
1/32 px along the normal (:func:`.data.bin_profile`), each bin's model its
samples' mean to the second order, weighted by the square root of its
count over the samples' noise (:func:`.data.profile_noise`); bounded least
squares (SciPy's ``least_squares``).  The covariance is the Jacobian's,
scaled up by the reduced chi-square when that exceeds 1; the model's MTF
along each normal comes with its delta-method interval.

Where a pair's transfer is zero (1 px spans 2 px apart at Nyquist) the
profile says nothing at that frequency by itself: the model's form (its
stages) carries the MTF across the zero, and the interval is the fit's,
under that form.
"""
from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..._blas import one_blas_thread
from ...errors import ImgmtfError, ParameterError
from ...metrics import first_crossing
from ...sensor.model import Sensor
from ..intervals import Interval
from ..spectrum import NYQUIST
from .bands import band_sensors, model_mtf_band
from .data import ProfileBins, bin_profile, profile_noise
from .model import hold_keys, initial_stages, stage_names
from .results import FittedParameter

#: a reduced chi-square above this: the model's form is not the sensor's (warned; ``misfit`` in its file)
MISFIT_REDUCED_CHI_SQUARE = 2.0
#: MTF50 is read off the model on this grid, cy/px
MTF50_GRID_CY_PX = np.linspace(0.0, 2.0, 2001)


@dataclass(frozen=True, eq=False)
class BarProfile:
    """One bar's or double bar's samples as the fit takes them.

    Attributes
    ----------
    source : str
        What messages name it by.
    x, y : numpy.ndarray
        The samples' signed distances from the target's centre line (px,
        ascending) and values (DN).
    normal_angle_deg : float
        Its normal's angle from the x axis, deg.
    width_px : float
        Each bar's width, px.
    gap_px : float or None
        A double bar's gap (edge to edge), px; None for a single bar.
    background_dn, peak_dn : float
        The levels measured (the fit's starting point), DN.
    quantum_dn : float, optional
        The values' step (1 for a file's integer DN, 0 for floats): the
        noise is at least its rounding's, quantum / sqrt(12).
    """

    source: str
    x: np.ndarray
    y: np.ndarray
    normal_angle_deg: float
    width_px: float
    gap_px: float | None
    background_dn: float
    peak_dn: float
    quantum_dn: float = 0.0
    bins: ProfileBins = field(init=False)
    noise: float = field(init=False)

    def __post_init__(self):
        order = np.argsort(self.x, kind="stable")
        x, y = np.asarray(self.x, float)[order], np.asarray(self.y, float)[order]
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "bins", bin_profile(x, y))
        contrast = abs(self.peak_dn - self.background_dn)
        object.__setattr__(self, "noise", max(profile_noise(x, y), self.quantum_dn / math.sqrt(12.0),
                                                 1e-5 * contrast, 1e-12))

    @property
    def centres_px(self) -> tuple[float, ...]:
        """Its bars' centres along the normal, px from its centre line."""
        if self.gap_px is None:
            return (0.0,)
        half = (self.width_px + self.gap_px) / 2.0
        return (-half, half)

    @property
    def span_px(self) -> float:
        """Outer side to outer side, px."""
        return 2.0 * max(abs(c) for c in self.centres_px) + self.width_px

    def amplitude_guess(self) -> float:
        """A bar's full height (DN) from the profile's area over the bars' total width."""
        step = np.diff(self.bins.x, prepend=self.bins.x[0])
        area = float(np.sum((self.bins.y - self.background_dn) * step))
        return area / (self.width_px * len(self.centres_px)) if area else self.peak_dn - self.background_dn


def bar_profile(result: Any, source: str, quantum_dn: float = 0.0) -> BarProfile:
    """A measured bar (:class:`imgmtf.PulseResult`) or double bar
    (:class:`imgmtf.DoubleBarResult`) as the fit takes it (``quantum_dn``
    its values' step: 1 for a file's integer DN).

    Raises
    ------
    ParameterError
        A result of another kind.
    """
    width = getattr(result, "pulse_width_px", None)
    if width is None or not hasattr(result, "prf"):
        raise ParameterError(f"{source}: a {type(result).__name__}; the bars' fit takes bars and double bars")
    return BarProfile(source, np.asarray(result.samples_x_px, float), np.asarray(result.samples_dn, float),
                      float(result.normal_angle_deg), float(width), getattr(result, "gap_px", None),
                      float(result.background_dn), float(result.peak_dn), quantum_dn)


@dataclass(frozen=True, eq=False)
class ModelMTF:
    """The fitted model's MTF along one profile's normal, with its
    delta-method band: what a figure draws where the profile's own
    transform cannot be read (a pair's transfer zeros).

    Attributes
    ----------
    frequencies_cy_px, mtf : numpy.ndarray
        The model's MTF (1 at zero frequency) and its frequencies, cy/px.
    low, high : numpy.ndarray
        Its band at ``confidence``, clipped to [0, 1].
    stages : str
        The model's stages, comma-separated.
    confidence : float
        Of the band.
    """

    frequencies_cy_px: np.ndarray
    mtf: np.ndarray
    low: np.ndarray
    high: np.ndarray
    stages: str
    confidence: float

    def to_dict(self) -> dict:
        """JSON-ready: the curve and its band, rounded to 6 decimals."""
        return {"model_stages": self.stages, "model_confidence": self.confidence,
                "model_mtf": [round(float(v), 6) for v in self.mtf],
                "model_mtf_ci": [[round(float(a), 6), round(float(b), 6)] for a, b in zip(self.low, self.high)]}


@dataclass(frozen=True, eq=False)
class BarFit:
    """The sensor model fitted to bars' profiles.

    Attributes
    ----------
    sensor : Sensor
        The fitted sensor.
    stages : str
        Its stages, comma-separated.
    parameters : tuple of FittedParameter
        Each stage parameter: fitted (with its standard error), or tied.
    reduced_chi_square : float
        The samples' chi-square per degree of freedom.
    sources : tuple of str
        The profiles, in order.
    normal_angles_deg : tuple of float
        Their normals.
    mtf_nyquist : tuple of float
        The model's MTF at Nyquist along each normal.
    mtf_nyquist_ci : tuple of Interval
        Their intervals.
    mtf50_cy_px : tuple of float
        The model's MTF50 along each normal, cy/px.
    mtf50_ci_cy_px : tuple of Interval
        Their intervals.
    confidence : float
        Of the intervals.
    warnings : tuple of str
        What the fit must say.
    """

    sensor: Sensor
    stages: str
    parameters: tuple[FittedParameter, ...]
    reduced_chi_square: float
    sources: tuple[str, ...]
    normal_angles_deg: tuple[float, ...]
    mtf_nyquist: tuple[float, ...]
    mtf_nyquist_ci: tuple[Interval, ...]
    mtf50_cy_px: tuple[float, ...]
    mtf50_ci_cy_px: tuple[Interval, ...]
    confidence: float
    warnings: tuple[str, ...] = ()
    #: ``band(f, angle_deg)``: the model's MTF along a normal at ``f`` and its band
    band: Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray, np.ndarray]] | None = field(
        default=None, repr=False, compare=False)

    def mtf_curve(self, frequencies_cy_px: np.ndarray, index: int = 0) -> ModelMTF:
        """The model's MTF along the ``index``-th profile's normal at
        ``frequencies_cy_px`` (cy/px), with its delta-method band at
        ``confidence``.

        Examples
        --------
        >>> import imgmtf
        >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("double-bar", 5.0, width_px=1.0, gap_px=2.0), 40)
        >>> r = imgmtf.measure_double_bar(chip.image, width_px=1.0, gap_px=2.0)
        >>> curve = fit_bars([bar_profile(r, "chip")]).mtf_curve(np.array([0.0, 0.5]))
        >>> float(curve.mtf[0]), bool(curve.low[1] <= curve.mtf[1] <= curve.high[1])
        (1.0, True)
        """
        if self.band is None:
            raise ParameterError("this fit carries no model to evaluate")
        f = np.asarray(frequencies_cy_px, float)
        value, low, high = self.band(f, self.normal_angles_deg[index])
        return ModelMTF(f, value, low, high, self.stages, self.confidence)

    @property
    def misfit(self) -> bool:
        """Whether the profiles' residuals exceed their noise beyond what
        the model's form explains (reduced chi-square above
        ``MISFIT_REDUCED_CHI_SQUARE``; warned)."""
        return self.reduced_chi_square > MISFIT_REDUCED_CHI_SQUARE

    def to_toml(self, path: str | os.PathLike, comment: str = "") -> None:
        """Write the fitted sensor as TOML with its ``[fit]`` record, as
        :meth:`imgmtf.SensorFit.to_toml` does for edges:
        :meth:`imgmtf.Sensor.from_toml` reads it, ``imgmtf restore``
        refuses it when ``misfit``.  The bars' fit has no test of structure
        in each profile's residuals: ``misfit_p`` and ``misfit_fraction``
        are NaN (not tested), the verdict the reduced chi-square's.

        Raises
        ------
        FileWriteError
            The file cannot be written.

        Examples
        --------
        >>> import imgmtf
        >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("double-bar", 5.0, width_px=1.0, gap_px=2.0), 40)
        >>> r = imgmtf.measure_double_bar(chip.image, width_px=1.0, gap_px=2.0)
        >>> import os, tempfile
        >>> path = os.path.join(tempfile.mkdtemp(), "pair_sensor.toml")
        >>> fit_bars([bar_profile(r, "pair.tif")]).to_toml(path)
        >>> imgmtf.read_fit_record(path).sources
        ('pair.tif',)
        """
        from ...version import __version__
        from .record import FitRecord, write_fitted_sensor
        record = FitRecord(self.misfit, float(self.reduced_chi_square), math.nan, math.nan,
                           tuple(s.name for s in self.sensor.stages), self.sources, __version__)
        write_fitted_sensor(path, self, comment=comment, record=record)

    def to_dict(self) -> dict:
        """JSON-ready: the parameters, and per profile the model's figures."""
        return {"stages": self.stages, "reduced_chi_square": self.reduced_chi_square, "misfit": self.misfit,
                "confidence": self.confidence, "parameters": [p.to_dict() for p in self.parameters],
                "profiles": [{"source": s, "normal_angle_deg": a, "mtf_nyquist": m, "mtf_nyquist_ci": [ci.low, ci.high],
                              "mtf50_cy_px": f, "mtf50_ci_cy_px": [fci.low, fci.high]}
                             for s, a, m, ci, f, fci in zip(self.sources, self.normal_angles_deg, self.mtf_nyquist,
                                                            self.mtf_nyquist_ci, self.mtf50_cy_px,
                                                            self.mtf50_ci_cy_px)],
                "warnings": list(self.warnings)}


class _BarModel:
    """The stages' free coordinates and each profile's (B, A, x0) as one
    vector; each profile's line response kept for the last coordinates."""

    def __init__(self, profiles: Sequence[BarProfile], stages: list, gsd: float, hold: Any = ()):
        self.profiles, self.gsd = list(profiles), gsd
        self.stages = stages
        self.keys, self.specs, self.units, start = [], {}, {}, {}
        for stage in stages:
            for name, spec in stage.fit_specs().items():
                key = f"{stage.name}.{name}"
                self.keys.append(key)
                self.specs[key] = spec
                self.units[key] = stage.units()[name]
            start.update({f"{stage.name}.{k}": v for k, v in stage.fit_coordinates(gsd).items()})
        self.start = start
        self.held = hold_keys(hold, self.keys)        # at their starting values
        seen = {"x" if abs(p.normal_angle_deg) < 45 else "y" for p in self.profiles}
        self.ties: dict[str, str] = {}
        for key, spec in self.specs.items():
            if spec.axis == "xy" or spec.axis in seen or key in self.held:
                continue
            stage = key.split(".")[0]
            twin = f"{stage}.{spec.pair}" if spec.pair else next(
                (k for k, s in self.specs.items() if s.pair and f"{k.split('.')[0]}.{s.pair}" == key), None)
            if twin is None:
                raise ParameterError(f"{key} acts on an axis no profile sees and has no twin to follow: hold "
                                     "it or give a profile along that axis")
            self.ties[key] = twin
        self.free = [k for k in self.keys if k not in self.ties and k not in self.held]
        self._kept: tuple[bytes | None, list] = (None, [])

    @property
    def n_free(self) -> int:
        return len(self.free)

    def sensor(self, u: np.ndarray) -> Sensor:
        coords = {key: self.start[key] for key in self.held}
        coords.update(zip(self.free, (float(v) for v in u)))
        coords.update({key: coords[twin] for key, twin in self.ties.items()})
        stages = [stage.with_fit_coordinates({name: coords[f"{stage.name}.{name}"] for name in stage.fit_specs()},
                                             self.gsd) for stage in self.stages]
        return Sensor(self.gsd, stages)

    def responses(self, u: np.ndarray) -> list:
        key = u.tobytes()
        if self._kept[0] != key:
            sensor = self.sensor(u)
            self._kept = (key, [sensor.line_response(p.normal_angle_deg, self.gsd,
                                                     reach_px=float(np.abs(p.x).max()) + p.span_px + 2.0)
                                for p in self.profiles])
        return self._kept[1]

    def initial_vector(self) -> np.ndarray:
        nuisance = [v for p in self.profiles for v in (p.background_dn, p.amplitude_guess(), 0.0)]
        return np.array([self.start[k] for k in self.free] + nuisance, float)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lower = [self.specs[k].lower for k in self.free] + [-np.inf] * (3 * len(self.profiles))
        upper = [self.specs[k].upper_px ** self.specs[k].power for k in self.free] + [np.inf] * (
            3 * len(self.profiles))
        return np.array(lower), np.array(upper)

    @staticmethod
    def shape(response, p: BarProfile, x: np.ndarray, m2: np.ndarray | None) -> np.ndarray:
        """The profile's unit-height shape at ``x`` (its bins' means to the
        second order where ``m2`` is given)."""
        total = np.zeros_like(x)
        for centre in p.centres_px:
            for side, sign in ((-p.width_px / 2.0, 1.0), (p.width_px / 2.0, -1.0)):
                if m2 is None:
                    total += sign * response.esf(x - centre - side)
                else:
                    value, curvature = response.esf_with_curvature(x - centre - side)
                    total += sign * (value + 0.5 * m2 * curvature)
        return total

    def residuals(self, z: np.ndarray) -> np.ndarray:
        out = []
        for k, (p, response) in enumerate(zip(self.profiles, self.responses(z[: self.n_free]))):
            b, a, x0 = z[self.n_free + 3 * k: self.n_free + 3 * k + 3]
            model = b + a * self.shape(response, p, p.bins.x - x0, p.bins.m2)
            out.append(np.sqrt(p.bins.count) * (p.bins.y - model) / p.noise)
        return np.concatenate(out)

    def sample_chi_square(self, z: np.ndarray) -> float:
        total = 0.0
        for k, (p, response) in enumerate(zip(self.profiles, self.responses(z[: self.n_free]))):
            b, a, x0 = z[self.n_free + 3 * k: self.n_free + 3 * k + 3]
            total += float(np.sum(((p.y - b - a * self.shape(response, p, p.x - x0, None)) / p.noise) ** 2))
        return total

    def dof(self) -> int:
        return sum(p.x.size for p in self.profiles) - self.n_free - 3 * len(self.profiles)


def fit_bars(profiles: Sequence[BarProfile], *, stages: str | Sequence[str] | None = "optics,detector",
             gsd_m: float = 1.0, confidence: float = 0.95, start: Sensor | None = None,
             hold: str | Sequence[str] = ()) -> BarFit:
    """Fit the sensor's stages to bars' and double bars' profiles.

    Parameters
    ----------
    profiles : sequence of BarProfile
        The profiles (:func:`bar_profile` of measured bars).
    stages : str or sequence of str, optional
        The stages fitted (default "optics,detector", Storey's Gaussian
        optics and the detector's box); names as :func:`imgmtf.fit_sensor`
        takes them ("auto" is the edges' fit's only).
    gsd_m : float, optional
        The pixel, m (parameters in its units; default 1: in px).
    confidence : float, optional
        Of the intervals, in (0, 1).
    start : Sensor, optional
        Starting (and held) values of the stages it has; its stages are
        fitted when ``stages`` is None.
    hold : str or sequence of str, optional
        Parameters held at their starting values: a stage ("detector") or
        "stage.parameter" ("detector.width_x_m").

    Returns
    -------
    BarFit
        The fitted sensor, its parameters and the model's MTF along each
        profile's normal with intervals.

    Raises
    ------
    ParameterError
        No profiles, unknown stages, a held name that is no fitted
        parameter, a bad ``confidence``.
    ImgmtfError
        A fit that does not converge (reason ``fit``).

    Examples
    --------
    >>> import imgmtf
    >>> target = imgmtf.Target("double-bar", 5.0, width_px=1.0, gap_px=2.0)
    >>> chip = imgmtf.render(imgmtf.Sensor(), target, 40)
    >>> r = imgmtf.measure_double_bar(chip.image, width_px=1.0, gap_px=2.0)
    >>> fit = fit_bars([bar_profile(r, "chip")])
    >>> abs(fit.mtf_nyquist[0] - float(chip.true_mtf(0.5))) < 0.005
    True
    """
    from scipy.optimize import least_squares
    if not profiles:
        raise ParameterError("no bars to fit")
    if not 0 < confidence < 1:
        raise ParameterError(f"confidence must be in (0, 1), got {confidence!r}")
    if isinstance(stages, str) and stages.strip() == "auto":
        raise ParameterError("stages 'auto' is the edges' fit's; name the bars' stages (optics,detector)")
    names = stage_names(stages, start)
    model = _BarModel(profiles, initial_stages(names, start, gsd_m), gsd_m, hold)
    lower, upper = model.bounds()
    z0 = np.clip(model.initial_vector(), lower, upper)
    with one_blas_thread():
        solved = least_squares(model.residuals, z0, bounds=(lower, upper), method="trf", x_scale="jac",
                               ftol=1e-10, xtol=1e-10, gtol=1e-10, max_nfev=200 * (z0.size + 1))
    if solved.status <= 0:
        raise ImgmtfError(f"the fit of {', '.join(names)} to the bars did not converge; try fewer stages",
                          reason="fit")
    z = solved.x
    reduced = model.sample_chi_square(z) / max(model.dof(), 1)
    jacobian = solved.jac
    covariance = np.linalg.pinv(jacobian.T @ jacobian) * max(reduced, 1.0)
    u, cov = z[: model.n_free], covariance[: model.n_free, : model.n_free]
    # the fitted sensor and its stepped copies, made once for every profile's angle and the curve's
    sensors = band_sensors(model, u)
    sensor = sensors[0]

    def band(f: np.ndarray, angle_deg: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return model_mtf_band(model, u, cov, f, angle_deg, model.gsd, confidence, sensors)

    nyquist, nyquist_ci, mtf50, mtf50_ci = [], [], [], []
    for p in model.profiles:
        value, low, high = band(np.array([NYQUIST]), p.normal_angle_deg)
        nyquist.append(float(value[0]))
        nyquist_ci.append(Interval(float(low[0]), float(high[0])))
        value, low, high = band(MTF50_GRID_CY_PX, p.normal_angle_deg)
        mtf50.append(float(first_crossing(MTF50_GRID_CY_PX, value, 0.5)))
        mtf50_ci.append(Interval(float(first_crossing(MTF50_GRID_CY_PX, low, 0.5)),
                                 float(first_crossing(MTF50_GRID_CY_PX, high, 0.5))))
    warnings = []
    if reduced > MISFIT_REDUCED_CHI_SQUARE:
        warnings.append(f"the model ({', '.join(names)}) leaves the profiles' residuals {math.sqrt(reduced):.1f} "
                        "times their noise: its form may not be the sensor's, and its MTF not the truth")
    return BarFit(sensor, ",".join(names), _parameters(model, z, covariance), float(reduced),
                  tuple(p.source for p in model.profiles), tuple(p.normal_angle_deg for p in model.profiles),
                  tuple(nyquist), tuple(nyquist_ci), tuple(mtf50), tuple(mtf50_ci), confidence, tuple(warnings),
                  band)


def _parameters(model: _BarModel, z: np.ndarray, covariance: np.ndarray) -> tuple[FittedParameter, ...]:
    """Each stage parameter in its unit, with its standard error (the
    coordinate's, through the coordinate's power), or tied."""
    sensor = model.sensor(z[: model.n_free])
    out = []
    for stage in sensor.stages:
        for name, spec in stage.fit_specs().items():
            key = f"{stage.name}.{name}"
            value = float(getattr(stage, name))
            if key in model.held:
                out.append(FittedParameter(stage.name, name, value, math.nan, model.units[key], "held",
                                           "at its starting value"))
                continue
            if key in model.ties:
                out.append(FittedParameter(stage.name, name, value, math.nan, model.units[key], "tied",
                                           f"no profile along its axis: taken equal to {model.ties[key]}"))
                continue
            i = model.free.index(key)
            u, se_u = float(z[i]), math.sqrt(max(covariance[i, i], 0.0))
            if spec.kind == "length" and spec.power > 1 and u > 0:
                se = se_u * u ** (1.0 / spec.power - 1.0) / spec.power * model.gsd
            elif spec.kind == "length" and spec.power == 1:
                se = se_u * model.gsd
            else:
                se = math.nan
            out.append(FittedParameter(stage.name, name, value, se, model.units[key], "fitted"))
    return tuple(out)
