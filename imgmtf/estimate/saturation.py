"""The saturation checks: a side or a bar's peak clipped at the levels the
sensor records (an integer type's limits, or a saturation range given), or
at a level no limit declares, seen as a side held at one exact value, a
pile-up of samples at the extreme, or a bar's peak cut flat.

Reason ``saturated`` (see :mod:`.gate` for every reason the gate gives).
"""
from __future__ import annotations

from collections.abc import Sequence
from statistics import NormalDist
from typing import Any

import numpy as np

from ._order import median
from .gate import Check, not_run
from .ragged import Groups

SATURATED_SIDE = 0.10           # fraction of a side's samples at a saturation limit
PILE_UP = 3.0                   # samples at the extreme value / samples one quantum below it
HELD_PLATEAU = 0.98             # share of a side's samples beyond where it first meets its extreme still there
MIN_HELD_SAMPLES = 10
MIRROR_QUANTA = 1.5             # ...or this many quanta (half a quantum of rounding, one of a last-digit wobble)
HELD_BAND_PX = 0.5
PIVOT_BAND_PX = 0.1
MIRROR_CLIP = 0.005             # the other side's distance from its level there (of the contrast): clipped
FLAT_PEAK = 0.3                 # fraction of a noise-free bar's peak at exactly one value: clipped flat...
FLAT_SHOULDER = 0.02            # ...unless it is reached gradually, through samples this far below (of the height)


def saturation_checks(distance, values, centre, rise_px, sides, limits, quantum, noise_free,
                      bright_core=None, monotone=True, contrast=None, bar_edge_px=None) -> list[Check]:
    """Clipping on either side (``sides``: list of (name, mask, level)) or,
    for a bar, at its peak (``bright_core``: mask of the peak samples).
    ``limits`` = (low, high) DN the sensor records (integer type limits or
    the user's), or None.  Clipping no limit declares (float data, 12 bits
    in 16) shows, where a side holds one exact value from some distance
    on (a noise-free plateau, or noise cut off), as that value held where
    the other side has not yet arrived at its own level
    (:func:`_held_plateaus`; ``monotone`` profiles only): a clip cuts the
    profile off while it still changes, a noise-free level is approached
    as smoothly as the other side's.  With noise and no such plateau, as
    a pile-up at one value.  ``contrast``: the step (DN), read off the
    values where not given; ``bar_edge_px``: a bar's half-width where it is
    known (given, not read off the profile), the pivot of its top's mirror.
    A batch of one of :func:`saturation_checks_many`."""
    return saturation_checks_many([dict(distance=distance, values=values, centre=centre, rise_px=rise_px,
                                        sides=sides, limits=limits, quantum=quantum, noise_free=noise_free,
                                        bright_core=bright_core, monotone=monotone, contrast=contrast,
                                        bar_edge_px=bar_edge_px)])[0]


def saturation_checks_many(calls: Sequence[dict[str, Any]]) -> list[list[Check]]:
    """:func:`saturation_checks` of many chips, the sides' held plateaus
    and pile-ups looked for together (:mod:`.ragged`): each chip's checks
    the same, to the bit, as alone.

    Parameters
    ----------
    calls : sequence of dict
        Each chip's keywords of :func:`saturation_checks`.

    Returns
    -------
    list of list of Check
        Each chip's checks, in order.

    Examples
    --------
    >>> d = np.linspace(-10.0, 10.0, 400)
    >>> edge = 200.0 + 1000.0 / (1.0 + np.exp(-d / 0.6))
    >>> calls = [dict(distance=d, values=v, centre=0.0, rise_px=2.0, limits=None, quantum=0.0, noise_free=True,
    ...               sides=[("dark", d <= -3.0, None), ("bright", d >= 3.0, None)])
    ...          for v in (edge, np.minimum(edge, 1000.0))]
    >>> [[c.outcome for c in checks] for checks in saturation_checks_many(calls)]
    [['passed'], ['failed']]
    """
    plans: list[list[Any]] = []
    held_asks: list[tuple] = []        # (distance, values, half, other, centre, name, contrast, quantum)
    pile_asks: list[tuple] = []        # (name, values, mask, quantum, contrast)
    for call in calls:
        plans.append(_plan(held_asks, pile_asks, **call))
    held = _held_plateaus(held_asks)
    piles = _pile_ups(pile_asks)
    out = []
    for plan in plans:
        checks = []
        for step in plan:
            if isinstance(step, Check):
                checks.append(step)
            elif step[0] == "held-or-pile":
                found = held[step[1]]
                if found is not None:
                    checks.append(found)
                elif step[2] is not None:
                    checks.append(piles[step[2]])
            else:                               # ("pile", its place)
                checks.append(piles[step[1]])
        out.append(checks or [Check("saturated", True, "no side reaches a saturation limit")])
    return out


