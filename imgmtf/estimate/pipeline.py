"""One profile pipeline for edges and bars: a short sequence of named
stages over a small typed state (:mod:`.state`, one record a stage).

Every estimate runs the same stages; a target kind (:class:`.kind.TargetKind`:
:class:`imgmtf.estimate.edge.EdgeKind`, :class:`imgmtf.estimate.pulse.PulseKind`)
supplies only what differs:

1. :func:`.chip.prepare_chip` -> :class:`.state.Chip`: validation, crop, mask,
   linearisation, left-out pixels, quantum, pixel noise, fill check;
2. :func:`locate_target` -> ``Located``: the kind seeds its line and locates
   it row by row (an edge by a Fermi fit, a bar by centroids); a robust line
   through the locations; every pixel's signed distance from it and its value;
3. :func:`.profile.rebuild_staircase` -> ``Samples``: a noise-free quantised
   edge's staircase rebuilt as the smooth ESF it samples (:mod:`.quantisation`);
4. :func:`.profile.read_profile` -> ``Profile``, ``Shape``: the samples smoothed
   onto a uniform grid by the chosen method (:mod:`.resampling`), classified
   as an edge or a bar; the kind's levels, centre and width;
5. :func:`.window.measure_noise` -> ``Noise``: the sides' scatter about their
   model, at least the quantisation floor q / sqrt(12); the SNR;
6. :func:`.window.choose_window` -> ``Window``: the LSF window's core (from the
   target's width, the SNR and the tails) and taper;
7. :func:`.profile.widen_profile` -> ``Profile``: resampled farther where the
   window reaches past it;
8. :func:`.window.blend_tails` -> ``TailedLSF``: the kind's LSF-like profile (an
   ESF's central difference, a pulse response above its background) kept as
   measured in the window, each side's tail model (a / x^2) beyond it;
9. :func:`.transform.transform_steps` -> ``Spectrum``: the transform divided by the transfer
   between the system's LSF and that profile (the kind's and the resampling
   method's); its figures;
10. :func:`.judge.judge` -> checks, warnings: the quality gate (:mod:`.gate`) and the
    registered profile checks (:mod:`.profile_checks`);
11. :func:`.intervals.intervals` -> ``FigureIntervals``: the figures' intervals
    by the chosen method (:mod:`.intervals`).
"""
from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from ..errors import ImgmtfError, TargetNotFoundError, UnsuitableTargetError
from . import gate
from .asks import Ask, Steps, alone
from .chip import prepare_chip
from .geometry import TargetGeometry, check_angle, direction_label, profile_samples, vertical_frame
from .intervals import Estimate, FigureIntervals, intervals
from .judge import judge_steps
from .kind import Shape, TargetKind, refuse_other_kind
from .prefit import Prefit
from .profile import read_profile_steps, rebuild_staircase, widen_profile_steps
from .resampling import Resampled, resample_profile
from .settings import Settings
from .sharpening import mtf_peak
from .spectrum import mtf_area
from .state import Chip, Located, Noise, Profile, Samples
from .transform import transform_steps
from .window import blend_tails, choose_window, measure_noise


