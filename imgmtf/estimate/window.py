"""The LSF window and the tails beyond it: the noise that sizes the window
(:func:`measure_noise`), its core and taper (:func:`choose_window`), and the
LSF-like profile kept as measured within it and replaced beyond it by each
side's tail model, blended in under the taper (:func:`blend_tails`).

The tail model, level + A / |x|^p fitted to each side's samples, gives an
LSF-like tail falling as a / x^2: the asymptote of every blur with a
hard-edged aperture, diffraction and stray light among them.  The tails
are so kept whole without their noise; a blur without tails fits a = 0.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import UnsuitableTargetError
from .kind import Shape, TargetKind
from .settings import Settings
from .spectrum import flat_top_window
from .state import Noise, Profile, Samples, TailedLSF, Window
from .tails import fit_side, reach_and_fit, tail_integral

TAPER_FACTOR = 1.0                # the window's raised-cosine taper, in units of its flat half-width
TAIL_FIT_MAX_START = 0.6          # the tail fit starts at most this far out, as a fraction of the range
LONG_TAIL_SHARE = 0.03            # tails beyond the core holding more of the signal keep the clean window
CORE_STEP_PX = 0.5                # the core grows in these steps while the tail model misfits


def measure_noise(kind: TargetKind, samples: Samples, shape: Shape, quantum_dn: float) -> Noise:
    """The profile's noise: each side's scatter about its own level and
    tail, beyond where the sides begin, and never below the quantisation
    floor q / sqrt(12).

    Parameters
    ----------
    kind : TargetKind
        The target's kind (its tail power p).
    samples : Samples
        The profile's samples.
    shape : Shape
        What the kind read off the profile (its centre, levels, plateau).
    quantum_dn : float
        The values' step, DN (0: not quantised).

    Returns
    -------
    Noise
        The noise (DN), the contrast (DN) and their ratio, the SNR (NaN
        where the sides hold too few samples to tell).

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=5.0, seed=1)
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> noise = measure_noise(EdgeKind(), m.estimate.samples, m.shape, m.chip.quantum_dn)
    >>> noise == m.noise, 4 < noise.noise_dn < 6
    (True, True)
    """
    offsets = samples.distance_px - shape.centre
    plateau = [fit_side(offsets, samples.values_dn, side & (np.abs(offsets) >= shape.plateau_px), kind.tail_power)
               for side in (offsets < 0, offsets > 0)]
    side_sd = [fit.sd for fit in plateau if math.isfinite(fit.sd)]
    noise = max(float(np.mean(side_sd)) if side_sd else math.nan, quantum_dn / math.sqrt(12.0))
    contrast = abs(shape.high - shape.low)
    snr = contrast / noise if noise > 0 else math.inf
    if not math.isfinite(noise):
        snr = math.nan
    return Noise(noise, contrast, snr)


def choose_window(kind: TargetKind, samples: Samples, shape: Shape, noise: Noise, settings: Settings,
                  quantum_dn: float) -> Window:
    """The LSF window's core and taper: the caller's half-width, or the
    kind's multiple of the target's width at this SNR, grown out to where
    each side's tail model explains the profile; a profile whose tails
    stand out of their own noise (a long tail: diffraction, a real lens)
    keeps the clean window, since there the narrow low-SNR window costs
    more bias than it saves noise.

    Parameters
    ----------
    kind : TargetKind
        The target's kind (its window factors and tail power).
    samples : Samples
        The profile's samples.
    shape : Shape
        What the kind read off the profile.
    noise : Noise
        The profile's noise and SNR.
    settings : Settings
        The caller's ``lsf_half_width_px`` or ``lsf_window_factor``, if any.
    quantum_dn : float
        The values' step, DN (a noise-free quantised profile's residuals
        do not average down below its q / sqrt(12)).

    Returns
    -------
    Window
        The core and taper (px), how much the noise narrowed the core, and
        whether a given half-width cuts the target.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=5.0, seed=1)
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> fixed = choose_window(EdgeKind(), m.estimate.samples, m.shape, m.noise,
    ...                       make_settings(lsf_half_width_px=1.0), m.chip.quantum_dn)
    >>> fixed.core_px, fixed.taper_px, fixed.cut
    (1.0, 1.0, True)
    """
    offsets = samples.distance_px - shape.centre
    fixed = settings.lsf_half_width_px
    core = fixed or kind.core_px(shape, noise.snr, settings.lsf_window_factor)
    taper_snr = noise.snr
    if fixed is None and settings.lsf_window_factor is None:
        # a noise-free quantised profile rounds neighbouring samples alike:
        # its residuals do not average down below the rounding's own q / sqrt(12)
        floor = quantum_dn / math.sqrt(12.0) if noise.noise_dn < 0.5 * quantum_dn else 0.0
        reached = [reach_and_fit(offsets, samples.values_dn, side, core, kind.tail_power, CORE_STEP_PX, floor)
                   for side in (-1, 1)]
        core = max(core, max(reach for reach, _ in reached))
        # a side whose tail model took over at the core has its fit from there made already
        tails = [tail_integral(offsets, samples.values_dn, side, core, samples.half_range_px, kind,
                               fit if reach == core else None)
                 for side, (reach, fit) in zip((-1, 1), reached)]
        share = sum(abs(area) for area, _ in tails) / noise.contrast_dn
        share_sd = math.hypot(*(sd for _, sd in tails)) / noise.contrast_dn
        if share > LONG_TAIL_SHARE and share > 3.0 * share_sd:
            core = max(core, kind.core_px(shape, math.inf, None))
            taper_snr = math.inf
    taper = kind.taper_factor(taper_snr) * core if fixed is None else TAPER_FACTOR * core
    # how much narrower than the clean window the noise made it: its truncation bias joins the budget
    narrowed = max(0.0, 1.0 - core / kind.core_px(shape, math.inf, None))
    return Window(core, taper, narrowed, fixed is not None and fixed < shape.scale_px)


def blend_tails(kind: TargetKind, samples: Samples, profile: Profile, shape: Shape, window: Window) -> TailedLSF:
    """The LSF-like profile out to the data's reach, on the profile grid's
    lattice: the kind's (an ESF's central difference, a pulse response
    above its background) as measured within the window, each side's
    fitted tail a / s^2 beyond it, blended under the window's taper.

    Parameters
    ----------
    kind : TargetKind
        The target's kind (its LSF-like profile and tail power).
    samples : Samples
        The profile's samples (the sides are fitted to them).
    profile : Profile
        The resampled profile.
    shape : Shape
        What the kind read off the profile (its centre).
    window : Window
        The window's core and taper.

    Returns
    -------
    TailedLSF
        The blended profile and what it was made of (the sides' fits, the
        window, the tail model), for the spectrum and the intervals.

    Raises
    ------
    UnsuitableTargetError
        A side holds too few samples for its level, or the profile has no
        net signal.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60)
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> e = m.estimate
    >>> lsf = blend_tails(EdgeKind(), e.samples, e.profile, m.shape, e.window)
    >>> bool(np.array_equal(lsf.combined, e.lsf.combined)), abs(lsf.tail_share) < 0.01
    (True, True)
    """
    centre = shape.centre
    offsets = samples.distance_px - centre
    half_range = samples.half_range_px
    starts = (min(window.core_px, TAIL_FIT_MAX_START * (half_range + centre)),
              min(window.core_px, TAIL_FIT_MAX_START * (half_range - centre)))
    sides = (fit_side(offsets, samples.values_dn, (offsets <= -starts[0]), kind.tail_power),
             fit_side(offsets, samples.values_dn, (offsets >= starts[1]), kind.tail_power))
    if any(not np.isfinite(side.coef).all() for side in sides):
        raise UnsuitableTargetError(f"a side of the {kind.name} holds too few samples for its level")
    background = 0.5 * (sides[0].coef[0] + sides[1].coef[0])
    grid = profile.grid
    x_data, lsf_data, lsf_adjoint = kind.lsf(grid, profile.values, background)
    step = float(grid[1] - grid[0])
    # the same lattice as the grid, out to the data's reach
    reach = samples.reach_px
    x = np.arange(-np.floor(reach / step), np.floor(reach / step) + 1) * step
    first = int(round((x_data[0] - x[0]) / step))
    measured_at = slice(first, first + x_data.size)
    measured = np.zeros_like(x)
    measured[measured_at] = lsf_data
    in_data = np.zeros(x.size, bool)
    in_data[measured_at] = True
    left, right = kind.lsf_tail_amplitudes()
    amplitudes = (float(left @ sides[0].coef), float(right @ sides[1].coef))
    weights = flat_top_window(x, centre, window.core_px, window.taper_px) * in_data
    from_centre = x - centre
    tail_shape = np.where(np.abs(from_centre) > 1e-9, 1.0 / np.maximum(from_centre * from_centre, 1e-18), 0.0)
    model = np.where(from_centre < 0, amplitudes[0], amplitudes[1]) * tail_shape
    combined: np.ndarray = weights * measured + (1.0 - weights) * model
    total = float(np.sum(combined) * step)
    if total == 0 or not math.isfinite(total):
        raise UnsuitableTargetError(f"the {kind.name}'s profile has no net signal")
    tail_share = float(np.sum((1.0 - weights) * model) * step) / total
    return TailedLSF(x, measured_at, measured, lsf_adjoint, weights, sides, starts, (left, right), amplitudes,
                     tail_shape, combined, step, tail_share)
