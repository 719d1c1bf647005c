"""Double-bar MTF estimator: two parallel bars of one width, a gap apart
(Storey's Lake Pontchartrain Causeway for Landsat 7 ETM+: two spans of a
bridge under the pixel).

The pair goes through the bar's part of the shared pipeline
(:class:`imgmtf.estimate.pulse.PulseKind`: the line found by Canny + Hough,
each row's centre the centroid of its background-subtracted profile, which
is the pair's middle, a robust line through them, the oversampled profile
along its normal).  Its profile is the sum of two pulse responses: its
transform is the system's MTF times the pair's transfer

    T(f) = sinc(W f) cos(pi f (W + G))      (1 at f = 0)

for bars W wide whose near sides are G apart (their centres W + G apart).
Where |T| is well away from zero the MTF is the transform divided by it
(masked, NaN, where |T| < 0.1).  Where it is not (1 px spans with a 2 px
gap: cos(1.5 pi) = 0 at Nyquist) no division can read the MTF: Storey's
way, the sensor model's stages (:mod:`imgmtf.estimate.fit`) are fitted to
the double-pulse profile (:mod:`.fit.bars`), and the model's MTF along the
normal, with its delta-method interval, is the figure reported there.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from .._blas import one_blas_thread
from ..errors import ParameterError, TargetNotFoundError, UnsuitableTargetError
from ..inputs import check_number, check_width
from ..kinds.double_bar import DOUBLE_BAR
from ..metrics import fwhm
from . import gate
from .bar_results import BarProfileResult
from .bar_width import half_width_at
from .kind import Shape
from .pipeline import run
from .pulse import BACKGROUND_FRACTION, MIN_HEIGHT_NOISE, WINDOW_FACTOR, PulseKind
from .results import finite
from .settings import make_settings
from .spectrum import MIN_TRANSFER, NYQUIST, with_transfer
from .tails import outer_samples

#: at Nyquist, a pair's |T| below this is too near its zero to divide by: the
#: model is fitted (a transfer of 0.3 multiplies the MTF's noise by 3.3)
MODEL_BELOW_TRANSFER = 0.3


def pair_transfer(f: ArrayLike, width_px: float, gap_px: float) -> np.ndarray:
    """The transfer of two bars ``width_px`` wide whose near sides are
    ``gap_px`` apart, normalised to 1 at zero frequency: sinc(W f)
    cos(pi f (W + G)), signed, at ``f`` (cy/px).

    Examples
    --------
    >>> pair_transfer([0.0, 0.5], 1.0, 2.0).round(6).tolist()
    [1.0, -0.0]
    """
    f = np.asarray(f, float)
    return np.sinc(width_px * f) * np.cos(np.pi * f * (width_px + gap_px))


def check_gap(gap_px: float) -> float:
    """A double bar's gap (px) as a float.

    Raises
    ------
    ParameterError
        A gap that is not a positive finite number.

    Examples
    --------
    >>> check_gap(2)
    2.0
    """
    return check_number("the gap between the bars (px)", gap_px, positive=True)


@dataclass(frozen=True, eq=False, kw_only=True, repr=False)
class DoubleBarResult(BarProfileResult):
    """MTF from a double bar (see :class:`imgmtf.estimate.bar_results.BarProfileResult`
    for each bar's width and the pair's pulse response,
    :class:`imgmtf.estimate.results.MTFResult` for the fields every measurement has).  Where the pair's transfer is
    near zero at Nyquist (``model_fitted``), ``mtf_nyquist`` and its
    interval are the fitted sensor model's (Storey's method); elsewhere the
    profile's transform divided by the pair's transfer.

    Attributes
    ----------
    gap_px : float
        The gap between the bars (edge to edge), px.
    pair_transfer_nyquist : float
        The pair's transfer at Nyquist (:func:`pair_transfer`).
    model_fitted : bool
        Whether the sensor model was fitted to the profile.
    measured_mtf_nyquist : float
        The MTF at Nyquist by division (NaN where the transfer hides it).
    model : imgmtf.estimate.fit.bars.BarFit or None
        The fitted model, when fitted.
    model_mtf : imgmtf.estimate.fit.bars.ModelMTF or None
        The fitted model's MTF along the normal on ``frequencies_cy_px``,
        with its band, when fitted: what the figures read off the model
        come from, across the pair's transfer zeros where ``mtf`` is NaN
        (``mtf`` stays the profile's own, divided by the pair's transfer).
    model_figures : tuple of str
        The figures read off the model ("mtf_nyquist", "mtf50_cy_px").

    Examples
    --------
    >>> import imgmtf
    >>> target = imgmtf.Target("double-bar", 5.0, width_px=0.6, gap_px=1.2)
    >>> chip = imgmtf.render(imgmtf.Sensor(), target, 60)
    >>> result = imgmtf.measure_double_bar(chip.image, width_px=0.6, gap_px=1.2)
    >>> result.gap_px, result.model_fitted
    (1.2, False)
    """

    target: ClassVar[str] = DOUBLE_BAR.name
    gap_px: float
    pair_transfer_nyquist: float
    model_fitted: bool
    measured_mtf_nyquist: float
    model: Any = None
    model_mtf: Any = None
    model_figures: tuple[str, ...] = ()

    def _specific(self) -> dict:
        return {"pulse_width_px": finite(self.pulse_width_px), "gap_px": finite(self.gap_px),
                "pair_transfer_nyquist": finite(self.pair_transfer_nyquist), "model_fitted": self.model_fitted,
                "measured_mtf_nyquist": finite(self.measured_mtf_nyquist),
                **self._profile_figures(), "model_figures": list(self.model_figures)}

    def to_dict(self, curves: bool = True) -> dict:
        """JSON-ready summary, as :meth:`MTFResult.to_dict`; with ``curves``
        and a fitted model, also the model's MTF on the same frequencies and
        its band (``model_mtf``, ``model_mtf_ci``), apart from the measured
        ``mtf``.

        Parameters
        ----------
        curves : bool, optional
            Add the curves (default True).

        Returns
        -------
        dict
            The record's figures (units in the names).
        """
        out = super().to_dict(curves)
        if curves and self.model_mtf is not None:
            out.update(self.model_mtf.to_dict())
        return out


class DoubleBarKind(PulseKind):
    """What a double bar brings to the pipeline: a bar's seed, locations,
    LSF-like profile and tails (:class:`PulseKind`), its own levels and
    width and the pair's transfer as the divisor; ``width_px`` each bar's
    width and ``gap_px`` the gap between them, px, both known."""

    registered = DOUBLE_BAR
    profile = gate.BAR_PROFILE

    def __init__(self, width_px: float, gap_px: float):
        self.bar_px: float = check_width(width_px)
        self.width_px = self.bar_px             # what the bar's seed reads
        self.gap_px = check_gap(gap_px)

    @property
    def span_px(self) -> float:
        """The pair's whole width, outer side to outer side, px."""
        return 2.0 * self.bar_px + self.gap_px

    def shape(self, grid, values, d, v, half_range) -> Shape:
        background_sides = outer_samples(d, half_range, BACKGROUND_FRACTION)
        left, right = (float(v[side].mean()) for side in background_sides)
        background = (left + right) / 2
        near = np.abs(grid) <= self.span_px / 2 + 1.0
        sign = 1.0 if np.mean(values[near]) >= background else -1.0
        peak = sign * (values - background)
        height = float(peak[near].max())
        outer = np.abs(d) > 0.6 * half_range
        noise = float(np.std(v[outer])) if outer.sum() > 3 else 0.0
        if height <= MIN_HEIGHT_NOISE * noise or height <= 0:
            raise TargetNotFoundError(f"no double bar found: the profile peaks {height:.1f} DN above its "
                                      f"background, within the noise ({noise:.1f} DN)")
        if self.span_px / 2 + 2.0 > half_range:
            raise UnsuitableTargetError(
                f"the double bar ({self.span_px:.1f} px) is too wide for the chip: it needs "
                f"{self.span_px / 2 + 2:.1f} px of background on each side of its centre", reason="border")
        prf01 = peak / height
        h10 = half_width_at(grid, prf01, 0.1)
        area = float(np.sum(prf01[np.abs(grid) <= self._core(h10)]) * (grid[1] - grid[0]))
        return Shape(0.0, h10, float(background), float(background + sign * height),
                     min(1.5 * h10 + 1.0, half_range - 1.0),
                     {"width_px": self.bar_px, "gap_px": self.gap_px, "width_estimated": False,
                      "prf01": prf01, "sign": sign, "area_px": area, "h10": h10,
                      "background_sides": background_sides})

    def _core(self, h10: float, factor: float | None = None) -> float:
        return max((factor or WINDOW_FACTOR) * h10, self.span_px / 2 + 1.0)

    def core_px(self, shape, snr, factor):
        return self._core(shape.scale_px, factor)

    def divisor(self, step, transfer, shape):
        return with_transfer(lambda f: pair_transfer(f, self.bar_px, self.gap_px), transfer)

    def peak_mask(self, s, shape):
        return np.abs(s - shape.centre) <= max(0.5 * self.span_px, 0.5)

    def known_half_width_px(self, shape):
        return None            # two tops: no one bar's top to mirror

    def read_width(self, grid, shape):
        return None


