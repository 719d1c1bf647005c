"""Pulse-target MTF estimator: bridges, tarp strips, painted lines.

The bar's part of the shared pipeline (:mod:`.pipeline`; Choi and Helder,
Figure 8): Canny + Hough finds the bar's direction (:mod:`.detection`);
the bar's centre in every row is the centroid of its background-subtracted
profile, re-centred twice on the fitted line; the profile is the pulse
response (PRF), its levels the background and the peak, and the LSF-like
profile the PRF above its background.  No derivative is taken: the
transform is divided by the bar's sinc(f W) (and the resampling method's
transfer), and frequencies where |sinc(f W)| < 0.1 are masked (NaN).  A
PRF's tails fall as C / x^2, like an LSF's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from .._blas import one_blas_thread
from ..errors import TargetNotFoundError, UnsuitableTargetError
from ..inputs import check_width
from ..kinds.pulse import PULSE
from ..metrics import fwhm
from . import gate
from .bar_pair import PAIR_REASON, bar_pair
from .bar_results import BarProfileResult
from .bar_width import estimate_width, half_width_at, width_reading
from .detection import bar_contrast, describe, find_lines, meet_inside, parallel_within
from .geometry import fit_line, row_windows
from .kind import Shape, TargetKind
from .pipeline import run
from .results import finite
from .settings import make_settings
from .spectrum import MIN_TRANSFER, NYQUIST, with_transfer
from .tails import outer_samples
from .window import TAPER_FACTOR

RESTORE_MIN_SINC = 0.02         # below this |sinc| the LSF spectrum is interpolated
SNR_THRESHOLD = 100.0           # the paper's threshold for a confident estimate
MIN_HEIGHT_NOISE = 5.0          # a bar must peak this many noise sd above its background
BAR_SIDES_PX = 8.0              # a bar's two sides are found within this of each other
OUTER_PX = 5                    # a row window's pixels this far from the centre are background
LOCATE_HALF_WINDOW_PX = 12      # the bar is first followed in row windows reaching this far either side of its seed
REACH_MARGIN_PX = 2             # a row window reaches this far beyond where the bar's profile fades to 5 %
WINDOW_FACTOR = 1.6             # LSF window half-width / the bar's PRF half-width at 10 %
BACKGROUND_FRACTION = 2.0 / 3.0  # a bar's background is read from the samples beyond this share of the range


@dataclass(frozen=True, eq=False, kw_only=True, repr=False)
class PulseResult(BarProfileResult):
    """MTF from one bar (see :class:`imgmtf.estimate.bar_results.BarProfileResult`
    for the bar's width and its pulse response, :class:`imgmtf.estimate.results.MTFResult`
    for the fields every measurement has; ``fwhm_px`` is the recovered LSF's).

    Attributes
    ----------
    width_estimated : bool
        True when the width came from the profile rather than the caller.
    usable_band_cy_px : float
        The frequency below which the bar's sinc stays above 0.1, so that
        dividing by it is meaningful, cy/px.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("pulse", 6.0, width_px=1.5), 60)
    >>> result = imgmtf.measure_pulse(chip.image, width_px=1.5)
    >>> result.pulse_width_px, result.width_estimated, result.polarity
    (1.5, False, 'bright')
    """

    target: ClassVar[str] = PULSE.name
    width_estimated: bool
    usable_band_cy_px: float

    def _specific(self) -> dict:
        return {"pulse_width_px": finite(self.pulse_width_px), "width_estimated": self.width_estimated,
                "usable_band_cy_px": finite(self.usable_band_cy_px), **self._profile_figures()}


class PulseKind(TargetKind):
    """What a bar brings to the pipeline; ``width_px`` the bar's width, or
    None to estimate it from the profile."""

    registered = PULSE
    profile = gate.BAR_PROFILE
    tail_power = 2
    monotone = False
    subtracts_background = True
    restore_min_divisor = RESTORE_MIN_SINC

    def __init__(self, width_px: float | None = None):
        self.width_px = None if width_px is None else check_width(width_px)

    def seed(self, data, noise):
        lines = find_lines(data)
        if not lines:
            raise TargetNotFoundError("no bar found: no straight line of strong contrast")
        lines = [ln for ln in lines if bar_contrast(data, ln) >= 3.0 * noise]
        if not lines:
            raise TargetNotFoundError("no bar found: no straight line stands out of the noise")
        best = lines[0]
        reach = BAR_SIDES_PX + (self.width_px or 0.0)
        # a second target lies beside the bar, apart from it and not crossing it
        # (pieces of one line meet inside the chip: the profile judges those)
        others = [ln for ln in lines[1:] if not parallel_within(best, ln, data.shape, reach, angle_deg=8.0)
                  and not meet_inside(best, ln, data.shape) and ln.votes >= 0.5 * best.votes]
        checks = [gate.Check("two-targets", False, f"another line of strong contrast at {describe(others[0])} "
                             f"besides the bar at {describe(best)}")
                  ] if others else []
        return best, checks

    def locate(self, work, seed_x, transposed):
        return locate_pulse(work, seed_x, transposed)

    def shape(self, grid, values, d, v, half_range) -> Shape:
        background_sides = outer_samples(d, half_range, BACKGROUND_FRACTION)
        left, right = (float(v[side].mean()) for side in background_sides)
        background = (left + right) / 2
        centre = int(np.argmin(np.abs(grid)))
        sign = 1.0 if values[centre] >= background else -1.0
        peak = sign * (values - background)
        height = float(peak[max(centre - 20, 0): centre + 21].max())
        outer = np.abs(d) > 0.6 * half_range
        noise = float(np.std(v[outer])) if outer.sum() > 3 else 0.0
        if height <= MIN_HEIGHT_NOISE * noise or height <= 0:
            raise TargetNotFoundError(f"no bar found: the profile peaks {height:.1f} DN above its "
                                      f"background, within the noise ({noise:.1f} DN)")
        prf01 = peak / height
        pair = bar_pair(grid, prf01, noise / height)
        if pair is not None:        # measured as one bar, a pair's MTF would read times |cos(pi f s)|
            raise UnsuitableTargetError(pair.message(), reason=PAIR_REASON)
        h10 = half_width_at(grid, prf01, 0.1)
        if self.width_px is None:
            density = d.size / (2.0 * half_range)           # samples per px along the normal
            width = check_width(estimate_width(grid, prf01, noise / height / math.sqrt(density)))
        else:
            width = self.width_px
        if width / 2 + 2.0 > half_range:
            raise UnsuitableTargetError(
                f"the bar ({width:.1f} px) is too wide for the chip: it needs "
                f"{width / 2 + 2:.1f} px of background on each side of its centre", reason="border")
        area = float(np.sum(prf01[np.abs(grid) <= _core_px(h10, width)]) * (grid[1] - grid[0]))
        return Shape(0.0, h10, float(background), float(background + sign * height),
                     min(1.5 * h10 + 1.0, half_range - 1.0),
                     {"width_px": width, "width_estimated": self.width_px is None, "prf01": prf01,
                      "sign": sign, "area_px": area, "h10": h10, "background_sides": background_sides})

    def core_px(self, shape, snr, factor):
        return _core_px(shape.scale_px, shape.extra["width_px"], factor)

    def taper_factor(self, snr: float) -> float:
        return TAPER_FACTOR

    @staticmethod
    def confident_snr(rows: int) -> float:
        return SNR_THRESHOLD

    def lsf(self, grid, values, background):
        return grid, values - background, lambda h: np.asarray(h, float)

    def lsf_tail_amplitudes(self):
        return [np.array([0.0, 1.0]), np.array([0.0, 1.0])]

    def divisor(self, step, transfer, shape):
        return pulse_divisor(shape.extra["width_px"], transfer)

    def noise_gain(self, shape, contrast):
        area = shape.extra["area_px"]
        return lambda f: np.full(np.shape(f), 1.0 / max(area, 1e-9))

    def saturation_sides(self, sides):
        return [("background " + ("left" if i == 0 else "right"), mask, level)
                for i, (_, mask, level) in enumerate(sides)]

    def peak_mask(self, s, shape):
        return np.abs(s - shape.centre) <= max(0.5 * shape.extra["width_px"], 0.5)

    def known_half_width_px(self, shape):
        return None if shape.extra["width_estimated"] else 0.5 * shape.extra["width_px"]

    def read_width(self, grid, shape):
        if not shape.extra["width_estimated"]:
            return None
        return width_reading(grid, shape.extra["prf01"], shape.extra["width_px"], shape.high - shape.low,
                             shape.extra["background_sides"])


class PulseEstimator:
    """A configured pulse estimator: set up once, apply to many chips.

    Parameters
    ----------
    method : str, optional
        Resampling method, a key of :data:`imgmtf.estimate.resampling.METHODS`
        (default "msg").
    **settings
        The settings of :class:`imgmtf.estimate.settings.Settings` as
        keywords (``bootstrap=N`` for N bootstrap replicates, 0 for no
        intervals); ``snr_threshold=None`` uses the paper's 100 (the
        reproduction study measured edges only).

    Raises
    ------
    ParameterError
        An unknown method or keyword, or a setting out of its range.
        Calling the estimator raises as :func:`measure_pulse` does.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("pulse", 6.0, width_px=1.5), 100)
    >>> r = imgmtf.PulseEstimator()(chip.image, width_px=1.5)
    >>> round(r.mtf_nyquist, 2)
    0.27
    """

    def __init__(self, method: str = "msg", **settings: Any):
        self.settings = make_settings(method, **settings)

    @property
    def method(self) -> str:
        return self.settings.method

    def __call__(self, image: ArrayLike, *, width_px: float | None = None, roi: tuple[int, int, int, int] | None = None,
                 mask: np.ndarray | None = None, gsd_m: float | None = None,
                 saturation: tuple[float, float] | None = None, dtype: DTypeLike | None = None,
                 track_azimuth_deg: float | None = 0.0) -> PulseResult:
        """Measure the bar in ``image`` (2-D array, DN), ``width_px`` wide
        (estimated from the profile when None); see :func:`measure_pulse`."""
        with one_blas_thread():         # small matrices: threads cost more than they save
            m = run(PulseKind(width_px), image, self.settings, roi=roi, mask=mask, gsd_m=gsd_m, saturation=saturation,
                    dtype=dtype, track_azimuth_deg=track_azimuth_deg)
        extra = m.shape.extra
        width = extra["width_px"]
        band = usable_band(width)
        warnings = list(m.warnings)
        if band < NYQUIST:
            warnings.append(f"the bar's sinc falls below {MIN_TRANSFER} at {band:.3f} cy/px, before "
                            "Nyquist: MTF values near its zeros are masked (NaN)")
        return PulseResult(
            **m.result_fields(), method=self.settings.method, params={**m.params, "pulse_width_px": width},
            polarity="bright" if extra["sign"] > 0 else "dark", warnings=tuple(warnings), pulse_width_px=float(width),
            width_estimated=extra["width_estimated"], usable_band_cy_px=band, prf_x_px=m.profile.grid,
            prf=extra["prf01"], prf_fwhm_px=fwhm(m.profile.grid, extra["prf01"]), background_dn=float(m.shape.low),
            peak_dn=float(m.shape.high))


def measure_pulse(image: ArrayLike, *, width_px: float | None = None, roi: tuple[int, int, int, int] | None = None,
                  mask: np.ndarray | None = None, method: str = "msg", gsd_m: float | None = None,
                  saturation: tuple[float, float] | None = None, force: bool = False,
                  track_azimuth_deg: float | None = 0.0, dtype: DTypeLike | None = None,
                  **options: Any) -> PulseResult:
    """Measure the MTF from the bar (pulse) in ``image``.

    Parameters
    ----------
    image : array_like
        2-D image (DN) with one straight bar, bright or dark.
    width_px : float, optional
        The bar's width along its normal (px); estimated from the first
        zero of the PRF's spectrum when None.
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
    **options
        As for :func:`imgmtf.measure_edge`.

    Returns
    -------
    PulseResult
        The MTF along the bar's normal (cy/px; 1 at zero frequency, the
        bar's own sinc divided out), its figures with their intervals, and
        what they were computed from.

    Raises
    ------
    ParameterError, ImageContentError, TargetNotFoundError, UnsuitableTargetError
        As for :func:`imgmtf.measure_edge`; also a width that is not a
        positive number, or so wide that its sinc's first zero lies below
        0.1 cy/px.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("pulse", 6.0, width_px=1.5), 100)
    >>> r = imgmtf.measure_pulse(chip.image, width_px=1.5)
    >>> abs(r.mtf_nyquist - float(chip.true_mtf(0.5))) < 0.005
    True
    """
    return PulseEstimator(method, force=force, **options)(
        image, width_px=width_px, roi=roi, mask=mask, gsd_m=gsd_m, saturation=saturation, dtype=dtype,
        track_azimuth_deg=track_azimuth_deg)


def pulse_divisor(width_px: float, transfer):
    """Transfer between the system LSF and the resampled PRF: the bar's
    sinc(f W) (signed) times the resampling method's transfer."""
    return with_transfer(lambda f: np.sinc(f * width_px), transfer)


