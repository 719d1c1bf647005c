"""One profile pipeline for edges and bars.

Every estimate runs the same stages; a target kind (:class:`.kind.TargetKind`:
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
from dataclasses import dataclass

import numpy as np

from ..errors import ImgmtfError, ParameterError, TargetNotFoundError, UnsuitableTargetError
from ..inputs import as_array, check_number, prepare_image, quantum, saturation_levels
from ..metrics import fwhm
from ..transfer import full_scale
from . import gate
from .detection import robust_noise
from .evidence import Evidence
from .geometry import (
    TargetGeometry,
    check_angle,
    direction_label,
    profile_samples,
    vertical_frame,
)
from .intervals import Interval
from .intervals.bootstrap import bootstrap_intervals
from .intervals.influence import influence_intervals
from .kind import TargetKind, refuse_other_kind
from .outliers import isolated_outliers
from .profile_checks import run_profile_checks
from .quantisation import dequantise
from .resampling import resample_profile
from .settings import Settings
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
from .tails import fit_side, model_reach, outer_samples, tail_integral

TAPER_FACTOR = 1.0                # the window's raised-cosine taper, in units of its flat half-width
TAIL_FIT_MAX_START = 0.6          # the tail fit starts at most this far out, as a fraction of the range
LONG_TAIL_SHARE = 0.03            # tails beyond the core holding more of the signal keep the clean window
INITIAL_SPAN_PX = 16.0            # the profile is first resampled this far from the line
CORE_STEP_PX = 0.5                # the core grows in these steps while the tail model misfits
BACKGROUND_FRACTION = 2.0 / 3.0   # a bar's background is read from the samples beyond this share of the range
WIDTH_SHARE_WARNING = 0.5         # an estimated width making more of the variance at Nyquist is worth a warning
MASK_SCAN_STEP_CY_PX = 0.005      # where a divisor's zeros hide the MTF is looked for on this grid, to 2 cy/px



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
    kind : TargetKind
        What the target brings (:class:`imgmtf.estimate.edge.EdgeKind`,
        :class:`imgmtf.estimate.pulse.PulseKind`).
    image : array_like
        2-D image, DN.
    settings : Settings
        The estimator's settings (:func:`make_settings`).
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

    Returns
    -------
    Measurement
        The figures and arrays the kind turns into its result.

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
        tails = [tail_integral(s, v, side, core, half_range, kind) for side in (-1, 1)]
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
        nyquist_ci, mtf50_ci, width_share = influence_intervals(
            settings.intervals, mtf, mtf_nyquist, f50, resampled, span, x, data_at, lsf, c, w, lsf_adjoint,
            tail_shape, sides, to_amplitude, amplitudes, kind, d, v, row, tail_share, rebuilt is not None,
            narrowed, width_influence)
        if width_share is not None and width_share > WIDTH_SHARE_WARNING:
            warnings.append(
                f"the bar's width, read off its profile ({shape.extra['width_px']:.3f} px), is uncertain "
                f"enough to make {100 * width_share:.0f} % of the variance at Nyquist: give the width "
                "if it is known")
    elif settings.intervals.method == "bootstrap":
        if width_influence is not None:
            warnings.append(f"the bootstrap holds the bar's width ({shape.extra['width_px']:.3f} px, read "
                            "off its profile) fixed, so its intervals leave out the width's uncertainty: "
                            "give the width if it is known, or use the default (influence) intervals")
        nyquist_ci, mtf50_ci = bootstrap_intervals(
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
