"""The whole 2-D PSF and MTF from an array of point targets (stars, convex
mirrors, lamps, Rauchmiller's squares): every target found and located
(:mod:`.sources`), all stacked by their sub-pixel phases, transformed.

The stack is a transform of the scatter: each target's stamp ``v_k``
(flux 1, background 0) at its pixels' distances from its fitted centre
``p_k``, weighted by ``w_k`` (the inverse of its noise's variance: its
flux squared, capped at 3 times the median flux), so that

    F(f) = sum_k w_k sum_n v_k[n] exp(-2 pi i f . (n - p_k))
         = T(f) + sum_{j != 0} c_j T(f + j),   c_j = sum_k w_k exp(-2 pi i j . p_k),

``T`` the transfer of sensor and target, ``j`` the integer aliases (the
Poisson sum of the pixel samples).  Targets whose phases tile the pixel
evenly (Rauchmiller's quarter pixels: 4 x 4 phases) cancel every ``c_j``
with ``|j| < 4``: the stack is then exact to 2 cy/px, as the edge's
projection is.  What the phases leave is taken out with the model the
targets were located with (a Gaussian integrated over the pixel, their
median widths): ``F - sum c_j T_model(f + j)``; a lone point depends on the
model as much as its one phase leaves aliased, and the result says how much
(``alias_weight``).  A target of known size (a square of W px) has its
``W^2 sinc(W fx) sinc(W fy)`` divided out, where it is above 0.1.

Directions: "across-track" is frequency along the image's x (columns),
"along-track" along y (rows), as in sensor geometry.  The intervals are a
percentile bootstrap over the targets, expanded for their small number
(:meth:`Stack.small_sample_factor`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ParameterError, TargetNotFoundError, UnsuitableTargetError
from ...metrics import first_crossing, fwhm
from ...version import __version__
from ..intervals import Interval, Intervals, as_intervals
from .sources import FoundSources, Source, find_sources

#: the directions' names: across and along the ground track, or the image's axes when the track is unknown
ACROSS, ALONG = "across-track", "along-track"
IMAGE_X, IMAGE_Y = "image-x", "image-y"
#: the highest alias order the model correction covers, and the band (cy/px) the PSF is drawn from
ALIAS_ORDER = 4
BAND_CY_PX = 2.0
#: where a square's sinc is too small to divide out (NaN there)
MIN_DIVISOR = 0.1
SECTION_STEP_CY_PX = 0.01
SECTION_MAX_CY_PX = 1.0


@dataclass(frozen=True, eq=False)
class DirectionMTF:
    """The MTF of a point stack along one direction.

    Attributes
    ----------
    direction : str
        "across-track" or "along-track" ("image-x", "image-y" when the
        track is unknown).
    angle_deg : float
        The frequency axis's angle from the image's x axis towards +y, in
        (-90, 90] (0: across track in sensor geometry).
    frequencies_cy_px, mtf : numpy.ndarray
        The section, 0 to 1 cy/px in 0.01 steps (1 at zero).
    mtf_nyquist : float
        MTF at 0.5 cy/px.
    mtf_nyquist_ci : Interval
        Its bootstrap interval over the targets (NaN when off).
    mtf50_cy_px : float
        Where the MTF first falls to 0.5, cy/px.
    mtf50_ci_cy_px : Interval
        Its interval.
    fwhm_px : float
        The FWHM of the line spread function in this direction (the PSF
        integrated across it), px; a square target's size is in it.
    lsf_x_px, lsf : numpy.ndarray
        That LSF (1/px) and its positions, px.
    """

    direction: str
    angle_deg: float
    frequencies_cy_px: np.ndarray
    mtf: np.ndarray
    mtf_nyquist: float
    mtf_nyquist_ci: Interval
    mtf50_cy_px: float
    mtf50_ci_cy_px: Interval
    fwhm_px: float
    lsf_x_px: np.ndarray
    lsf: np.ndarray


@dataclass(frozen=True, eq=False)
class PointsResult:
    """The 2-D PSF and MTF of a stack of point targets.

    Attributes
    ----------
    directions : tuple of DirectionMTF
        Across and along track.
    psf : numpy.ndarray, shape (m, m)
        The stacked PSF (pixel aperture included, target size not), 1/px^2,
        on a grid of ``psf_step_px`` centred on the middle sample.
    psf_step_px : float
        Its spacing, px.
    mtf2d : numpy.ndarray, shape (k, k)
        The 2-D MTF on ``frequencies2d_cy_px`` x ``frequencies2d_cy_px``
        (rows fy, columns fx), target size divided out (NaN where masked).
    frequencies2d_cy_px : numpy.ndarray
        Its frequencies, -1 to 1 cy/px.
    sources : tuple of Source
        Every target found, used or refused (with its reason).
    polarity : str
        "bright" or "dark".
    point_size_px : float
        The targets' known size divided out, px (0: points).
    noise_dn : float
        The chip's noise, DN.
    alias_weight : float
        The largest ``|c_j|`` over the first aliases (0 for a perfectly
        tiled pixel, 1 for a lone point): how much the model correction
        carries.
    gsd_m : float or None
        The pixel on the ground, m.
    roi : (int, int, int, int)
        (x, y, width, height) of the chip measured, px.
    params : dict
        The settings.
    warnings : tuple of str
        What the reader should know.
    method, target : str
        "points": the stack (no resampling method of the 1-D pipeline), and
        the kind.
    checks : tuple
        Empty: a point stack has no gate of line checks; its targets are
        refused one by one (``sources``).

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.sensor.points import PointArray, render_points
    >>> chip = render_points(imgmtf.Sensor(), PointArray(4, 4), 64)
    >>> result = measure_points(chip.image, intervals="none")
    >>> result.direction("along-track").direction, len(result.used), result.psf_step_px
    ('along-track', 16, 0.25)
    """

    directions: tuple[DirectionMTF, ...]
    psf: np.ndarray
    psf_step_px: float
    mtf2d: np.ndarray
    frequencies2d_cy_px: np.ndarray
    sources: tuple[Source, ...]
    polarity: str
    point_size_px: float
    noise_dn: float
    alias_weight: float
    gsd_m: float | None = None
    roi: tuple[int, int, int, int] = (0, 0, 0, 0)
    params: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    method: str = "points"
    target: str = "points"
    checks: tuple = ()

    @property
    def used(self) -> tuple[Source, ...]:
        return tuple(s for s in self.sources if s.used)

    @property
    def refused(self) -> tuple[Source, ...]:
        return tuple(s for s in self.sources if not s.used)

    def direction(self, name: str) -> DirectionMTF:
        """The section called ``name``.

        Parameters
        ----------
        name : str
            "across-track", "along-track" (or "image-x", "image-y").

        Returns
        -------
        DirectionMTF
            That section and its figures.

        Raises
        ------
        ParameterError
            No section of that name.
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
            Include the MTF section (default True).

        Returns
        -------
        list of dict
            Keys with units in their names, as an edge's.
        """
        refusals: dict[str, int] = {}
        for source in self.refused:
            refusals[source.status] = refusals.get(source.status, 0) + 1
        snr = float(np.median([s.peak_snr for s in self.used])) if self.used else math.nan
        out = []
        for section in self.directions:
            row: dict[str, Any] = {
                "target": self.target, "method": self.method, "direction": section.direction,
                "normal_angle_deg": _finite(section.angle_deg),
                "polarity": self.polarity, "snr": _finite(snr), "noise_dn": _finite(self.noise_dn),
                "mtf_nyquist": _finite(section.mtf_nyquist),
                "mtf_nyquist_ci": [_finite(section.mtf_nyquist_ci.low), _finite(section.mtf_nyquist_ci.high)],
                "mtf50_cy_px": _finite(section.mtf50_cy_px),
                "mtf50_ci_cy_px": [_finite(section.mtf50_ci_cy_px.low), _finite(section.mtf50_ci_cy_px.high)],
                "fwhm_px": _finite(section.fwhm_px), "gsd_m": self.gsd_m,
                "mtf50_cy_m": _finite(section.mtf50_cy_px / self.gsd_m) if self.gsd_m else None,
                "fwhm_m": _finite(section.fwhm_px * self.gsd_m) if self.gsd_m else None,
                "points_used": len(self.used), "points_refused": len(self.refused),
                "points_refused_by": refusals, "point_size_px": self.point_size_px,
                "alias_weight": _finite(self.alias_weight),
                "roi": list(self.roi), "warnings": list(self.warnings), "params": dict(self.params),
                "imgmtf_version": __version__,
            }
            if curves:
                row["frequencies_cy_px"] = [round(float(f), 4) for f in section.frequencies_cy_px]
                row["mtf"] = [_finite(v) for v in section.mtf]
            out.append(row)
        return out

    def to_dict(self, curves: bool = True) -> dict:
        """The first section's summary (:meth:`summaries` gives both).

        Parameters
        ----------
        curves : bool, optional
            Include the MTF section (default True).

        Returns
        -------
        dict
            The across-track (or image-x) summary.
        """
        return self.summaries(curves)[0]


def _widened(replicates: np.ndarray, estimate: float, tail: float, widen: float) -> Interval:
    """The percentile interval of ``replicates``, its ends moved ``widen``
    times as far from ``estimate``."""
    low, high = np.nanpercentile(replicates, [tail, 100 - tail])
    return Interval(estimate - widen * (estimate - low), estimate + widen * (high - estimate))


def _finite(value: Any) -> float | None:
    value = float(value)
    return round(value, 6) if math.isfinite(value) else None


def measure_points(image: np.ndarray, *, point_size_px: float = 0.0, polarity: str = "auto",
                   stamp_radius_px: int = 4, min_snr: float = 20.0, min_separation_px: float | None = None,
                   saturation: tuple[float, float] | None = None, intervals: Intervals | str | int | None = None,
                   gsd_m: float | None = None, track_azimuth_deg: float | None = 0.0) -> PointsResult:
    """The 2-D PSF and MTF of the point targets on ``image``, stacked by
    their sub-pixel phases (see the module).

    Parameters
    ----------
    image : numpy.ndarray, shape (rows, cols)
        The chip, DN, linear in light.
    point_size_px : float, optional
        Each target's side, px, when it is a square of known size (its sinc
        is divided out); 0 (default) for points.
    polarity : {"auto", "bright", "dark"}, optional
        Bright targets on a dark field or dark on bright (default: found).
    stamp_radius_px : int, optional
        Half side of the square cut around each target, px (default 4).
    min_snr : float, optional
        The smallest peak over the noise a target may have (default 20).
    min_separation_px : float, optional
        The closest two targets may lie, px (default ``2 R + 2``).
    saturation : (float, float), optional
        (low, high) DN the sensor records (clipped targets are refused).
    intervals : Intervals, str or int, optional
        The bootstrap over targets: "bootstrap" (default), "none", an
        :class:`~imgmtf.Intervals` (its confidence, replicates and seed)
        or a number of replicates.
    gsd_m : float, optional
        The pixel on the ground, m (figures in m too).
    track_azimuth_deg : float or None, optional
        The ground track's direction, degrees clockwise from the image's up
        (0, the default: rows along track); None when unknown: the sections
        are then along the image's x and y ("image-x", "image-y").

    Returns
    -------
    PointsResult
        The sections across and along track, the 2-D PSF and MTF, every
        target with its verdict.

    Raises
    ------
    TargetNotFoundError
        No target usable (the message counts the refusals by reason).
    UnsuitableTargetError
        (reason ``not-points``) Most features found reach across their
        stamps: an edge or a bar.
    ParameterError
        A bad setting.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.sensor.points import PointArray, render_points
    >>> from imgmtf.sensor.stages import Detector, GaussianOptics
    >>> sensor = imgmtf.Sensor(stages=[GaussianOptics(0.45, 0.55), Detector(1.0, 1.0)])
    >>> chip = render_points(sensor, PointArray(4, 4, spacing_px=12.0), 64, bits=None)
    >>> result = measure_points(chip.image, intervals="none")
    >>> [(d.direction, round(d.mtf_nyquist, 3)) for d in result.directions]
    [('across-track', 0.234), ('along-track', 0.143)]
    >>> round(float(chip.true_mtf(0.5, "across")), 3), len(result.used)
    (0.234, 16)
    """
    if not (isinstance(point_size_px, (int, float)) and math.isfinite(point_size_px) and 0 <= point_size_px <= 20):
        raise ParameterError(f"point size must be 0 to 20 px, got {point_size_px!r}")
    settings = as_intervals("bootstrap" if intervals is None else intervals)
    found = find_sources(image, polarity=polarity, stamp_radius_px=stamp_radius_px, min_snr=min_snr,
                         min_separation_px=min_separation_px, saturation=saturation)
    if not found.used:
        counts = found.refusal_counts()
        if counts.get("extended", 0) * 2 > len(found.sources):
            raise UnsuitableTargetError(
                f"{counts['extended']} of the {len(found.sources)} {found.polarity} features found reach across "
                f"their {2 * stamp_radius_px + 1} px stamps: the chip holds an edge or a bar, not point targets",
                reason="not-points")
        raise TargetNotFoundError(_nothing_usable(found, np.asarray(image).shape))
    stack = Stack(found, float(point_size_px))
    directions = tuple(stack.direction(name, vector, settings) for name, vector in section_axes(track_azimuth_deg))
    psf, step = stack.psf()
    f2d = np.round(np.arange(-50, 51) * 0.02, 10)
    mtf2d = stack.mtf(f2d[None, :], f2d[:, None])
    warnings = []
    if stack.alias_weight > 0.3:
        warnings.append(f"the {len(found.used)} targets' phases leave aliases of weight {stack.alias_weight:.2f} "
                        "(0: a pixel tiled evenly): the MTF near Nyquist leans on the Gaussian model they were "
                        "located with")
    if len(found.used) < 8 and settings.method != "none":
        warnings.append(f"only {len(found.used)} targets: the bootstrap over them is rough")
    rows, cols = np.asarray(image).shape
    params = {"point_size_px": float(point_size_px), "polarity": polarity, "stamp_radius_px": int(stamp_radius_px),
              "min_snr": float(min_snr), "min_separation_px": min_separation_px,
              "intervals": settings.as_dict()}
    return PointsResult(directions, psf, step, mtf2d, f2d, found.sources, found.polarity, float(point_size_px),
                        found.noise_dn, stack.alias_weight, gsd_m, (0, 0, cols, rows), params, tuple(warnings))


def section_axes(track_azimuth_deg: float | None) -> tuple[tuple[str, tuple[float, float]], ...]:
    """The sections' names and unit frequency vectors (fx, fy): across and
    along a track ``track_azimuth_deg`` clockwise from the image's up (x
    right, y down), or the image's axes when it is None."""
    if track_azimuth_deg is None:
        return ((IMAGE_X, (1.0, 0.0)), (IMAGE_Y, (0.0, 1.0)))
    a = math.radians(float(track_azimuth_deg))
    along = (math.sin(a), -math.cos(a))
    return ((ACROSS, (math.cos(a), math.sin(a))), (ALONG, (along[0] + 0.0, along[1] + 0.0)))


