"""The stack of point targets (:class:`Stack`): their normalised stamps
and sub-pixel phases, the weights, the aliases the phases leave, and every
transform read off them (the 2-D transfer, the sections with their
bootstrap, the LSF, the PSF); :mod:`.points` describes the method."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...metrics import first_crossing, fwhm
from ..intervals import Interval, Intervals
from .sources import FoundSources

#: the highest alias order the model correction covers, and the band (cy/px) the PSF is drawn from
ALIAS_ORDER = 4
BAND_CY_PX = 2.0
#: the taper: each stamp is its data within TAPER_SIGMAS fitted sigmas (at least TAPER_CORE_PX) of its centre,
#: eased over TAPER_WIDTH_PX into its fitted model beyond, unless the targets' tails hold more than MAX_TAIL_LIGHT
#: of their light (or three standard errors) that the model has not
TAPER_CORE_PX = 2.0
TAPER_SIGMAS = 3.0
TAPER_WIDTH_PX = 1.5
MAX_TAIL_LIGHT = 0.005
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


def _widened(replicates: np.ndarray, estimate: float, tail: float, widen: float) -> Interval:
    """The percentile interval of ``replicates``, its ends moved ``widen``
    times as far from ``estimate``."""
    if not math.isfinite(widen):            # one target's worth of weight: no spread to draw an interval from
        return Interval.none()
    low, high = np.nanpercentile(replicates, [tail, 100 - tail])
    return Interval(estimate - widen * (estimate - low), estimate + widen * (high - estimate))


class Stack:
    """The used targets' stamps and phases, and the transforms of their
    stack (see the module); built once, read for every frequency."""

    def __init__(self, found: FoundSources, point_size_px: float, *, taper: bool = True):
        self.stamps, self.phases, self.size = found.stamps, found.phases_px, point_size_px
        radius = found.stamp_radius_px
        self.offsets = np.arange(-radius, radius + 1, dtype=float)
        self.radius = radius
        used = found.used
        self.sigmas = np.array([[s.sigma_x_px, s.sigma_y_px] for s in used])
        self.tail_note = ""
        if taper and len(used):
            self.stamps, self.tail_note = self._tapered()
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

    def _tapered(self) -> tuple[np.ndarray, str]:
        """The stamps with their far pixels eased into each target's fitted
        model (see the module), or as they are, with the reason, when the
        targets' tails hold light the model has not."""
        from .sources import pixel_gaussian
        core = max(TAPER_CORE_PX, TAPER_SIGMAS * float(np.median(self.sigmas, axis=0).max()) + 0.35)
        outer = core + TAPER_WIDTH_PX
        if outer > self.radius + 0.5:               # a core that fills the stamp: nothing to ease
            return self.stamps, ""
        n = self.offsets
        models = np.array([pixel_gaussian((1.0, dx, dy, sx, sy, 0.0), n)
                           for (dx, dy), (sx, sy) in zip(self.phases, self.sigmas)])
        r = np.hypot(n[None, None, :] - self.phases[:, 0, None, None], n[None, :, None] - self.phases[:, 1, None, None])
        tail = np.where(r > core, self.stamps - models, 0.0).sum(axis=(1, 2))      # light beyond the model's
        spread = float(tail.std(ddof=1)) / math.sqrt(len(tail)) if len(tail) > 1 else math.inf
        if abs(float(tail.mean())) > max(3.0 * spread, MAX_TAIL_LIGHT):
            return self.stamps, tail_note(float(tail.mean()), core)
        weight = np.sin(0.5 * np.pi * np.clip((outer - r) / TAPER_WIDTH_PX, 0.0, 1.0)) ** 2
        return weight * self.stamps + (1.0 - weight) * models, ""

    def contributions(self, fx: np.ndarray, fy: np.ndarray) -> np.ndarray:
        """Each target's phase-corrected transform at the frequency pairs
        (``fx``, ``fy``) (1-D, cy/px): shape (targets, frequencies)."""
        ex = np.exp(-2j * np.pi * fx[:, None] * self.offsets[None, :])       # (F, L) along x
        ey = np.exp(-2j * np.pi * fy[:, None] * self.offsets[None, :])       # (F, L) along y
        dft = np.einsum("fm,kmn,fn->kf", ey, self.stamps, ex, optimize=True)
        return dft * np.exp(2j * np.pi * (self.phases[:, :1] * fx[None, :] + self.phases[:, 1:] * fy[None, :]))

    def model(self, fx: np.ndarray, fy: np.ndarray, sigmas: np.ndarray) -> np.ndarray:
        """The located targets' model transfer: a Gaussian of the median
        widths, integrated over the pixel (1 at zero); ``sigmas`` (n, 2)
        gives one model, (replicates, n, 2) one per replicate (a leading
        axis on the result)."""
        sx, sy = np.moveaxis(np.median(sigmas, axis=-2), -1, 0)
        sx, sy = np.reshape(sx, np.shape(sx) + (1,) * fx.ndim), np.reshape(sy, np.shape(sy) + (1,) * fx.ndim)
        return np.exp(-2 * np.pi ** 2 * ((sx * fx) ** 2 + (sy * fy) ** 2)) * (np.sinc(fx) * np.sinc(fy))

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
        picks = np.asarray(picks)
        # each replicate's shares of the targets (a target picked twice counts twice): all replicates at once
        counts = np.zeros((len(picks), len(self.stamps)))
        np.add.at(counts, (np.repeat(np.arange(len(picks)), picks.shape[1]), picks.ravel()), 1.0)
        shares = counts * self.weights[None, :]
        shares /= shares.sum(axis=1, keepdims=True)
        out = np.empty((len(picks), len(fx0)), complex)
        ax, ay = fx0[:, None] + self.aliases[None, :, 0], fy0[:, None] + self.aliases[None, :, 1]
        for start in range(0, len(picks), 50):          # the aliases' models of 50 replicates at a time (memory)
            block = slice(start, start + 50)
            aliased = self.model(ax, ay, self.sigmas[picks[block]])              # (R, F, aliases)
            out[block] = shares[block] @ each - np.einsum("rfa,ra->rf", aliased,
                                                           shares[block] @ self.alias_phasors)
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
        expanded percentile interval; the degrees of freedom rounded);
        1.09 x 1.03 for 16 targets."""
        from statistics import NormalDist

        from ..._stats import t_quantile
        n = float(self.weights.sum() ** 2 / (self.weights ** 2).sum())
        if n <= 1.5:
            return math.inf
        q = 0.5 + confidence / 2
        # (t's degrees of freedom rounded to an integer: the closed form, without SciPy's stats, 2 s to import)
        return float(t_quantile(q, max(int(round(n - 1)), 1)) / NormalDist().inv_cdf(q) * math.sqrt(n / (n - 1)))

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


def tail_note(share: float, core_px: float) -> str:
    """The warning of targets whose light beyond ``core_px`` (px from
    their centres) differs from their Gaussian model's by ``share`` of
    their light: more is a halo or wings, less tails that fall faster than
    the Gaussian's (a flat-topped spot, a background taken too high).

    Examples
    --------
    >>> tail_note(-0.043, 2.2).split(" than ")[0]
    'the targets hold 4.3 % less of their light beyond 2.2 px'
    """
    what = "more" if share > 0 else "less"
    why = "a halo or wings" if share > 0 else "tails lighter than a Gaussian's"
    return (f"the targets hold {100 * abs(share):.1f} % {what} of their light beyond {core_px:.1f} px than their "
            f"Gaussian model ({why}): measured as they are, not eased into the model, at the cost of precision")
