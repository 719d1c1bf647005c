"""Compact targets found on a chip, judged and located to a fraction of a
pixel: the first half of the point-target pipeline (:mod:`.points` stacks
them).

A target is a local maximum of the background-subtracted chip (its sign
turned for dark targets), smoothed by a 1 px Gaussian, above five times the
smoothed noise.  Each is cut out as a square stamp and refused, with a
reason code and a message, when its peak is under the SNR floor
(``faint``), signal reaches its stamp's border beyond the plane fitted to
the border (``extended``: an edge or a bar, not a point; the plane is a
textured field's slope), its stamp touches the chip's edge (``edge``),
another target (above the SNR floor, and of at least a tenth of its peak)
lies within the separation (``blended``; a faint bump of texture does not
blend), a pixel of it is at the
recorded range's end (``clipped``) or it is sharper than any optics
(``hot-pixel``).
The rest are located by a least-squares fit of an elliptical Gaussian
integrated over each pixel, plus a constant: exact for Gaussian optics and
a square pixel, and unbiased at the phases 0 and 1/2 for any symmetric PSF.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage, special

from ...errors import ParameterError

#: refusal reasons of a target, in the order they are tested
REASONS = ("faint", "extended", "edge", "blended", "clipped", "hot-pixel", "fit")
POLARITIES = ("auto", "bright", "dark")
#: the narrowest Gaussian sigma (px) a point's image may have: below it, a lone hot pixel
MIN_SIGMA_PX = 0.15
#: the share of its peak a target's smoothed signal may keep on its stamp's border
MAX_BORDER_FRACTION = 0.2
#: a neighbour blends a target when its smoothed peak is at least this share of the target's
BLEND_FRACTION = 0.1
#: the smallest peak SNR of a point target that tells a chip refused as a line holds points instead
POINTS_SEEN_SNR = 10.0
# peaks whose nearest neighbours are found at once (a block against every peak: 256 x peaks floats)
NEAREST_BLOCK = 256


@dataclass(frozen=True)
class Source:
    """One compact target found on the chip.

    Attributes
    ----------
    x_px, y_px : float
        Its centre, px (pixel centres at integers; the fitted centre when
        used, else the peak pixel).
    peak_snr : float
        Its peak over the noise (smoothed image's).
    status : str
        ``"used"`` or a reason code of :data:`REASONS`.
    message : str
        Why it was refused ("" when used).
    flux_dn : float
        Its integral, DN px^2 (NaN when not fitted).
    background_dn : float
        The level around it, DN.
    sigma_x_px, sigma_y_px : float
        The fitted Gaussian's widths (before the pixel), px.
    """

    x_px: float
    y_px: float
    peak_snr: float
    status: str
    message: str = ""
    flux_dn: float = math.nan
    background_dn: float = math.nan
    sigma_x_px: float = math.nan
    sigma_y_px: float = math.nan

    @property
    def used(self) -> bool:
        return self.status == "used"


class SourceTally:
    """The targets a result holds (its ``sources``) sorted into used and
    refused, and the refusals counted by reason: for the targets found and
    for the measurement made of them alike."""

    sources: tuple[Source, ...]

    @property
    def used(self) -> tuple[Source, ...]:
        return tuple(s for s in self.sources if s.used)

    @property
    def refused(self) -> tuple[Source, ...]:
        return tuple(s for s in self.sources if not s.used)

    def refusal_counts(self) -> dict[str, int]:
        """How many targets each reason refused."""
        counts: dict[str, int] = {}
        for source in self.refused:
            counts[source.status] = counts.get(source.status, 0) + 1
        return counts


@dataclass(frozen=True, eq=False)
class FoundSources(SourceTally):
    """What :func:`find_sources` returns.

    Attributes
    ----------
    sources : tuple of Source
        Every target found, used or refused.
    stamps : numpy.ndarray, shape (n, L, L)
        The used targets' stamps, background subtracted and divided by
        their flux (each integrates to about 1), polarity turned positive.
    phases_px : numpy.ndarray, shape (n, 2)
        Each used target's (dx, dy) from its stamp's centre pixel, px.
    polarity : str
        "bright" or "dark".
    noise_dn : float
        The chip's noise, DN (robust).
    stamp_radius_px : int
        The stamps' half side, px (L = 2 R + 1).
    """

    sources: tuple[Source, ...]
    stamps: np.ndarray
    phases_px: np.ndarray
    polarity: str
    noise_dn: float
    stamp_radius_px: int


def background(image: np.ndarray, box_px: int = 32) -> np.ndarray:
    """The slowly varying background: the median of each ``box_px`` block,
    interpolated bilinearly (one median for a chip under two blocks)."""
    rows, cols = image.shape
    by, bx = max(1, rows // box_px), max(1, cols // box_px)
    if by * bx < 4:
        return np.full(image.shape, float(np.median(image)))
    cut = image[: by * (rows // by), : bx * (cols // bx)]
    blocks = cut.reshape(by, rows // by, bx, cols // bx).transpose(0, 2, 1, 3).reshape(by, bx, -1)
    medians = np.median(blocks, axis=-1)
    yc = (np.arange(by) + 0.5) * (rows // by) - 0.5
    xc = (np.arange(bx) + 0.5) * (cols // bx) - 0.5
    yi = np.clip(np.interp(np.arange(rows), yc, np.arange(by)), 0, by - 1)
    xi = np.clip(np.interp(np.arange(cols), xc, np.arange(bx)), 0, bx - 1)
    return ndimage.map_coordinates(medians, np.meshgrid(yi, xi, indexing="ij"), order=1, mode="nearest")


def robust_noise(values: np.ndarray) -> float:
    """The noise of ``values``, DN: 1.4826 times the median absolute
    deviation of their differences between neighbours over sqrt(2), which
    the targets and the background's slope barely touch."""
    d = np.diff(values, axis=1).ravel()
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0))


