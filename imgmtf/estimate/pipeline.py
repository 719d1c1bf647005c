"""One profile pipeline for edges and bars.

Every estimate runs the same stages; a target kind (:class:`TargetKind`:
:class:`imgmtf.estimate.edge.EdgeKind`, :class:`imgmtf.estimate.pulse.PulseKind`)
supplies only what differs:

1. chip: validation, fill check (:mod:`imgmtf.inputs`, :mod:`.gate`);
2. seed and geometry: the kind finds its line and locates it row by row
   (an edge by a Fermi fit, a bar by centroids); a robust line through the
   locations (:mod:`.geometry`);
3. samples: every pixel's signed distance from the line and its value;
4. resample: the over-sampled profile smoothed onto a uniform grid by the
   chosen method (:mod:`.resampling`); the profile is classified as an
   edge or a bar;
5. normalise: the kind's levels (an edge's two sides, a bar's background
   and peak), the noise and SNR from the sides' scatter about their model,
   with the quantisation floor q / sqrt(12);
6. window and tails: the kind's LSF-like profile (an ESF's central
   difference, a pulse response above its background) is kept as measured
   over a core chosen from its width and the SNR; beyond it, out to the
   end of the data, it is replaced by a model fitted to each side's samples
   (level + A / |x|^p, whose LSF-like tail falls as a / x^2: the asymptote
   of every blur with a hard-edged aperture, diffraction and stray light
   among them), blended in under the window's taper.  The tails are so
   kept whole without their noise; a blur without tails fits a = 0;
7. divide: the transform divided by the transfer of everything between
   the system's LSF and that profile (the kind's: the central difference or
   the bar's sinc, times the resampling method's);
8. figures, quality gate and intervals (:mod:`.spectrum`, :mod:`.gate`,
   :mod:`.intervals`).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from .._stats import t_quantile
from ..errors import ImgmtfError, ParameterError, TargetNotFoundError, UnsuitableTargetError
from ..inputs import as_array, check_number, prepare_image, quantum, saturation_levels
from ..metrics import fwhm
from ..transfer import Transfer, full_scale, parse_transfer
from . import gate
from .detection import Line, robust_noise
from .evidence import Evidence
from .geometry import (
    EDGE_FIT_HALF_WINDOW_PX,
    TargetGeometry,
    check_angle,
    direction_label,
    profile_samples,
    row_windows,
    vertical_frame,
)
from .intervals import (
    Interval,
    Intervals,
    as_intervals,
    bootstrap_figures,
    influence_sd,
    influence_sds,
    linearised_interval,
)
from .outliers import isolated_outliers
from .profile_checks import run_profile_checks
from .quantisation import dequantise
from .resampling import METHODS, check_method, resample_profile
from .spectrum import (
    MIN_TRANSFER,
    NYQUIST,
    corrected_mtf,
    flat_top_window,
    mtf50,
    mtf_area,
    noise_limited_frequency,
    restore_lsf,
    white_noise_mtf_sd,
)

DEFAULT_FREQUENCIES = np.round(np.arange(0.0, 1.0 + 1e-9, 0.01), 10)
STEP_RANGE_PX = (0.005, 0.25)     # finer costs time for nothing; coarser misses the LSF's shape
MAX_FREQUENCY_CY_PX = 4.0
TAPER_FACTOR = 1.0                # the window's raised-cosine taper, in units of its flat half-width
TAIL_FIT_MAX_START = 0.6          # the tail fit starts at most this far out, as a fraction of the range
MIN_TAIL_SAMPLES = 12
LONG_TAIL_SHARE = 0.03            # tails beyond the core holding more of the signal keep the clean window
INITIAL_SPAN_PX = 16.0            # the profile is first resampled this far from the line
CORE_STEP_PX = 0.5                # the core grows in these steps while the tail model misfits
MODEL_CHECK_PX = 3.0              # the model must explain this much of the profile past the core
MODEL_BIN_PX = 0.5
# The estimator's own error where noise is not the whole error, added in
# quadrature to the interval: on exact chips the worst error at Nyquist is
# about 0.0005 for Gaussian-type blurs; the tail model's share of the
# signal is uncertain to about a tenth of itself.
SYSTEMATIC_NYQUIST = 0.0008
SYSTEMATIC_MTF50 = 0.001          # relative
TAIL_MODEL_UNCERTAINTY = 0.1
# A rebuilt staircase (a noise-free quantised edge) is off by up to 0.01 at
# Nyquist and 0.5 % in MTF50 on 12-30 DN edges, and its residuals are nil
SYSTEMATIC_DEQUANTISED = 0.005
SYSTEMATIC_DEQUANTISED_MTF50 = 0.003      # relative
# The window narrowed for noise cuts the LSF a little: at its narrowest (a
# third narrower) MTF50 reads about 1 % and MTF at Nyquist 0.002 high
NARROW_WINDOW_NYQUIST = 0.009
NARROW_WINDOW_MTF50 = 0.03                # relative
LEVERAGE_CAP = 0.9
BACKGROUND_FRACTION = 2.0 / 3.0   # a bar's background is read from the samples beyond this share of the range
WIDTH_SHARE_WARNING = 0.5         # an estimated width making more of the variance at Nyquist is worth a warning
MASK_SCAN_STEP_CY_PX = 0.005      # where a divisor's zeros hide the MTF is looked for on this grid, to 2 cy/px


@dataclass(frozen=True, eq=False)
class Settings:
    """How an over-sampled-profile estimator measures (shared by edges and
    bars).

    Parameters
    ----------
    method : str
        Resampling method, a key of :data:`imgmtf.estimate.resampling.METHODS`
        ("msg", "sliding", "spline", "iso").
    step_px : float
        Resampled profile grid step (px), 0.005 to 0.25; "iso" always uses
        its 1/4-px bins.
    correct : bool
        Divide out the blur of the estimator's own steps.  False
        reproduces the uncorrected classic algorithms.
    frequencies_cy_px : array_like
        Where the reported MTF curve is sampled (cy/px, 0 to 4).
    snr_threshold : float or None
        Below this SNR the result carries a warning; None uses the
        measured threshold for the target's length.
    method_options : dict
        Overrides of the method's defaults (e.g. ``window_px``).
    lsf_half_width_px : float or None
        Half-width of the flat core of the LSF window (px); None chooses
        it from the target's width and the SNR.
    lsf_window_factor : float or None
        That half-width in units of the 10-90 % rise (edges); None adapts
        it to the SNR.
    intervals : Intervals or str or int
        Confidence-interval settings (:class:`imgmtf.estimate.intervals.Intervals`),
        or a method's name as ``--intervals`` takes it ("influence",
        "bootstrap", "none"), or a number of bootstrap replicates (0: none).
    force : bool
        Measure even when a quality check fails (each failure becomes a
        warning) instead of refusing.
    transfer : str or Transfer
        How the stored values relate to light (:mod:`imgmtf.transfer`):
        "linear" (default: as stored), "srgb" or "gamma:G"; the values are
        linearised before measuring.

    Raises
    ------
    ParameterError
        For any value out of its range or of the wrong kind.
    """

    method: str = "msg"
    step_px: float = 0.05
    correct: bool = True
    frequencies_cy_px: np.ndarray = field(default_factory=lambda: DEFAULT_FREQUENCIES)
    snr_threshold: float | None = None
    method_options: dict = field(default_factory=dict)
    lsf_half_width_px: float | None = None
    lsf_window_factor: float | None = None
    intervals: Intervals = field(default_factory=Intervals)
    force: bool = False
    transfer: Transfer = field(default_factory=Transfer)

    def __post_init__(self):
        check_method(self.method)
        set_ = object.__setattr__
        set_(self, "step_px", check_number("step_px", self.step_px, low=STEP_RANGE_PX[0], high=STEP_RANGE_PX[1]))
        if not isinstance(self.correct, (bool, np.bool_)):
            raise ParameterError(f"correct must be True or False, got {self.correct!r}")
        try:
            f = np.asarray(self.frequencies_cy_px, float).ravel()
        except (TypeError, ValueError):
            raise ParameterError(f"frequencies_cy_px must be numbers, got {self.frequencies_cy_px!r}") from None
        if f.size == 0 or not np.all(np.isfinite(f)) or f.min() < 0 or f.max() > MAX_FREQUENCY_CY_PX:
            raise ParameterError(f"frequencies_cy_px must be finite, in [0, {MAX_FREQUENCY_CY_PX:g}] cy/px")
        set_(self, "frequencies_cy_px", f)
        if self.snr_threshold is not None:
            set_(self, "snr_threshold", check_number("snr_threshold", self.snr_threshold, positive=True))
        if not isinstance(self.method_options, dict):
            raise ParameterError(f"method_options must be a dict, got {self.method_options!r}")
        _check_method_options(self.method, self.method_options)
        if self.lsf_half_width_px is not None:
            set_(self, "lsf_half_width_px", check_number("lsf_half_width_px", self.lsf_half_width_px,
                                                         low=0.5, high=64.0))
        if self.lsf_window_factor is not None:
            set_(self, "lsf_window_factor", check_number("lsf_window_factor", self.lsf_window_factor,
                                                         low=0.5, high=10.0))
        set_(self, "intervals", as_intervals(self.intervals))
        if not isinstance(self.force, (bool, np.bool_)):
            raise ParameterError(f"force must be True or False, got {self.force!r}")
        set_(self, "transfer", parse_transfer(self.transfer))

    def as_dict(self) -> dict:
        out = {"method": self.method, "step_px": self.step_px, "correct": self.correct,
               "intervals": self.intervals.as_dict(), "force": self.force, "transfer": str(self.transfer)}
        for key in ("snr_threshold", "lsf_half_width_px", "lsf_window_factor"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        if self.method_options:
            out["method_options"] = dict(self.method_options)
        return out


def _check_method_options(method: str, options: dict) -> None:
    """Bounds of the resampling methods' options (unknown names are the
    dispatcher's to refuse)."""
    bounds = {"window_px": (0.05, 8.0), "order": (0, 8), "cutoff_cy_px": (0.1, 20.0), "bin_px": (0.02, 1.0)}
    for name, value in options.items():
        if name in bounds:
            low, high = bounds[name]
            check_number(name, value, low=low, high=high, integer=name == "order")
    unknown = set(options) - set(METHODS[method].defaults)
    if unknown:
        raise ParameterError(f"method {method!r} takes no option(s) {', '.join(sorted(unknown))}; "
                             f"it takes {', '.join(METHODS[method].defaults)}")