def usable_band(width_px: float) -> float:
    """First frequency (cy/px) where |sinc(f W)| falls to ``MIN_TRANSFER``."""
    f = np.linspace(0.0, 1.0 / width_px, 2001)
    return float(f[np.argmax(np.abs(np.sinc(f * width_px)) < MIN_TRANSFER)])


def locate_pulse(work: np.ndarray, seed_x: np.ndarray, transposed: bool,
                 half_window: int = LOCATE_HALF_WINDOW_PX):
    """Per-row bar centres (centroids of the background-subtracted profile),
    re-centred on the fitted line: three times within ``half_window`` px,
    which finds the bar wherever the seed put it, then twice within the
    bar's own reach (:func:`bar_reach_px`).  A centroid's noise grows with
    its window's lever arm: at SNR 25 a 1.5 px bar's centres scatter by
    about 1 px in a 25 px window, and the line through them, off by a tenth
    of a pixel, smears the profile and reads MTF50 1.6 % low."""
    background = np.nanmedian(work, axis=1)
    rows = np.arange(work.shape[0])
    centre_x, window, noise = seed_x, half_window, 0.0
    for step in range(5):
        cols, values, inside = row_windows(work, centre_x, window)
        excess = (values - background[:, None]) * inside
        sign = 1.0 if excess.sum() >= 0 else -1.0
        weight = sign * excess
        total = weight.sum(axis=1)
        usable = (inside.sum(axis=1) == 2 * window + 1) & (total > 0)
        if usable.sum() < 5:
            raise UnsuitableTargetError(
                f"fewer than 5 rows hold the bar with {window} px of background on both "
                "sides: the chip is too narrow, or the bar too wide or too close to its border")
        centres = (weight * cols).sum(axis=1)[usable] / total[usable]
        # a centroid's noise: the pixel noise (the wide window's outer
        # pixels' scatter) times the root-sum-square of the offsets it weighs
        offsets = cols[usable] - centres[:, None]
        if window == half_window:
            outer = np.abs(offsets) >= OUTER_PX
            noise = float(np.std(excess[usable][outer])) if outer.any() else 0.0
        expected = float(np.median(noise * np.sqrt((offsets ** 2).sum(axis=1)) / total[usable]))
        geometry = fit_line(rows[usable], centres, transposed, expected)
        centre_x = geometry.slope * rows + geometry.intercept
        if step == 2:
            window = min(half_window, bar_reach_px(cols[usable] - centre_x[usable, None], weight[usable]))
    return geometry


