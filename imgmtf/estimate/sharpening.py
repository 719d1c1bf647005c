"""Sharpening told from trouble: an MTF above 1 that a sharpening kernel
explains, and one that nothing a kernel does explains.

Ground segments apply MTF compensation to delivered products (IKONOS,
QuickBird, KOMPSAT-2, Pleiades): a small symmetric kernel on the pixel grid
(3 x 3, 5 x 5) whose transfer rises above 1 at mid frequencies.  The
product's MTF, the system's times the kernel's, then rises above 1 and is
still an MTF to measure.  What such a kernel leaves, and the checks here
read:

- a smooth bump: the MTF rises above 1 beyond its noise over one run of
  mid frequencies (its peak below Nyquist, at most ``MAX_PEAK``) and falls
  back below 1 before the noise takes over;
- symmetric negative lobes: the LSF dips below zero on both sides of its
  peak, by alike depths at alike distances (a symmetric kernel's
  undershoot and overshoot);
- the same along the target: the edge's overshoot and undershoot (a bar's
  lobes) are alike in the two halves of its rows.

A rise at the highest frequencies only or at the lowest (a side's
shading), a halo or ringing on one side, or lobes that change along the
target stay refused (``mtf-above-one``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._order import distinct
from .evidence import Evidence
from .gate import MAX_MTF_EXCESS, Check

STEP_CY_PX = 0.005
MIN_RISE = 0.01                 # a peak this far above 1 (and beyond 3 noise sd) is a rise to report
MAX_PEAK = 1.5                  # MTF compensation stays below this; a stronger rise is not a product's
MAX_PEAK_CY_PX = 0.45           # the bump's peak below Nyquist: a rise at the highest frequencies is noise
MIN_PEAK_CY_PX = 0.06           # a 3 x 3 or 5 x 5 kernel barely acts below this: a rise there is a side's shading
MIN_LOBE = 0.02                 # each negative lobe at least this share of the LSF's peak...
MIN_LOBE_RATIO = 0.5            # ...the shallower at least this share of the deeper...
MIN_LOBE_PLACE_RATIO = 0.5      # ...at distances from the peak alike to this ratio
MAX_LOBE_CHANGE = 0.25          # the halves' overshoots differ by at most this share of their mean...
SIGNIFICANCE = 5.0              # ...or their noise (sd) times this
LOBE_BAND_PX = 0.5


@dataclass(frozen=True)
class Peak:
    """The MTF's largest value up to the noise limit and where, cy/px."""

    mtf: float
    cy_px: float


def mtf_peak(mtf, limit_cy_px: float) -> Peak:
    """The largest MTF (1 at zero frequency) from 0 to ``limit_cy_px`` (at
    most 1 cy/px) and its frequency.

    Examples
    --------
    >>> peak = mtf_peak(lambda f: 1 + 0.2 * np.sin(np.pi * f / 0.5) * (f < 0.5), 0.8)
    >>> round(peak.mtf, 3), round(peak.cy_px, 3)
    (1.2, 0.25)
    """
    f = np.arange(0.0, max(min(limit_cy_px, 1.0), 0.0) + 1e-9, STEP_CY_PX)
    m = np.asarray(mtf(f), float)
    if not np.isfinite(m).any():
        return Peak(math.nan, math.nan)
    i = int(np.nanargmax(m))
    return Peak(float(m[i]), float(f[i]))


def sharpening_check(excess: Check, spectrum, ev: Evidence) -> tuple[Check, list[str], Peak, bool]:
    """Judge an MTF above 1: where a sharpening kernel explains it, the
    excess check ``excess`` (:func:`.gate.mtf_excess_check`) passes with
    the cause said (``explained_by`` "sharpening") and a note; where the
    MTF rises beyond the gate's allowance and no kernel explains it, the
    check fails naming what does not fit.  ``spectrum`` gives the MTF, its
    noise, its noise limit and the recovered LSF; ``ev`` the samples.

    Returns
    -------
    Check, list of str, Peak, bool
        The judged check, the notes, the MTF's peak and whether the
        product is sharpened.
    """
    peak = mtf_peak(spectrum.mtf, spectrum.noise_limit_cy_px)
    noise = float(np.asarray(spectrum.noise_sd(np.array([peak.cy_px])))[0]) if math.isfinite(peak.cy_px) else 0.0
    rising = math.isfinite(peak.mtf) and peak.mtf - 1.0 > max(MIN_RISE, 3.0 * noise)
    if not rising:
        return excess, [], peak, False
    why_not = _not_a_kernel(spectrum, ev, peak)
    said = (f"the MTF rises to {peak.mtf:.3f} at {peak.cy_px:.3f} cy/px")
    if why_not is None:
        check = Check("mtf-above-one", True,
                      f"{said}, as a sharpening kernel raises it (a smooth mid-frequency bump, alike negative lobes "
                      "on both sides of the LSF, the same along the target): a sharpened product",
                      excess.value, excess.limit, explained_by="sharpening")
        note = (f"sharpened: {said} (MTF compensation or another sharpening kernel applied to the image): the "
                "figures are the product's as delivered, not the sensor's own")
        return check, [note], peak, True
    if excess.passed:
        return excess, [], peak, False
    return Check("mtf-above-one", False, f"{said}, above 1 beyond its noise, and no sharpening kernel explains it "
                 f"({why_not}): not a clean target", excess.value, MAX_MTF_EXCESS), [], peak, False