def make_settings(method: str = "msg", *, bootstrap=None, **options) -> Settings:
    """:class:`Settings` from keywords, with ``bootstrap=N`` meaning N
    bootstrap replicates (0: no intervals) and unknown keywords refused by
    name."""
    known = set(Settings.__dataclass_fields__)
    unknown = sorted(set(options) - known)
    if unknown:
        raise ParameterError(f"unknown option(s) {', '.join(unknown)}; valid: bootstrap, "
                             f"{', '.join(sorted(known - {'method'}))}")
    if bootstrap is not None:
        if "intervals" in options:
            raise ParameterError("give intervals= or bootstrap=, not both")
        options["intervals"] = as_intervals(bootstrap)
    return Settings(method, **options)


class TargetKind:
    """What differs between targets; see :class:`imgmtf.estimate.edge.EdgeKind`
    and :class:`imgmtf.estimate.pulse.PulseKind`, the two implementations.

    Attributes: ``name`` is the target as a user names it ("edge", "bar");
    ``profile`` what its profile must look like
    (:func:`.gate.classify_profile`); ``tail_power`` p of its profile's
    tails, level + A / |s|^p; ``monotone`` whether the profile only rises
    (a staircase can then be rebuilt, :mod:`.quantisation`);
    ``subtracts_background`` whether its LSF-like profile is the profile
    above a fitted background (a bar) rather than a derivative (an edge);
    ``restore_min_divisor`` the divisor below which the recovered LSF's
    spectrum is bridged rather than divided.
    """

    name: ClassVar[str]
    profile: ClassVar[str]
    tail_power: ClassVar[int]
    monotone: ClassVar[bool]
    subtracts_background: ClassVar[bool]
    restore_min_divisor: ClassVar[float]

    def seed(self, data: np.ndarray, noise: float) -> tuple[Line, list[gate.Check]]:
        """The target's line in the chip and the gate's checks of what else
        was found, the chip's pixel noise being ``noise`` (DN)."""
        raise NotImplementedError

    def locate(self, work: np.ndarray, seed_x: np.ndarray, transposed: bool) -> TargetGeometry:
        """The target's line fitted through its per-row locations."""
        raise NotImplementedError

    def shape(self, grid: np.ndarray, values: np.ndarray, d: np.ndarray, v: np.ndarray,
              half_range: float) -> Shape:
        """What the resampled profile (and its samples) say of the target."""
        raise NotImplementedError

    def core_px(self, shape: Shape, snr: float, factor: float | None) -> float:
        """The LSF window's flat half-width at this SNR (``factor``: a
        user's multiple of the target's width)."""
        raise NotImplementedError

    def taper_factor(self, snr: float) -> float:
        """The window's taper as a multiple of its core."""
        raise NotImplementedError

    def confident_snr(self, rows: int) -> float:
        """The SNR below which the estimate carries a warning."""
        raise NotImplementedError

    def lsf(self, grid: np.ndarray, values: np.ndarray,
            background) -> tuple[np.ndarray, np.ndarray, Callable[[np.ndarray], np.ndarray]]:
        """(x, lsf, adjoint): the LSF-like profile on ``x`` and the map of
        weights on ``x`` back to weights on ``grid``."""
        raise NotImplementedError

    def lsf_tail_amplitudes(self) -> list[np.ndarray]:
        """Per side (left, right), the linear map from that side's fitted
        (level, A) to the LSF-like tail's amplitude a (a / s^2)."""
        raise NotImplementedError

    def divisor(self, step: float, transfer, shape: Shape) -> Callable[[np.ndarray], np.ndarray]:
        """The transfer between the system's LSF and the LSF-like profile."""
        raise NotImplementedError

    def noise_gain(self, shape: Shape, contrast: float) -> Callable[[np.ndarray], np.ndarray]:
        """How white sample noise grows with frequency in the MTF."""
        raise NotImplementedError

    def saturation_sides(self, sides: list) -> list:
        """The sides the saturation checks examine, named for the user."""
        raise NotImplementedError

    def peak_mask(self, s: np.ndarray, shape: Shape) -> np.ndarray | None:
        """The samples of a bar's peak (None for an edge)."""
        raise NotImplementedError

    def read_width(self, grid: np.ndarray, shape: Shape) -> WidthReading | None:
        """Where the divisor rests on a width read off the profile (a bar's
        estimated width), how it was read (:class:`WidthReading`), so that
        its own noise joins the intervals; None where the divisor is known."""
        return None


