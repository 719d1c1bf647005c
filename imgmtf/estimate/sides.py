"""The sides' uniformity: each side of a target beyond its plateau's start
fitted with its level, its tail and a trend across and along the target;
a drifting level, texture beyond the pixel noise, or a 1-px band far off
the model (a second feature) fail (reasons ``non-uniform`` and
``two-targets``, see :mod:`.gate`).
"""
from __future__ import annotations

import math

import numpy as np

from .gate import MAX_SECOND_FEATURE, MAX_SIDE_TEXTURE, MAX_SIDE_TREND, ROUNDING_SHARE, Check, beyond_rounding, not_run


def side_checks(distance, values, along, centre, start_px, contrast, pixel_noise, tail_power,
                names: tuple[str, str] = ("left", "right")) -> list[Check]:
    """Uniform sides: each side's samples beyond ``start_px`` from the
    centre fitted with its level, its tail (a / |s|^p), a trend across and
    a trend along the target; a trend over the side larger than
    ``MAX_SIDE_TREND`` of the contrast, texture beyond the pixel noise, or
    a 1-px band far off the model (another edge or bar) fail.
    ``pixel_noise`` (DN): one for both sides, or (left, right) where it
    differs (linearised values: the stored noise scaled at each level);
    ``names`` what the left and right sides are called ("dark", "bright")."""
    checks = []
    s = distance - centre
    noises = tuple(pixel_noise) if np.ndim(pixel_noise) else (pixel_noise, pixel_noise)
    for (name, mask), pixel_noise in zip(((names[0], s <= -start_px), (names[1], s >= start_px)), noises):
        if mask.sum() < 20:
            # the sides' settling check (:mod:`.settling`) refuses a side without a plateau
            checks.append(not_run("non-uniform", f"the {name} side holds {int(mask.sum())} samples beyond "
                                  f"{start_px:.1f} px (20 needed): its trend and texture not measured"))
            continue
        ss, v, t = np.abs(s[mask]), values[mask], along[mask]
        design = np.column_stack([np.ones_like(ss), ss ** -tail_power, ss - ss.mean(), t - t.mean()])
        coef, *_ = np.linalg.lstsq(design, v, rcond=None)
        resid = v - design @ coef
        across, along_target = (beyond_rounding(abs(coef[2]) * np.ptp(ss) / contrast),
                                beyond_rounding(abs(coef[3]) * np.ptp(t) / contrast))
        trend, way = max((across, "across"), (along_target, "along"))
        scatter = np.var(resid)
        texture = math.sqrt(max(scatter - pixel_noise ** 2, 0.0)) / contrast
        bands = np.floor(ss).astype(int)
        counts = np.bincount(bands)
        sums = np.bincount(bands, weights=resid)
        full = counts >= 10
        band_means = np.abs(sums[full] / counts[full])
        band_means[band_means <= ROUNDING_SHARE * abs(contrast)] = 0.0     # a flat side's: rounding, no feature
        band_noise = np.sqrt(scatter / counts[full])
        checks += [
            Check("non-uniform", trend <= MAX_SIDE_TREND,
                  f"the {name} side's level drifts by {100 * trend:.0f} % of the contrast {way} the target (at "
                  f"most {100 * MAX_SIDE_TREND:g} %): not a uniform field", trend, MAX_SIDE_TREND),
            Check("non-uniform", texture <= MAX_SIDE_TEXTURE,
                  f"the {name} side carries texture of {100 * texture:.0f} % of the contrast beyond the "
                  f"pixel noise (at most {100 * MAX_SIDE_TEXTURE:g} %): not a uniform field",
                  texture, MAX_SIDE_TEXTURE),
        ]
        if not full.any():
            checks.append(not_run("two-targets", f"no 1-px band of the {name} side holds 10 samples: a second "
                                  "feature there not looked for"))
            continue
        worst = int(np.argmax(band_means - 5 * band_noise))
        second = float(band_means[worst]) / contrast if band_means[worst] > 5 * band_noise[worst] else 0.0
        checks.append(Check("two-targets", second <= MAX_SECOND_FEATURE,
                            f"another feature lies on the {name} side, {np.nonzero(full)[0][worst]} px from the "
                            f"target ({100 * second:.0f} % of the contrast)", second, MAX_SECOND_FEATURE))
    return checks
