"""The sides of a profile and its tails: level + A / |s|^p fitted to each
side's samples, how far out that model explains the profile, and the
signal the tail holds beyond the core."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MIN_TAIL_SAMPLES = 12
MODEL_CHECK_PX = 3.0              # the model must explain this much of the profile past the core
MODEL_BIN_PX = 0.5


@dataclass(frozen=True, eq=False)
class SideFit:
    """Level + A / |s|^p fitted to one side's samples: ``coef`` (level, A),
    ``operator`` the least-squares map from the selected samples' values to
    ``coef`` (2 x n), ``mask`` which samples, ``sd`` the residual standard
    deviation (DN)."""

    coef: np.ndarray
    operator: np.ndarray
    mask: np.ndarray
    sd: float


def tail_integral(s, v, side: int, start: float, half_range: float, kind,
                  fit: SideFit | None = None) -> tuple[float, float]:
    """Area (DN px) of one side's fitted LSF-like tail a / s^2 from ``start``
    to the data's reach, a (1 / start - 1 / reach), and its standard error.
    ``fit``: the side's fit from ``start`` on where already made
    (:func:`reach_and_fit`)."""
    if fit is None:
        fit = fit_side(s, v, (np.sign(s) == side) & (np.abs(s) >= start), kind.tail_power)
    if not np.isfinite(fit.coef).all() or not math.isfinite(fit.sd):
        return 0.0, math.inf
    to_amplitude = kind.lsf_tail_amplitudes()[0 if side < 0 else 1]
    span = 1.0 / start - 1.0 / max(half_range, start)
    amplitude_sd = fit.sd * math.sqrt(float(np.sum((to_amplitude @ fit.operator) ** 2)))
    return float(to_amplitude @ fit.coef) * span, amplitude_sd * span


def outer_samples(d: np.ndarray, half_range: float, fraction: float) -> tuple[np.ndarray, np.ndarray]:
    """Masks of the samples beyond ``fraction`` of the range on the left
    and on the right (at least the three outermost pixels' worth each)."""
    order = np.sort(d)
    left = min(-fraction * half_range, order[min(order.size - 1, 3 * MIN_TAIL_SAMPLES)])
    right = max(fraction * half_range, order[max(0, order.size - 1 - 3 * MIN_TAIL_SAMPLES)])
    return d <= left, d >= right


def fit_side(s: np.ndarray, v: np.ndarray, mask: np.ndarray, power: int) -> SideFit:
    """Least-squares level and tail of the samples selected by ``mask``
    (``s``: distance from the target's centre).  Too few samples, or too
    little spread in |s|^-p to tell a tail from a level: a flat level."""
    x = np.abs(s[mask])
    values = v[mask]
    if x.size < 3:
        return SideFit(np.array([np.nan, 0.0]), np.zeros((2, x.size)), mask, math.nan)
    u = x ** -float(power)
    mean_u = float(np.add.reduce(u)) / x.size          # np.mean's sum and division, without its wrappers
    centred = u - mean_u
    spread = float(centred @ centred)
    operator = np.empty((2, x.size))
    if x.size >= MIN_TAIL_SAMPLES and math.sqrt(spread / x.size) > 1e-3 * mean_u:
        # the straight-line fit in closed form about the mean of u: slope
        # centred . values / spread, level mean(values) - slope mean(u)
        operator[1] = centred / spread
        operator[0] = 1.0 / x.size - mean_u * operator[1]
        parameters = 2
    else:
        operator[0], operator[1] = 1.0 / x.size, 0.0
        parameters = 1
    coef = operator @ values
    resid = values - (coef[0] + coef[1] * u)
    dof = max(x.size - parameters, 1)
    return SideFit(coef, operator, mask, float(math.sqrt(resid @ resid / dof)))


def reach_and_fit(s: np.ndarray, v: np.ndarray, side: int, start: float, power: int, step: float,
                  floor: float = 0.0) -> tuple[float, SideFit | None]:
    """Where a side's tail model takes over, and the side's fit from there
    on where it was made (else None).

    The reach is the smallest distance from ``start`` on (in ``step`` px
    steps, at most half the side's range) from which level + A / |s|^p,
    fitted out to the end of the data, explains the next few pixels to
    within their noise.  Before it the LSF still carries structure of its
    own (a shoulder, a halo) that the window must keep as measured; at low
    SNR the test has little power and the core stays at ``start``.
    ``floor`` (DN) is a part of each bin's error that does not average down
    (rounding shared by neighbouring samples).  The fit is made of the same
    samples in the same order as :func:`fit_side` of all the samples
    selects from the reach on: the same floats."""
    on_side = np.sign(s) == side
    reach = np.abs(s[on_side])
    values = v[on_side]
    if reach.size < 4 * MIN_TAIL_SAMPLES:
        return start, None
    far = float(reach.max())
    x0 = start
    while x0 <= 0.5 * far:
        beyond = reach >= x0
        fit = fit_side(reach, values, beyond, power)
        near = beyond & (reach < x0 + MODEL_CHECK_PX)
        if not math.isfinite(fit.sd) or fit.sd == 0 or np.count_nonzero(near) < MIN_TAIL_SAMPLES:
            return x0, fit
        u = reach[near] ** -float(power)
        resid = values[near] - (fit.coef[0] + fit.coef[1] * u)
        bins = np.floor((reach[near] - x0) / MODEL_BIN_PX).astype(int)
        counts = np.bincount(bins)
        full = counts >= 3
        means = np.bincount(bins, weights=resid)[full] / counts[full]
        chi2 = float(np.add.reduce(means ** 2 / (fit.sd ** 2 / counts[full] + floor ** 2)))
        dof = int(np.count_nonzero(full))
        if dof == 0 or chi2 <= dof + 3.0 * math.sqrt(2.0 * dof):
            return x0, fit
        x0 += step
    return x0, None
