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

import numpy as np

from .evidence import Evidence
from .gate import ROUNDING_SHARE, Check, beyond_rounding, not_run

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
    """
    s = ev.distance_px - ev.centre_px
    fits = [_side_fit(ev, s, mask) for mask in (s <= -ev.plateau_px, s >= ev.plateau_px)]
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


def _side_fit(ev: Evidence, s: np.ndarray, mask: np.ndarray) -> dict | Check:
    """One side's level + A / |s|^p fit: its smooth departure (DN, its
    standard deviation, where, px; None where the side holds too few bands
    to see a curve) and its unsettled share at the side's start (fraction
    of the contrast towards the other level, and its sd).  Where no fit
    can be made, the side's check instead (its message holds ``{name}``
    for the side's name): failed where the side holds no plateau within
    the chip (too few samples, too short a span beyond ``plateau_px``:
    a level still changing there reads as blur, and nothing would
    show it), not run where the fit is ill-conditioned."""
    side = s[mask]
    count = side.size
    reach = np.abs(side)
    extent = float(reach.max() - reach.min()) if count else 0.0
    if count < MIN_SIDE_SAMPLES or extent < MIN_PLATEAU_PX:
        return Check("non-uniform", False,
                     f"the {{name}} side holds no plateau within the chip: {count} samples over {extent:.1f} px lie "
                     f"beyond {ev.plateau_px:.1f} px from the {ev.name} (at least {MIN_SIDE_SAMPLES} over "
                     f"{MIN_PLATEAU_PX:g} px needed to see it settle): its level may still be changing "
                     "(illumination, a slope) and would read as blur; crop wider or choose a flatter side")
    v = ev.values[mask]
    u = reach ** -float(ev.tail_power)
    # the straight line in u in closed form about its mean: the normal
    # matrix [[n, sum u], [sum u, sum u^2]] has determinant n * spread
    mean_u = float(u.sum()) / count
    centred = u - mean_u
    spread = float(centred @ centred)
    n = u.size
    trace = n + spread + n * mean_u ** 2
    largest = 0.5 * (trace + math.hypot(n - spread - n * mean_u ** 2, 2.0 * n * mean_u))
    if not spread > 0 or largest ** 2 > 1e12 * n * spread:      # its condition number, largest^2 / det
        return not_run("non-uniform", "the {name} side's level and tail cannot be told apart (its samples span "
                       "too little of the tail): its settling not judged")
    coef = np.empty(2)
    coef[1] = float(centred @ v) / spread
    coef[0] = float(v.sum()) / count - coef[1] * mean_u
    resid = v - (coef[0] + coef[1] * u)
    sigma2 = max(float(resid @ resid) / max(resid.size - 2, 1), ev.quantum ** 2 / 12.0)
    # the model's own noise: its tail at the side's start, towards the target's other level
    start_u = ev.plateau_px ** -float(ev.tail_power)
    towards = _towards_target(ev, left=bool(side[0] < 0))
    tail_cov = sigma2 / spread                      # the slope's variance, (M^-1)[1, 1] sigma^2
    unsettled = (beyond_rounding(towards * coef[1] * start_u / ev.contrast),
                 math.sqrt(tail_cov) * start_u / ev.contrast)

    nearest = float(reach.min())
    band = ((reach - nearest) / BAND_PX).astype(int)       # (non-negative: truncation is the floor)
    counts = np.bincount(band)
    sums = np.bincount(band, weights=resid)
    full = counts >= MIN_BAND_SAMPLES
    if full.sum() <= SMOOTH_DEGREE + 1 or extent < MIN_SIDE_EXTENT_PX:
        return {"departure": None, "unsettled": unsettled}
    centres = nearest + (np.nonzero(full)[0] + 0.5) * BAND_PX
    counted = counts[full]
    means = sums[full] / counted
    error2 = sigma2 / counted + ev.rounding_floor ** 2
    t = 2.0 * (centres - centres[0]) / max(centres[-1] - centres[0], 1e-9) - 1.0
    basis = np.polynomial.legendre.legvander(t, SMOOTH_DEGREE)
    weights = 1.0 / np.maximum(error2, 1e-300)
    normal_b = (basis * weights[:, None]).T @ basis
    cov = np.linalg.pinv(normal_b)
    smooth_coef = cov @ (basis * weights[:, None]).T @ means
    curve = basis @ smooth_coef
    if np.max(np.abs(curve)) <= ROUNDING_SHARE * abs(ev.contrast):
        # a flat side (noise-free): the curve is the arithmetic's rounding, and where it peaks would
        # move with any change of the arithmetic before it; no departure, said at the side's start
        curve = np.zeros_like(curve)
    worst = int(np.argmax(np.abs(curve)))
    sd = math.sqrt(max(float(basis[worst] @ cov @ basis[worst]), 0.0))
    return {"departure": (float(abs(curve[worst])), sd, float(centres[worst])), "unsettled": unsettled}


def _towards_target(ev: Evidence, left: bool) -> float:
    """+1 or -1: the sign that turns a side's tail amplitude A into the
    share of the contrast still to come towards the target (positive for a
    blur's tail, whose LSF is positive)."""
    if ev.profile == "bar":
        return 1.0 if ev.high >= ev.low else -1.0
    rising = ev.high >= ev.low           # the right level above the left
    return (1.0 if rising else -1.0) * (1.0 if left else -1.0)