@dataclass(frozen=True, eq=False)
class WidthReading:
    """A width W (px) read off the profile as the first zero f0 = 1 / W of
    R(f), a linear functional of the profile's values (a bar's spectrum
    about its centre).  ``freqs`` (cy/px): f0, then a grid about it;
    ``on_grid``: dR(f) / d value, one row per frequency over the profile's
    grid; ``per_background``: dR(f) / d background level; ``values``: R at
    ``freqs``; ``slope``: R'(f0); ``log_slope(f)``: d ln|divisor(f)| / dW."""

    width_px: float
    freqs: np.ndarray
    on_grid: np.ndarray
    per_background: np.ndarray
    values: np.ndarray
    slope: float
    log_slope: Callable[[np.ndarray], np.ndarray]

    def width_change(self, spectrum_change_at_zero):
        """The change of W (px) a change dR of R at f0 makes: the zero moves
        by -dR / R'(f0), and W = 1 / f0 by dR / (R'(f0) f0^2)."""
        f_zero = float(self.freqs[0])
        return spectrum_change_at_zero / (self.slope * f_zero * f_zero)

    def spread_px(self, spectrum_sd: np.ndarray, t: float) -> float:
        """Half the width (px) of the set of W whose zero 1 / W the data
        cannot tell from f0: the run of the grid about f0 where
        |R(f)| <= t sd(R(f)) (Fieller's interval for a zero, which stays
        honest where R is shallow and the linearised one is not); inf when
        the run reaches the grid's low end (no zero is read at all)."""
        f, margin = self.freqs[1:], t * spectrum_sd - np.abs(self.values[1:])
        inside = margin >= 0
        k = int(np.clip(np.searchsorted(f, self.freqs[0]), 1, f.size - 1))
        k = k if inside[k] else k - 1
        if not inside[k]:
            return 0.0
        outside = np.flatnonzero(~inside)
        below, above = outside[outside < k], outside[outside > k]
        if below.size == 0:
            return math.inf

        def edge(i, j):      # where the margin crosses 0 between grid points i (inside) and j (outside)
            return f[i] + (f[j] - f[i]) * margin[i] / (margin[i] - margin[j])
        f_low = edge(below[-1] + 1, below[-1])
        f_high = edge(above[0] - 1, above[0]) if above.size else f[-1]
        return 0.5 * (1.0 / f_low - 1.0 / f_high)


@dataclass(frozen=True)
class Shape:
    """What a kind reads off its resampled profile: ``centre`` (px, the
    target's middle along the normal), ``scale_px`` (its width: an edge's
    10-90 % rise, a bar's half-width at 10 %), the reference levels
    ``low``/``high`` (DN: an edge's left and right, a bar's background and
    peak), the ``core_px`` the LSF window keeps flat at the given SNR
    factor, where the ``plateau_px`` sides begin, and ``extra`` figures."""

    centre: float
    scale_px: float
    low: float
    high: float
    plateau_px: float
    extra: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class SideFit:
    """Level + A / |s|^p fitted to one side's samples: ``coef`` (level, A),
    ``operator`` the least-squares map from the selected samples' values to
    ``coef`` (2 x n), ``mask`` which samples, ``sd`` the residual standard
    deviation (DN)."""

    coef: np.ndarray
    operator: np.ndarray
    mask: np.ndarray
    sd: float


def _tail_integral(s, v, side: int, start: float, half_range: float, kind) -> tuple[float, float]:
    """Area (DN px) of one side's fitted LSF-like tail a / s^2 from ``start``
    to the data's reach, a (1 / start - 1 / reach), and its standard error."""
    fit = fit_side(s, v, (np.sign(s) == side) & (np.abs(s) >= start), kind.tail_power)
    if not np.isfinite(fit.coef).all() or not math.isfinite(fit.sd):
        return 0.0, math.inf
    to_amplitude = kind.lsf_tail_amplitudes()[0 if side < 0 else 1]
    span = 1.0 / start - 1.0 / max(half_range, start)
    amplitude_sd = fit.sd * math.sqrt(float(np.sum((to_amplitude @ fit.operator) ** 2)))
    return float(to_amplitude @ fit.coef) * span, amplitude_sd * span


def refuse_other_kind(kind: TargetKind, work: np.ndarray, seed_x: np.ndarray) -> None:
    """Where the target could not be followed row by row (a bar defeats an
    edge's step fits, and leaves its phases too sparse), the rows' mean
    profile about the seed says whether it is the other kind of target:
    that is the reason to give (``not-an-edge``, ``not-a-bar``), or, where
    the whole rows hold a step and a bar, the second target
    (``two-targets``).

    Raises
    ------
    UnsuitableTargetError
        The mean profile is of the other kind."""
    _, values, inside = row_windows(work, seed_x, EDGE_FIT_HALF_WINDOW_PX)
    counts = inside.sum(axis=0)
    if counts.min() > 0:
        mean = values.sum(axis=0) / counts
        check = gate.kind_check(gate.classify_profile(mean), kind.profile, mean)
        if not check.passed:
            # the whole rows say whether the other kind stands beside a target of the wanted kind
            _, wide, wide_inside = row_windows(work, seed_x, work.shape[1])
            wide_counts = wide_inside.sum(axis=0)
            covered = wide_counts >= 0.5 * work.shape[0]
            if covered.sum() > 2 * EDGE_FIT_HALF_WINDOW_PX + 1:
                whole = wide.sum(axis=0)[covered] / wide_counts[covered]
                check = gate.kind_check(gate.classify_profile(mean), kind.profile, whole)
            raise UnsuitableTargetError(check.message, reason=check.reason) from None


