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
"""
from __future__ import annotations

import numpy as np

MAX_LEVELS = 256          # with more steps the staircase's own error is below 0.001 at Nyquist
MAX_CROSSINGS_PER_PX = 100  # denser steps (a sharp edge of many DN) read true as they are, and
                            # rebuilding them costs the FWHM more than it gains
MAX_NOISE_QUANTA = 0.5    # noise above half a step dithers the rounding away
MIN_CROSSINGS = 3
SMOOTH_ABOVE = 40           # more crossings than this are smoothed, fewer interpolated
Z_RANGE = 8.0             # the rebuilt ESF is tabulated for |z| <= this


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
    >>> import numpy as np
    >>> from scipy.special import ndtr
    >>> d = np.linspace(-5, 5, 4001)
    >>> v = np.round(100 + 12 * ndtr(d / 0.6))
    >>> rebuilt = dequantise(d, v, 1.0)
    >>> bool(np.abs(rebuilt - (100 + 12 * ndtr(d / 0.6))).max() < 0.05)
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
    # each threshold's crossing: the split of the sorted samples that leaves
    # the fewest above it on the left and below it on the right
    above = u[None, :] > thresholds[:, None]
    above_left = np.cumsum(above, axis=1)
    n = u.size
    below_right = (n - np.arange(1, n + 1))[None, :] - (above_left[:, -1:] - above_left)
    split = np.argmin(above_left + below_right, axis=1)
    crossing = 0.5 * (d[split] + d[np.minimum(split + 1, n - 1)])
    increasing = np.r_[True, np.diff(crossing) > 1e-9]
    crossing, thresholds = crossing[increasing], thresholds[increasing]
    if crossing.size < MIN_CROSSINGS:
        return None
    fraction = (thresholds - low) / (high - low)
    rise = np.interp(0.9, fraction, crossing) - np.interp(0.1, fraction, crossing)
    if rise > 0 and 0.8 * (high - low) / quantum / rise > MAX_CROSSINGS_PER_PX:
        return None
    # SciPy is slow to import: only for the few staircase edges that need it
    from scipy.interpolate import PchipInterpolator, make_smoothing_spline
    from scipy.special import ndtr, ndtri
    z = ndtri((thresholds - low) / (high - low))
    if z.size > SMOOTH_ABOVE:
        # many crossings, each placed to within the samples' spacing: smooth
        # their jitter (the smoothing chosen by generalised cross-validation)
        position = make_smoothing_spline(z, crossing)
    else:
        position = PchipInterpolator(z, crossing, extrapolate=False)
    slope = position.derivative()
    ends = position(z[[0, -1]])
    grid = np.linspace(-Z_RANGE, Z_RANGE, 4001)
    at = np.where(grid < z[0], ends[0] + slope(z[0]) * (grid - z[0]),
                  np.where(grid > z[-1], ends[1] + slope(z[-1]) * (grid - z[-1]), position(grid)))
    at = np.maximum.accumulate(at)
    esf = ndtr(np.interp(distance, at, grid))
    return sign * (low + (high - low) * esf)