def find_sources(image: np.ndarray, *, polarity: str = "auto", stamp_radius_px: int = 4, min_snr: float = 20.0,
                 min_separation_px: float | None = None,
                 saturation: tuple[float, float] | None = None) -> FoundSources:
    """Find, judge and locate every compact target on ``image``.

    Parameters
    ----------
    image : numpy.ndarray, shape (rows, cols)
        The chip, DN.
    polarity : {"auto", "bright", "dark"}, optional
        Bright targets on a dark field, dark on bright, or the one whose
        extreme departs further from the background (default).
    stamp_radius_px : int, optional
        Half side of the square cut around each target, px (default 4).
    min_snr : float, optional
        The smallest peak over the noise a target may have (default 20).
    min_separation_px : float, optional
        The closest another target may lie, px (default ``2 R + 2``).
    saturation : (float, float), optional
        (low, high) DN the sensor records: a stamp with a pixel at or
        beyond either is clipped.

    Returns
    -------
    FoundSources
        Every target, used or refused, and the used ones' stamps.

    Raises
    ------
    ParameterError
        A bad polarity or radius, or an image that is not 2-D.

    Examples
    --------
    >>> import numpy as np
    >>> n = np.arange(-3, 4.0)
    >>> image = np.zeros((40, 40)); image[10, 30] = 80.0                 # a hot pixel
    >>> image[17:24, 17:24] = pixel_gaussian((100.0, 0.25, -0.5, 0.6, 0.7, 0.0), n)
    >>> found = find_sources(image, stamp_radius_px=3)
    >>> [(s.status, round(s.x_px, 3), round(s.y_px, 3)) for s in found.sources]
    [('hot-pixel', 30.0, 10.0), ('used', 20.25, 19.5)]
    """
    if polarity not in POLARITIES:
        raise ParameterError(f"polarity must be one of {POLARITIES}, got {polarity!r}")
    if not isinstance(stamp_radius_px, (int, np.integer)) or not 2 <= stamp_radius_px <= 50:
        raise ParameterError(f"stamp radius must be an integer of 2 to 50 px, got {stamp_radius_px!r}")
    data = np.asarray(image, float)
    if data.ndim != 2:
        raise ParameterError(f"a chip must be 2-D, got shape {data.shape}")
    peaks = _peaks(image, data, polarity)
    polarity, signal, smoothed, noise = peaks.polarity, peaks.signal, peaks.smoothed, peaks.noise
    iy, ix = peaks.iy, peaks.ix
    radius = int(stamp_radius_px)
    separation = 2 * radius + 2 if min_separation_px is None else float(min_separation_px)
    sources, stamps, phases = [], [], []
    padded = np.pad(smoothed, radius, constant_values=np.nan)      # off the chip is no border
    peaks_xy = np.column_stack([ix, iy])
    snr, nearest = peaks.snr(), peaks.nearest(peaks.faint(min_snr))
    for k, (y, x) in enumerate(zip(iy, ix)):
        source, stamp, phase = _judge(data, signal, smoothed, padded, (int(x), int(y)), np.delete(peaks_xy, k, 0),
                                      radius, float(snr[k]), float(nearest[k]), separation, min_snr, saturation,
                                      polarity)
        sources.append(source)
        if stamp is not None:
            stamps.append(stamp)
            phases.append(phase)
    size = 2 * radius + 1
    return FoundSources(tuple(sources), np.array(stamps).reshape(-1, size, size),
                        np.array(phases, float).reshape(-1, 2), polarity, noise, radius)