def outer_samples(d: np.ndarray, half_range: float, fraction: float) -> tuple[np.ndarray, np.ndarray]:
    """Masks of the samples beyond ``fraction`` of the range on the left
    and on the right (at least the three outermost pixels' worth each)."""
    order = np.sort(d)
    left = min(-fraction * half_range, order[min(order.size - 1, 3 * MIN_TAIL_SAMPLES)])
    right = max(fraction * half_range, order[max(0, order.size - 1 - 3 * MIN_TAIL_SAMPLES)])
    return d <= left, d >= right


def fit_side(s: np.ndarray, v: np.ndarray, mask: np.ndarray, power: int) -> SideFit:
    """Least-squares level and tail of the samples selected by ``mask``
    (``s``: distance from the target's centre).  Too few samples, or too
    little spread in |s|^-p to tell a tail from a level: a flat level."""
    x = np.abs(s[mask])
    values = v[mask]
    if x.size < 3:
        return SideFit(np.array([np.nan, 0.0]), np.zeros((2, x.size)), mask, math.nan)
    u = x ** -float(power)
    if x.size >= MIN_TAIL_SAMPLES and np.std(u) > 1e-3 * np.mean(u):
        design = np.column_stack([np.ones_like(u), u])
        operator = np.linalg.solve(design.T @ design, design.T)
    else:
        design = np.ones((x.size, 1))
        operator = np.vstack([np.full(x.size, 1.0 / x.size), np.zeros(x.size)])
    coef = operator @ values
    resid = values - np.column_stack([np.ones_like(u), u]) @ coef
    dof = max(x.size - design.shape[1], 1)
    return SideFit(coef, operator, mask, float(math.sqrt(resid @ resid / dof)))


def model_reach(s: np.ndarray, v: np.ndarray, side: int, start: float, power: int, step: float,
                floor: float = 0.0) -> float:
    """Where a side's tail model takes over: the smallest distance from
    ``start`` on (in ``step`` px steps, at most half the side's range) from
    which level + A / |s|^p, fitted out to the end of the data, explains the
    next few pixels to within their noise.  Before it the LSF still carries
    structure of its own (a shoulder, a halo) that the window must keep as
    measured; at low SNR the test has little power and the core stays at
    ``start``.  ``floor`` (DN) is a part of each bin's error that does not
    average down (rounding shared by neighbouring samples)."""
    reach = np.abs(s[np.sign(s) == side])
    values = v[np.sign(s) == side]
    if reach.size < 4 * MIN_TAIL_SAMPLES:
        return start
    far = float(reach.max())
    x0 = start
    while x0 <= 0.5 * far:
        fit = fit_side(reach, values, reach >= x0, power)
        near = (reach >= x0) & (reach < x0 + MODEL_CHECK_PX)
        if not math.isfinite(fit.sd) or fit.sd == 0 or near.sum() < MIN_TAIL_SAMPLES:
            return x0
        u = reach[near] ** -float(power)
        resid = values[near] - (fit.coef[0] + fit.coef[1] * u)
        bins = np.floor((reach[near] - x0) / MODEL_BIN_PX).astype(int)
        counts = np.bincount(bins)
        full = counts >= 3
        means = np.bincount(bins, weights=resid)[full] / counts[full]
        chi2 = float(np.sum(means ** 2 / (fit.sd ** 2 / counts[full] + floor ** 2)))
        dof = int(full.sum())
        if dof == 0 or chi2 <= dof + 3.0 * math.sqrt(2.0 * dof):
            return x0
        x0 += step
    return x0


@dataclass(frozen=True)
class Measurement:
    """The pipeline's output, which each kind turns into its result type."""

    figures: dict
    arrays: dict
    checks: tuple
    warnings: tuple
    params: dict

    def result_fields(self) -> dict:
        """The :class:`.results.MTFResult` fields every kind fills alike;
        the kind adds ``method``, ``params``, ``polarity``, ``warnings`` and
        its own."""
        f, a = self.figures, self.arrays
        return dict(
            normal_angle_deg=f["normal_angle_deg"], tilt_deg=f["tilt_deg"], direction=f["direction"],
            orientation=f["orientation"], rows_used=f["rows_used"], rows_total=f["rows_total"], snr=f["snr"],
            noise_dn=f["noise_dn"], mtf_nyquist=f["mtf_nyquist"], mtf50_cy_px=f["mtf50_cy_px"],
            mtf_nyquist_ci=f["mtf_nyquist_ci"], mtf50_ci_cy_px=f["mtf50_ci_cy_px"], fwhm_px=f["fwhm_px"],
            mtfa=f["mtfa"], gsd_m=f["gsd_m"], frequencies_cy_px=a["frequencies"], mtf=a["mtf"],
            lsf_x_px=a["lsf_x"], lsf=a["lsf"], samples_x_px=a["samples_x"], samples_dn=a["samples_dn"],
            geometry=a["geometry"], roi=f["roi"], noise_limit_cy_px=f["noise_limit_cy_px"],
            lsf_half_width_px=f["lsf_half_width_px"], tail_fraction=f["tail_fraction"], checks=self.checks,
            mtf_function=a["mtf_function"])


