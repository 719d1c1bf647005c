"""The MTF in every direction from a Siemens star (ISO 12233:2017's
sinusoidal s-SFR star, or a binary one): its small pipeline, beside the 1-D
pipeline of edges and bars.

located (:mod:`.centre`: the centre, N, the profile) -> rings fitted
(:mod:`.rings`: each ring of each direction's sector pair, the known
sinusoid in angle) -> divided by the full contrast (:mod:`.contrast`) ->
smoothed against frequency ``f = N / (2 pi r)`` (:mod:`.curve`) -> read at
Nyquist and at MTF50, with intervals from the rings' residuals and the
error the model leaves on exact chips (:data:`MODEL_ERROR_MTF`).

A ring's modulation is complex; its phase at low frequency is the star's,
so that the real part is the MTF with its sign (the OTF of a symmetric
PSF) and the imaginary part what an asymmetric PSF shifts; the MTF is the
modulus of the two smoothed.
"""
from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np

from ...errors import ImageContentError, ParameterError, TargetNotFoundError
from ..intervals import Interval, Intervals, as_intervals
from .centre import locate_star
from .contrast import Contrast, full_contrast
from .curve import Curve, smooth
from .result import StarDirection, StarResult
from .rings import Rings, direction_angles, fit_rings

#: the highest frequency a ring is read at, cy/px (inside, the star is far beyond any sensor's resolution)
TOP_CY_PX = 0.8
#: the unresolved zone: where the MTF averaged over the directions falls to this
UNRESOLVED_MTF = 0.1
#: above this lowest frequency, cy/px, an extrapolated full contrast is warned of
FAR_EXTRAPOLATION_CY_PX = 0.15
#: a binary star's levels and its extrapolation may part by this share before a warning
CONTRAST_AGREEMENT = 0.03
#: the error the rings' model leaves on exact chips (bench/star_accuracy.py: up to 0.003 in MTF where the
#: wavefronts' curvature and the sector's width pull it), added to every value's so that no interval is narrower
MODEL_ERROR_MTF = 0.003
#: the rings' reduced chi-square about a curve above which the model is said not to hold
MAX_SCATTER = 4.0
#: ... and by more than this in MTF units
MAX_MISFIT = 0.005


def direction_names(angles_deg: np.ndarray, track_azimuth_deg: float | None) -> list[str]:
    """The directions' names: the first "across-track" and the one 90 deg
    on "along-track" (the image's "image-x" and "image-y" when the track
    is unknown), the others their angle ("22.5deg")."""
    first, second = ("image-x", "image-y") if track_azimuth_deg is None else ("across-track", "along-track")
    names = []
    for k, angle in enumerate(angles_deg):
        offset = (angle - angles_deg[0]) % 180.0
        names.append(first if k == 0 else second if abs(offset - 90.0) < 1e-9 else f"{angle:g}deg")
    return names


