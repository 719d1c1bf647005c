"""The profile's stages: the samples' values as the profile is built from
them (a quantised edge's staircase rebuilt), the samples resampled onto a
uniform grid by the chosen method and read by the target's kind, and
resampled farther where the LSF window reaches past them."""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ..errors import ImgmtfError, UnsuitableTargetError
from . import gate
from .asks import Ask, Steps, alone
from .kind import Shape, TargetKind
from .quantisation import dequantise
from .settings import Settings
from .stacked_resampling import ResampleRequest
from .state import Profile, Samples, Window

INITIAL_SPAN_PX = 16.0            # the profile is first resampled this far from the line
EXPLAINING_REASONS = ("fill", "two-targets")   # checks that explain a profile's odd shape better than it does


def rebuild_staircase(kind: TargetKind, samples: Samples, quantum_dn: float) -> Samples:
    """The values the profile is built from: a noise-free quantised
    profile's staircase rebuilt as the smooth ESF it samples (monotone
    kinds only; :func:`.quantisation.dequantise`), or ``samples`` as they
    are.  The gate reads the raw values either way.

    Parameters
    ----------
    kind : TargetKind
        The target's kind (only a monotone profile's staircase is rebuilt).
    samples : Samples
        The samples, their values as recorded.
    quantum_dn : float
        The values' step, DN (0: not quantised).

    Returns
    -------
    Samples
        ``samples`` with ``values_dn`` rebuilt and ``dequantised`` set, or
        ``samples`` itself.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> from imgmtf.estimate.pipeline import run
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> rebuild_staircase(EdgeKind(), m.located.samples, m.chip.quantum_dn) is m.located.samples  # noisy
    True
    """
    rebuilt = dequantise(samples.distance_px, samples.raw_dn, quantum_dn) if kind.monotone else None
    return samples if rebuilt is None else replace(samples, values_dn=rebuilt, dequantised=True)


def read_profile(kind: TargetKind, samples: Samples, settings: Settings,
                 known: Sequence[gate.Check] = ()) -> tuple[Profile, Shape]:
    """The profile resampled within ``INITIAL_SPAN_PX`` of the line (all of
    it where a level still drifts at the span's end), checked to be of the
    kind's shape, and what the kind reads off it.  A failure is explained
    by a failed fill or second-target check among ``known`` where there is
    one (unless ``settings.force``).

    Parameters
    ----------
    kind : TargetKind
        The target's kind.
    samples : Samples
        The profile's samples.
    settings : Settings
        The resampling method, its step and options; ``force``.
    known : sequence of Check, optional
        The gate's checks so far.

    Returns
    -------
    Profile, Shape
        The resampled profile and what the kind read off it.

    Raises
    ------
    ImgmtfError
        A profile not of the kind's shape, or one the kind cannot read.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> from imgmtf.estimate.pipeline import run
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> profile, shape = read_profile(EdgeKind(), m.estimate.samples, make_settings())
    >>> shape.centre == m.shape.centre, round(shape.scale_px, 2)
    (True, 1.32)
    """
    return alone(read_profile_steps(kind, samples, settings, known))


def read_profile_steps(kind: TargetKind, samples: Samples, settings: Settings,
                       known: Sequence[gate.Check] = ()) -> Steps[tuple[Profile, Shape]]:
    """:func:`read_profile` as a generator of its asks (:mod:`.asks`)."""
    reach = samples.reach_px
    try:
        profile = yield from resample_samples_steps(samples, settings, min(reach, INITIAL_SPAN_PX), kind.name)
        seen = gate.classify_profile(profile.values)
        if seen != kind.profile:
            outer = np.abs(samples.distance_px) > 0.6 * samples.half_range_px      # as a bar's shape reads its noise
            noise_dn = float(np.std(samples.values_dn[outer])) if outer.sum() > 3 else 0.0
            kind_check = gate.kind_check(seen, kind.profile, profile.values, profile.grid, noise_dn)
            raise UnsuitableTargetError(kind_check.message, reason=kind_check.reason)
        try:
            shape = kind.shape(profile.grid, profile.values, samples.distance_px, samples.values_dn,
                               samples.half_range_px)
        except UnsuitableTargetError:
            if profile.grid[-1] >= reach - settings.step_px:
                raise
            # a profile still rising at the span's end (a drifting level): all of it
            profile = yield from resample_samples_steps(samples, settings, reach, kind.name)
            shape = kind.shape(profile.grid, profile.values, samples.distance_px, samples.values_dn,
                               samples.half_range_px)
    except ImgmtfError:
        if not settings.force:
            gate.enforce([check for check in known if check.reason in EXPLAINING_REASONS], force=False)
        raise
    return profile, shape