def run(kind: TargetKind, image, settings: Settings, *, roi=None, mask=None, gsd_m=None, saturation=None,
        dtype=None, track_azimuth_deg: float | None = 0.0) -> Measurement:
    """Measure the target of ``kind`` in ``image`` (2-D array, DN).

    Parameters
    ----------
    roi : (x, y, width, height) crop, px, or None.
    mask : boolean array of the image's shape, True for the pixels that
        belong to the chip (a tilted ROI, a target cut out of its fill);
        None for all.
    gsd_m : ground sample distance (m) or None.
    saturation : (low, high) DN the sensor records, or None for an
        integer image's type range (floats: none declared).
    dtype : the type the values were stored as when ``image`` is a float
        copy (a file's samples), for quantisation and integer limits.
    track_azimuth_deg : direction of the ground track in the image,
        degrees clockwise from the image's up direction (0: rows along
        track, as in L0/L1 products); None when unknown (map-projected).

    Raises
    ------
    ImgmtfError
        Every refusal: unusable input, no target, a failed quality check.
    """
    array = as_array(image)
    stored = np.dtype(dtype) if dtype is not None else array.dtype
    data, (x0, y0) = prepare_image(array, roi, mask)
    gsd_m = None if gsd_m is None else check_number("gsd_m", gsd_m, positive=True)
    if track_azimuth_deg is not None:
        track_azimuth_deg = check_number("track_azimuth_deg", track_azimuth_deg, signed=True)
    limits = _saturation(saturation) if saturation is not None else saturation_levels(stored)
    decoded = []
    if not settings.transfer.is_linear:
        # linear light in the same DN scale; the type's limits stay put, its
        # quantum does not (the decoded steps are uneven)
        scale = full_scale(stored)
        data = settings.transfer.linearise(data, scale)
        limits = None if limits is None else (float(settings.transfer.linearise(np.array(limits[0]), scale)),
                                              float(settings.transfer.linearise(np.array(limits[1]), scale)))
        stored = np.dtype(np.float64)
        decoded.append(f"the values were linearised ({settings.transfer}, full scale {scale:g} DN) before "
                       "measuring")
    q = quantum(data, stored)
    checks = [gate.fill_check(data, stored)]
    pixel_noise = robust_noise(data)
    rows, cols = data.shape
    chosen = None if mask is None else np.asarray(mask)[y0:y0 + rows, x0:x0 + cols]
    left_out = _left_out_pixels(data, chosen, pixel_noise)

    try:
        line, seed_checks = kind.seed(data, pixel_noise)
        checks += seed_checks
        work, seed_x, transposed = vertical_frame(data, line)
        try:
            geometry = kind.locate(work, seed_x, transposed)
            check_angle(geometry, kind.name)
            d, v, row, half_range = profile_samples(work, geometry, kind.name)
        except (TargetNotFoundError, UnsuitableTargetError):
            refuse_other_kind(kind, work, seed_x)
            raise
    except ImgmtfError:
        # what the gate already knows (fill, a second target) explains more
        # than the failure it caused further on
        if not settings.force:
            gate.enforce(checks, force=False)
        raise
    rows_used = int(geometry.kept.sum())
    checks += gate.line_checks(geometry, geometry.location_sd_px, kind.name)
    checks.append(gate.rows_check(rows_used, kind.name))

    # the values the profile is built from: a noise-free quantised edge's
    # staircase rebuilt as the smooth ESF it samples; the gate reads the raw ones
    rebuilt = dequantise(d, v, q) if kind.monotone else None
    raw, v = v, (v if rebuilt is None else rebuilt)
    # the profile is resampled where the LSF window needs data: a central
    # span first, widened below if the window's core and taper reach past it
    reach = half_range - 0.6

    def resample(span_px):
        r = resample_profile(d, v, method=settings.method, step=settings.step_px, half_range=span_px,
                             **settings.method_options)
        return (r, *_central_run(r.grid, r.values, kind.name))
    try:
        resampled, grid, values, span = resample(min(reach, INITIAL_SPAN_PX))
        kind_check = gate.kind_check(gate.classify_profile(values), kind.profile, values)
        if not kind_check.passed:
            raise UnsuitableTargetError(kind_check.message, reason=kind_check.reason)
        try:
            shape = kind.shape(grid, values, d, v, half_range)
        except UnsuitableTargetError:
            if grid[-1] >= reach - settings.step_px:
                raise
            # a profile still rising at the span's end (a drifting level): all of it
            resampled, grid, values, span = resample(reach)
            shape = kind.shape(grid, values, d, v, half_range)
    except ImgmtfError:
        if not settings.force:       # fill or a second target explain the profile's shape
            gate.enforce([c for c in checks if c.reason in ("fill", "two-targets")], force=False)
        raise
    c = shape.centre
    s = d - c
    # the samples' pull on a width read off this profile (see TargetKind.read_width)
    width_influence = None
    reading = kind.read_width(grid, shape)
    if reading is not None and resampled.adjoint is not None:
        def spectrum_pull(reading=reading, resampled=resampled, span=span):
            """dR(f) / dv for the reading's frequencies, through the
            resampling the width was read from (built only for intervals)."""
            full = np.zeros((reading.freqs.size, resampled.grid.size))
            full[:, span[0]: span[1]] = reading.on_grid
            pull = resampled.adjoint(full)
            for side in outer_samples(d, half_range, BACKGROUND_FRACTION):
                pull[:, side] += 0.5 * reading.per_background[:, None] / max(int(side.sum()), 1)
            return pull
        width_influence = (reading, spectrum_pull)

    # noise and SNR: each side's scatter about its own level and tail
    plateau = [fit_side(s, v, side & (np.abs(s) >= shape.plateau_px), kind.tail_power)
               for side in (s < 0, s > 0)]
    side_sd = [p.sd for p in plateau if math.isfinite(p.sd)]
    noise = max(float(np.mean(side_sd)) if side_sd else math.nan, q / math.sqrt(12.0))
    contrast = abs(shape.high - shape.low)
    snr = contrast / noise if noise > 0 else math.inf
    if not math.isfinite(noise):
        snr = math.nan
    threshold = settings.snr_threshold or kind.confident_snr(rows_used)

    # the LSF window's core and taper, and the tails beyond them
    core = settings.lsf_half_width_px or kind.core_px(shape, snr, settings.lsf_window_factor)
    if settings.lsf_half_width_px is None and settings.lsf_window_factor is None:
        # a noise-free quantised profile rounds neighbouring samples alike:
        # its residuals do not average down below the rounding's own q / sqrt(12)
        floor = q / math.sqrt(12.0) if noise < 0.5 * q else 0.0
        core = max(core, max(model_reach(s, v, side, core, kind.tail_power, CORE_STEP_PX, floor)
                             for side in (-1, 1)))
    taper_snr = snr
    if settings.lsf_half_width_px is None and settings.lsf_window_factor is None:
        # a long tail (diffraction, a real lens) is the model's weakest part
        # near the core: there the narrow low-SNR window costs more bias than
        # it saves noise, so such a profile (one whose tails stand out of
        # their own noise) keeps the clean window
        tails = [_tail_integral(s, v, side, core, half_range, kind) for side in (-1, 1)]
        share = sum(abs(area) for area, _ in tails) / contrast
        share_sd = math.hypot(*(sd for _, sd in tails)) / contrast
        if share > LONG_TAIL_SHARE and share > 3.0 * share_sd:
            core = max(core, kind.core_px(shape, math.inf, None))
            taper_snr = math.inf
    taper = kind.taper_factor(taper_snr) * core if settings.lsf_half_width_px is None else TAPER_FACTOR * core
    # how much narrower than the clean window the noise made it: its truncation bias joins the budget
    narrowed = max(0.0, 1.0 - core / kind.core_px(shape, math.inf, None))
    cut = settings.lsf_half_width_px is not None and settings.lsf_half_width_px < shape.scale_px
    window_end = abs(c) + core + taper + 3.0 * settings.step_px
    if window_end > min(-grid[0], grid[-1]) and grid[-1] < reach - settings.step_px:
        resampled, grid, values, span = resample(min(reach, window_end + 1.0))
    start = [min(core, TAIL_FIT_MAX_START * (half_range + c)), min(core, TAIL_FIT_MAX_START * (half_range - c))]
    sides = [fit_side(s, v, (s <= -start[0]), kind.tail_power), fit_side(s, v, (s >= start[1]), kind.tail_power)]
    if any(not np.isfinite(sf.coef).all() for sf in sides):
        raise UnsuitableTargetError(f"a side of the {kind.name} holds too few samples for its level")
    background = 0.5 * (sides[0].coef[0] + sides[1].coef[0])
    x_data, lsf_data, lsf_adjoint = kind.lsf(grid, values, background)
    step = float(grid[1] - grid[0])
    # the LSF-like profile out to the data's reach: measured within the
    # window, the tail model beyond it (the same lattice as the grid)
    x = np.arange(-np.floor(reach / step), np.floor(reach / step) + 1) * step
    data_at = slice(int(round((x_data[0] - x[0]) / step)), int(round((x_data[0] - x[0]) / step)) + x_data.size)
    lsf = np.zeros_like(x)
    lsf[data_at] = lsf_data
    in_data = np.zeros(x.size, bool)
    in_data[data_at] = True
    to_amplitude = kind.lsf_tail_amplitudes()
    amplitudes = [float(to_amplitude[i] @ sides[i].coef) for i in range(2)]
    w = flat_top_window(x, c, core, taper) * in_data
    sx = x - c
    tail_shape = np.where(np.abs(sx) > 1e-9, 1.0 / np.maximum(sx * sx, 1e-18), 0.0)
    model = np.where(sx < 0, amplitudes[0], amplitudes[1]) * tail_shape
    combined: np.ndarray = w * lsf + (1.0 - w) * model
    divisor = kind.divisor(step, resampled.transfer if settings.correct else None, shape)
    mtf = corrected_mtf(combined, step, divisor)
    total = float(np.sum(combined) * step)
    if total == 0 or not math.isfinite(total):
        raise UnsuitableTargetError(f"the {kind.name}'s profile has no net signal")
    tail_share = float(np.sum((1.0 - w) * model) * step) / total

    density = d.size / (2.0 * half_range)
    white = white_noise_mtf_sd(snr, 2.0 * core + taper, density, kind.noise_gain(shape, contrast))

    def noise_sd(f):
        # the noise is divided by the corrections as the MTF is
        f = np.atleast_1d(np.asarray(f, float))
        return white(f) / np.maximum(np.abs(divisor(f) / divisor(np.zeros(1))), MIN_TRANSFER)
    noise_limit = noise_limited_frequency(mtf, noise_sd)
    x_c, lsf_c = restore_lsf(combined, x, divisor, noise_limit, min_divisor=kind.restore_min_divisor)
    mtf_nyquist = float(mtf(np.array([NYQUIST]))[0])
    f50 = mtf50(mtf)

    # the gate
    side_masks = [("dark" if (shape.low <= shape.high) == (i == 0) else "bright", m, None)
                  for i, m in enumerate((s <= -shape.plateau_px, s >= shape.plateau_px))]
    checks += gate.saturation_checks(d, raw, c, shape.scale_px, kind.saturation_sides(side_masks), limits, q,
                                     noise_free=noise <= max(1.5 * q / math.sqrt(12.0), 1e-9 * contrast),
                                     bright_core=kind.peak_mask(s, shape), monotone=kind.monotone,
                                     contrast=contrast, bar_edge_px=None if shape.extra.get("width_estimated", True)
                                     else 0.5 * shape.extra["width_px"])
    checks += gate.side_checks(d, raw, row.astype(float), c, shape.plateau_px, contrast,
                               pixel_noise, kind.tail_power)
    snr_failures, snr_warnings = gate.snr_checks(snr, threshold, rows_used, kind.name)
    checks += snr_failures
    checks.append(gate.mtf_excess_check(mtf, noise_sd, noise_limit))
    fwhm_px = fwhm(x_c, lsf_c)
    # where a divisor's zeros hide the MTF (a bar's sinc), a figure there is rightly missing
    f_check = np.arange(0.0, 2.0, MASK_SCAN_STEP_CY_PX)
    hidden = np.abs(divisor(f_check) / divisor(np.zeros(1))) < MIN_TRANSFER
    first_hidden = f_check[np.argmax(hidden)] if hidden.any() else math.inf
    checks.append(gate.figures_check(
        mtf_nyquist, f50, fwhm_px, nyquist_masked=bool(hidden[int(round(NYQUIST / MASK_SCAN_STEP_CY_PX))]),
        mtf50_masked=math.isfinite(first_hidden) and float(mtf(np.array([first_hidden - 0.01]))[0]) > 0.5))
    # the registered checks come last: a failure above (a sharpened halo) names the cause better
    side_names = tuple(name for name, _, _ in kind.saturation_sides(side_masks))
    profile_checks, profile_warnings = run_profile_checks(Evidence(
        d, raw, row, c, shape.scale_px, shape.plateau_px, shape.low, shape.high, noise, q, kind.tail_power,
        kind.name, kind.profile, (side_names[0], side_names[1]), geometry))
    checks += profile_checks
    warnings = list(gate.enforce(checks, settings.force)) + snr_warnings + profile_warnings + left_out[1] + decoded
    if cut:
        warnings.append(f"the LSF window's core ({core:.2f} px) is narrower than the {kind.name}'s width "
                        f"({shape.scale_px:.2f} px): it cuts the LSF, and the MTF reads high")

    # intervals
    nyquist_ci = mtf50_ci = Interval.none()
    if settings.intervals.method == "influence":
        nyquist_ci, mtf50_ci, width_share = _influence_intervals(
            settings.intervals, mtf, mtf_nyquist, f50, resampled, span, x, data_at, lsf, c, w, lsf_adjoint,
            tail_shape, sides, to_amplitude, amplitudes, kind, d, v, row, tail_share, rebuilt is not None,
            narrowed, width_influence)
        if width_share is not None and width_share > WIDTH_SHARE_WARNING:
            warnings.append(
                f"the bar's width, read off its profile ({shape.extra['width_px']:.3f} px), is uncertain "
                f"enough to make {100 * width_share:.0f} % of the variance at Nyquist: give the width "
                "if it is known (--pulse-width, width_px=)")
    elif settings.intervals.method == "bootstrap":
        if width_influence is not None:
            warnings.append(f"the bootstrap holds the bar's width ({shape.extra['width_px']:.3f} px, read "
                            "off its profile) fixed, so its intervals leave out the width's uncertainty: "
                            "give the width if it is known, or use the default (influence) intervals")
        nyquist_ci, mtf50_ci = _bootstrap_intervals(
            settings, kind, d, v, row, c, core, taper, start, divisor, x, float(grid[-1]))
    # an MTF (a modulus) and a frequency are never negative: ends below 0 are raised to 0 (docs/method.md)
    nyquist_ci, mtf50_ci = nyquist_ci.clipped_at_zero(), mtf50_ci.clipped_at_zero()

    figures = dict(
        normal_angle_deg=_normal_angle(geometry), tilt_deg=geometry.tilt_deg,
        direction=direction_label(_normal_angle(geometry), track_azimuth_deg),
        orientation="horizontal" if transposed else "vertical",
        rows_used=rows_used, rows_total=int(work.shape[0]), snr=snr, noise_dn=noise,
        mtf_nyquist=mtf_nyquist, mtf50_cy_px=f50, mtf_nyquist_ci=nyquist_ci, mtf50_ci_cy_px=mtf50_ci,
        fwhm_px=fwhm_px, mtfa=mtf_area(mtf), gsd_m=gsd_m, noise_limit_cy_px=noise_limit,
        lsf_half_width_px=core, tail_fraction=tail_share, roi=(x0, y0, data.shape[1], data.shape[0]),
        centre_px=c, levels=(shape.low, shape.high), side_levels=(sides[0].coef[0], sides[1].coef[0]),
        scale_px=shape.scale_px, transposed=transposed, **shape.extra)
    arrays = dict(grid=grid, values=values, lsf_x=x_c, lsf=lsf_c, samples_x=d, samples_dn=raw,
                  geometry=geometry, mtf_function=mtf, frequencies=settings.frequencies_cy_px,
                  mtf=mtf(settings.frequencies_cy_px))
    if track_azimuth_deg is None:
        warnings.append("the image is not in sensor geometry (map-projected): its rows are not along "
                        "track, so the direction is unknown; give the track's azimuth to label it")
    params = {**settings.as_dict(), **resampled.params, "lsf_half_width_px": core, "lsf_taper_px": taper,
              "track_azimuth_deg": track_azimuth_deg, "dequantised": rebuilt is not None,
              **left_out[0]}
    return Measurement(figures, arrays, tuple(checks), tuple(warnings), params)