def _not_a_kernel(spectrum, ev: Evidence, peak: Peak) -> str | None:
    """What a sharpening kernel would not have done here, or None."""
    if peak.mtf > MAX_PEAK:
        return f"a peak of {peak.mtf:.2f}, more than the {MAX_PEAK:g} MTF compensation gives"
    if peak.cy_px < MIN_PEAK_CY_PX:
        return (f"the rise peaks at {peak.cy_px:.3f} cy/px, the lowest frequencies, where a small kernel does "
                "nothing: a side's level that changes across it (a shading, a slope, flare)")
    if peak.cy_px > MAX_PEAK_CY_PX:
        return f"the rise peaks at {peak.cy_px:.2f} cy/px, at the highest frequencies"
    f = np.arange(STEP_CY_PX, min(spectrum.noise_limit_cy_px, 1.0) + 1e-9, STEP_CY_PX)
    m, sd = np.asarray(spectrum.mtf(f), float), np.asarray(spectrum.noise_sd(f), float)
    above = m - 1.0 > 3.0 * sd
    runs = int(np.count_nonzero(np.diff(above.astype(int)) == 1) + above[0])
    if runs > 1:
        return "the MTF rises above 1 in more than one band"
    if above[-1] or not (m[f > peak.cy_px] < 1.0).any():
        return "the MTF does not fall back below 1 before its noise"
    lobes = _lobes(np.asarray(spectrum.lsf_x_px, float), np.asarray(spectrum.lsf, float))
    if lobes is None:
        return "the LSF has no negative lobes"
    (left, left_at), (right, right_at) = lobes
    if min(left, right) < MIN_LOBE or min(left, right) < MIN_LOBE_RATIO * max(left, right):
        return (f"the LSF dips {100 * left:.0f} % of its peak on the left and {100 * right:.0f} % on the right: a "
                "one-sided halo or ringing")
    if min(left_at, right_at) < MIN_LOBE_PLACE_RATIO * max(left_at, right_at):
        return f"the LSF's negative lobes lie {left_at:.1f} and {right_at:.1f} px from its peak: not symmetric"
    change = _lobe_change(ev)
    if change is not None:
        return change
    return None


def _lobes(x: np.ndarray, lsf: np.ndarray) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """The depths (share of the peak) and distances (px) from the peak of
    the LSF's deepest dip on each side; None without a peak."""
    if x.size < 5 or not np.isfinite(lsf).all():
        return None
    i = int(np.argmax(lsf))
    top = float(lsf[i])
    if not top > 0 or i == 0 or i == x.size - 1:
        return None
    left, right = int(np.argmin(lsf[:i])), i + int(np.argmin(lsf[i:]))
    return ((max(-float(lsf[left]), 0.0) / top, float(x[i] - x[left])),
            (max(-float(lsf[right]), 0.0) / top, float(x[right] - x[i])))


def _lobe_change(ev: Evidence) -> str | None:
    """Where the overshoot beyond either level (an edge's sides; a bar's
    background dips) differs between the halves of the target's rows by
    more than ``MAX_LOBE_CHANGE`` of it and its noise: what says so.  Where
    no side's overshoot can be compared (too few rows or samples), that is
    said too: an unchecked consistency is no evidence of one kernel."""
    s = ev.distance_px - ev.centre_px
    rows = distinct(ev.rows)
    unchecked = ("its overshoot could not be compared between the halves of its rows (too few rows or samples "
                 "near it): one kernel along it is not shown")
    if rows.size < 4:
        return unchecked
    compared = False
    middle = rows[rows.size // 2]
    halves = (ev.rows < middle, ev.rows >= middle)
    near = np.abs(s) <= max(ev.plateau_px, 2.0)
    for side, level, outward in _sides(ev):
        mask = near & (np.sign(s) == side)
        if np.count_nonzero(mask) < 20:
            continue
        # where the whole profile overshoots most: the band there, in each half
        bands = np.floor(np.abs(s[mask]) / LOBE_BAND_PX).astype(int)
        counts = np.bincount(bands)
        means = np.bincount(bands, weights=outward * (ev.values[mask] - level)) / np.maximum(counts, 1)
        means[counts < 5] = -np.inf
        worst = int(np.argmax(means))
        if not means[worst] > 0:
            continue
        band = np.zeros_like(mask)
        band[mask] = bands == worst
        parts = [outward * (ev.values[band & half] - level) for half in halves]
        if min(p.size for p in parts) < 3:
            continue
        a, b = (float(np.mean(p)) for p in parts)
        compared = True
        sd = max(ev.pixel_noise, ev.quantum / math.sqrt(12.0)) * math.sqrt(sum(1.0 / p.size for p in parts))
        if abs(a - b) > max(MAX_LOBE_CHANGE * 0.5 * abs(a + b), SIGNIFICANCE * sd):
            return (f"the overshoot {(worst + 0.5) * LOBE_BAND_PX:.1f} px from the {ev.name} is "
                    f"{100 * a / ev.contrast:.1f} % of the contrast in one half of its rows and "
                    f"{100 * b / ev.contrast:.1f} % in the other: not one kernel along it")
    return None if compared else unchecked


def _sides(ev: Evidence) -> list[tuple[int, float, float]]:
    """(side sign, its level, the outward sign of an overshoot) for each
    side: beyond an edge's levels, below a bar's background."""
    if ev.profile == "bar":
        outward = -1.0 if ev.high >= ev.low else 1.0
        return [(-1, ev.low, outward), (1, ev.low, outward)]
    rising = ev.high >= ev.low
    return [(-1, ev.low, -1.0 if rising else 1.0), (1, ev.high, 1.0 if rising else -1.0)]