def _plan(held_asks: list, pile_asks: list, *, distance, values, centre, rise_px, sides, limits, quantum, noise_free,
          bright_core=None, monotone=True, contrast=None, bar_edge_px=None) -> list:
    """One chip's checks in their order, those made among other chips'
    as places to fill: its held plateaus appended to ``held_asks``, its
    pile-ups to ``pile_asks``."""
    plan: list[Any] = []
    sides = list(sides)
    for name, mask, _ in sides:
        if limits is None:
            continue
        if mask.sum() < 5:
            plan.append(not_run("saturated", f"the {name} side holds {int(mask.sum())} samples beyond its "
                                "plateau's start (5 needed): its share at the limits not measured"))
            continue
        low, high = limits
        at_limit = float(np.mean((values[mask] <= low) | (values[mask] >= high)))
        plan.append(Check("saturated", at_limit <= SATURATED_SIDE,
                          f"the {name} side is saturated ({100 * at_limit:.0f} % of its samples at {low:g} "
                          f"or {high:g} DN): its true level is unknown", at_limit, SATURATED_SIDE))
    if monotone:
        halves = (distance < centre, distance > centre)      # the sides are listed left, right
        if contrast is None:
            contrast = abs(float(median(values[halves[1]]) - median(values[halves[0]])))
        for (name, mask, _), half, other in zip(sides, halves, halves[::-1]):
            held_asks.append((distance, values, half, other, centre, name, contrast, quantum))
            pile = None
            if not noise_free and mask.sum() >= 5:
                pile_asks.append((name, values, mask, quantum, contrast))
                pile = len(pile_asks) - 1
            plan.append(("held-or-pile", len(held_asks) - 1, pile))
    elif not noise_free:
        for name, mask, _ in sides:
            if mask.sum() >= 5:
                pile_asks.append((name, values, mask, quantum, None))
                plan.append(("pile", len(pile_asks) - 1))
    if bright_core is not None and bright_core.sum() >= 5:
        v = values[bright_core]
        background = float(median(values[~bright_core]))
        outward = 1.0 if v.mean() >= background else -1.0
        extreme = v.max() if outward > 0 else v.min()
        if limits is not None and (extreme <= limits[0] or extreme >= limits[1]):
            plan.append(Check("saturated", False, f"the bar's peak reaches the saturation limit {extreme:g} DN: "
                              "its true height is unknown", extreme, None))
        elif noise_free:
            plan.append(_held_top(distance, values, centre, extreme, outward, quantum, bar_edge_px)
                        or _flat_top(v, extreme, outward, abs(extreme - background)))
        else:
            pile_asks.append(("peak", values, bright_core, quantum, None))
            plan.append(("pile", len(pile_asks) - 1))
    return plan