def measure_star(image: np.ndarray, *, profile: str = "auto", cycles: int | None = None, n_directions: int = 8,
                 intervals: Intervals | str | int | None = None, gsd_m: float | None = None,
                 track_azimuth_deg: float | None = 0.0,
                 saturation: tuple[float, float] | None = None) -> StarResult:
    """The MTF in ``n_directions`` directions from the Siemens star filling
    ``image`` (see the module).

    Parameters
    ----------
    image : numpy.ndarray, shape (rows, cols)
        The chip, DN, linear in light, the star's centre inside it and its
        pattern out to the nearest border.
    profile : {"auto", "sinusoidal", "binary"}, optional
        The star's profile (default: told from its outer circles).
    cycles : int, optional
        N, periods around the centre (default: the strongest angular
        harmonic).
    n_directions : int, optional
        Directions over 180 deg (default 8; 4 to 36), each read on two
        opposite sectors of ``180 / n_directions`` deg.
    intervals : Intervals, str or int, optional
        "none" for none; otherwise the intervals at its confidence (default
        0.95), from the rings' residuals.
    gsd_m : float, optional
        The pixel on the ground, m.
    track_azimuth_deg : float or None, optional
        The ground track's direction, deg clockwise from the image's up (0,
        the default: rows along track); the first direction is across it.
        None: unknown, the first direction along the image's x.
    saturation : (float, float), optional
        (low, high) DN the sensor records: clipped pixels are warned of.

    Returns
    -------
    StarResult
        The MTF in each direction, the star's centre, cycles, contrast and
        unresolved zone.

    Raises
    ------
    UnsuitableTargetError
        (reason ``not-a-star``) no Siemens star fills the chip.
    TargetNotFoundError
        The star's resolved rings do not fit on the chip.
    ImageContentError
        Not a 2-D image of finite values.
    ParameterError
        A bad setting.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.sensor.star import SiemensStar, render_star
    >>> from imgmtf.sensor.stages import Detector, GaussianOptics
    >>> sensor = imgmtf.Sensor(stages=[GaussianOptics(0.45, 0.6), Detector(1.0, 1.0)])
    >>> chip = render_star(sensor, SiemensStar(cycles=60), 161, bits=None)
    >>> result = measure_star(chip.image, intervals="none")
    >>> across, along = result.direction("across-track"), result.direction("along-track")
    >>> round(across.mtf_nyquist, 3), round(float(chip.true_mtf(0.5, 0.0)), 3)
    (0.236, 0.234)
    >>> round(along.mtf50_cy_px, 3), round(chip.true_mtf50_cy_px(90.0), 3)
    (0.282, 0.281)
    """
    data = _checked(image)
    if profile not in ("auto", "sinusoidal", "binary"):
        raise ParameterError(f"star profile must be auto, sinusoidal or binary, got {profile!r}")
    if isinstance(n_directions, bool) or not isinstance(n_directions, (int, np.integer)) \
            or not 4 <= n_directions <= 36:
        raise ParameterError(f"n_directions must be an integer from 4 to 36, got {n_directions!r}")
    settings = as_intervals("influence" if intervals is None else intervals)
    geometry = locate_star(data, profile=profile, cycles=cycles)
    n = geometry.cycles
    inner = max(3.0, n / (2.0 * math.pi * TOP_CY_PX))
    outer = geometry.outer_radius_px
    if outer < inner + 8.0:
        raise TargetNotFoundError(f"the star's {n} cycles leave {outer - inner:.0f} px between the radius where "
                                  f"they reach {TOP_CY_PX} cy/px ({inner:.0f} px) and the chip's border: a larger "
                                  "chip")
    first = 0.0 if track_azimuth_deg is None else float(track_azimuth_deg) % 180.0
    rings = fit_rings(data, geometry.x_px, geometry.y_px, n, geometry.profile, inner_px=inner, outer_px=outer,
                      n_directions=int(n_directions), first_deg=first)
    contrast = full_contrast(rings, data, geometry.x_px, geometry.y_px, n, geometry.profile, outer)
    z = NormalDist().inv_cdf(0.5 + settings.confidence / 2.0) if settings.method != "none" else math.nan
    names = direction_names(direction_angles(int(n_directions), first), track_azimuth_deg)
    directions = tuple(_direction(rings, contrast, k, name, z) for k, name in enumerate(names))
    noise = float(np.nanmedian(rings.residual_dn))
    amplitude = contrast.modulation * float(np.nanmedian(rings.mean_dn))
    star_range = amplitude * (math.pi / 2 if geometry.profile == "binary" else 2.0)
    unresolved = _unresolved_radius(directions, n)
    warnings = _warnings(data, geometry.profile, contrast, directions, saturation, inner, outer, n)
    rows, cols = data.shape
    params = {"profile": profile, "cycles": cycles, "n_directions": int(n_directions),
              "intervals": settings.as_dict(), "ring_top_cy_px": TOP_CY_PX}
    return StarResult(directions, (geometry.x_px, geometry.y_px), geometry.centre_rms_px, n, geometry.profile,
                      contrast.modulation, contrast.method, inner, outer, unresolved, noise,
                      star_range / noise if noise > 0 else math.inf, gsd_m, (0, 0, cols, rows), params,
                      tuple(warnings))


def _checked(image: np.ndarray) -> np.ndarray:
    data = np.asarray(image, float)
    if data.ndim != 2:
        raise ImageContentError(f"a star chip must be a 2-D image, got shape {data.shape}")
    if min(data.shape) < 32:
        raise ImageContentError(f"a star chip must be at least 32 x 32 px, got {data.shape[1]} x {data.shape[0]}")
    if not np.isfinite(data).all():
        raise ImageContentError("the star chip holds non-finite values (NaN or infinity)")
    return data