@dataclass(frozen=True, eq=False)
class _Peaks:
    """A chip's candidate targets before they are judged: its signal (the
    residual from its background, turned to ``polarity``), that signal
    smoothed, the chip's noise (DN) and the peaks (rows ``iy``, columns
    ``ix``), strongest first."""

    polarity: str
    signal: np.ndarray
    smoothed: np.ndarray
    noise: float
    iy: np.ndarray
    ix: np.ndarray
    heights: np.ndarray             # the smoothed signal at the peaks

    def snr(self) -> np.ndarray:
        """Each peak's signal over the chip's noise (infinite where the
        noise is 0)."""
        signal = self.signal[self.iy, self.ix]
        if self.noise > 0:
            return signal / self.noise
        return np.full(signal.shape, np.inf)

    def faint(self, min_snr: float) -> np.ndarray:
        """Which peaks are too faint to blend with another (under
        ``min_snr`` times the noise)."""
        return self.signal[self.iy, self.ix] < min_snr * self.noise

    def nearest(self, faint: np.ndarray, among: np.ndarray | None = None) -> np.ndarray:
        """The distance (px) from each peak (of the indices ``among``; all
        by default) to the nearest other peak that could blend with it: one
        not ``faint`` and of some weight beside it (infinite: none)."""
        among = np.arange(len(self.iy)) if among is None else np.asarray(among, int)
        nearest = np.empty(len(among))
        for start in range(0, len(among), NEAREST_BLOCK):       # a block of peaks against all: memory bounded
            k = among[start: start + NEAREST_BLOCK]
            distance = np.hypot(self.ix - self.ix[k, None], self.iy - self.iy[k, None])
            distance[np.arange(len(k)), k] = np.inf
            # a neighbour blends only if it is a target of some weight beside this one (a faint bump of texture
            # is not)
            distance[faint | (self.heights < BLEND_FRACTION * self.heights[k, None])] = np.inf
            nearest[start: start + NEAREST_BLOCK] = distance.min(axis=1, initial=np.inf)
        return nearest


def _peaks(image: np.ndarray, data: np.ndarray, polarity: str) -> _Peaks:
    """The peaks of ``data`` (``image`` as floats) that may be targets, of
    ``polarity`` ("auto": the one whose extreme departs further)."""
    residual = data - background(data)
    if polarity == "auto":
        polarity = "bright" if residual.max() >= -residual.min() else "dark"
    signal = residual if polarity == "bright" else -residual
    noise = robust_noise(data)
    if np.issubdtype(np.asarray(image).dtype, np.integer):
        noise = max(noise, 1.0 / math.sqrt(12.0))        # an integer chip's rounding, where nothing else shows
    smoothed = ndimage.gaussian_filter(signal, 1.0)
    # a 1 px Gaussian averages white noise over 4 pi sigma^2 pixels
    floor = max(5.0 * noise / math.sqrt(4.0 * math.pi), 1e-3 * float(np.abs(smoothed).max()))
    peaks = (smoothed == ndimage.maximum_filter(smoothed, size=5)) & (smoothed > floor)
    iy, ix = np.nonzero(peaks)
    order = np.argsort(-smoothed[iy, ix])
    iy, ix = iy[order], ix[order]
    # one target, one peak: a tie (a target half-way between pixels) or a shoulder within 2.5 px of a
    # stronger peak is that peak's
    # (on Python's integers: NumPy's scalars cost ten times as much in a loop)
    xs, ys = ix.tolist(), iy.tolist()
    keep: list[int] = []
    for k, (x, y) in enumerate(zip(xs, ys)):
        if all((x - xs[i]) ** 2 + (y - ys[i]) ** 2 > 6.25 for i in keep):
            keep.append(k)
    iy, ix = iy[keep], ix[keep]
    return _Peaks(polarity, signal, smoothed, noise, iy, ix, smoothed[iy, ix])


