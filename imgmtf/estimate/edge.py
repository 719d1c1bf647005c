"""Slanted-edge MTF estimator.

The edge's part of the shared pipeline (:mod:`.pipeline`): Canny + Hough
seeds the edge (:mod:`.detection`); a Fermi fit in every row gives its
sub-pixel locations (:mod:`.fermi`, :mod:`.geometry`); the profile is the
ESF, its levels the two sides, its width the 10-90 % rise, and the
LSF-like profile its central difference, whose transfer sinc(2 f step) is
divided out with the resampling method's.  An ESF's tails approach their
levels as A / |x|, so the LSF's as A / x^2.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from .._blas import one_blas_thread
from ..kinds.edge import EDGE
from . import gate
from .detection import describe, find_edge, meet_inside, parallel_within
from .fermi import FermiRows
from .geometry import TargetGeometry, edge_rows, locate_edge
from .kind import Shape, TargetKind
from .many import run_many
from .pipeline import run
from .results import MTFResult, finite
from .settings import Settings, make_settings
from .spectrum import MIN_TRANSFER, central_difference, edge_divisor, relative_edge_response, rise_distance
from .tails import outer_samples

# Measured by `imgmtf reproduce` (docs/reproduction.md): on the paper's 40-row
# edge chips, 95 % of msg estimates fall within +-5 % of the true MTF at
# Nyquist from SNR 125 on.  The noise falls as 1 / (SNR sqrt(rows)), so the
# threshold for an edge of n rows is 125 sqrt(40 / n).
CONFIDENT_SNR_40_ROWS = 125.0
WINDOW_FACTOR_CLEAN = 1.35     # LSF window half-width / 10-90 % rise, high SNR
WINDOW_FACTOR_NOISY = 0.9      # ... and at SNR <= 30
TAPER_FACTOR_CLEAN = 1.0       # the window's taper / its flat half-width, high SNR
TAPER_FACTOR_NOISY = 0.35      # ... and at SNR <= 30
IQR_TO_RISE = 1.9              # 10-90 % rise / 25-75 % distance of a Gaussian edge
BAR_MAX_SEPARATION_PX = 8.0    # two parallel lines closer than this are one bar's sides


@dataclass(frozen=True, eq=False, kw_only=True, repr=False)
class EdgeResult(MTFResult):
    """MTF of one edge and everything it was computed from (see
    :class:`imgmtf.estimate.results.MTFResult` for the fields every
    measurement has).

    Attributes
    ----------
    rer : float
        The relative edge response: the normalised ESF's rise over the
        pixel centred on the edge.
    esf_x_px, esf : numpy.ndarray
        The resampled ESF, normalised to rise from 0 to 1 whatever the
        edge's polarity, and its positions along the normal, px.
    levels_dn : (float, float)
        The left and right levels, DN (the vertical frame's: left is -x, or
        up for a near-horizontal edge).
    bright_side : str
        Where the bright side lies in the image as stored.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60)
    >>> result = imgmtf.measure_edge(chip.image)
    >>> round(result.rer, 2), result.polarity, round(float(result.esf[-1]), 2)
    (0.67, 'rising', 1.0)
    """

    target: ClassVar[str] = EDGE.name
    rer: float
    esf_x_px: np.ndarray
    esf: np.ndarray
    levels_dn: tuple[float, float]
    bright_side: str

    def normalised_profile(self) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
        """The ESF (0 to 1), its positions along the normal (px) and its
        two levels (DN)."""
        return self.esf_x_px, self.esf, self.levels_dn

    def lsf_like(self) -> tuple[np.ndarray, np.ndarray, float]:
        """The LSF, its positions along the normal (px) and its FWHM (px)."""
        return self.lsf_x_px, self.lsf, self.fwhm_px

    def _specific(self) -> dict:
        return {"rer": finite(self.rer), "levels_dn": [finite(v) for v in self.levels_dn],
                "bright_side": self.bright_side}


class EdgeKind(TargetKind):
    """What an edge brings to the pipeline."""

    registered = EDGE
    profile = gate.STEP_PROFILE
    tail_power = 1
    monotone = True
    subtracts_background = False
    restore_min_divisor = MIN_TRANSFER

    def seed(self, data, noise):
        line, rival = find_edge(data, noise=noise)
        checks = []
        if rival is None or parallel_within(line, rival, data.shape, BAR_MAX_SEPARATION_PX):
            return line, checks      # one edge, or a bar's two sides (the profile tells)
        if meet_inside(line, rival, data.shape, min_angle_deg=2.0):
            checks.append(gate.Check("not-straight", False, f"the edge bends: two straight pieces (at "
                                     f"{describe(line)} and {describe(rival)}) meet inside the chip"))
        else:
            checks.append(gate.Check("two-targets", False, f"two edges found (at {describe(line)} and "
                                     f"{describe(rival)})"))
        return line, checks

    def locate(self, work, seed_x, transposed) -> TargetGeometry:
        return locate_edge(work, seed_x, transposed=transposed)

    def fermi_rows(self, work, seed_x) -> FermiRows:
        return edge_rows(work, seed_x)[1]

    def locate_fitted(self, work, seed_x, transposed, fit) -> TargetGeometry:
        return locate_edge(work, seed_x, transposed=transposed, fit=fit)

    def shape(self, grid, values, d, v, half_range) -> Shape:
        # the levels: the samples in the outer eighth of the range each side
        left, right = (float(v[side].mean()) for side in outer_samples(d, half_range, 0.75))
        if left == right:
            raise gate.UnsuitableTargetError("the two sides of the edge have the same level", reason="not-an-edge")
        esf01 = (values - left) / (right - left)
        centre = _crossing_nearest(grid, esf01)
        rise = rise_distance(grid, esf01, centre)
        if not rise > 0:
            raise gate.UnsuitableTargetError("the edge profile does not rise cleanly from 10 % to 90 %: "
                                             "no usable edge (noise or a second feature?)", reason="not-straight")
        # the sides begin 3 rises out, the rise taken from the 25-75 % distance
        # (1.9 x it is the 10-90 % rise of a Gaussian edge) so that a slow drift
        # of a level cannot stretch it
        core_rise = IQR_TO_RISE * rise_distance(grid, esf01, centre, 0.25, 0.75)
        plateau = min(max(3.0 * min(rise, core_rise), 2.0), 0.7 * half_range)
        return Shape(centre, rise, left, right, plateau,
                     {"esf01": esf01, "rer": relative_edge_response(grid, esf01, centre)})

    def core_px(self, shape: Shape, snr: float, factor: float | None) -> float:
        return (factor or window_factor(snr)) * shape.scale_px

    def taper_factor(self, snr: float) -> float:
        return _snr_blend(snr, TAPER_FACTOR_NOISY, TAPER_FACTOR_CLEAN)

    @staticmethod
    def confident_snr(rows: int) -> float:
        return confident_snr(rows)

    def lsf(self, grid, values, background):
        step = float(grid[1] - grid[0])

        def adjoint(h):
            out = np.zeros((*np.shape(h)[:-1], grid.size))
            out[..., 2:] += h / (2 * step)
            out[..., :-2] -= h / (2 * step)
            return out
        return (*central_difference(grid, values), adjoint)

    def lsf_tail_amplitudes(self):
        # ESF = level + A / |s|: its slope is +A / s^2 on the left, -A / s^2 on the right
        return [np.array([0.0, 1.0]), np.array([0.0, -1.0])]

    def divisor(self, step, transfer, shape):
        return edge_divisor(step, transfer)

    def noise_gain(self, shape, contrast):
        return lambda f: 2 * np.pi * f

    def saturation_sides(self, sides):
        return sides

    def peak_mask(self, s, shape):
        return None


class EdgeEstimator:
    """A configured slanted-edge estimator: set up once, apply to many chips.

    Parameters
    ----------
    method : str, optional
        Resampling method, a key of :data:`imgmtf.estimate.resampling.METHODS`
        (default "msg").
    **settings
        The settings of :class:`imgmtf.estimate.settings.Settings` as
        keywords (``bootstrap=N`` for N bootstrap replicates, 0 for no
        intervals); ``snr_threshold=None`` uses the measured threshold for
        the edge's length (:func:`confident_snr`); ``lsf_window_factor=None``
        adapts the LSF window to the SNR (:func:`window_factor`).

    Raises
    ------
    ParameterError
        An unknown method or keyword, or a setting out of its range.
        Calling the estimator raises as :func:`measure_edge` does.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 100)
    >>> estimate = imgmtf.EdgeEstimator("msg", intervals=imgmtf.Intervals("none"))
    >>> abs(estimate(chip.image).mtf_nyquist - float(chip.true_mtf(0.5))) < 0.001
    True
    """

    def __init__(self, method: str = "msg", **settings: Any):
        self.settings: Settings = make_settings(method, **settings)

    @property
    def method(self) -> str:
        return self.settings.method

    def __call__(self, image: ArrayLike, *, roi: tuple[int, int, int, int] | None = None,
                 mask: np.ndarray | None = None, gsd_m: float | None = None,
                 saturation: tuple[float, float] | None = None, dtype: DTypeLike | None = None,
                 track_azimuth_deg: float | None = 0.0) -> EdgeResult:
        """Measure the edge in ``image`` (2-D array, DN); see :func:`measure_edge`."""
        with one_blas_thread():         # small matrices: threads cost more than they save
            m = run(EdgeKind(), image, self.settings, roi=roi, mask=mask, gsd_m=gsd_m, saturation=saturation,
                    dtype=dtype, track_azimuth_deg=track_azimuth_deg)
        return self._result(m)

    def measure_many(self, images: list[np.ndarray], masks: list[np.ndarray | None], **keywords: Any
                     ) -> list[EdgeResult | Exception]:
        """Measure the edge in each image, the work alike across them made
        together (:func:`imgmtf.estimate.many.run_many`): each the result of
        this estimator's call on it, or the exception the call raises.

        Parameters
        ----------
        images : list of numpy.ndarray
            The chips (2-D arrays, DN).
        masks : list of numpy.ndarray or None
            Each chip's mask (True for its pixels), or None for all.
        **keywords
            What every call takes alike (``gsd_m``, ``saturation``,
            ``dtype``, ``track_azimuth_deg``; see :func:`measure_edge`).

        Returns
        -------
        list of EdgeResult or Exception
            One per image, in order: a refusal is the exception the call
            raises (an :class:`imgmtf.errors.ImgmtfError` for the data's).

        Examples
        --------
        >>> import imgmtf
        >>> chips = [imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", a), 40).image for a in (5.0, 8.0)]
        >>> estimate = EdgeEstimator(intervals=imgmtf.Intervals("none"))
        >>> [r.mtf_nyquist for r in estimate.measure_many(chips, [None, None])] == [estimate(c).mtf_nyquist
        ...                                                                          for c in chips]
        True
        """
        with one_blas_thread():
            measured = run_many(EdgeKind(), images, self.settings, [{**keywords, "mask": m} for m in masks])
        return [self._outcome(m) for m in measured]

    def _outcome(self, m) -> EdgeResult | Exception:
        """A measurement's result, or the exception it or its making raised."""
        if isinstance(m, Exception):
            return m
        try:
            return self._result(m)
        except Exception as exc:        # as the call would have raised it
            return exc

    def _result(self, m) -> EdgeResult:
        """The pipeline's measurement as this estimator's result."""
        left, right = m.estimate.lsf.side_levels_dn
        return EdgeResult(
            **m.result_fields(), method=self.settings.method, params=m.params,
            polarity="rising" if right > left else "falling", warnings=m.warnings,
            bright_side=_bright_side(right > left, m.located.transposed), rer=m.shape.extra["rer"],
            esf_x_px=m.profile.grid, esf=(m.profile.values - left) / (right - left),
            levels_dn=(float(left), float(right)))


def measure_edge(image: ArrayLike, *, roi: tuple[int, int, int, int] | None = None, mask: np.ndarray | None = None,
                 method: str = "msg", gsd_m: float | None = None, saturation: tuple[float, float] | None = None,
                 force: bool = False, track_azimuth_deg: float | None = 0.0, dtype: DTypeLike | None = None,
                 **options: Any) -> EdgeResult:
    """Measure the MTF of the straight edge in ``image``.

    Parameters
    ----------
    image : array_like
        2-D image (DN) with one straight edge crossing it, 16 x 16 px at
        least.
    roi : (int, int, int, int), optional
        (x, y, width, height) crop, px.
    mask : ndarray of bool, optional
        Of the image's shape: True for the pixels that belong to the chip
        (a tilted ROI, a target cut out of its fill), the others left out.
    method : str, optional
        "msg" (default), "sliding", "spline" or "iso".
    gsd_m : float, optional
        Ground sample distance (m), to report cycles/m and metres.
    saturation : (float, float), optional
        (low, high) DN the sensor records; default an integer image's
        type range, none declared for floats (clipping is still detected
        from the values).
    force : bool, optional
        Measure even when a quality check fails, each failure a warning.
    track_azimuth_deg : float or None, optional
        The ground track's direction, degrees clockwise from the image's
        up (0, the default: rows along track); None when unknown.
    dtype : numpy dtype, optional
        The type the values were stored as, when ``image`` is a copy.
    **options
        Settings of :class:`imgmtf.estimate.settings.Settings`
        (``intervals``, ``bootstrap``, ``step_px``, ``lsf_half_width_px``, ``transfer``...).

    Returns
    -------
    EdgeResult
        The MTF along the edge's normal (cy/px; 1 at zero frequency), its
        figures with their intervals, and what they were computed from.

    Raises
    ------
    ParameterError
        A setting out of range or unknown.
    ImageContentError, TargetNotFoundError, UnsuitableTargetError
        The image cannot be measured; ``reason`` says why (the quality
        gate's codes, :mod:`imgmtf.estimate.gate`).

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 100, noise_std_dn=5.0, seed=1)
    >>> r = imgmtf.measure_edge(chip.image)
    >>> abs(r.mtf_nyquist - float(chip.true_mtf(0.5))) < 0.02
    True
    """
    return EdgeEstimator(method, force=force, **options)(
        image, roi=roi, mask=mask, gsd_m=gsd_m, saturation=saturation, dtype=dtype,
        track_azimuth_deg=track_azimuth_deg)


def _bright_side(rising: bool, transposed: bool) -> str:
    if transposed:
        return "below" if rising else "above"
    return "right" if rising else "left"


def _crossing_nearest(grid, esf01) -> float:
    """Position of the 0.5 crossing of the normalised ESF closest to 0."""
    s = np.sign(esf01 - 0.5)
    idx = np.nonzero(s[:-1] * s[1:] <= 0)[0]
    if idx.size == 0:
        return 0.0
    i = idx[np.argmin(np.abs(grid[idx]))]
    y0, y1 = esf01[i], esf01[i + 1]
    return float(grid[i] + (0.5 - y0) / (y1 - y0) * (grid[i + 1] - grid[i])) if y1 != y0 else float(grid[i])


def confident_snr(rows: int) -> float:
    """Lowest SNR at which an edge of ``rows`` rows gives 95 % of its MTF at
    Nyquist estimates within 5 % of the truth (measured for MTF ~0.27)."""
    return CONFIDENT_SNR_40_ROWS * math.sqrt(40.0 / max(rows, 1))


def window_factor(snr: float) -> float:
    """Half-width of the flat LSF window in units of the 10-90 % rise.

    A bias-variance trade measured on exact chips (docs/accuracy.md): 1.35
    rises keeps the truncation bias at Nyquist below 0.0005 for Gaussian,
    pixel and Butterworth blurs (longer tails are the tail model's), and is
    used at SNR >= 100; the noise of the flat tails grows with the window,
    so at SNR <= 30 the window shrinks to 0.9 rise (its taper from 1 to 0.35 of
    it), log-linearly in between: RMS error at Nyquist 0.0177 at SNR 25 on
    100 x 100 px Gaussian edges, against 0.0187 with 1 rise and half of it."""
    return _snr_blend(snr, WINDOW_FACTOR_NOISY, WINDOW_FACTOR_CLEAN)


def _snr_blend(snr: float, noisy: float, clean: float) -> float:
    """``noisy`` at SNR <= 30, ``clean`` at SNR >= 100, log-linear between."""
    if not math.isfinite(snr):
        return clean
    t = min(max(math.log(max(snr, 1e-9) / 30.0) / math.log(100.0 / 30.0), 0.0), 1.0)
    return noisy + t * (clean - noisy)
