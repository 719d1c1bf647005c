"""Linearised (row influence) intervals: the estimate's gradient with
respect to every sample, times its residual, summed per row; the variance
of the row influences (the infinitesimal jackknife) with the covariances of
neighbouring rows, widened by the estimator's own systematic error."""
from __future__ import annotations

import math

import numpy as np

from ..._stats import t_quantile
from ..spectrum import NYQUIST
from .interval import Interval

# The estimator's own error where noise is not the whole error, added in
# quadrature to the interval: on exact chips the worst error at Nyquist is
# about 0.0005 for Gaussian-type blurs; the tail model's share of the
# signal is uncertain to about a tenth of itself.
SYSTEMATIC_NYQUIST = 0.0008
SYSTEMATIC_MTF50 = 0.001          # relative
TAIL_MODEL_UNCERTAINTY = 0.1
# A rebuilt staircase (a noise-free quantised edge) is off by up to 0.01 at
# Nyquist and 0.5 % in MTF50 on 12-30 DN edges, and its residuals are nil
SYSTEMATIC_DEQUANTISED = 0.005
SYSTEMATIC_DEQUANTISED_MTF50 = 0.003      # relative
# The window narrowed for noise cuts the LSF a little: at its narrowest (a
# third narrower) MTF50 reads about 1 % and MTF at Nyquist 0.002 high
NARROW_WINDOW_NYQUIST = 0.009
NARROW_WINDOW_MTF50 = 0.03                # relative
LEVERAGE_CAP = 0.9


def influence_sd(influence: np.ndarray, rows: np.ndarray) -> tuple[float, int]:
    """Standard error of a linearised estimate from per-sample influences
    (gradient times residual) and each sample's row: the rows' summed
    influences, their variance plus Bartlett-weighted covariances of
    neighbouring rows (lags up to 4 (n / 100)^(2/9)).  Returns (sd, number
    of rows)."""
    sds, n = influence_sds(np.asarray(influence, float)[None, :], rows)
    return float(sds[0]), n


def influence_sds(influences: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, int]:
    """:func:`influence_sd` of every row of ``influences`` (estimates,
    samples) at once.  Returns (sds, number of rows)."""
    ids, inverse = np.unique(rows, return_inverse=True)
    n, m = ids.size, influences.shape[0]
    bins = (inverse[None, :] + n * np.arange(m)[:, None]).ravel()
    per_row = np.bincount(bins, weights=influences.ravel(), minlength=m * n).reshape(m, n)
    if n < 3:
        return np.full(m, math.nan), n
    centred = per_row - per_row.mean(axis=1, keepdims=True)
    variance = np.einsum("ij,ij->i", centred, centred)
    lags = int(math.ceil(4 * (n / 100.0) ** (2.0 / 9.0)))
    for lag in range(1, min(lags, n - 1) + 1):
        variance += 2.0 * (1.0 - lag / (lags + 1.0)) * np.einsum("ij,ij->i", centred[:, lag:], centred[:, :-lag])
    return np.sqrt(np.maximum(variance, 0.0) * n / (n - 1)), n


def linearised_interval(value: float, sd: float, rows: int, confidence: float,
                        systematic: float = 0.0) -> Interval:
    """``value`` plus or minus Student's t (rows - 1 degrees of freedom)
    times the standard error ``sd`` widened by a ``systematic`` standard
    deviation in quadrature."""
    if not (math.isfinite(value) and math.isfinite(sd)) or rows < 3:
        return Interval.none()
    half = t_quantile(0.5 + confidence / 2, rows - 1) * math.hypot(sd, systematic)
    return Interval(value - half, value + half)