def _left_out_pixels(data: np.ndarray, mask, noise: float) -> tuple[dict, list[str]]:
    """Leave isolated hot and dead pixels out of ``data`` (set to NaN, in
    place) and count them and the NaN or nodata pixels among those the
    caller's ``mask`` (cropped to ``data``) keeps: (params, warnings)
    saying so."""
    nodata = int(np.count_nonzero(np.isnan(data) if mask is None else np.isnan(data) & mask))
    hot = isolated_outliers(data, noise)
    data[hot] = np.nan
    counts = {"nodata_px": nodata, "outlier_px": int(hot.sum())}
    said = []
    if nodata:
        said.append(f"{nodata} NaN or nodata pixel(s) inside the chip are left out of the estimate")
    if hot.any():
        said.append(f"{int(hot.sum())} isolated outlying pixel(s) (hot or dead) are left out of the estimate")
    return {k: v for k, v in counts.items() if v}, said


def _saturation(value) -> tuple[float, float]:
    try:
        low, high = value
    except (TypeError, ValueError):
        raise ParameterError(f"saturation must be two numbers (low, high) in DN, got {value!r}") from None
    low = check_number("saturation low", low, signed=True)
    high = check_number("saturation high", high, signed=True)
    if not low < high:
        raise ParameterError(f"saturation low must be below high, got ({low:g}, {high:g})")
    return low, high


