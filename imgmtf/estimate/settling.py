"""Do the sides settle?  A side of a clean target is a flat field beside a
blur's tail, level + A / |s|^p: what an imaging system's LSF leaves beyond
a few widths of it (diffraction, stray light and every hard-edged aperture
fall off so).  Beyond three rises a Gaussian, a pixel, a defocus disk,
diffraction from f/4 to f/22 and an OLPF all stay within 0.1 % of the
contrast of that model, and their tails are alike on both sides.

Two things real imagery does break it, and the pipeline's tail model would
absorb either as blur (the MTF reads low, in the issue's case 0.04 for
0.27 at Nyquist):

- a level that curves across a side (an illumination fall-off, a slope
  beside a tarp): the side departs from level + A / |s|^p by a smooth
  shape that no tail takes;
- a plateau that never settles (one side still rising far from the target,
  a shading towards it): one side's tail is much larger than the other's,
  where a lens's own tails come in pairs.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .evidence import Evidence
from .gate import ROUNDING_SHARE, Check, beyond_rounding, not_run
from .ragged import Groups

MIN_SIDE_SAMPLES = 40
MIN_SIDE_EXTENT_PX = 4.0       # a side spanning less beyond the plateau's start is too short to see curve...
MIN_PLATEAU_PX = 2.0           # ...and one spanning less than this holds no plateau at all: refused
BAND_PX = 1.0                  # the side's residuals are averaged in bands this wide
MIN_BAND_SAMPLES = 5
SMOOTH_DEGREE = 3              # a smooth departure: a cubic across the side's extent
MAX_DEPARTURE = 0.02           # of the contrast: refused beyond this...
WARN_DEPARTURE = 0.005         # ...and said beyond this
MAX_TAIL_ASYMMETRY = 0.05      # one side's unsettled share at its start beyond the other's...
MAX_UNSETTLED = 0.08            # ...with this much of the contrast still to come on it: refused
WARN_TAIL_ASYMMETRY = 0.03      # said, with...
WARN_UNSETTLED = 0.04           # ...this much still to come (a gamma-encoded camera edge shows up to 6.5 %)
SIGNIFICANCE = 5.0             # in standard deviations of the noise


def settled_sides(ev: Evidence) -> tuple[list[Check], list[str]]:
    """The departure of each side from level + A / |s|^p (a smooth shape
    fitted to its band means) and the asymmetry of the two sides' tails.

    Returns the checks (reason ``non-uniform``) and the warnings for
    departures too small to refuse but larger than the estimate ignores.
    The chip's sides are fitted as a batch of one
    (:func:`settled_sides_many`).
    """
    return settled_sides_many([ev])[0]


def settled_sides_many(evidences: Sequence[Evidence]) -> list[tuple[list[Check], list[str]]]:
    """:func:`settled_sides` of many chips, their sides fitted together
    (:mod:`.ragged`): each chip's outcome the same, to the bit, as alone.

    Parameters
    ----------
    evidences : sequence of Evidence
        The chips' samples and shapes.

    Returns
    -------
    list of (list of Check, list of str)
        Each chip's checks and warnings, in order.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.evidence import evidence_of
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chips = [imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", a), 60, noise_std_dn=2.0, seed=1).image
    ...          for a in (5.0, 8.0)]
    >>> ms = [run(EdgeKind(), c, make_settings()) for c in chips]
    >>> evs = [evidence_of(EdgeKind(), m.chip, m.located, m.estimate.samples, m.shape, m.noise) for m in ms]
    >>> settled_sides_many(evs) == [settled_sides(ev) for ev in evs]
    True
    """
    fits = _side_fits(evidences)
    return [_verdicts(ev, fits[2 * k: 2 * k + 2]) for k, ev in enumerate(evidences)]


def _verdicts(ev: Evidence, fits: list[dict | Check]) -> tuple[list[Check], list[str]]:
    """A chip's settling checks and warnings from its two sides' fits
    (:func:`_side_fits`)."""
    checks: list[Check] = []
    warnings: list[str] = []
    for name, fit in zip(ev.side_names, fits):
        if isinstance(fit, Check):
            # (no value: the gate's figures of a side's variation are shares of the contrast)
            checks.append(Check(fit.reason, fit.passed, fit.message.format(name=name), ran=fit.ran))
            continue
        if fit["departure"] is None:
            checks.append(not_run("non-uniform", f"the {name} side spans too little beyond its plateau's start "
                                  f"(at least {MIN_SIDE_EXTENT_PX:g} px in {SMOOTH_DEGREE + 2} 1-px bands of "
                                  f"{MIN_BAND_SAMPLES} samples) to see its level curve"))
            continue
        departure, sd, where = fit["departure"]
        share = departure / ev.contrast
        significant = departure > SIGNIFICANCE * sd
        checks.append(Check(
            "non-uniform", not (significant and share > MAX_DEPARTURE),
            f"the {name} side's level departs from a settled level by {100 * share:.1f} % of the contrast "
            f"({where:.0f} px from the {ev.name}; at most {100 * MAX_DEPARTURE:g} %): it curves or keeps "
            "changing (illumination, a slope), not a uniform field", share, MAX_DEPARTURE))
        if significant and WARN_DEPARTURE < share <= MAX_DEPARTURE:
            warnings.append(f"the {name} side's level departs from a settled level by {100 * share:.1f} % of "
                            f"the contrast ({where:.0f} px from the {ev.name}): a shading, a halo or a "
                            "texture there changes the MTF")
    if any(isinstance(fit, Check) for fit in fits):
        checks.append(not_run("non-uniform", "the two sides' tails cannot be compared: "
                              + " and ".join(ev.side_names[i] for i, fit in enumerate(fits) if isinstance(fit, Check))
                              + " side not fitted"))
    else:
        (left, left_sd), (right, right_sd) = (fit["unsettled"] for fit in fits)  # type: ignore[index]
        asymmetry, slow = abs(left - right), max(left, right)
        significant = asymmetry > SIGNIFICANCE * math.hypot(left_sd, right_sd)
        slower = ev.side_names[0] if left > right else ev.side_names[1]
        unsettled = significant and asymmetry > MAX_TAIL_ASYMMETRY and slow > MAX_UNSETTLED
        checks.append(Check(
            "non-uniform", not unsettled,
            f"the {slower} side has not settled {ev.plateau_px:.1f} px from the {ev.name}: "
            f"{100 * slow:.1f} % of the contrast is still to come there (at most {100 * MAX_UNSETTLED:g} %), "
            f"against {100 * min(left, right):.1f} % on the other side: a shading beside the target, not a "
            "lens's tails", slow, MAX_UNSETTLED))
        if significant and not unsettled and asymmetry > WARN_TAIL_ASYMMETRY and slow > WARN_UNSETTLED:
            warnings.append(f"the {slower} side settles more slowly than the other ({100 * slow:.1f} % of the "
                            f"contrast still to come {ev.plateau_px:.1f} px from the {ev.name}, against "
                            f"{100 * min(left, right):.1f} %): a shading beside the target, or a gamma-encoded "
                            "image, reads as blur")
    return checks, warnings


def _side_fits(evidences: Sequence[Evidence]) -> list[dict | Check]:
    """Every chip's two sides' level + A / |s|^p fits (left, right, chip
    after chip), made together: each side's smooth departure (DN, its
    standard deviation, where, px; None where the side holds too few bands
    to see a curve) and its unsettled share at the side's start (fraction
    of the contrast towards the other level, and its sd).  Where no fit
    can be made, the side's check instead (its message holds ``{name}``
    for the side's name): failed where the side holds no plateau within
    the chip (too few samples, too short a span beyond ``plateau_px``:
    a level still changing there reads as blur, and nothing would
    show it), not run where the fit is ill-conditioned."""
    side_s, side_v, owner = [], [], []
    for ev in evidences:
        s = ev.distance_px - ev.centre_px
        for mask in (s <= -ev.plateau_px, s >= ev.plateau_px):
            side_s.append(s[mask])
            side_v.append(ev.values[mask])
            owner.append(ev)
    sides = Groups([side.size for side in side_s])
    side = np.concatenate(side_s) if side_s else np.empty(0)
    reach = np.abs(side)
    counts = sides.sizes
    far, nearest = sides.extreme(reach, True), sides.extreme(reach, False)
    extent = np.where(counts > 0, far - nearest, 0.0)
    out: list[dict | Check | None] = [None] * sides.count
    for g in np.flatnonzero((counts < MIN_SIDE_SAMPLES) | (extent < MIN_PLATEAU_PX)):
        ev = owner[g]
        out[g] = Check("non-uniform", False,
                       f"the {{name}} side holds no plateau within the chip: {counts[g]} samples over "
                       f"{extent[g]:.1f} px lie beyond {ev.plateau_px:.1f} px from the {ev.name} (at least "
                       f"{MIN_SIDE_SAMPLES} over {MIN_PLATEAU_PX:g} px needed to see it settle): its level may "
                       "still be changing (illumination, a slope) and would read as blur; crop wider or choose "
                       "a flatter side")
    fitted = np.array([o is None for o in out], bool)
    if not fitted.any():
        return out      # type: ignore[return-value]   # every place filled
    keep = sides.spread(fitted)
    fits = Groups(counts[fitted])
    owners = [owner[g] for g in np.flatnonzero(fitted)]
    side, reach, v = side[keep], reach[keep], np.concatenate(side_v)[keep]
    u = fits.power(reach, [-float(ev.tail_power) for ev in owners])
    n = fits.sizes.astype(float)
    # the straight line in u in closed form about its mean: the normal
    # matrix [[n, sum u], [sum u, sum u^2]] has determinant n * spread
    mean_u = fits.sum(u) / n
    centred = u - fits.spread(mean_u)
    spread = fits.sum(centred * centred)
    trace = n + spread + n * mean_u ** 2
    largest = 0.5 * (trace + np.hypot(n - spread - n * mean_u ** 2, 2.0 * n * mean_u))
    conditioned = (spread > 0) & ~(largest ** 2 > 1e12 * n * spread)      # its condition number, largest^2 / det
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = fits.sum(centred * v) / spread
    level = fits.sum(v) / n - slope * mean_u
    resid = v - (fits.spread(level) + fits.spread(slope) * u)
    quantum = np.array([ev.quantum for ev in owners])
    sigma2 = np.maximum(fits.sum(resid * resid) / np.maximum(n - 2, 1), quantum ** 2 / 12.0)
    departures = _departures(fits, reach, resid, fits.extreme(reach, False), sigma2,
                             np.array([ev.rounding_floor for ev in owners]),
                             np.array([abs(ev.contrast) for ev in owners]), extent[fitted])
    firsts = side[fits.starts]
    for j, g in enumerate(np.flatnonzero(fitted)):
        ev = owners[j]
        if not conditioned[j]:
            out[g] = not_run("non-uniform", "the {name} side's level and tail cannot be told apart (its samples "
                             "span too little of the tail): its settling not judged")
            continue
        # the model's own noise: its tail at the side's start, towards the target's other level
        start_u = ev.plateau_px ** -float(ev.tail_power)
        towards = _towards_target(ev, left=bool(firsts[j] < 0))
        tail_cov = float(sigma2[j] / spread[j])          # the slope's variance, (M^-1)[1, 1] sigma^2
        unsettled = (beyond_rounding(towards * float(slope[j]) * start_u / ev.contrast),
                     math.sqrt(tail_cov) * start_u / ev.contrast)
        out[g] = {"departure": departures[j], "unsettled": unsettled}
    return out      # type: ignore[return-value]   # every place filled


def _departures(sides: Groups, reach: np.ndarray, resid: np.ndarray, nearest: np.ndarray, sigma2: np.ndarray,
                floor: np.ndarray, contrast: np.ndarray, extent: np.ndarray) -> list[tuple | None]:
    """Each side's smooth departure from its model: a Legendre cubic fitted
    to its 1-px band means of the residuals ``resid``, weighted by their
    errors; (its largest size (DN), that size's sd, where (px)), or None
    where the side holds too few full bands or too short an extent."""
    band = ((reach - sides.spread(nearest)) / BAND_PX).astype(int)       # (non-negative: truncation is the floor)
    # each side's bands in a run of slots of its own
    slots = Groups(np.where(sides.sizes > 0, np.nan_to_num(sides.extreme(band.astype(float), True)) + 1, 0))
    slot = sides.spread(slots.starts) + band
    counts = np.bincount(slot, minlength=slots.ids.size)
    sums = np.bincount(slot, weights=resid, minlength=slots.ids.size)
    full = counts >= MIN_BAND_SAMPLES
    used = slots.sum(full.astype(float))
    curved = (used > SMOOTH_DEGREE + 1) & (extent >= MIN_SIDE_EXTENT_PX)
    out: list[tuple | None] = [None] * sides.count
    if not curved.any():
        return out
    take = full & slots.spread(curved)
    bands = Groups(slots.sum(take.astype(float)).astype(np.intp)[curved])
    groups = np.flatnonzero(curved)
    centres = nearest[slots.ids[take]] + (np.flatnonzero(take) - slots.starts[slots.ids[take]] + 0.5) * BAND_PX
    counted = counts[take]
    means = sums[take] / counted
    error2 = bands.spread(sigma2[groups]) / counted + bands.spread(floor[groups] ** 2)
    first = centres[bands.starts]
    last = centres[bands.starts + bands.sizes - 1]
    t = 2.0 * (centres - bands.spread(first)) / bands.spread(np.maximum(last - first, 1e-9)) - 1.0
    basis = np.polynomial.legendre.legvander(t, SMOOTH_DEGREE)
    weights = 1.0 / np.maximum(error2, 1e-300)
    size = SMOOTH_DEGREE + 1
    normal_b = np.empty((bands.count, size, size))
    for i in range(size):
        for j in range(i, size):
            normal_b[:, i, j] = normal_b[:, j, i] = bands.sum(weights * basis[:, i] * basis[:, j])
    cov = np.linalg.pinv(normal_b)
    rhs = [bands.sum(weights * basis[:, i] * means) for i in range(size)]
    smooth_coef = [sum(cov[:, i, j] * rhs[j] for j in range(size)) for i in range(size)]
    curve = sum(basis[:, i] * bands.spread(smooth_coef[i]) for i in range(size))
    flat = bands.extreme(np.abs(curve), True) <= ROUNDING_SHARE * contrast[groups]
    # a flat side (noise-free): the curve is the arithmetic's rounding, and where it peaks would
    # move with any change of the arithmetic before it; no departure, said at the side's start
    curve = np.where(bands.spread(flat), 0.0, curve)
    worst = bands.starts + bands.argmax(np.abs(curve))
    row = basis[worst]
    variance = sum(row[:, i] * sum(cov[:, i, j] * row[:, j] for j in range(size)) for i in range(size))
    sd = np.sqrt(np.maximum(variance, 0.0))
    for k, g in enumerate(groups):
        out[g] = (float(abs(curve[worst[k]])), float(sd[k]), float(centres[worst[k]]))
    return out


def _towards_target(ev: Evidence, left: bool) -> float:
    """+1 or -1: the sign that turns a side's tail amplitude A into the
    share of the contrast still to come towards the target (positive for a
    blur's tail, whose LSF is positive)."""
    if ev.profile == "bar":
        return 1.0 if ev.high >= ev.low else -1.0
    rising = ev.high >= ev.low           # the right level above the left
    return (1.0 if rising else -1.0) * (1.0 if left else -1.0)