def bar_reach_px(offsets: np.ndarray, weight: np.ndarray, level: float = 0.05) -> int:
    """How far from the line (px, a whole number) a bar's row windows
    need to reach: the farthest distance at which the rows' mean profile
    (``weight`` at ``offsets`` from the line, half-pixel bins) stays above
    ``level`` of its peak, plus ``REACH_MARGIN_PX``."""
    half_px = np.rint(2.0 * offsets).astype(int).ravel()
    bins = half_px - half_px.min()                       # distance 0 is bin -half_px.min()
    counts = np.bincount(bins)
    mean = np.bincount(bins, weights=weight.ravel()) / np.maximum(counts, 1)
    above = np.nonzero((mean >= level * mean.max()) & (counts > 0))[0]
    reach = np.abs(above + half_px.min()).max() / 2.0
    return int(math.ceil(reach)) + REACH_MARGIN_PX


def _core_px(h10: float, width_px: float, factor: float | None = None) -> float:
    """The LSF window's flat half-width (px): ``factor`` (default
    ``WINDOW_FACTOR``) times the PRF's half-width at 10 % ``h10``, and at
    least the bar's half-width and a pixel; the bar's area is measured over
    the same core."""
    return max((factor or WINDOW_FACTOR) * h10, width_px / 2 + 1.0)