def _central_run(grid, values, name):
    """The longest run of finite resampled values around the target
    (gaps at the far ends come from sparse samples)."""
    good = np.isfinite(values)
    mid = grid.size // 2
    if not good[max(mid - 5, 0): mid + 6].all():
        raise UnsuitableTargetError(f"the {name} profile has gaps at the target: too few sub-pixel "
                                    "samples (target too short or angle unsuitable)")
    bad_left = np.nonzero(~good[:mid])[0]
    bad_right = np.nonzero(~good[mid:])[0]
    lo = bad_left[-1] + 1 if bad_left.size else 0
    hi = mid + bad_right[0] if bad_right.size else grid.size
    return grid[lo:hi], values[lo:hi], (lo, hi)


def _normal_angle(geometry: TargetGeometry) -> float:
    """Angle (deg, in (-90, 90]) of the target's normal from the image's x
    axis (y down): the tilt of the target from the column axis."""
    vertical = -math.degrees(math.atan(geometry.slope))
    if not geometry.transposed:
        return vertical
    angle = 90.0 - vertical
    return angle - 180.0 if angle > 90.0 else angle


def _influence_intervals(intervals, mtf, nyquist, f50, resampled, span, x, data_at, lsf, c, w, lsf_adjoint,
                         tail_shape, sides, to_amplitude, amplitudes, kind, d, v, row, tail_share,
                         dequantised, narrowed, width_influence):
    """Linearised intervals for MTF at Nyquist and MTF50 (see
    :mod:`.intervals`).

    The transform F(f) = sum_k e_k(f) [w_k lsf_k + (1 - w_k) model_k] is
    linear in the samples: through the LSF operator and the resampling
    (their adjoints) where the window holds data, through each side's tail
    amplitude (its least-squares operator), and for a bar through the
    background under the window.  Each figure is |F(f)| / |F(0)| divided by
    the corrections, so its gradient follows, and with each sample's
    residual (scaled up by its leverage) gives the row influences.  Where
    the divisor rests on a width read off the same samples
    (``width_influence``: its :class:`WidthReading` and a function giving
    dR(f) / dv), its
    pull joins the gradient, widened where Fieller's set for the zero is
    wider than the linearised one; the share of the variance at Nyquist it
    makes is returned third (None without it)."""
    step = float(x[1] - x[0])
    width_share = None
    freqs = np.array([0.0, NYQUIST] + ([f50] if math.isfinite(f50) else []))
    e = np.exp(-2j * np.pi * freqs[:, None] * x[None, :]) * step                   # (n_f, n_x)
    left = x < c
    model = np.where(left, amplitudes[0], amplitudes[1]) * tail_shape
    transform = e @ (w * lsf + (1.0 - w) * model)
    weighted = (e * w)[:, data_at]
    on_grid = lsf_adjoint(np.concatenate([weighted.real, weighted.imag]))
    full = np.zeros((on_grid.shape[0], resampled.grid.size))
    full[:, span[0]: span[1]] = on_grid
    through = resampled.adjoint(full)
    n_f = freqs.size
    grad_f = through[:n_f] + 1j * through[n_f:]                                  # dF(f) / dv
    for i, side in enumerate(sides):
        in_side = left if i == 0 else ~left
        per_amplitude = e @ ((1.0 - w) * tail_shape * in_side)
        idx = np.nonzero(side.mask)[0]
        grad_f[:, idx] += per_amplitude[:, None] * (to_amplitude[i] @ side.operator)[None, :]
        if kind.subtracts_background:
            grad_f[:, idx] -= 0.5 * (e @ w)[:, None] * side.operator[0][None, :]
    f0 = transform[0].real
    run_grid, run_values = resampled.grid[span[0]: span[1]], resampled.values[span[0]: span[1]]
    # each sample's residual from the profile: the resampled one where it
    # was resampled, the side's model beyond
    far = np.abs(d - c) ** -float(kind.tail_power)
    model_dn = np.where(d < c, sides[0].coef[0] + sides[0].coef[1] * far, sides[1].coef[0] + sides[1].coef[1] * far)
    inside = (d >= run_grid[0]) & (d <= run_grid[-1])
    residual = v - np.where(inside, np.interp(d, run_grid, run_values), model_dn)
    if resampled.leverage is not None:
        residual = residual / np.sqrt(1.0 - np.minimum(resampled.leverage, LEVERAGE_CAP))
    width_pull = None
    if width_influence is not None:
        reading, spectrum_pull = width_influence
        dspectrum_dv = spectrum_pull()
        dwidth_dv = reading.width_change(dspectrum_dv[0])
        width_sd, n_rows = influence_sd(dwidth_dv * residual, row)
        spectrum_sd, _ = influence_sds(dspectrum_dv[1:] * residual, row)
        t = t_quantile(0.5 + intervals.confidence / 2, max(n_rows - 1, 1))
        spread = reading.spread_px(spectrum_sd, t)
        widen = max(1.0, spread / (t * width_sd)) if width_sd > 0 else 1.0
        width_pull = (widen * dwidth_dv, reading.log_slope)
    out = []
    for j in range(1, n_f):
        fj, f = transform[j], freqs[j]
        ratio = abs(fj) / abs(f0)
        # the MTF is this ratio divided by the corrections: scale the gradient alike
        scale = float(mtf(np.array([f]))[0]) / ratio if ratio else 0.0
        grad = (np.real(np.conj(fj) * grad_f[j]) / (abs(fj) * abs(f0)) - ratio * grad_f[0].real / f0) * scale
        if width_pull is not None:
            dwidth_dv, log_slope = width_pull
            if j == 1:
                fixed_sd, _ = influence_sd(grad * residual, row)
            # MTF = |F| / |F0| / |divisor(f; W)|: W's pull moves it by -MTF d ln|divisor| / dW
            grad = grad - float(mtf(np.array([f]))[0]) * float(log_slope(f)) * dwidth_dv
        sd, n_rows = influence_sd(grad * residual, row)
        if j == 1 and width_pull is not None:
            width_share = 1.0 - (fixed_sd / sd) ** 2 if sd > 0 else 0.0
        if j == 1:
            systematic = (SYSTEMATIC_NYQUIST + TAIL_MODEL_UNCERTAINTY * abs(tail_share) * abs(nyquist)
                          + (SYSTEMATIC_DEQUANTISED if dequantised else 0.0) + NARROW_WINDOW_NYQUIST * narrowed)
            out.append(linearised_interval(nyquist, sd, n_rows, intervals.confidence, systematic))
        else:
            h = 1e-3
            slope = float(mtf(np.array([f50 + h]))[0] - mtf(np.array([f50 - h]))[0]) / (2 * h)
            sd50 = sd / abs(slope) if slope else math.inf
            systematic = f50 * (SYSTEMATIC_MTF50 + TAIL_MODEL_UNCERTAINTY * abs(tail_share)
                                + (SYSTEMATIC_DEQUANTISED_MTF50 if dequantised else 0.0)
                                + NARROW_WINDOW_MTF50 * narrowed)
            out.append(linearised_interval(f50, sd50, n_rows, intervals.confidence, systematic))
    while len(out) < 2:
        out.append(Interval.none())
    return out[0], out[1], width_share


