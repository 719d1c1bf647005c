"""Undo the staircase of a noise-free quantised edge.

When the pixel noise is well below one DN step, rounding is not averaged
away: every sample at the same distance from the edge rounds the same way,
and the over-sampled ESF is a staircase of as many steps as the edge spans
DN.  Its MTF is not the edge's: with 12 DN across a Gaussian edge the
staircase alone reads MTF at Nyquist 0.029 low, whatever the smoothing.

But the staircase still says exactly where the ESF crosses every
half-integer level: the boundary between the samples that rounded down
and up.  The ESF is smooth and monotone, so it is rebuilt through those
crossings: the distance d is interpolated (monotone cubic) as a function
of z = probit(ESF), in which a Gaussian-type edge is a straight line, and
continued linearly in z beyond the outermost crossings.  Each sample's
value is then read off the rebuilt ESF.  With 12 to 30 DN edges this
brings MTF at Nyquist within about 0.009 of the truth (bench/edge_accuracy.py).

It costs about what the rest of a measurement does: O(n) in the samples
(each crossing searched only among the samples whose order disagrees about
it), its curves in closed form (:mod:`.splines`), no SciPy.
"""
from __future__ import annotations

import functools
import math
from statistics import NormalDist

import numpy as np

from .splines import monotone_cubic, smoothing_spline

MAX_LEVELS = 256          # with more steps the staircase's own error is below 0.001 at Nyquist
MAX_CROSSINGS_PER_PX = 100  # denser steps (a sharp edge of many DN) read true as they are, and
                            # rebuilding them costs the FWHM more than it gains
MAX_NOISE_QUANTA = 0.5    # noise above half a step dithers the rounding away
MIN_CROSSINGS = 3
SMOOTH_ABOVE = 40           # more crossings than this are smoothed, fewer interpolated
Z_RANGE = 8.0             # the rebuilt ESF is tabulated for |z| <= this
Z_GRID = np.linspace(-Z_RANGE, Z_RANGE, 4001)


def dequantise(distance: np.ndarray, values: np.ndarray, quantum: float):
    """Sample values read off the ESF rebuilt through its level crossings,
    or None where the staircase needs no undoing (unquantised data, noise
    of ``MAX_NOISE_QUANTA`` steps or more, more than ``MAX_LEVELS`` steps
    or more than ``MAX_CROSSINGS_PER_PX`` within the 10-90 % rise, or too
    few crossings).

    Parameters
    ----------
    distance : ndarray
        Each sample's signed distance from the edge (px).
    values : ndarray
        Its value (DN), quantised to multiples of ``quantum``.
    quantum : float
        The DN step (0: not quantised).  The noise is the scatter of the
        outermost eighth of the samples on each side.

    Returns
    -------
    ndarray or None
        The de-quantised values (DN), same shape as ``values``.

    Examples
    --------
    >>> import math
    >>> d = np.linspace(-5, 5, 4001)
    >>> exact = 100 + 6 * np.array([math.erfc(-x / (0.6 * math.sqrt(2))) for x in d])
    >>> rebuilt = dequantise(d, np.round(exact), 1.0)
    >>> bool(np.abs(rebuilt - exact).max() < 0.05)
    True
    """
    if quantum <= 0:
        return None
    order = np.argsort(distance)
    d, v = distance[order], values[order]
    n_side = max(v.size // 8, 1)
    noise = 0.5 * (np.std(v[:n_side]) + np.std(v[-n_side:]))
    if noise >= MAX_NOISE_QUANTA * quantum:
        return None
    first, last = float(np.median(v[:n_side])), float(np.median(v[-n_side:]))
    sign = 1.0 if last >= first else -1.0
    u = sign * v
    low, high = sign * first, sign * last
    if not 1 < (high - low) / quantum <= MAX_LEVELS:
        return None
    thresholds = (np.arange(np.ceil(low / quantum), np.floor(high / quantum)) + 0.5) * quantum
    thresholds = thresholds[(thresholds > low) & (thresholds < high)]
    if thresholds.size < MIN_CROSSINGS:
        return None
    split = _crossings(u, thresholds)
    n = u.size
    crossing = 0.5 * (d[split] + d[np.minimum(split + 1, n - 1)])
    increasing = np.r_[True, np.diff(crossing) > 1e-9]
    crossing, thresholds = crossing[increasing], thresholds[increasing]
    if crossing.size < MIN_CROSSINGS:
        return None
    fraction = (thresholds - low) / (high - low)
    rise = np.interp(0.9, fraction, crossing) - np.interp(0.1, fraction, crossing)
    if rise > 0 and 0.8 * (high - low) / quantum / rise > MAX_CROSSINGS_PER_PX:
        return None
    z = np.array([NormalDist().inv_cdf(float(f)) for f in fraction])      # one per level, not per sample
    if z.size > SMOOTH_ABOVE:
        # many crossings, each placed to within the samples' spacing: smooth
        # their jitter (the smoothing chosen by generalised cross-validation)
        position = smoothing_spline(z, crossing)
    else:
        position = monotone_cubic(z, crossing)
    first_z, last_z = position.x[0], position.x[-1]
    at = np.where(Z_GRID < first_z, position.y[0] + position.slope[0] * (Z_GRID - first_z),
                  np.where(Z_GRID > last_z, position.y[-1] + position.slope[-1] * (Z_GRID - last_z),
                           position(Z_GRID)))
    at = np.maximum.accumulate(at)
    esf = np.interp(distance, at, _normal_cdf_table())
    return sign * (low + (high - low) * esf)


def _crossings(u: np.ndarray, thresholds: np.ndarray) -> np.ndarray:
    """Each threshold's crossing in ``u`` (values in the order of their
    distance): the split s (left: samples 0..s) leaving the fewest samples
    above it on the left plus at or below it on the right, the first of
    equals.  Before the first sample above it and after the last at or
    below, every step away raises that count: only the samples between
    (none for a clean staircase, a few where noise or the rows' phases
    interleave levels) are searched, all thresholds in one pass."""
    n = u.size
    first_above = np.searchsorted(np.maximum.accumulate(u), thresholds, side="right")
    last_below = np.searchsorted(np.minimum.accumulate(u[::-1])[::-1], thresholds, side="right") - 1
    start = np.maximum(first_above - 1, 0)
    length = np.maximum(last_below - start + 1, 1)
    # every (threshold, candidate split) pair, thresholds one after another
    offsets = np.cumsum(length) - length
    owner = np.repeat(np.arange(thresholds.size), length)
    split = np.arange(int(length.sum())) - offsets[owner] + start[owner]
    above = (u[np.minimum(split, n - 1)] > thresholds[owner]).astype(np.int64)
    # within each threshold's run: samples above it up to the split, at or below it after the split
    above_left = _run_cumsum(above, offsets)
    below = 1 - above
    below_right = np.add.reduceat(below, offsets)[owner] - _run_cumsum(below, offsets)
    cost = above_left + below_right
    best = np.minimum.reduceat(cost, offsets)
    first = np.where(cost == best[owner], np.arange(cost.size), cost.size)
    return split[np.minimum.reduceat(first, offsets)]


def _run_cumsum(values: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Cumulative sums of ``values`` restarting at every offset."""
    total = np.cumsum(values)
    before = np.r_[0, total][offsets]
    return total - np.repeat(before, np.diff(np.r_[offsets, values.size]))


@functools.cache
def _normal_cdf_table() -> np.ndarray:
    """The standard normal CDF on ``Z_GRID`` (4001 values, once)."""
    return np.array([0.5 * math.erfc(-z / math.sqrt(2.0)) for z in Z_GRID])
