"""Stage 9 of the pipeline (:mod:`.pipeline`): the windowed LSF-like
profile's transform divided by the transfer between the system's LSF and
that profile, judged against its white noise, and the figures read off it."""
from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike

from ..metrics import fwhm
from .asks import Ask, Steps, alone
from .kind import Shape, TargetKind
from .settings import Settings
from .spectrum import (
    MIN_TRANSFER,
    NYQUIST,
    RestoreRequest,
    mtf50,
    noise_limited_frequency,
    supported,
    tabulated_mtf,
    white_noise_mtf_sd,
)
from .state import Noise, Profile, Samples, Spectrum, TailedLSF, Window


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
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> e = m.estimate
    >>> spectrum = transform(EdgeKind(), e.samples, e.profile, m.shape, m.noise, e.window, e.lsf, make_settings())
    >>> spectrum.mtf_nyquist == e.spectrum.mtf_nyquist
    True
    """
    return alone(transform_steps(kind, samples, profile, shape, noise, window, lsf, settings))


def transform_steps(kind: TargetKind, samples: Samples, profile: Profile, shape: Shape, noise: Noise,
                    window: Window, lsf: TailedLSF, settings: Settings) -> Steps[Spectrum]:
    """:func:`transform` as a generator of asks (:mod:`.asks`): the
    profile's zero-padded FFT (``spectrum``) and the LSF's restoration
    (``restore-lsf``) are made among other chips' (:func:`.spectrum.spectrum_many`,
    :func:`.spectrum.restore_lsf_many`)."""
    divisor = kind.divisor(lsf.step_px, profile.resampled.transfer if settings.correct else None, shape)
    freqs, modulus = yield Ask("spectrum", (supported(lsf.combined), lsf.step_px))
    mtf = tabulated_mtf(freqs, modulus, divisor)
    density = samples.distance_px.size / (2.0 * samples.half_range_px)
    white = white_noise_mtf_sd(noise.snr, 2.0 * window.core_px + window.taper_px, density,
                               kind.noise_gain(shape, noise.contrast_dn))
    noise_sd = functools.partial(_corrected_noise_sd, white=white, divisor=divisor)
    noise_limit = noise_limited_frequency(mtf, noise_sd)
    lsf_x, restored = yield Ask("restore-lsf", RestoreRequest(lsf.combined, lsf.x_px, divisor, noise_limit,
                                                             min_divisor=kind.restore_min_divisor))
    return Spectrum(divisor, mtf, noise_sd, noise_limit, lsf_x, restored, float(mtf(np.array([NYQUIST]))[0]),
                    mtf50(mtf), fwhm(lsf_x, restored))


def _corrected_noise_sd(f: ArrayLike, *, white: Callable, divisor: Callable) -> np.ndarray:
    """The MTF's noise at ``f`` (cy/px): the white noise divided by the
    corrections as the MTF is."""
    f = np.atleast_1d(np.asarray(f, float))
    return white(f) / np.maximum(np.abs(divisor(f) / divisor(np.zeros(1))), MIN_TRANSFER)

