"""Stage 10 of the pipeline (:mod:`.pipeline`): the quality gate, every
check of the measurement enforced and the warnings it must carry."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from . import gate
from .asks import Ask, Steps, alone
from .blocks import block_boundaries
from .evidence import evidence_of, side_masks
from .kind import Shape, TargetKind
from .profile_checks import run_profile_checks
from .settings import Settings
from .settling import settled_sides
from .sharpening import sharpening_check
from .spectrum import MIN_TRANSFER, NYQUIST
from .state import Chip, Located, Noise, Samples, Spectrum, Window

MASK_SCAN_STEP_CY_PX = 0.005      # where a divisor's zeros hide the MTF is looked for on this grid, to 2 cy/px


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
    >>> from imgmtf.estimate.pipeline import run
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
    sides = kind.saturation_sides(side_masks(shape, offsets))
    checks = list(located.checks)
    checks += yield Ask("saturation", dict(
        distance=distance, values=raw, centre=centre, rise_px=shape.scale_px, sides=sides, limits=chip.limits,
        quantum=quantum_dn, noise_free=noise.noise_dn <= max(1.5 * quantum_dn / math.sqrt(12.0), 1e-9 * contrast),
        bright_core=kind.peak_mask(offsets, shape), monotone=kind.monotone, contrast=contrast,
        bar_edge_px=kind.known_half_width_px(shape)))
    # each side's texture against its own pixel noise (linearisation scales it with the level)
    side_noise = (chip.noise_at(shape.low), chip.noise_at(shape.low if kind.profile == "bar" else shape.high))
    side_names = tuple(name for name, _, _ in sides)
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

