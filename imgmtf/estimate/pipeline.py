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
9. :func:`transform` -> ``Spectrum``: the transform divided by the transfer
   between the system's LSF and that profile (the kind's and the resampling
   method's); its figures;
10. :func:`judge` -> checks, warnings: the quality gate (:mod:`.gate`) and the
    registered profile checks (:mod:`.profile_checks`);
11. :func:`.intervals.intervals` -> ``FigureIntervals``: the figures' intervals
    by the chosen method (:mod:`.intervals`).
"""
from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from ..errors import ImgmtfError, TargetNotFoundError, UnsuitableTargetError
from ..metrics import fwhm
from . import gate
from .asks import Ask, Steps, alone
from .blocks import block_boundaries
from .chip import prepare_chip
from .evidence import evidence_of
from .geometry import TargetGeometry, check_angle, direction_label, profile_samples, vertical_frame
from .intervals import Estimate, FigureIntervals, intervals
from .kind import Shape, TargetKind, refuse_other_kind
from .prefit import Prefit
from .profile import read_profile_steps, rebuild_staircase, widen_profile_steps
from .profile_checks import run_profile_checks
from .resampling import Resampled, resample_profile
from .settings import Settings
from .settling import settled_sides
from .sharpening import mtf_peak, sharpening_check
from .spectrum import (
    MIN_TRANSFER,
    NYQUIST,
    corrected_mtf,
    mtf50,
    mtf_area,
    noise_limited_frequency,
    restore_lsf,
    white_noise_mtf_sd,
)
from .state import Chip, Located, Noise, Profile, Samples, Spectrum, TailedLSF, Window
from .window import blend_tails, choose_window, measure_noise

MASK_SCAN_STEP_CY_PX = 0.005      # where a divisor's zeros hide the MTF is looked for on this grid, to 2 cy/px


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
        spectrum = transform(kind, samples, profile, shape, noise, window, lsf, settings)
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


def transform(kind: TargetKind, samples: Samples, profile: Profile, shape: Shape, noise: Noise, window: Window,
              lsf: TailedLSF, settings: Settings) -> Spectrum:
    """The MTF: the windowed profile's transform divided by the transfer
    between the system's LSF and that profile (the kind's, times the
    resampling method's where ``settings.correct``); the white-noise
    level it is judged against, where it falls into that noise, the
    recovered LSF and the figures.

    Parameters
    ----------
    kind : TargetKind
        The target's kind (its divisor and noise gain).
    samples : Samples
        The profile's samples (their density).
    profile : Profile
        The resampled profile (its method's transfer).
    shape : Shape
        What the kind read off the profile.
    noise : Noise
        The profile's noise and SNR.
    window : Window
        The LSF window.
    lsf : TailedLSF
        The windowed LSF-like profile.
    settings : Settings
        Whether the resampling's transfer is divided out (``correct``).

    Returns
    -------
    Spectrum
        The MTF (cy/px, 1 at zero frequency), its noise, the recovered LSF
        and the figures.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> e = m.estimate
    >>> spectrum = transform(EdgeKind(), e.samples, e.profile, m.shape, m.noise, e.window, e.lsf, make_settings())
    >>> spectrum.mtf_nyquist == e.spectrum.mtf_nyquist
    True
    """
    divisor = kind.divisor(lsf.step_px, profile.resampled.transfer if settings.correct else None, shape)
    mtf = corrected_mtf(lsf.combined, lsf.step_px, divisor)
    density = samples.distance_px.size / (2.0 * samples.half_range_px)
    white = white_noise_mtf_sd(noise.snr, 2.0 * window.core_px + window.taper_px, density,
                               kind.noise_gain(shape, noise.contrast_dn))
    noise_sd = functools.partial(_corrected_noise_sd, white=white, divisor=divisor)
    noise_limit = noise_limited_frequency(mtf, noise_sd)
    lsf_x, restored = restore_lsf(lsf.combined, lsf.x_px, divisor, noise_limit, min_divisor=kind.restore_min_divisor)
    return Spectrum(divisor, mtf, noise_sd, noise_limit, lsf_x, restored, float(mtf(np.array([NYQUIST]))[0]),
                    mtf50(mtf), fwhm(lsf_x, restored))


def judge(kind: TargetKind, chip: Chip, located: Located, samples: Samples, shape: Shape, noise: Noise,
          window: Window, spectrum: Spectrum, settings: Settings) -> tuple[list[gate.Check], list[str]]:
    """The quality gate: every check (saturation, the sides, SNR, MTF above
    its noise, the figures, then the registered profile checks) added to
    those run so far, enforced (failures raise unless ``settings.force``),
    and the warnings the result must carry.

    Parameters
    ----------
    kind : TargetKind
        The target's kind.
    chip : Chip
        The prepared chip (its limits, quantum, noise and warnings).
    located : Located
        The line, its rows and the checks so far.
    samples : Samples
        The profile's samples (the gate reads their raw values).
    shape : Shape
        What the kind read off the profile.
    noise : Noise
        The profile's noise and SNR.
    window : Window
        The LSF window.
    spectrum : Spectrum
        The MTF and its figures.
    settings : Settings
        The SNR threshold and ``force``.

    Returns
    -------
    list of Check, list of str
        Every check run, and the warnings.

    Raises
    ------
    ImgmtfError
        A failed check, unless ``settings.force``.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> e = m.estimate
    >>> checks, warnings = judge(EdgeKind(), m.chip, m.located, e.samples, m.shape, m.noise, e.window,
    ...                          e.spectrum, make_settings())
    >>> all(check.passed for check in checks), warnings
    (True, [])
    """
    return alone(judge_steps(kind, chip, located, samples, shape, noise, window, spectrum, settings))


def judge_steps(kind: TargetKind, chip: Chip, located: Located, samples: Samples, shape: Shape, noise: Noise,
                window: Window, spectrum: Spectrum, settings: Settings) -> Steps[tuple[list[gate.Check], list[str]]]:
    """:func:`judge` as a generator of asks (:mod:`.asks`): the sides'
    saturation (``saturation``), uniformity (``side-checks``), settling (``settled-sides``), block
    jumps (``block-boundaries``) and the blur check's widths of its halves and thirds (``blur-widths``,
    :attr:`.evidence.Evidence.blur_widths`) are fitted among other chips' (its Examples: :func:`judge`,
    a batch of one).
    """
    distance, raw, centre = samples.distance_px, samples.raw_dn, shape.centre
    offsets = distance - centre
    contrast, quantum_dn = noise.contrast_dn, chip.quantum_dn
    side_masks = [("dark" if (shape.low <= shape.high) == (i == 0) else "bright", mask, None)
                  for i, mask in enumerate((offsets <= -shape.plateau_px, offsets >= shape.plateau_px))]
    sides = kind.saturation_sides(side_masks)
    checks = list(located.checks)
    checks += yield Ask("saturation", dict(
        distance=distance, values=raw, centre=centre, rise_px=shape.scale_px, sides=sides, limits=chip.limits,
        quantum=quantum_dn, noise_free=noise.noise_dn <= max(1.5 * quantum_dn / math.sqrt(12.0), 1e-9 * contrast),
        bright_core=kind.peak_mask(offsets, shape), monotone=kind.monotone, contrast=contrast,
        bar_edge_px=kind.known_half_width_px(shape)))
    # each side's texture against its own pixel noise (linearisation scales it with the level)
    side_noise = (chip.noise_at(shape.low), chip.noise_at(shape.low if kind.profile == "bar" else shape.high))
    side_names = tuple(name for name, _, _ in kind.saturation_sides(side_masks))
    checks += yield Ask("side-checks", (distance, raw, samples.rows.astype(float), centre, shape.plateau_px,
                                        contrast, side_noise, kind.tail_power, (side_names[0], side_names[1])))
    threshold = settings.snr_threshold or kind.confident_snr(located.rows_used)
    snr_failures, snr_warnings = gate.snr_checks(noise.snr, threshold, located.rows_used, kind.name)
    checks += snr_failures
    evidence = evidence_of(kind, chip, located, samples, shape, noise)
    evidence = replace(evidence, blur_widths=(yield Ask("blur-widths", evidence)))
    settled = yield Ask("settled-sides", evidence)
    blocks = yield Ask("block-boundaries", evidence)
    # an MTF above 1: a sharpening kernel's (measured, and said) or trouble (refused)
    excess, sharpening_notes, _, _ = sharpening_check(
        gate.mtf_excess_check(spectrum.mtf, spectrum.noise_sd, spectrum.noise_limit_cy_px), spectrum, evidence)
    checks.append(excess)
    first_hidden, nyquist_hidden = _divisor_zeros(spectrum)
    figures = _figures_check(spectrum, first_hidden, nyquist_hidden)
    checks.append(figures)
    # the registered checks come last: a failure above (a sharpened halo) names the cause better
    profile_checks, profile_warnings = run_profile_checks(evidence, made={block_boundaries: blocks,
                                                                                settled_sides: settled})
    checks += profile_checks
    warnings = (list(gate.enforce(checks, settings.force)) + snr_warnings + sharpening_notes + profile_warnings
                + list(chip.warnings))
    if kind.profile != "bar" and figures.passed and not math.isfinite(spectrum.mtf50_cy_px):
        # hidden by the corrections (the check passed it as masked); a bar's sinc is its kind's to say
        warnings.append(f"no MTF50: the MTF is still above 0.5 at {first_hidden:.2f} cy/px, where the "
                        "profile's corrections hide it (a target sharper than the profile resolves, or not a "
                        "clean one)")
    if window.cut:
        warnings.append(f"the LSF window's core ({window.core_px:.2f} px) is narrower than the {kind.name}'s width "
                        f"({shape.scale_px:.2f} px): it cuts the LSF, and the MTF reads high")
    return checks, warnings


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


def _divisor_zeros(spectrum: Spectrum) -> tuple[float, bool]:
    """Where the divisor's zeros (a bar's sinc, the resampling's or the
    derivative's transfer) hide the MTF: its first hidden frequency below
    2 cy/px (inf where none), and whether Nyquist is hidden."""
    f_check = np.arange(0.0, 2.0, MASK_SCAN_STEP_CY_PX)
    hidden = np.abs(spectrum.divisor(f_check) / spectrum.divisor(np.zeros(1))) < MIN_TRANSFER
    first_hidden = float(f_check[np.argmax(hidden)]) if hidden.any() else math.inf
    return first_hidden, bool(hidden[int(round(NYQUIST / MASK_SCAN_STEP_CY_PX))])


def _figures_check(spectrum: Spectrum, first_hidden: float, nyquist_hidden: bool) -> gate.Check:
    """The figures' check, knowing where the divisor's zeros
    (:func:`_divisor_zeros`) hide the MTF: a figure there is rightly missing."""
    return gate.figures_check(
        spectrum.mtf_nyquist, spectrum.mtf50_cy_px, spectrum.fwhm_px, nyquist_masked=nyquist_hidden,
        mtf50_masked=(math.isfinite(first_hidden)
                      and float(spectrum.mtf(np.array([first_hidden - 0.01]))[0]) > 0.5))


def _corrected_noise_sd(f: ArrayLike, *, white: Callable, divisor: Callable) -> np.ndarray:
    """The MTF's noise at ``f`` (cy/px): the white noise divided by the
    corrections as the MTF is."""
    f = np.atleast_1d(np.asarray(f, float))
    return white(f) / np.maximum(np.abs(divisor(f) / divisor(np.zeros(1))), MIN_TRANSFER)


def _resample_weighted(samples: Samples, settings: Settings, keep: np.ndarray, weights: np.ndarray,
                       half_range_px: float) -> Resampled:
    """The samples ``keep`` selects resampled as the estimate's profile was,
    under a stack of ``weights`` (the bootstrap's replicates)."""
    return resample_profile(samples.distance_px[keep], samples.values_dn[keep], method=settings.method,
                            step=settings.step_px, half_range=half_range_px, weights=weights,
                            **settings.method_options)