def _bootstrap_intervals(settings, kind, d, v, row, c, core, taper, start, divisor, x, span_px):
    """Bootstrap intervals: every replicate re-resamples the rows it drew
    (within ``span_px`` of the line), refits its sides' levels and tails,
    and is windowed onto the lattice ``x`` as the estimate is."""
    s = d - c
    masks = [s <= -start[0], s >= start[1]]
    to_amplitude = kind.lsf_tail_amplitudes()
    step = float(x[1] - x[0])
    sx = x - c
    shape = np.where(np.abs(sx) > 1e-9, 1.0 / np.maximum(sx * sx, 1e-18), 0.0)

    def resample(keep, weights, span):
        return resample_profile(d[keep], v[keep], method=settings.method, step=settings.step_px,
                                half_range=span, weights=weights, **settings.method_options)

    def windowed(grid_b, values_b, weights_of):
        coefs = []
        for mask in masks:
            u = np.abs(s[mask]) ** -float(kind.tail_power)
            design = np.column_stack([np.ones_like(u), u])
            wts = weights_of(mask)
            normal = np.einsum("ri,ij,ik->rjk", wts, design, design)
            rhs = np.einsum("ri,ij,i->rj", wts, design, v[mask])
            coefs.append(np.linalg.solve(normal + 1e-12 * np.eye(2), rhs[..., None])[..., 0])
        background = 0.5 * (coefs[0][:, 0] + coefs[1][:, 0])
        x_data, lsf_data, _ = kind.lsf(grid_b, values_b, background[:, None])
        first = int(round((x_data[0] - x[0]) / step))
        lsf = np.zeros((lsf_data.shape[0], x.size))
        lsf[:, first: first + x_data.size] = lsf_data
        in_data = np.zeros(x.size, bool)
        in_data[first: first + x_data.size] = True
        amp = [coefs[i] @ to_amplitude[i] for i in range(2)]
        w = flat_top_window(x, c, core, taper) * in_data
        model = np.where(sx < 0, amp[0][:, None], amp[1][:, None]) * shape
        return w * lsf + (1.0 - w) * model
    return bootstrap_figures(settings.intervals, d, row, span_px, resample, windowed, step, divisor)