def _judge(data, signal, smoothed, padded, at, others, radius, snr, nearest, separation, min_snr, saturation,
           polarity):
    """One target's verdict, and its stamp and phase when used (its peak's
    ``snr`` and ``nearest`` blending neighbour, px, as :class:`_Peaks`
    gives them)."""
    x, y = at
    rows, cols = data.shape

    def refused(reason, message):
        return Source(float(x), float(y), snr, reason, message), None, None
    if snr < min_snr:
        return refused("faint", f"its peak is {snr:.1f} times the noise (under {min_snr:g})")
    # an edge or a bar: its signal reaches the stamp's border (what of the stamp lies on the chip)
    # (less what lies within 3 px of another target's peak: that is a neighbour, judged next)
    ring = np.ones((2 * radius + 1,) * 2, bool)
    ring[1:-1, 1:-1] = False
    ry, rx = np.nonzero(ring)
    near = ((rx[:, None] + x - radius - others[None, :, 0]) ** 2
            + (ry[:, None] + y - radius - others[None, :, 1]) ** 2 <= 9).any(axis=1)
    border, level = border_excess(padded[ry + y, rx + x][~near], rx[~near] - radius, ry[~near] - radius)
    height = float(smoothed[y, x]) - level
    if border > MAX_BORDER_FRACTION * height:
        share = 100 * border / max(height, 1e-12)
        return refused("extended", f"its signal reaches {2 * radius + 1} px across ({share:.0f} % of its peak on "
                       "the border): an edge or a bar, not a point")
    if x - radius < 0 or y - radius < 0 or x + radius >= cols or y + radius >= rows:
        return refused("edge", f"its {2 * radius + 1} px stamp touches the chip's edge")
    if nearest < separation:
        return refused("blended", f"another target lies {nearest:.1f} px away (under {separation:g} px)")
    window = (slice(y - radius, y + radius + 1), slice(x - radius, x + radius + 1))
    stamp = data[window]
    if saturation is not None and (stamp.max() >= saturation[1] or stamp.min() <= saturation[0]):
        return refused("clipped", f"a pixel of it is at the recorded range's end ({saturation[0]:g}, "
                       f"{saturation[1]:g} DN)")
    sign = 1.0 if polarity == "bright" else -1.0
    fit = fit_pixel_gaussian(sign * stamp)
    if fit is None:
        return refused("fit", "the 2-D Gaussian fit did not converge")
    flux, dx, dy, sx, sy, level = fit
    if max(sx, sy) < MIN_SIGMA_PX:
        return refused("hot-pixel", f"narrower than any optics (sigma {max(sx, sy):.2f} px): a hot pixel or a "
                       "cosmic ray")
    if abs(dx) > 1.0 or abs(dy) > 1.0 or max(sx, sy) > radius / 2.0:
        return refused("fit", f"the fitted centre or width ({max(sx, sy):.2f} px) does not fit the stamp")
    source = Source(x + dx, y + dy, snr, "used", "", flux, sign * level, sx, sy)
    return source, (sign * stamp - level) / flux, (dx, dy)