@dataclass(frozen=True, eq=False)
class Measurement:
    """The pipeline's output, which each kind turns into its result type.

    Attributes
    ----------
    chip : Chip
        The pixels measured.
    located : Located
        The target's line and per-row locations.
    shape : Shape
        What the kind read off the profile (levels, centre, width, its own figures).
    noise : Noise
        The profile's noise and SNR.
    estimate : Estimate
        The samples, profile, window, tails and spectrum (what the intervals read).
    intervals : FigureIntervals
        The figures' intervals.
    checks : tuple of Check
        Every quality check run.
    warnings : tuple of str
        What the result must say.
    params : dict
        The settings used (provenance).
    frequencies_cy_px : numpy.ndarray
        Where the MTF is reported, cy/px.
    """

    chip: Chip
    located: Located
    shape: Shape
    noise: Noise
    estimate: Estimate
    intervals: FigureIntervals
    checks: tuple[gate.Check, ...]
    warnings: tuple[str, ...]
    params: dict[str, Any]
    frequencies_cy_px: np.ndarray

    @property
    def profile(self) -> Profile:
        """The resampled profile (an edge's ESF, a bar's PRF), DN on px."""
        return self.estimate.profile

    def result_fields(self) -> dict[str, Any]:
        """The :class:`.results.MTFResult` fields every kind fills alike;
        the kind adds ``method``, ``params``, ``polarity``, ``warnings`` and
        its own.

        Returns
        -------
        dict
            Field name to value.

        Examples
        --------
        >>> import imgmtf
        >>> from imgmtf.estimate.edge import EdgeKind
        >>> from imgmtf.estimate.settings import make_settings
        >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60)
        >>> fields = run(EdgeKind(), chip.image, make_settings()).result_fields()
        >>> fields["direction"], fields["rows_used"]
        ('across-track', 60)
        """
        geometry, spectrum = self.located.geometry, self.estimate.spectrum
        normal = normal_angle(geometry)
        peak = mtf_peak(spectrum.mtf, spectrum.noise_limit_cy_px)
        return dict(
            normal_angle_deg=normal, tilt_deg=geometry.tilt_deg,
            direction=direction_label(normal, self.chip.track_azimuth_deg),
            orientation="horizontal" if self.located.transposed else "vertical",
            rows_used=self.located.rows_used, rows_total=self.located.rows_total, snr=self.noise.snr,
            noise_dn=self.noise.noise_dn, mtf_nyquist=spectrum.mtf_nyquist, mtf50_cy_px=spectrum.mtf50_cy_px,
            mtf_nyquist_ci=self.intervals.mtf_nyquist, mtf50_ci_cy_px=self.intervals.mtf50_cy_px,
            fwhm_px=spectrum.fwhm_px, mtfa=mtf_area(spectrum.mtf), gsd_m=self.chip.gsd_m,
            frequencies_cy_px=self.frequencies_cy_px, mtf=spectrum.mtf(self.frequencies_cy_px),
            lsf_x_px=spectrum.lsf_x_px, lsf=spectrum.lsf, samples_x_px=self.estimate.samples.distance_px,
            samples_dn=self.estimate.samples.raw_dn, geometry=geometry, roi=self.chip.roi,
            noise_limit_cy_px=spectrum.noise_limit_cy_px, lsf_half_width_px=self.estimate.window.core_px,
            tail_fraction=self.estimate.lsf.tail_share, checks=self.checks, mtf_function=spectrum.mtf,
            mtf_peak=peak.mtf, mtf_peak_cy_px=peak.cy_px,
            sharpened=any(c.explained_by == "sharpening" for c in self.checks))


def run(kind: TargetKind, image: ArrayLike, settings: Settings, *, roi: tuple[int, int, int, int] | None = None,
        mask: np.ndarray | None = None, gsd_m: float | None = None, saturation: tuple[float, float] | None = None,
        dtype: DTypeLike | None = None, track_azimuth_deg: float | None = 0.0,
        prefit: Prefit | None = None) -> Measurement:
    """Measure the target of ``kind`` in ``image`` (2-D array, DN).

    Parameters
    ----------
    kind : TargetKind
        What the target brings (:class:`imgmtf.estimate.edge.EdgeKind`,
        :class:`imgmtf.estimate.pulse.PulseKind`).
    image : array_like
        2-D image, DN.
    settings : Settings
        The estimator's settings (:func:`imgmtf.estimate.settings.make_settings`).
    roi : (int, int, int, int), optional
        (x, y, width, height) crop, px.
    mask : numpy.ndarray of bool, optional
        Of the image's shape, True for the pixels that belong to the chip
        (a tilted ROI, a target cut out of its fill); None for all.
    gsd_m : float, optional
        Ground sample distance (m).
    saturation : (float, float), optional
        (low, high) DN the sensor records, or None for an integer image's
        type range (floats: none declared).
    dtype : numpy dtype, optional
        The type the values were stored as when ``image`` is a float copy
        (a file's samples), for quantisation and integer limits.
    track_azimuth_deg : float or None, optional
        Direction of the ground track in the image, degrees clockwise from
        the image's up direction (0: rows along track, as in L0/L1
        products); None when unknown (map-projected).
    prefit : Prefit, optional
        The chip's first stages made among other chips'
        (:func:`.prefit.prefit_chips`, from these arguments): the same
        result, sooner.

    Returns
    -------
    Measurement
        The records of every stage, which the kind turns into its result.

    Raises
    ------
    ImgmtfError
        Every refusal: unusable input, no target, a failed quality check.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60)
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> abs(m.estimate.spectrum.mtf_nyquist - float(chip.true_mtf(0.5))) < 0.002, m.located.rows_used
    (True, 60)
    """
    return alone(run_steps(kind, image, settings, roi=roi, mask=mask, gsd_m=gsd_m, saturation=saturation,
                           dtype=dtype, track_azimuth_deg=track_azimuth_deg, prefit=prefit))