def _nothing_usable(found: FoundSources, shape) -> str:
    if not found.sources:
        return (f"no compact target stands out of the {shape[1]} x {shape[0]} px chip's noise "
                f"({found.noise_dn:.3g} DN)")
    counts = ", ".join(f"{n} {reason}" for reason, n in sorted(found.refusal_counts().items()))
    example = found.refused[0]
    return (f"none of the {len(found.sources)} compact targets found is usable ({counts}); e.g. at "
            f"({example.x_px:.0f}, {example.y_px:.0f}): {example.message}")


class Stack:
    """The used targets' stamps and phases, and the transforms of their
    stack (see the module); built once, read for every frequency."""

    def __init__(self, found: FoundSources, point_size_px: float):
        self.stamps, self.phases, self.size = found.stamps, found.phases_px, point_size_px
        radius = found.stamp_radius_px
        self.offsets = np.arange(-radius, radius + 1, dtype=float)
        self.radius = radius
        used = found.used
        self.sigmas = np.array([[s.sigma_x_px, s.sigma_y_px] for s in used])
        # inverse variance: a stamp divided by its flux has noise / flux; capped at 3x the median flux so that
        # no one bright target (one phase) carries the stack alone
        flux = np.array([s.flux_dn for s in used])
        self.weights = np.minimum(flux, 3.0 * np.median(flux)) ** 2
        j = np.arange(-ALIAS_ORDER, ALIAS_ORDER + 1)
        jx, jy = np.meshgrid(j, j)
        keep = (jx != 0) | (jy != 0)
        self.aliases = np.column_stack([jx[keep], jy[keep]]).astype(float)
        # exp(-2 pi i j . p_k), per target and alias
        self.alias_phasors = np.exp(-2j * np.pi * (self.phases @ self.aliases.T))
        first = np.max(np.abs(self.aliases), axis=1) == 1
        share = self.weights / self.weights.sum()
        self.alias_weight = float(np.abs(share @ self.alias_phasors[:, first]).max())

    def contributions(self, fx: np.ndarray, fy: np.ndarray) -> np.ndarray:
        """Each target's phase-corrected transform at the frequency pairs
        (``fx``, ``fy``) (1-D, cy/px): shape (targets, frequencies)."""
        ex = np.exp(-2j * np.pi * fx[:, None] * self.offsets[None, :])       # (F, L) along x
        ey = np.exp(-2j * np.pi * fy[:, None] * self.offsets[None, :])       # (F, L) along y
        dft = np.einsum("fm,kmn,fn->kf", ey, self.stamps, ex, optimize=True)
        return dft * np.exp(2j * np.pi * (self.phases[:, :1] * fx[None, :] + self.phases[:, 1:] * fy[None, :]))

    def model(self, fx: np.ndarray, fy: np.ndarray, sigmas: np.ndarray) -> np.ndarray:
        """The located targets' model transfer: a Gaussian of the median
        widths, integrated over the pixel (1 at zero)."""
        sx, sy = np.median(sigmas, axis=0)
        return np.exp(-2 * np.pi ** 2 * ((sx * fx) ** 2 + (sy * fy) ** 2)) * np.sinc(fx) * np.sinc(fy)

    def transfer(self, fx: np.ndarray, fy: np.ndarray, *, divide_size: bool = True) -> np.ndarray:
        """The stack's transfer at the pairs (``fx``, ``fy``), the model's
        aliases taken out, normalised to 1 at zero, the target's size
        divided out (NaN where it masks) unless ``divide_size`` is false."""
        return self.replicates(fx, fy, np.arange(len(self.stamps))[None, :], divide_size=divide_size)[0]

    def replicates(self, fx: np.ndarray, fy: np.ndarray, picks: np.ndarray, *,
                   divide_size: bool = True) -> np.ndarray:
        """:meth:`transfer` of the targets each row of ``picks`` names
        (indices, repeats allowed: a bootstrap's replicates), shape
        (replicates, frequencies)."""
        fx0, fy0 = np.append(fx, 0.0), np.append(fy, 0.0)
        each = self.contributions(fx0, fy0)                                   # (targets, F)
        out = np.empty((len(picks), len(fx0)), complex)
        for r, pick in enumerate(picks):
            aliased = self.model(fx0[:, None] + self.aliases[None, :, 0], fy0[:, None] + self.aliases[None, :, 1],
                                 self.sigmas[pick])
            share = self.weights[pick] / self.weights[pick].sum()
            out[r] = share @ each[pick] - aliased @ (share @ self.alias_phasors[pick])
        t = out[:, :-1] / out[:, -1:].real
        if divide_size and self.size > 0:
            divisor = np.sinc(self.size * fx) * np.sinc(self.size * fy)
            t = np.where(np.abs(divisor) >= MIN_DIVISOR, t / np.where(divisor == 0, 1.0, divisor), np.nan)
        return t

    def mtf(self, fx: np.ndarray, fy: np.ndarray) -> np.ndarray:
        """|transfer| on the broadcast grid of ``fx`` and ``fy``."""
        fx, fy = np.broadcast_arrays(fx, fy)
        return np.abs(self.transfer(fx.ravel(), fy.ravel())).reshape(fx.shape)

    def direction(self, name: str, vector, settings: Intervals) -> DirectionMTF:
        """The section along ``vector`` with its figures and intervals."""
        steps = int(round(SECTION_MAX_CY_PX / SECTION_STEP_CY_PX))
        f = np.arange(steps + 1) * SECTION_STEP_CY_PX
        ux, uy = vector
        mtf = np.abs(self.transfer(f * ux, f * uy))
        nyquist = steps // 2
        lsf_x, lsf = self.lsf(vector)
        nyquist_ci = mtf50_ci = Interval.none()
        if settings.method != "none" and len(self.stamps) > 1:
            rng = np.random.default_rng(settings.seed)
            n = len(self.stamps)
            reps = np.abs(self.replicates(f * ux, f * uy, rng.integers(0, n, (settings.replicates, n))))
            tail = 100 * (1 - settings.confidence) / 2
            widen = self.small_sample_factor(settings.confidence)
            nyquist_ci = _widened(reps[:, nyquist], float(mtf[nyquist]), tail, widen).clipped_at_zero()
            m50 = first_crossing(f, reps, 0.5)
            mtf50 = first_crossing(f, mtf, 0.5)
            mtf50_ci = (_widened(m50, mtf50, tail, widen) if np.isfinite(m50).any() and np.isfinite(mtf50)
                        else Interval.none())
        angle = math.degrees(math.atan2(uy, ux))
        angle = angle - 180.0 if angle > 90.0 else angle + 180.0 if angle <= -90.0 else angle
        return DirectionMTF(name, angle + 0.0, f, mtf, float(mtf[nyquist]), nyquist_ci, first_crossing(f, mtf, 0.5),
                            mtf50_ci, fwhm(lsf_x, lsf), lsf_x, lsf)

    def small_sample_factor(self, confidence: float) -> float:
        """How much wider than its bootstrap percentiles an interval over
        few targets is drawn: Student's t over the normal quantile, times
        sqrt(n / (n - 1)) (the bootstrap's variance of a mean is (n - 1) / n
        of the truth), n the weights' effective count (Hesterberg's
        expanded percentile interval); 1.09 x 1.03 for 16 targets."""
        from scipy import stats
        n = float(self.weights.sum() ** 2 / (self.weights ** 2).sum())
        if n <= 1.5:
            return math.inf
        q = 0.5 + confidence / 2
        return float(stats.t.ppf(q, n - 1) / stats.norm.ppf(q) * math.sqrt(n / (n - 1)))

    def lsf(self, vector) -> tuple[np.ndarray, np.ndarray]:
        """The line spread function along ``vector``: the inverse transform
        of the section over the band, on a 0.01 px grid (1/px), the target's
        size left in (the LSF as imaged: its sinc cannot be divided out over
        the whole band)."""
        df = 1.0 / (4 * (2 * self.radius + 1))
        f = np.arange(-BAND_CY_PX, BAND_CY_PX + df / 2, df)
        t = self.transfer(f * vector[0], f * vector[1], divide_size=False)
        x = np.arange(-self.radius * 100, self.radius * 100 + 1) / 100.0
        lsf = (np.exp(2j * np.pi * x[:, None] * f[None, :]) @ t).real * df
        return x, lsf

    def psf(self) -> tuple[np.ndarray, float]:
        """The stacked PSF on a quarter-pixel grid over the stamp, 1/px^2,
        from the transfer over the band (target size left in)."""
        step = 1.0 / (2 * BAND_CY_PX)
        n = int(round((2 * self.radius + 1) / step))
        f = np.fft.fftfreq(n, d=step)
        fx, fy = np.meshgrid(f, f)
        t = self.transfer(fx.ravel(), fy.ravel(), divide_size=False).reshape(fx.shape)
        psf = np.fft.fftshift(np.fft.ifft2(t).real) / step ** 2
        return psf, step