def resample_samples(samples: Samples, settings: Settings, span_px: float, name: str) -> Profile:
    """The samples resampled by the chosen method within ``span_px`` of the
    line, kept over the central run of finite values (gaps at the far ends
    come from sparse samples).

    Parameters
    ----------
    samples : Samples
        The profile's samples.
    settings : Settings
        The resampling method, its step (px) and options.
    span_px : float
        How far from the line the profile is resampled, px.
    name : str
        The target as a user names it, for a refusal.

    Returns
    -------
    Profile
        The resampled profile over its central run.

    Raises
    ------
    UnsuitableTargetError
        The profile has gaps at the target (too few sub-pixel samples).

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> from imgmtf.estimate.pipeline import run
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> profile = resample_samples(m.estimate.samples, make_settings(), 4.0, "edge")
    >>> float(profile.grid[0]), float(profile.grid[-1])
    (-4.0, 4.0)
    """
    return alone(resample_samples_steps(samples, settings, span_px, name))


def resample_samples_steps(samples: Samples, settings: Settings, span_px: float, name: str) -> Steps[Profile]:
    """:func:`resample_samples` as a generator of its ask (``resample``, :mod:`.asks`)."""
    resampled = yield Ask("resample", ResampleRequest(samples.distance_px, samples.values_dn, span_px,
                                                      settings.method, settings.step_px,
                                                      settings.method_options))
    return Profile(resampled, _central_run(resampled.values, name))


def widen_profile(profile: Profile, samples: Samples, shape: Shape, window: Window, settings: Settings,
                  name: str) -> Profile:
    """``profile``, or the samples resampled farther out where the window's
    core and taper reach past it (and the samples reach farther).

    Parameters
    ----------
    profile : Profile
        The profile as first resampled.
    samples : Samples
        The profile's samples.
    shape : Shape
        What the kind read off the profile (its centre).
    window : Window
        The LSF window.
    settings : Settings
        The resampling method and its step.
    name : str
        The target as a user names it, for a refusal.

    Returns
    -------
    Profile
        ``profile``, or one reaching past the window.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> from imgmtf.estimate.pipeline import run
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> widen_profile(m.profile, m.estimate.samples, m.shape, m.estimate.window, make_settings(), "edge") is m.profile
    True
    """
    return alone(widen_profile_steps(profile, samples, shape, window, settings, name))


def widen_profile_steps(profile: Profile, samples: Samples, shape: Shape, window: Window, settings: Settings,
                        name: str) -> Steps[Profile]:
    """:func:`widen_profile` as a generator of its asks (:mod:`.asks`)."""
    grid, reach = profile.grid, samples.reach_px
    window_end = abs(shape.centre) + window.core_px + window.taper_px + 3.0 * settings.step_px
    if window_end > min(-grid[0], grid[-1]) and grid[-1] < reach - settings.step_px:
        return (yield from resample_samples_steps(samples, settings, min(reach, window_end + 1.0), name))
    return profile


def _central_run(values: np.ndarray, name: str) -> tuple[int, int]:
    """The [start, stop) of the longest run of finite resampled values
    around the target (gaps at the far ends come from sparse samples)."""
    good = np.isfinite(values)
    mid = values.size // 2
    if not good[max(mid - 5, 0): mid + 6].all():
        raise UnsuitableTargetError(f"the {name} profile has gaps at the target: too few sub-pixel "
                                    "samples (target too short or angle unsuitable)")
    bad_left = np.nonzero(~good[:mid])[0]
    bad_right = np.nonzero(~good[mid:])[0]
    start = int(bad_left[-1] + 1) if bad_left.size else 0
    stop = int(mid + bad_right[0]) if bad_right.size else values.size
    return start, stop