def _direction(rings: Rings, contrast: Contrast, k: int, name: str, z: float) -> StarDirection:
    """One direction's rings divided by the full contrast, smoothed, read."""
    rotated = rings.modulation[k] * np.exp(-1j * contrast.phase_rad) / contrast.modulation
    errors = rings.standard_error[k] / contrast.modulation
    relative = contrast.standard_error / contrast.modulation
    a, b = contrast.curvature[k]

    def below(f):                         # the extrapolation's curve; its error is the contrast's, added below
        return np.exp(-a * f ** 2 - b * f ** 4), 0.0 * f
    real = smooth(rings.frequencies_cy_px, rotated.real, errors, below=below)
    imaginary = smooth(rings.frequencies_cy_px, rotated.imag, errors, below=lambda f: (0.0 * f, 0.0 * f))
    mtf = np.hypot(real.mtf, imaginary.mtf)
    # the full contrast's error is every value's in proportion; the model's own beside the noise's
    error = np.sqrt(real.standard_error ** 2 + (mtf * relative) ** 2 + MODEL_ERROR_MTF ** 2)
    curve = Curve(real.frequencies_cy_px, mtf, error, real.scatter)
    nyquist, nyquist_error = curve.at(0.5)
    mtf50, mtf50_error = curve.crossing(0.5)
    return StarDirection(name, float(rings.directions_deg[k]), curve.frequencies_cy_px, mtf, error,
                         rings.frequencies_cy_px, np.abs(rotated), errors, nyquist,
                         _interval(nyquist, nyquist_error, z), mtf50, _interval(mtf50, mtf50_error, z),
                         curve.scatter)


def _interval(value: float, error: float, z: float) -> Interval:
    if not (math.isfinite(value) and math.isfinite(error) and math.isfinite(z)):
        return Interval.none()
    return Interval(max(value - z * error, 0.0), value + z * error)


def _unresolved_radius(directions: tuple[StarDirection, ...], cycles: int) -> float:
    curve = Curve(directions[0].frequencies_cy_px, np.mean([d.mtf for d in directions], axis=0),
                  np.zeros_like(directions[0].mtf), math.nan)
    f, _ = curve.crossing(UNRESOLVED_MTF)
    return cycles / (2.0 * math.pi * f) if math.isfinite(f) and f > 0 else math.nan


def _warnings(data, profile, contrast, directions, saturation, inner, outer, cycles) -> list[str]:
    warnings = []
    if contrast.method == "extrapolated" and contrast.lowest_cy_px > FAR_EXTRAPOLATION_CY_PX:
        warnings.append(f"the star's outermost ring reads {contrast.lowest_cy_px:.3f} cy/px: its full contrast is "
                        "extrapolated far to zero frequency (a larger chip, or a star of fewer cycles, reads lower)")
    if contrast.method == "levels" and abs(contrast.extrapolated / contrast.modulation - 1.0) > CONTRAST_AGREEMENT:
        warnings.append(f"the wedges' levels give a full contrast {contrast.modulation:.4f} and the rings "
                        f"extrapolated to zero frequency {contrast.extrapolated:.4f}: a star that is not binary, or "
                        "values not linear in light")
    if contrast.method == "extrapolated" and profile == "binary":
        warnings.append("the binary star's plateaus are too narrow to read its levels: its full contrast is "
                        "extrapolated to zero frequency")
    nyquist_radius = cycles / math.pi
    if not inner <= nyquist_radius <= outer:
        warnings.append(f"the Nyquist radius ({nyquist_radius:.1f} px) lies outside the rings read "
                        f"({inner:.1f} to {outer:.1f} px): no MTF at Nyquist")
    worst = max(directions, key=lambda d: d.scatter if math.isfinite(d.scatter) else -1.0)
    # the scatter beyond the rings' errors, in MTF units: a noise-free chip's tiny errors make any misfit many of them
    excess = math.sqrt(max(worst.scatter - 1.0, 0.0)) * float(np.nanmedian(worst.ring_errors)) \
        if math.isfinite(worst.scatter) else 0.0
    if worst.scatter > MAX_SCATTER and excess > MAX_MISFIT:
        warnings.append(f"the rings of {worst.direction} scatter {math.sqrt(worst.scatter):.1f} times their errors "
                        f"(by {excess:.3f} in MTF) about its curve: the star is not the pattern it is fitted with "
                        "(a printed or moving star?); the intervals are widened by it")
    if saturation is not None:
        clipped = float(np.mean((data <= saturation[0]) | (data >= saturation[1])))
        if clipped > 0.001:
            warnings.append(f"{100 * clipped:.1f} % of the chip's pixels are clipped at {saturation[0]:g} or "
                            f"{saturation[1]:g} DN: its modulation is not the light's")
    return warnings