def run_steps(kind: TargetKind, image: ArrayLike, settings: Settings, *, prefit: Prefit | None = None,
              **chip_options: Any) -> Steps[Measurement]:
    """:func:`run` as a generator of asks (:mod:`.asks`): at each stage
    whose work is alike across chips it yields an :class:`.asks.Ask` and
    takes its answer (made among other chips' by :func:`.many.run_many`,
    alone by :func:`run`), then returns the measurement.  It asks for the
    profile's resamplings (``resample``) and the quality gate's fits
    (:func:`judge_steps`).
    ``chip_options``: :func:`run`'s keywords of the chip (``roi``, ``mask``...)."""
    chip = prefit.chip if prefit is not None else prepare_chip(image, settings, **chip_options)
    try:
        located = yield from locate_target_steps(kind, chip, force=settings.force, prefit=prefit)
        samples = rebuild_staircase(kind, located.samples, chip.quantum_dn)
        read, shape = yield from read_profile_steps(kind, samples, settings, located.checks)
        noise = measure_noise(kind, samples, shape, chip.quantum_dn)
        window = choose_window(kind, samples, shape, noise, settings, chip.quantum_dn)
        profile = yield from widen_profile_steps(read, samples, shape, window, settings, kind.name)
        lsf = blend_tails(kind, samples, profile, shape, window)
        spectrum = yield from transform_steps(kind, samples, profile, shape, noise, window, lsf, settings)
        checks, warnings = yield from judge_steps(kind, chip, located, samples, shape, noise, window, spectrum,
                                                  settings)
    except ImgmtfError as exc:
        raise _points_instead(exc, kind, chip, image) from None
    estimate = Estimate(samples, profile, read, shape.centre, window, lsf, spectrum, kind.tail_power,
                        kind.subtracts_background, kind.lsf, functools.partial(_resample_weighted, samples, settings),
                        kind.read_width(read.grid, shape), kind.name)
    found = intervals(estimate, **asdict(settings.intervals))
    warnings += found.warnings
    if chip.track_azimuth_deg is None:
        warnings.append("the image is not in sensor geometry (map-projected): its rows are not along "
                        "track, so the direction is unknown; give the track's azimuth to label it")
    params = {**settings.as_dict(), **profile.resampled.params, "lsf_half_width_px": window.core_px,
              "lsf_taper_px": window.taper_px, "track_azimuth_deg": chip.track_azimuth_deg,
              "dequantised": samples.dequantised, **chip.left_out_px}
    return Measurement(chip, located, shape, noise, estimate, found, tuple(checks), tuple(warnings), params,
                       settings.frequencies_cy_px)


def _points_instead(exc: ImgmtfError, kind: TargetKind, chip: Chip, image: ArrayLike) -> ImgmtfError:
    """A chip refused as an edge or a bar that holds point targets instead
    says so (reason ``points``), or a Siemens star (reason ``star``); any
    other refusal stands as it was.  The
    chip's own pixels have its outliers (points among them) left out: the
    image as given is what is looked at."""
    from .mtf2d.sources import points_seen
    if exc.reason not in ("no-target", "two-targets", "not-straight", "unsuitable", "not-an-edge", "not-a-bar",
                          "angle", "snr", "non-uniform"):
        return exc
    x0, y0 = chip.origin
    rows, cols = chip.pixels.shape
    pixels = np.asarray(image, float)
    seen = points_seen(pixels[y0: y0 + rows, x0: x0 + cols]) if pixels.ndim == 2 else None
    if seen is None:
        from .star.centre import star_seen
        star = star_seen(pixels[y0: y0 + rows, x0: x0 + cols]) if pixels.ndim == 2 else None
        if star is None:
            return exc
        return UnsuitableTargetError(f"no {kind.name} here: the chip holds {star}, not a line", reason="star")
    return UnsuitableTargetError(f"no {kind.name} here: the chip holds {seen}, not a line", reason="points")