def influence_intervals(intervals, mtf, nyquist, f50, resampled, span, x, data_at, lsf, c, w, lsf_adjoint,
                         tail_shape, sides, to_amplitude, amplitudes, kind, d, v, row, tail_share,
                         dequantised, narrowed, width_influence):
    """Linearised intervals for MTF at Nyquist and MTF50 (see
    :mod:`.intervals`).

    The transform F(f) = sum_k e_k(f) [w_k lsf_k + (1 - w_k) model_k] is
    linear in the samples: through the LSF operator and the resampling
    (their adjoints) where the window holds data, through each side's tail
    amplitude (its least-squares operator), and for a bar through the
    background under the window.  Each figure is |F(f)| / |F(0)| divided by
    the corrections, so its gradient follows, and with each sample's
    residual (scaled up by its leverage) gives the row influences.  Where
    the divisor rests on a width read off the same samples
    (``width_influence``: its :class:`WidthReading` and a function giving
    dR(f) / dv), its
    pull joins the gradient, widened where Fieller's set for the zero is
    wider than the linearised one; the share of the variance at Nyquist it
    makes is returned third (None without it)."""
    step = float(x[1] - x[0])
    width_share = None
    freqs = np.array([0.0, NYQUIST] + ([f50] if math.isfinite(f50) else []))
    e = np.exp(-2j * np.pi * freqs[:, None] * x[None, :]) * step                   # (n_f, n_x)
    left = x < c
    model = np.where(left, amplitudes[0], amplitudes[1]) * tail_shape
    transform = e @ (w * lsf + (1.0 - w) * model)
    weighted = (e * w)[:, data_at]
    on_grid = lsf_adjoint(np.concatenate([weighted.real, weighted.imag]))
    full = np.zeros((on_grid.shape[0], resampled.grid.size))
    full[:, span[0]: span[1]] = on_grid
    through = resampled.adjoint(full)
    n_f = freqs.size
    grad_f = through[:n_f] + 1j * through[n_f:]                                  # dF(f) / dv
    for i, side in enumerate(sides):
        in_side = left if i == 0 else ~left
        per_amplitude = e @ ((1.0 - w) * tail_shape * in_side)
        idx = np.nonzero(side.mask)[0]
        grad_f[:, idx] += per_amplitude[:, None] * (to_amplitude[i] @ side.operator)[None, :]
        if kind.subtracts_background:
            grad_f[:, idx] -= 0.5 * (e @ w)[:, None] * side.operator[0][None, :]
    f0 = transform[0].real
    run_grid, run_values = resampled.grid[span[0]: span[1]], resampled.values[span[0]: span[1]]
    # each sample's residual from the profile: the resampled one where it
    # was resampled, the side's model beyond
    far = np.abs(d - c) ** -float(kind.tail_power)
    model_dn = np.where(d < c, sides[0].coef[0] + sides[0].coef[1] * far, sides[1].coef[0] + sides[1].coef[1] * far)
    inside = (d >= run_grid[0]) & (d <= run_grid[-1])
    residual = v - np.where(inside, np.interp(d, run_grid, run_values), model_dn)
    if resampled.leverage is not None:
        residual = residual / np.sqrt(1.0 - np.minimum(resampled.leverage, LEVERAGE_CAP))
    width_pull = None
    if width_influence is not None:
        reading, spectrum_pull = width_influence
        dspectrum_dv = spectrum_pull()
        dwidth_dv = reading.width_change(dspectrum_dv[0])
        width_sd, n_rows = influence_sd(dwidth_dv * residual, row)
        spectrum_sd, _ = influence_sds(dspectrum_dv[1:] * residual, row)
        t = t_quantile(0.5 + intervals.confidence / 2, max(n_rows - 1, 1))
        spread = reading.spread_px(spectrum_sd, t)
        widen = max(1.0, spread / (t * width_sd)) if width_sd > 0 else 1.0
        width_pull = (widen * dwidth_dv, reading.log_slope)
    out = []
    for j in range(1, n_f):
        fj, f = transform[j], freqs[j]
        ratio = abs(fj) / abs(f0)
        # the MTF is this ratio divided by the corrections: scale the gradient alike
        scale = float(mtf(np.array([f]))[0]) / ratio if ratio else 0.0
        grad = (np.real(np.conj(fj) * grad_f[j]) / (abs(fj) * abs(f0)) - ratio * grad_f[0].real / f0) * scale
        if width_pull is not None:
            dwidth_dv, log_slope = width_pull
            if j == 1:
                fixed_sd, _ = influence_sd(grad * residual, row)
            # MTF = |F| / |F0| / |divisor(f; W)|: W's pull moves it by -MTF d ln|divisor| / dW
            grad = grad - float(mtf(np.array([f]))[0]) * float(log_slope(f)) * dwidth_dv
        sd, n_rows = influence_sd(grad * residual, row)
        if j == 1 and width_pull is not None:
            width_share = 1.0 - (fixed_sd / sd) ** 2 if sd > 0 else 0.0
        if j == 1:
            systematic = (SYSTEMATIC_NYQUIST + TAIL_MODEL_UNCERTAINTY * abs(tail_share) * abs(nyquist)
                          + (SYSTEMATIC_DEQUANTISED if dequantised else 0.0) + NARROW_WINDOW_NYQUIST * narrowed)
            out.append(linearised_interval(nyquist, sd, n_rows, intervals.confidence, systematic))
        else:
            h = 1e-3
            slope = float(mtf(np.array([f50 + h]))[0] - mtf(np.array([f50 - h]))[0]) / (2 * h)
            sd50 = sd / abs(slope) if slope else math.inf
            systematic = f50 * (SYSTEMATIC_MTF50 + TAIL_MODEL_UNCERTAINTY * abs(tail_share)
                                + (SYSTEMATIC_DEQUANTISED_MTF50 if dequantised else 0.0)
                                + NARROW_WINDOW_MTF50 * narrowed)
            out.append(linearised_interval(f50, sd50, n_rows, intervals.confidence, systematic))
    while len(out) < 2:
        out.append(Interval.none())
    return out[0], out[1], width_share