def _held_plateaus(asks: Sequence[tuple]) -> list[Check | None]:
    """Each side's held plateau (``asks``: its distance, values, half,
    other half, centre, name, contrast and quantum), looked for together:
    a side that holds one exact value from a distance r0 on (r0 where
    the run of 0.5-px bands each with at least ``HELD_PLATEAU`` of its
    samples at the side's extreme begins, holding ``MIN_HELD_SAMPLES``), checked
    against the other side at r0: an unclipped profile has arrived there
    too (within ``MIRROR_CLIP`` of the contrast, or ``MIRROR_QUANTA`` quanta); a clip
    holds its value where the other side is still on its way.  None where
    the side holds no such plateau (noise)."""
    out: list[Check | None] = [None] * len(asks)
    looked = [k for k, (_, values, half, other, _, _, contrast, _) in enumerate(asks)
              if np.count_nonzero(half) >= 5 and other.any() and contrast > 0]
    if not looked:
        return out
    reach = [np.abs(asks[k][0] - asks[k][4]) for k in looked]
    sides = Groups([np.count_nonzero(asks[k][2]) for k in looked])
    v = np.concatenate([asks[k][1][asks[k][2]] for k in looked])
    sv = np.concatenate([s[asks[k][2]] for s, k in zip(reach, looked)])
    others = Groups([np.count_nonzero(asks[k][3]) for k in looked])
    level = others.median(np.concatenate([asks[k][1][asks[k][3]] for k in looked]))
    outward = sides.sum(v) / sides.sizes >= level
    extreme = np.where(outward, sides.extreme(v, True), sides.extreme(v, False))
    # r0: the nearest distance beyond which the side holds its extreme
    # (a generator's last-digit wobble near the plateau aside)
    band = np.floor(sv / HELD_BAND_PX).astype(int)
    slots = Groups(sides.extreme(band.astype(float), True).astype(np.intp) + 1)
    slot = sides.spread(slots.starts) + band
    counts = np.bincount(slot, minlength=slots.ids.size)
    at = np.bincount(slot, weights=(v == sides.spread(extreme)).astype(float), minlength=slots.ids.size)
    share = at / np.maximum(counts, 1)
    local = np.arange(slots.ids.size) - slots.spread(slots.starts)
    failing = np.where((counts > 0) & (share < HELD_PLATEAU), local, -1)
    first = slots.extreme(failing.astype(float), True).astype(np.intp) + 1      # the bands from here out all hold it
    held = slots.sum(np.where(local >= slots.spread(first), counts, 0).astype(float))
    for j in np.flatnonzero(held >= MIN_HELD_SAMPLES):
        k = looked[j]
        _, values, _, other, _, name, contrast, quantum = asks[k]
        r0 = float(sv[sides.starts[j]: sides.starts[j] + sides.sizes[j]][
            band[sides.starts[j]: sides.starts[j] + sides.sizes[j]] >= first[j]].min())
        so, vo = reach[j][other], values[other]
        plateau = float(median(vo[so >= 0.5 * (r0 + so.max())])) if (so >= r0).any() else float(median(vo))
        gap = _gap_at(so, vo, r0, plateau, contrast)
        if gap is None:
            continue
        limit = max(MIRROR_CLIP, MIRROR_QUANTA * quantum / contrast)
        out[k] = Check("saturated", gap <= limit,
                       f"the {name} side holds exactly {extreme[j]:g} DN from {r0:.2f} px out, where the other side "
                       f"is still {100 * gap:.1f} % of the contrast from its level (at most {100 * limit:.1f} %): "
                       "clipped", gap, limit)
    return out


def _gap_at(distance, values, at_px, level, scale) -> float | None:
    """How far (a fraction of ``scale``) the samples at ``at_px`` from the
    centre (their median, within 0.25 px, widened to 2 px for at least 3
    samples) stand from ``level``; None where none lie near."""
    width = 0.25
    near = np.abs(distance - at_px) <= width
    while near.sum() < 3 and width < 2.0:
        width *= 2
        near = np.abs(distance - at_px) <= width
    if not near.any():
        return None
    return abs(float(median(values[near])) - level) / scale


def _flat_top(peak_values, extreme, outward, height) -> Check:
    """A noise-free bar's peak clipped flat: much of it at exactly one value,
    met steeply (few samples within ``FLAT_SHOULDER`` of the bar's height
    below it).  A bar wider than its blur has a flat top of its own, but
    reaches it gradually, through a shoulder of samples just below.
    ``height``: the peak's height above the background (DN)."""
    at_top = peak_values == extreme
    below = outward * (extreme - peak_values)
    shoulder = np.count_nonzero((below > 0) & (below <= FLAT_SHOULDER * height))
    ratio = at_top.sum() / max(shoulder, 1)
    clipped = at_top.mean() > FLAT_PEAK and ratio > PILE_UP
    return Check("saturated", not clipped,
                 f"{100 * at_top.mean():.0f} % of the bar's peak sits at exactly {extreme:g} DN, {ratio:.1f} x as "
                 f"many samples as within {100 * FLAT_SHOULDER:g} % of its height below it: its top is clipped "
                 "flat", ratio, PILE_UP)


