"""Linearised (row influence) intervals: the estimate's gradient with
respect to every sample, times its residual, summed per row; the variance
of the row influences (the infinitesimal jackknife) with the covariances of
neighbouring rows, widened by the estimator's own systematic error."""
from __future__ import annotations

import math

import numpy as np

from ..._stats import t_quantile
from ...errors import ParameterError
from ..spectrum import NYQUIST
from .interval import Estimate, FigureIntervals, Interval

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
WIDTH_SHARE_WARNING = 0.5   # a width read off the profile making more of the variance at Nyquist: a warning


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


def influence_intervals(estimate: Estimate, *, confidence: float = 0.95) -> FigureIntervals:
    """Linearised intervals for MTF at Nyquist and MTF50 (see
    :mod:`imgmtf.estimate.intervals`).

    The transform F(f) = sum_k e_k(f) [w_k lsf_k + (1 - w_k) model_k] is
    linear in the samples: through the LSF operator and the resampling
    (their adjoints) where the window holds data, through each side's tail
    amplitude (its least-squares operator), and for a bar through the
    background under the window.  Each figure is |F(f)| / |F(0)| divided by
    the corrections, so its gradient follows, and with each sample's
    residual (scaled up by its leverage) gives the row influences.  Where
    the divisor rests on a width read off the same samples
    (:attr:`Estimate.width`), its pull joins the gradient, widened where
    Fieller's set for the zero is wider than the linearised one, and a
    warning says so where it makes most of the variance at Nyquist.

    Parameters
    ----------
    estimate : Estimate
        The estimate (:attr:`imgmtf.estimate.pipeline.Measurement.estimate`).
    confidence : float, optional
        Coverage the intervals aim at, in (0, 1).

    Returns
    -------
    FigureIntervals
        The intervals of the MTF at Nyquist and of MTF50 (cy/px), NaN where
        a figure is undefined or fewer than 3 rows hold the samples.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=5.0, seed=1)
    >>> estimate = run(EdgeKind(), chip.image, make_settings(intervals="none")).estimate
    >>> found = influence_intervals(estimate)
    >>> float(chip.true_mtf(0.5)) in found.mtf_nyquist, found.mtf_nyquist.width < 0.05
    (True, True)
    """
    samples, lsf, spectrum = estimate.samples, estimate.lsf, estimate.spectrum
    resampled, span = estimate.profile.resampled, estimate.profile.span
    distance, values, rows, centre = samples.distance_px, samples.values_dn, samples.rows, estimate.centre_px
    x, w, tail_shape = lsf.x_px, lsf.weights, lsf.tail_shape
    f50 = spectrum.mtf50_cy_px
    step = float(x[1] - x[0])
    width_share = None
    freqs = np.array([0.0, NYQUIST] + ([f50] if math.isfinite(f50) else []))
    e = np.exp(-2j * np.pi * freqs[:, None] * x[None, :]) * step                   # (n_f, n_x)
    left = x < centre
    transform = e @ lsf.combined
    weighted = (e * w)[:, lsf.measured_at]
    on_grid = lsf.adjoint(np.concatenate([weighted.real, weighted.imag]))
    full = np.zeros((on_grid.shape[0], resampled.grid.size))
    full[:, span[0]: span[1]] = on_grid
    if resampled.adjoint is None:
        raise ParameterError("linearised intervals need the resampling's adjoint, which a stack of weightings "
                             "has not")
    through = resampled.adjoint(full)
    n_f = freqs.size
    grad_f = through[:n_f] + 1j * through[n_f:]                                  # dF(f) / dv
    for i, side in enumerate(lsf.sides):
        in_side = left if i == 0 else ~left
        per_amplitude = e @ ((1.0 - w) * tail_shape * in_side)
        idx = np.nonzero(side.mask)[0]
        grad_f[:, idx] += per_amplitude[:, None] * (lsf.to_amplitude[i] @ side.operator)[None, :]
        if estimate.subtracts_background:
            grad_f[:, idx] -= 0.5 * (e @ w)[:, None] * side.operator[0][None, :]
    f0 = transform[0].real
    run_grid, run_values = resampled.grid[span[0]: span[1]], resampled.values[span[0]: span[1]]
    # each sample's residual from the profile: the resampled one where it
    # was resampled, the side's model beyond
    sides = lsf.sides
    far = np.abs(distance - centre) ** -float(estimate.tail_power)
    model_dn = np.where(distance < centre, sides[0].coef[0] + sides[0].coef[1] * far,
                        sides[1].coef[0] + sides[1].coef[1] * far)
    inside = (distance >= run_grid[0]) & (distance <= run_grid[-1])
    residual = values - np.where(inside, np.interp(distance, run_grid, run_values), model_dn)
    if resampled.leverage is not None:
        residual = residual / np.sqrt(1.0 - np.minimum(resampled.leverage, LEVERAGE_CAP))
    mtf = spectrum.mtf
    width_pull = None
    read = estimate.shape_profile.resampled
    reading = estimate.width
    if reading is not None and read.adjoint is not None:
        dspectrum_dv = reading.sample_pull(read.adjoint, read.grid.size, estimate.shape_profile.span)
        dwidth_dv = reading.width_change(dspectrum_dv[0])
        width_sd, n_rows = influence_sd(dwidth_dv * residual, rows)
        spectrum_sd, _ = influence_sds(dspectrum_dv[1:] * residual, rows)
        t = t_quantile(0.5 + confidence / 2, max(n_rows - 1, 1))
        spread = reading.spread_px(spectrum_sd, t)
        widen = max(1.0, spread / (t * width_sd)) if width_sd > 0 else 1.0
        width_pull = (widen * dwidth_dv, reading.log_slope)
    out = []
    tail_share, dequantised, narrowed = lsf.tail_share, samples.dequantised, estimate.window.narrowed
    for j in range(1, n_f):
        fj, f = transform[j], freqs[j]
        ratio = abs(fj) / abs(f0)
        # the MTF is this ratio divided by the corrections: scale the gradient alike
        scale = float(mtf(np.array([f]))[0]) / ratio if ratio else 0.0
        grad = (np.real(np.conj(fj) * grad_f[j]) / (abs(fj) * abs(f0)) - ratio * grad_f[0].real / f0) * scale
        if width_pull is not None:
            dwidth_dv, log_slope = width_pull
            if j == 1:
                fixed_sd, _ = influence_sd(grad * residual, rows)
            # MTF = |F| / |F0| / |divisor(f; W)|: W's pull moves it by -MTF d ln|divisor| / dW
            grad = grad - float(mtf(np.array([f]))[0]) * float(log_slope(f)) * dwidth_dv
        sd, n_rows = influence_sd(grad * residual, rows)
        if j == 1 and width_pull is not None:
            width_share = 1.0 - (fixed_sd / sd) ** 2 if sd > 0 else 0.0
        if j == 1:
            systematic = (SYSTEMATIC_NYQUIST + TAIL_MODEL_UNCERTAINTY * abs(tail_share) * abs(spectrum.mtf_nyquist)
                          + (SYSTEMATIC_DEQUANTISED if dequantised else 0.0) + NARROW_WINDOW_NYQUIST * narrowed)
            out.append(linearised_interval(spectrum.mtf_nyquist, sd, n_rows, confidence, systematic))
        else:
            h = 1e-3
            slope = float(mtf(np.array([f50 + h]))[0] - mtf(np.array([f50 - h]))[0]) / (2 * h)
            sd50 = sd / abs(slope) if slope else math.inf
            systematic = f50 * (SYSTEMATIC_MTF50 + TAIL_MODEL_UNCERTAINTY * abs(tail_share)
                                + (SYSTEMATIC_DEQUANTISED_MTF50 if dequantised else 0.0)
                                + NARROW_WINDOW_MTF50 * narrowed)
            out.append(linearised_interval(f50, sd50, n_rows, confidence, systematic))
    while len(out) < 2:
        out.append(Interval.none())
    warnings: tuple[str, ...] = ()
    if reading is not None and width_share is not None and width_share > WIDTH_SHARE_WARNING:
        warnings = (f"the {estimate.target}'s width, read off its profile ({reading.width_px:.3f} px), is uncertain "
                    f"enough to make {100 * width_share:.0f} % of the variance at Nyquist: give the width "
                    "if it is known",)
    return FigureIntervals(out[0], out[1], warnings)