class DoubleBarEstimator:
    """A configured double-bar estimator: set up once, apply to many chips.

    Parameters
    ----------
    method : str, optional
        Resampling method, a key of :data:`imgmtf.estimate.resampling.METHODS`
        (default "msg").
    stages : str, optional
        The sensor model's stages fitted where the pair's transfer hides
        Nyquist (default the paper's optics + detector; see
        :func:`imgmtf.estimate.fit.fit_edges`).
    **settings
        The settings of :class:`imgmtf.estimate.settings.Settings` as
        keywords.

    Raises
    ------
    ParameterError
        An unknown method or keyword, or a setting out of its range.
        Calling the estimator raises as :func:`measure_double_bar` does.

    Examples
    --------
    >>> import imgmtf
    >>> target = imgmtf.Target("double-bar", 5.0, width_px=0.6, gap_px=1.2)
    >>> chip = imgmtf.render(imgmtf.Sensor(), target, 60)
    >>> r = imgmtf.DoubleBarEstimator()(chip.image, width_px=0.6, gap_px=1.2)
    >>> abs(r.mtf_nyquist - float(chip.true_mtf(0.5))) < 0.01
    True
    """

    def __init__(self, method: str = "msg", *, stages: str = "optics,detector", **settings: Any):
        self.settings = make_settings(method, **settings)
        self.stages = stages

    @property
    def method(self) -> str:
        return self.settings.method

    def __call__(self, image: ArrayLike, *, width_px: float | None = None, gap_px: float | None = None,
                 roi: tuple[int, int, int, int] | None = None, mask: np.ndarray | None = None,
                 gsd_m: float | None = None, saturation: tuple[float, float] | None = None,
                 dtype: DTypeLike | None = None, track_azimuth_deg: float | None = 0.0) -> DoubleBarResult:
        """Measure the double bar in ``image`` (2-D array, DN), each bar
        ``width_px`` wide, their near sides ``gap_px`` apart; see
        :func:`measure_double_bar`."""
        if width_px is None or gap_px is None:
            raise ParameterError("a double bar needs its bars' width and the gap between them "
                                 "(width_px, gap_px): neither can be read off two bars' profile")
        kind = DoubleBarKind(width_px, gap_px)
        with one_blas_thread():         # small matrices: threads cost more than they save
            m = run(kind, image, self.settings, roi=roi, mask=mask, gsd_m=gsd_m, saturation=saturation,
                    dtype=dtype, track_azimuth_deg=track_azimuth_deg)
        extra = m.shape.extra
        transfer_nyquist = float(pair_transfer(NYQUIST, kind.bar_px, kind.gap_px))
        fields = m.result_fields()
        warnings = list(m.warnings)
        measured = float(fields["mtf_nyquist"])
        fitted = model_mtf = None
        model_figures: tuple[str, ...] = ()
        if abs(transfer_nyquist) < MODEL_BELOW_TRANSFER:
            from .fit.bars import BarProfile, fit_bars
            samples = m.estimate.samples
            profile = BarProfile("the double bar", samples.distance_px - m.shape.centre, samples.values_dn,
                                 float(fields["normal_angle_deg"]), kind.bar_px, kind.gap_px,
                                 float(m.shape.low), float(m.shape.high), m.chip.quantum_dn)
            fitted = fit_bars([profile], stages=self.stages, confidence=self.settings.intervals.confidence)
            fields.update(mtf_nyquist=fitted.mtf_nyquist[0], mtf_nyquist_ci=fitted.mtf_nyquist_ci[0])
            model_figures = ("mtf_nyquist",)
            if not math.isfinite(fields["mtf50_cy_px"]):
                fields.update(mtf50_cy_px=fitted.mtf50_cy_px[0], mtf50_ci_cy_px=fitted.mtf50_ci_cy_px[0])
                model_figures += ("mtf50_cy_px",)
            model_mtf = fitted.mtf_curve(np.asarray(fields["frequencies_cy_px"], float))
            warnings.append(f"the pair's transfer at Nyquist is {abs(transfer_nyquist):.2f} in modulus (below "
                            f"{MODEL_BELOW_TRANSFER}): MTF at Nyquist read off the sensor model "
                            f"({fitted.stages}) fitted to the profile, as Storey did")
            warnings += fitted.warnings
        elif not math.isfinite(measured):
            warnings.append(f"the pair's transfer falls below {MIN_TRANSFER} near Nyquist: masked (NaN)")
        return DoubleBarResult(
            **fields, method=self.settings.method,
            params={**m.params, "pulse_width_px": kind.bar_px, "gap_px": kind.gap_px},
            polarity="bright" if extra["sign"] > 0 else "dark", warnings=tuple(warnings),
            pulse_width_px=kind.bar_px, gap_px=kind.gap_px, pair_transfer_nyquist=transfer_nyquist,
            model_fitted=fitted is not None, measured_mtf_nyquist=measured,
            model=fitted, model_mtf=model_mtf, model_figures=model_figures, prf_x_px=m.profile.grid, prf=extra["prf01"],
            prf_fwhm_px=fwhm(m.profile.grid, extra["prf01"]), background_dn=float(m.shape.low),
            peak_dn=float(m.shape.high))


