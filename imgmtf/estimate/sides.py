"""The sides' uniformity: each side of a target beyond its plateau's start
fitted with its level, its tail and a trend across and along the target;
a drifting level, texture beyond the pixel noise, or a 1-px band far off
the model (a second feature) fail (reasons ``non-uniform`` and
``two-targets``, see :mod:`.gate`).  Many chips' sides are fitted
together (:func:`side_checks_many`), each as it is alone.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .gate import MAX_SECOND_FEATURE, MAX_SIDE_TEXTURE, MAX_SIDE_TREND, ROUNDING_SHARE, Check, beyond_rounding, not_run
from .ragged import Groups, least_squares

MIN_SIDE_SAMPLES = 20
MIN_BAND_SAMPLES = 10


def side_checks(distance, values, along, centre, start_px, contrast, pixel_noise, tail_power,
                names: tuple[str, str] = ("left", "right")) -> list[Check]:
    """Uniform sides: each side's samples beyond ``start_px`` from the
    centre fitted with its level, its tail (a / |s|^p), a trend across and
    a trend along the target; a trend over the side larger than
    ``MAX_SIDE_TREND`` of the contrast, texture beyond the pixel noise, or
    a 1-px band far off the model (another edge or bar) fail.
    ``pixel_noise`` (DN): one for both sides, or (left, right) where it
    differs (linearised values: the stored noise scaled at each level);
    ``names`` what the left and right sides are called ("dark", "bright").
    A batch of one of :func:`side_checks_many`.

    Examples
    --------
    >>> d = np.r_[-np.arange(3.0, 13.0, 0.1), np.arange(3.0, 13.0, 0.1)]
    >>> values = np.where(d < 0, 200.0, 1200.0)
    >>> checks = side_checks(d, values, np.arange(d.size, dtype=float), 0.0, 2.0, 1000.0, 1.0, 2)
    >>> [c.outcome for c in checks]
    ['passed', 'passed', 'passed', 'passed', 'passed', 'passed']
    """
    return side_checks_many([(distance, values, along, centre, start_px, contrast, pixel_noise, tail_power,
                              names)])[0]


def side_checks_many(calls: Sequence[tuple[Any, ...]]) -> list[list[Check]]:
    """:func:`side_checks` of many chips, their sides fitted together
    (:mod:`.ragged`): each chip's checks the same, to the bit, as alone.

    Parameters
    ----------
    calls : sequence of tuple
        Each chip's arguments of :func:`side_checks`, in its order
        (``names`` may be left out).

    Returns
    -------
    list of list of Check
        Each chip's checks, in order.

    Examples
    --------
    >>> d = np.r_[-np.arange(3.0, 13.0, 0.1), np.arange(3.0, 13.0, 0.1)]
    >>> flat, drifting = np.where(d < 0, 200.0, 1200.0), np.where(d < 0, 200.0, 1200.0 + 30.0 * d)
    >>> rows = np.arange(d.size, dtype=float)
    >>> many = side_checks_many([(d, v, rows, 0.0, 2.0, 1000.0, 1.0, 2) for v in (flat, drifting)])
    >>> [[c.outcome for c in checks] for checks in many][1]
    ['passed', 'passed', 'passed', 'failed', 'passed', 'passed']
    """
    side_s, side_v, side_t, owner = [], [], [], []
    for k, (distance, values, along, centre, start_px, *_) in enumerate(calls):
        s = distance - centre
        for mask in (s <= -start_px, s >= start_px):
            side_s.append(np.abs(s[mask]))
            side_v.append(values[mask])
            side_t.append(along[mask])
            owner.append(k)
    sides = Groups([side.size for side in side_s])
    fitted = sides.sizes >= MIN_SIDE_SAMPLES
    fits = Groups(sides.sizes[fitted])
    ss = np.concatenate([side for side, use in zip(side_s, fitted) if use] or [np.empty(0)])
    v = np.concatenate([side for side, use in zip(side_v, fitted) if use] or [np.empty(0)])
    t = np.concatenate([side for side, use in zip(side_t, fitted) if use] or [np.empty(0)])
    n = fits.sizes.astype(float)
    power = fits.power(ss, [-float(calls[owner[g]][7]) for g in np.flatnonzero(fitted)])
    coef, resid = least_squares(fits, [np.ones_like(ss), power, ss - fits.spread(fits.sum(ss) / n),
                                       t - fits.spread(fits.sum(t) / n)], v)
    ss_range = fits.extreme(ss, True) - fits.extreme(ss, False)
    t_range = fits.extreme(t, True) - fits.extreme(t, False)
    centred = resid - fits.spread(fits.sum(resid) / n)
    scatter = fits.sum(centred * centred) / n
    bands = np.floor(ss).astype(int)
    slots = Groups(np.where(fits.sizes > 0, np.nan_to_num(fits.extreme(bands.astype(float), True)) + 1, 0))
    slot = fits.spread(slots.starts) + bands
    counts = np.bincount(slot, minlength=slots.ids.size)
    sums = np.bincount(slot, weights=resid, minlength=slots.ids.size)
    full = counts >= MIN_BAND_SAMPLES
    out: list[list[Check]] = [[] for _ in calls]
    j = 0
    for g, size in enumerate(sides.sizes):
        k, side = owner[g], g % 2
        _, _, _, _, start_px, contrast, pixel_noise, _, *named = calls[k]
        name = (named[0] if named else ("left", "right"))[side]
        noise = pixel_noise[side] if np.ndim(pixel_noise) else pixel_noise
        if not fitted[g]:
            # the sides' settling check (:mod:`.settling`) refuses a side without a plateau
            out[k].append(not_run("non-uniform", f"the {name} side holds {int(size)} samples beyond "
                                  f"{start_px:.1f} px (20 needed): its trend and texture not measured"))
            continue
        out[k] += _verdicts(name, coef[j], float(ss_range[j]), float(t_range[j]), float(scatter[j]), noise,
                            contrast, counts, sums, full, slots.starts[j], slots.sizes[j])
        j += 1
    return out


def _verdicts(name: str, coef: np.ndarray, ss_range: float, t_range: float, scatter: float, pixel_noise: float,
              contrast: float, counts: np.ndarray, sums: np.ndarray, full: np.ndarray, start: int, width: int
              ) -> list[Check]:
    """One side's checks from its fit: the coefficients of its trends
    across and along, its residuals' variance ``scatter`` and their 1-px
    bands' ``counts`` and ``sums`` (from ``start``, ``width`` bands)."""
    across, along_target = (beyond_rounding(abs(coef[2]) * ss_range / contrast),
                            beyond_rounding(abs(coef[3]) * t_range / contrast))
    trend, way = max((across, "across"), (along_target, "along"))
    texture = math.sqrt(max(scatter - pixel_noise ** 2, 0.0)) / contrast
    checks = [
        Check("non-uniform", trend <= MAX_SIDE_TREND,
              f"the {name} side's level drifts by {100 * trend:.0f} % of the contrast {way} the target (at "
              f"most {100 * MAX_SIDE_TREND:g} %): not a uniform field", trend, MAX_SIDE_TREND),
        Check("non-uniform", texture <= MAX_SIDE_TEXTURE,
              f"the {name} side carries texture of {100 * texture:.0f} % of the contrast beyond the "
              f"pixel noise (at most {100 * MAX_SIDE_TEXTURE:g} %): not a uniform field",
              texture, MAX_SIDE_TEXTURE),
    ]
    full = full[start: start + width]
    if not full.any():
        checks.append(not_run("two-targets", f"no 1-px band of the {name} side holds {MIN_BAND_SAMPLES} samples: "
                              "a second feature there not looked for"))
        return checks
    counted = counts[start: start + width][full]
    band_means = np.abs(sums[start: start + width][full] / counted)
    band_means[band_means <= ROUNDING_SHARE * abs(contrast)] = 0.0     # a flat side's: rounding, no feature
    band_noise = np.sqrt(scatter / counted)
    worst = int(np.argmax(band_means - 5 * band_noise))
    second = float(band_means[worst]) / contrast if band_means[worst] > 5 * band_noise[worst] else 0.0
    checks.append(Check("two-targets", second <= MAX_SECOND_FEATURE,
                        f"another feature lies on the {name} side, {np.nonzero(full)[0][worst]} px from the "
                        f"target ({100 * second:.0f} % of the contrast)", second, MAX_SECOND_FEATURE))
    return checks