def _held_top(distance, values, centre, extreme, outward, quantum, bar_edge_px=None) -> Check | None:
    """A noise-free bar whose top holds one exact value out to r_top from
    its centre, checked as an edge's held side is: mirrored about the bar's
    side h (``bar_edge_px`` where the width is known, else where the side is
    steepest), the background at 2 h - r_top has arrived at its
    level too when the top is the bar's own (a bar wider than its blur; the
    top sums both sides' tails, the background at most as much), and is
    still on its way when a clip cut the top off.  None where the top holds
    no run of exact values from the centre (the steepness test decides)."""
    s = np.abs(distance - centre)
    band = np.floor(s / HELD_BAND_PX).astype(int)
    counts = np.bincount(band)
    at = np.bincount(band, weights=(values == extreme).astype(float))
    holding = (counts > 0) & (at >= HELD_PLATEAU * counts)
    if counts.size < 4 or not holding[0]:
        return None
    run = int(np.argmin(holding)) if not holding.all() else holding.size
    top = band < run
    if top.sum() < MIN_HELD_SAMPLES:
        return None
    far = s >= 0.75 * s.max()
    background = float(median(values[far]))
    height = outward * (extreme - background)
    if height <= 0:
        return None
    # the pivot: the bar's side at its steepest (a clip leaves it where it was)
    fine = np.floor(s / PIVOT_BAND_PX).astype(int)
    fine_counts = np.bincount(fine)
    filled = fine_counts > 0
    centres = (np.nonzero(filled)[0] + 0.5) * PIVOT_BAND_PX
    means = np.bincount(fine, weights=values)[filled] / fine_counts[filled]
    slope = outward * np.diff(means) / np.diff(centres)
    steepest = int(np.argmin(slope))
    if slope[steepest] >= 0:
        return None
    pivot = bar_edge_px or 0.5 * (centres[steepest] + centres[steepest + 1])
    r_top = float(s[(values == extreme) & (s < pivot)].max())      # where the top's exact value ends
    mirror = 2.0 * pivot - r_top
    gap = _gap_at(s, values, mirror, background, height)
    if gap is None:
        return None
    limit = max(MIRROR_CLIP, MIRROR_QUANTA * quantum / height)
    return Check("saturated", gap <= limit,
                 f"the bar's top holds exactly {extreme:g} DN out to {r_top:.2f} px from its centre, where (mirrored "
                 f"about its side, {pivot:.2f} px out) the background is still "
                 f"{100 * gap:.1f} % of the height from its level (at most {100 * limit:.1f} %): its top is "
                 "clipped flat", gap, limit)


def _pile_ups(asks: Sequence[tuple]) -> list[Check]:
    """Each side's pile-up at its extreme (``asks``: its name, the values,
    its mask, the quantum and the contrast or None), looked for together.
    With noise, clipping piles samples up at exactly the extreme value:
    many there, few at the nearest value present inside it (one quantum
    where the values are dense); a natural noise tail thins out instead.

    Given the ``contrast`` (an edge's side), a clip that trims only the
    noise's outer tail (the side's median inside it) passes when it moves
    the side's level by less than ``MIRROR_CLIP`` of the contrast: for a
    normal noise of sd sigma cut at z sd beyond the level, by
    sigma (phi(z) - z P(Z > z)) (a generator's last-digit wobble at a
    flat white level piles up so, harmlessly)."""
    if not asks:
        return []
    sides = Groups([np.count_nonzero(mask) for _, _, mask, _, _ in asks])
    rests = Groups([mask.size - np.count_nonzero(mask) for _, _, mask, _, _ in asks])
    v = np.concatenate([values[mask] for _, values, mask, _, _ in asks])
    outward = np.where(sides.sum(v) / sides.sizes >= rests.median(
        np.concatenate([values[~mask] for _, values, mask, _, _ in asks])), 1.0, -1.0)
    extreme = np.where(outward > 0, sides.extreme(v, True), sides.extreme(v, False))
    at_extreme = v == sides.spread(extreme)
    inside = sides.spread(outward) * (sides.spread(extreme) - v)
    # the nearest value present inside it: the quantum, or wider where the
    # values are sparser (a generator's own rounding steps)
    nearest = sides.extreme(np.where(inside > 0, inside, np.inf), False)
    nearest[~np.isfinite(nearest)] = 1.0
    q = np.maximum([quantum for _, _, _, quantum, _ in asks], nearest)
    just_inside = sides.sum(((inside > 0) & (inside <= 1.5 * sides.spread(q))).astype(float))
    counted = sides.sum(at_extreme.astype(float))
    out = []
    for j, (name, _, _, _, contrast) in enumerate(asks):
        ratio = counted[j] / max(just_inside[j], 1)
        share = float(counted[j] / sides.sizes[j])
        clipped = share > 0.05 and ratio > PILE_UP
        if clipped and contrast and share < 0.5:
            side = v[sides.starts[j]: sides.starts[j] + sides.sizes[j]]
            sigma = 1.4826 * float(median(np.abs(side - median(side))))
            z = NormalDist().inv_cdf(1.0 - share)
            clipped = sigma * (NormalDist().pdf(z) - z * share) > MIRROR_CLIP * contrast
        out.append(Check("saturated", not clipped,
                         f"{100 * share:.0f} % of the {name} side's samples sit at exactly "
                         f"{extreme[j]:g} DN, {ratio:.1f} x as many as just inside it: clipped", ratio, PILE_UP))
    return out