def measure_double_bar(image: ArrayLike, *, width_px: float, gap_px: float,
                       roi: tuple[int, int, int, int] | None = None, mask: np.ndarray | None = None,
                       method: str = "msg", gsd_m: float | None = None,
                       saturation: tuple[float, float] | None = None, force: bool = False,
                       track_azimuth_deg: float | None = 0.0, dtype: DTypeLike | None = None,
                       stages: str = "optics,detector", **options: Any) -> DoubleBarResult:
    """Measure the MTF from a double bar (two parallel bars) in ``image``.

    Parameters
    ----------
    image : array_like
        2-D image (DN) with two parallel bars of one width, bright or dark.
    width_px : float
        Each bar's width along its normal, px.
    gap_px : float
        The gap between the bars, their near sides' distance along the
        normal, px (their centres lie ``width_px + gap_px`` apart).
    roi : (int, int, int, int), optional
        (x, y, width, height) crop, px.
    mask : ndarray of bool, optional
        Of the image's shape: True for the pixels that belong to the chip.
    method : str, optional
        "msg" (default), "sliding", "spline" or "iso".
    gsd_m : float, optional
        Ground sample distance (m), to report cycles/m and metres.
    saturation : (float, float), optional
        (low, high) DN the sensor records (default an integer image's type
        range).
    force : bool, optional
        Measure even when a quality check fails, each failure a warning.
    track_azimuth_deg : float or None, optional
        The ground track's direction, degrees clockwise from the image's
        up (0, the default: rows along track); None when unknown.
    dtype : numpy dtype, optional
        The type the values were stored as, when ``image`` is a copy.
    stages : str, optional
        The sensor model's stages fitted where the pair's transfer is near
        zero at Nyquist (default "optics,detector"; "auto" lets the data
        choose).
    **options
        As for :func:`imgmtf.measure_edge`.

    Returns
    -------
    DoubleBarResult
        The MTF along the normal (cy/px; 1 at zero frequency, the pair's
        transfer divided out), its figures with their intervals; at
        Nyquist the fitted model's where the pair's transfer hides it.

    Raises
    ------
    ParameterError, ImageContentError, TargetNotFoundError, UnsuitableTargetError
        As for :func:`imgmtf.measure_pulse`; also a width or gap that is
        not a positive number.

    Examples
    --------
    >>> import imgmtf
    >>> target = imgmtf.Target("double-bar", 5.0, width_px=1.0, gap_px=2.0)
    >>> chip = imgmtf.render(imgmtf.Sensor(), target, 60)
    >>> r = imgmtf.measure_double_bar(chip.image, width_px=1.0, gap_px=2.0)
    >>> r.model_fitted, abs(r.mtf_nyquist - float(chip.true_mtf(0.5))) < 0.01
    (True, True)
    """
    return DoubleBarEstimator(method, stages=stages, force=force, **options)(
        image, width_px=width_px, gap_px=gap_px, roi=roi, mask=mask, gsd_m=gsd_m, saturation=saturation,
        dtype=dtype, track_azimuth_deg=track_azimuth_deg)