def locate_target(kind: TargetKind, chip: Chip, *, force: bool = False, prefit: Prefit | None = None) -> Located:
    """The kind's target in the chip: its seed line, its per-row locations
    and the robust line through them (in the vertical frame), every
    pixel's signed distance from that line as a profile sample, and the
    gate's checks of the line and its rows.

    Where the target cannot be followed, the failure explains less than
    the other kind of target it turns out to be (:func:`.kind.refuse_other_kind`)
    or a failed check of the chip or the seed (fill, a second target),
    which are raised instead unless ``force``.

    Parameters
    ----------
    kind : TargetKind
        The target's kind.
    chip : Chip
        The prepared chip.
    force : bool, optional
        Raise the failure itself rather than a failed earlier check.
    prefit : Prefit, optional
        The chip's seed and rows' fit made among other chips'
        (:func:`.prefit.prefit_chips`).

    Returns
    -------
    Located
        The line, the rows, the samples and the checks so far.

    Raises
    ------
    ImgmtfError
        No target of the kind, or one that cannot be followed.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> located = locate_target(EdgeKind(), m.chip)
    >>> located.rows_used, located.geometry.slope == m.located.geometry.slope
    (60, True)
    """
    return alone(locate_target_steps(kind, chip, force=force, prefit=prefit))


def locate_target_steps(kind: TargetKind, chip: Chip, *, force: bool = False, prefit: Prefit | None = None
                        ) -> Steps[Located]:
    """:func:`locate_target` as a generator of asks (:mod:`.asks`): the
    line's checks (``line-checks``) are made among other chips' (its
    Examples: :func:`locate_target`, a batch of one).
    """
    checks = list(chip.checks)
    try:
        line, seed_checks = kind.seed(chip.pixels, chip.noise_dn) if prefit is None else prefit.seeded()
        checks += seed_checks
        frame, seed_x, transposed = vertical_frame(chip.pixels, line)
        try:
            geometry = (kind.locate(frame, seed_x, transposed) if prefit is None or prefit.fit is None
                        else kind.locate_fitted(frame, seed_x, transposed, prefit.fit))
            check_angle(geometry, kind.name)
            distance, values, rows, half_range = profile_samples(frame, geometry, kind.name)
        except (TargetNotFoundError, UnsuitableTargetError):
            refuse_other_kind(kind, frame, seed_x)
            raise
    except ImgmtfError:
        if not force:
            gate.enforce(checks, force=False)
        raise
    checks += yield Ask("line-checks", (geometry, geometry.location_sd_px, kind.name))
    checks.append(gate.rows_check(int(geometry.kept.sum()), kind.name))
    return Located(geometry, transposed, int(frame.shape[0]), Samples(distance, values, values, rows, half_range),
                   tuple(checks))


def normal_angle(geometry: TargetGeometry) -> float:
    """Angle (deg, in (-90, 90]) of the target's normal from the image's x
    axis (y down): the tilt of the target from the column axis.

    Parameters
    ----------
    geometry : TargetGeometry
        The target's line in the vertical frame.

    Returns
    -------
    float
        The normal's angle, degrees.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60)
    >>> round(normal_angle(imgmtf.measure_edge(chip.image).geometry), 1)
    6.0
    """
    vertical = -math.degrees(math.atan(geometry.slope))
    if not geometry.transposed:
        return vertical
    angle = 90.0 - vertical
    return angle - 180.0 if angle > 90.0 else angle


def _resample_weighted(samples: Samples, settings: Settings, keep: np.ndarray, weights: np.ndarray,
                       half_range_px: float) -> Resampled:
    """The samples ``keep`` selects resampled as the estimate's profile was,
    under a stack of ``weights`` (the bootstrap's replicates)."""
    return resample_profile(samples.distance_px[keep], samples.values_dn[keep], method=settings.method,
                            step=settings.step_px, half_range=half_range_px, weights=weights,
                            **settings.method_options)
