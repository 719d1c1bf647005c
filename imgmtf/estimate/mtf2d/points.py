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
(:meth:`.stack.Stack.small_sample_factor`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ParameterError, TargetNotFoundError, UnsuitableTargetError
from ...safe_json import finite_values
from ...version import __version__
from ..intervals import Intervals, as_intervals
from ..results import finite
from .sources import FoundSources, Source, SourceTally, find_sources
from .stack import DirectionMTF, Stack

#: a uniformity of the targets' phases less likely than this is reported (pixel-locking), and the fewest targets tested
PIXEL_LOCK_P = 0.01
MIN_PHASE_TEST = 8
#: the directions' names: across and along the ground track, or the image's axes when the track is unknown
ACROSS, ALONG = "across-track", "along-track"
IMAGE_X, IMAGE_Y = "image-x", "image-y"


@dataclass(frozen=True, eq=False)
class PointsResult(SourceTally):
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
    phase_cells : int
        The quarter-pixel cells (of 16) the used targets' phases fall in.
    phase_uniform_p : float
        The p-value of their phases being uniform over the pixel
        (:func:`phase_coverage`); small: pixel-locked or few phases, which
        a warning names.

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
    phase_cells: int = 0
    phase_uniform_p: float = math.nan

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
        refusals = self.refusal_counts()
        snr = float(np.median([s.peak_snr for s in self.used])) if self.used else math.nan
        out = []
        for section in self.directions:
            row: dict[str, Any] = {
                "target": self.target, "method": self.method, "direction": section.direction,
                "normal_angle_deg": finite(section.angle_deg),
                "polarity": self.polarity, "snr": finite(snr), "noise_dn": finite(self.noise_dn),
                "mtf_nyquist": finite(section.mtf_nyquist),
                "mtf_nyquist_ci": [finite(section.mtf_nyquist_ci.low), finite(section.mtf_nyquist_ci.high)],
                "mtf50_cy_px": finite(section.mtf50_cy_px),
                "mtf50_ci_cy_px": [finite(section.mtf50_ci_cy_px.low), finite(section.mtf50_ci_cy_px.high)],
                "fwhm_px": finite(section.fwhm_px), "gsd_m": self.gsd_m,
                "mtf50_cy_m": finite(section.mtf50_cy_px / self.gsd_m) if self.gsd_m else None,
                "fwhm_m": finite(section.fwhm_px * self.gsd_m) if self.gsd_m else None,
                "points_used": len(self.used), "points_refused": len(self.refused),
                "points_refused_by": refusals, "point_size_px": self.point_size_px,
                "alias_weight": finite(self.alias_weight), "phase_cells": int(self.phase_cells),
                "phase_uniform_p": finite(self.phase_uniform_p),
                "roi": list(self.roi), "warnings": list(self.warnings), "params": dict(self.params),
                "imgmtf_version": __version__,
            }
            if curves:
                row["frequencies_cy_px"] = [round(float(f), 4) for f in section.frequencies_cy_px]
                row["mtf"] = finite_values(section.mtf)
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
    # a real PSF's transfer is Hermitian: |T(-f)| = |T(f)|, so the half plane fy >= 0 gives the whole grid
    upper = stack.mtf(f2d[None, :], f2d[f2d.size // 2:, None])
    mtf2d = np.vstack([upper[:0:-1, ::-1], upper])
    warnings = []
    cells, uniform_p = phase_coverage(np.array([[s.x_px, s.y_px] for s in found.used]))
    coverage = f"cover {cells} of the pixel's 16 quarter-pixel cells"
    if uniform_p < PIXEL_LOCK_P:
        warnings.append(f"the {len(found.used)} targets' sub-pixel phases are not spread evenly over the pixel (they "
                        f"{coverage}; uniform phases p={uniform_p:.2g}): their locations may be pixel-locked (pulled "
                        "towards pixel centres by a PSF the Gaussian fit does not match), which the stack cannot "
                        f"undo, and the aliases they leave weigh {stack.alias_weight:.2f} (0: a pixel tiled evenly): "
                        "the MTF near Nyquist leans on the Gaussian model they were located with")
    elif stack.alias_weight > 0.3:
        warnings.append(f"the {len(found.used)} targets' phases {coverage} and leave aliases of weight "
                        f"{stack.alias_weight:.2f} (0: a pixel tiled evenly): the MTF near Nyquist leans on the "
                        "Gaussian model they were located with")
    if stack.tail_note:
        warnings.append(stack.tail_note)
    if len(found.used) < 8 and settings.method != "none":
        warnings.append(f"only {len(found.used)} targets: the bootstrap over them is rough")
    rows, cols = np.asarray(image).shape
    params = {"point_size_px": float(point_size_px), "polarity": polarity, "stamp_radius_px": int(stamp_radius_px),
              "min_snr": float(min_snr), "min_separation_px": min_separation_px,
              "intervals": settings.as_dict()}
    return PointsResult(directions, psf, step, mtf2d, f2d, found.sources, found.polarity, float(point_size_px),
                        found.noise_dn, stack.alias_weight, gsd_m, (0, 0, cols, rows), params, tuple(warnings),
                        phase_cells=cells, phase_uniform_p=uniform_p)


def phase_coverage(centres_px: np.ndarray) -> tuple[int, float]:
    """How evenly targets at ``centres_px`` (x, y), px, sample the pixel:
    the quarter-pixel cells (of 16) their sub-pixel phases fall in, and the
    p-value of their phases being uniform (Rayleigh's test on each axis,
    the smaller; NaN under ``MIN_PHASE_TEST`` targets).  Targets placed at
    random give a large p; an array tiled by quarter pixels gives 1;
    locations pixel-locked by a biased fit (real stars' phases crowding at
    the pixel's centre) give a small one.

    Parameters
    ----------
    centres_px : numpy.ndarray, shape (n, 2)
        The targets' fitted centres, px (pixel centres at integers).

    Returns
    -------
    (int, float)
        The cells covered, and the p-value.

    Examples
    --------
    >>> from imgmtf.sensor.points import quarter_pixel_offsets
    >>> cells, p = phase_coverage(quarter_pixel_offsets() + 10.0)
    >>> cells, round(p, 6)
    (16, 1.0)
    >>> rng = np.random.default_rng(0)
    >>> cells, p = phase_coverage(np.round(rng.uniform(0, 50, (40, 2))) + rng.normal(0, 0.08, (40, 2)))
    >>> cells, p < 1e-6                                     # crowding at the pixels' centres
    (4, True)
    """
    centres = np.asarray(centres_px, float).reshape(-1, 2)
    if not len(centres):
        return 0, math.nan
    phases = centres - np.floor(centres)                  # 0 to 1 from a pixel's centre
    cells = len({(int(a), int(b)) for a, b in np.floor(phases * 4).clip(0, 3)})
    if len(centres) < MIN_PHASE_TEST:
        return cells, math.nan
    n = len(centres)
    r2 = np.abs(np.exp(2j * np.pi * phases).mean(axis=0)) ** 2
    z = n * r2
    # Rayleigh's p-value with its small-sample correction (Zar, Biostatistical Analysis, eq. 27.4)
    p = np.exp(np.sqrt(1 + 4 * n + 4 * (n * n - (n * z))) - (1 + 2 * n))
    return cells, float(np.clip(p, 0.0, 1.0).min())


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