def border_excess(values: np.ndarray, x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """How far a stamp's border ``values`` (at offsets ``x``, ``y`` from its
    centre; NaN off the chip) stray from the plane fitted to them (the
    largest absolute residual), and that plane's level at the centre.  The
    plane is the background under the target (a textured field's slope); an
    edge's step or a bar's crossing stays in the residual, and a bump on a
    plateau has no height above the plane.

    Examples
    --------
    >>> x = np.array([-2, 0, 2, -2, 2, -2, 0, 2]); y = np.array([-2, -2, -2, 0, 0, 2, 2, 2])
    >>> [round(v, 9) for v in border_excess(5.0 + 0.3 * x - 0.1 * y, x, y)]
    [0.0, 5.0]
    >>> [round(v, 3) for v in border_excess(np.where(x > 0, 1.0, 0.0), x, y)]     # a step: no plane
    [0.375, 0.375]
    """
    keep = np.isfinite(values)
    if keep.sum() < 4:
        return (float(np.nanmax(np.abs(values), initial=0.0)) if keep.any() else 0.0), 0.0
    design = np.column_stack([np.ones(keep.sum()), x[keep], y[keep]]).astype(float)
    coefficients = np.linalg.lstsq(design, values[keep], rcond=None)[0]
    return float(np.abs(values[keep] - design @ coefficients).max()), float(coefficients[0])


def pixel_gaussian(params, n: np.ndarray) -> np.ndarray:
    """An elliptical Gaussian integrated over unit pixels, plus a constant:
    ``params`` (flux, dx, dy, sigma_x, sigma_y, level), on a stamp whose
    pixel offsets from its centre are ``n`` (both axes)."""
    flux, dx, dy, sx, sy, level = params
    root2 = math.sqrt(2.0)
    gx = 0.5 * (special.erf((n + 0.5 - dx) / (root2 * sx)) - special.erf((n - 0.5 - dx) / (root2 * sx)))
    gy = 0.5 * (special.erf((n + 0.5 - dy) / (root2 * sy)) - special.erf((n - 0.5 - dy) / (root2 * sy)))
    return flux * gy[:, None] * gx[None, :] + level


def _pixel_profile(n: np.ndarray, shift: float, sigma: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A Gaussian integrated over unit pixels along one axis, and its
    derivatives by the shift and by sigma."""
    root2 = math.sqrt(2.0)
    high, low = (n + 0.5 - shift) / (root2 * sigma), (n - 0.5 - shift) / (root2 * sigma)
    e_high, e_low = np.exp(-high ** 2), np.exp(-low ** 2)
    g = 0.5 * (special.erf(high) - special.erf(low))
    d_shift = -(e_high - e_low) / (math.sqrt(2.0 * math.pi) * sigma)
    d_sigma = -(high * e_high - low * e_low) / (math.sqrt(math.pi) * sigma)
    return g, d_shift, d_sigma


def pixel_gaussian_jacobian(params, n: np.ndarray) -> np.ndarray:
    """The derivatives of :func:`pixel_gaussian`'s pixels (raveled, rows
    first) by its ``params`` (flux, dx, dy, sigma_x, sigma_y, level): shape
    (pixels, 6); what its least-squares fit uses rather than differences.

    Examples
    --------
    >>> n, p = np.arange(-3, 4.0), np.array([100.0, 0.2, -0.3, 0.6, 0.8, 5.0])
    >>> step = 1e-6 * np.eye(6)[2]
    >>> numeric = (pixel_gaussian(p + step, n) - pixel_gaussian(p - step, n)).ravel() / 2e-6
    >>> bool(np.allclose(pixel_gaussian_jacobian(p, n)[:, 2], numeric, atol=1e-6))
    True
    """
    flux, dx, dy, sx, sy, _ = params
    gx, gx_shift, gx_sigma = _pixel_profile(n, dx, sx)
    gy, gy_shift, gy_sigma = _pixel_profile(n, dy, sy)
    columns = (np.outer(gy, gx), flux * np.outer(gy, gx_shift), flux * np.outer(gy_shift, gx),
               flux * np.outer(gy, gx_sigma), flux * np.outer(gy_sigma, gx), np.ones((n.size, n.size)))
    return np.column_stack([c.ravel() for c in columns])


def fit_pixel_gaussian(stamp: np.ndarray):
    """(flux, dx, dy, sigma_x, sigma_y, level) of the pixel-integrated
    Gaussian fitted to a positive ``stamp`` (dx, dy from its centre pixel),
    or None when the fit fails."""
    radius = stamp.shape[0] // 2
    n = np.arange(-radius, radius + 1, dtype=float)
    ring = np.ones(stamp.shape, bool)
    ring[1:-1, 1:-1] = False
    level = float(np.median(stamp[ring]))
    weights = np.clip(stamp - level, 0.0, None)
    total = float(weights.sum())
    if not total > 0:
        return None
    dx0 = float((weights.sum(axis=0) * n).sum() / total)
    dy0 = float((weights.sum(axis=1) * n).sum() / total)
    start = [total, np.clip(dx0, -0.9, 0.9), np.clip(dy0, -0.9, 0.9), 0.7, 0.7, level]
    low = [0.0, -radius, -radius, 0.02, 0.02, -np.inf]
    high = [np.inf, radius, radius, float(radius), float(radius), np.inf]
    # (SciPy's optimizer loaded here, by the first stamp fitted: a scan's edge refused for texture asks
    # points_seen whether it holds points, which finds none to fit, and needs not load it)
    from scipy import optimize
    try:
        fit = optimize.least_squares(lambda p: (pixel_gaussian(p, n) - stamp).ravel(), start, bounds=(low, high),
                                     jac=lambda p: pixel_gaussian_jacobian(p, n), x_scale="jac", xtol=1e-12,
                                     ftol=1e-12, gtol=1e-12, max_nfev=400)
    except (ValueError, np.linalg.LinAlgError):
        return None
    if not fit.success or not np.isfinite(fit.x).all() or fit.x[0] <= 0:
        return None
    return tuple(float(v) for v in fit.x)


def _may_hold_points(data: np.ndarray, min_snr: float, radius: int) -> bool:
    """Whether any of the peaks :func:`find_sources` finds on ``data``
    (floats; ``min_snr``, a stamp of ``radius`` and the default separation)
    passes its cheap checks, each as :func:`_judge` makes it: not faint,
    its stamp on the chip, no other target within the separation.  A peak
    that fails one is refused whatever else it is, so where none passes
    none is used, and the fits of a textured chip's many peaks are spared."""
    peaks = _peaks(data, data, "auto")
    iy, ix = peaks.iy, peaks.ix
    rows, cols = data.shape
    on_chip = (ix - radius >= 0) & (iy - radius >= 0) & (ix + radius < cols) & (iy + radius < rows)
    candidates = np.flatnonzero(~(peaks.snr() < min_snr) & on_chip)
    return bool((peaks.nearest(peaks.faint(min_snr), candidates) >= 2 * radius + 2).any())


def points_seen(image: np.ndarray) -> str | None:
    """What a chip refused as an edge or a bar shows if it holds point
    targets instead: "16 compact bright point targets (median peak SNR 95)",
    or None when it holds none (a lone usable point is enough; most of what
    stands out must be compact, not lines).

    Parameters
    ----------
    image : numpy.ndarray
        The chip, DN.

    Returns
    -------
    str or None
        The words naming what was seen.

    Examples
    --------
    >>> n = np.arange(-3, 4.0)
    >>> image = np.zeros((30, 30)); image[10:17, 10:17] = pixel_gaussian((900.0, 0.2, 0.1, 0.6, 0.6, 0.0), n)
    >>> points_seen(np.random.default_rng(0).normal(image, 1.0))
    '1 compact bright point target (median peak SNR 318)'
    >>> points_seen(np.zeros((30, 30))) is None
    True
    """
    data = np.asarray(image, float)
    if data.ndim != 2 or min(data.shape) < 9:
        return None
    if not _may_hold_points(data, POINTS_SEEN_SNR, 4):
        return None
    found = find_sources(data, min_snr=POINTS_SEEN_SNR)
    used = found.used
    lines = found.refusal_counts().get("extended", 0)
    if not used or lines >= len(used):
        return None
    snr = float(np.median([s.peak_snr for s in used]))
    plural = "s" if len(used) > 1 else ""
    return f"{len(used)} compact {found.polarity} point target{plural} (median peak SNR {snr:.0f})"
