"""Linearised (row influence) intervals: the estimate's gradient with
respect to every sample, times its residual, summed per row; the variance
of the row influences (the infinitesimal jackknife) with the covariances of
neighbouring rows, widened by the estimator's own systematic error."""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..._stats import t_quantile
from ...errors import ParameterError
from .._order import distinct
from ..spectrum import NYQUIST
from .interval import Estimate, FigureIntervals, Interval
from .width import WidthReading

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
    ids, inverse = distinct(np.asarray(rows), return_inverse=True)
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
    spectrum = estimate.spectrum
    f50 = spectrum.mtf50_cy_px
    freqs = np.array([0.0, NYQUIST] + ([f50] if math.isfinite(f50) else []))
    read = estimate.shape_profile.resampled
    reading = estimate.width if estimate.width is not None and read.adjoint is not None else None
    kernel = _transform_kernel(estimate.lsf.x_px, freqs)
    transform = kernel @ estimate.lsf.combined
    mtf_at = estimate.spectrum.mtf(freqs[1:])
    grads, spectrum_pull = _sample_gradients(estimate, kernel, _figure_combination(transform, mtf_at), reading)
    residual = _residuals(estimate)
    rows = estimate.samples.rows
    fixed_width = None
    if reading is not None and spectrum_pull is not None:
        width_change, log_slope = _width_pull(reading, spectrum_pull, residual, rows, confidence)
        fixed_width = grads[0].copy()
        # MTF = |F| / |F0| / |divisor(f; W)|: W's pull moves it by -MTF d ln|divisor| / dW
        for j in range(freqs.size - 1):
            grads[j] -= mtf_at[j] * float(log_slope(freqs[j + 1])) * width_change
        grads = np.concatenate([grads, fixed_width[None, :]])
    sds, n_rows = influence_sds(grads * residual, rows)
    width_share = None
    if fixed_width is not None:
        fixed_sd, sds = sds[-1], sds[:-1]
        width_share = 1.0 - (fixed_sd / sds[0]) ** 2 if sds[0] > 0 else 0.0
    window, lsf = estimate.window, estimate.lsf
    tail_share, dequantised, narrowed = lsf.tail_share, estimate.samples.dequantised, window.narrowed
    systematic = (SYSTEMATIC_NYQUIST + TAIL_MODEL_UNCERTAINTY * abs(tail_share) * abs(spectrum.mtf_nyquist)
                  + (SYSTEMATIC_DEQUANTISED if dequantised else 0.0) + NARROW_WINDOW_NYQUIST * narrowed)
    nyquist = linearised_interval(spectrum.mtf_nyquist, float(sds[0]), n_rows, confidence, systematic)
    fifty = Interval.none()
    if freqs.size > 2:
        h = 1e-3
        slope = float(spectrum.mtf(np.array([f50 + h]))[0] - spectrum.mtf(np.array([f50 - h]))[0]) / (2 * h)
        sd50 = float(sds[1]) / abs(slope) if slope else math.inf
        systematic = f50 * (SYSTEMATIC_MTF50 + TAIL_MODEL_UNCERTAINTY * abs(tail_share)
                            + (SYSTEMATIC_DEQUANTISED_MTF50 if dequantised else 0.0)
                            + NARROW_WINDOW_MTF50 * narrowed)
        fifty = linearised_interval(f50, sd50, n_rows, confidence, systematic)
    warnings: tuple[str, ...] = ()
    if reading is not None and width_share is not None and width_share > WIDTH_SHARE_WARNING:
        warnings = (f"the {estimate.target}'s width, read off its profile ({reading.width_px:.3f} px), is uncertain "
                    f"enough to make {100 * width_share:.0f} % of the variance at Nyquist: give the width "
                    "if it is known",)
    return FigureIntervals(nyquist, fifty, warnings)


def _transform_kernel(x: np.ndarray, freqs: np.ndarray) -> np.ndarray:
    """The transform's row at each of ``freqs`` (cy/px) over the profile's
    uniform positions ``x`` (px): F(f) = kernel @ profile."""
    return np.exp(-2j * np.pi * freqs[:, None] * x[None, :]) * float(x[1] - x[0])


def _stacked(z: np.ndarray) -> np.ndarray:
    """Complex rows, one per frequency (the first 0, whose imaginary part
    is nil), as real ones: every real part, then the imaginary parts of
    the frequencies after the first."""
    return np.concatenate([z.real, z.imag[1:]])


def _figure_combination(transform: np.ndarray, mtf_at: np.ndarray) -> np.ndarray:
    """The (figures, 2 n_f - 1) real map from the transform's stacked
    gradients (:func:`_stacked`; the transform F at n_f frequencies, the
    first 0) to the figures' gradients: a figure, |F(f)| / |F(0)| divided
    by the corrections (``mtf_at`` its value at each frequency after the
    first), changes by (Re(conj F dF) / (|F| |F0|) - |F| / |F0| dF0 / F0)
    times its ratio to |F| / |F0|."""
    n_f = transform.size
    f0 = transform[0].real
    combination = np.zeros((n_f - 1, 2 * n_f - 1))
    for j in range(1, n_f):
        fj = transform[j]
        ratio = abs(fj) / abs(f0)
        scale = mtf_at[j - 1] / ratio if ratio else 0.0
        norm = abs(fj) * abs(f0)
        combination[j - 1, j] = fj.real / norm * scale
        combination[j - 1, n_f - 1 + j] = fj.imag / norm * scale
        combination[j - 1, 0] = -ratio / f0 * scale
    return combination


def _sample_gradients(estimate: Estimate, kernel: np.ndarray, combination: np.ndarray,
                      reading: WidthReading | None) -> tuple[np.ndarray, np.ndarray | None]:
    """The gradients over the samples of the real combinations
    ``combination`` (rows; :func:`_figure_combination`, or the identity
    for every frequency's) of the transform's stacked rows ``kernel``
    (:func:`_transform_kernel`), and where a width was read, dR(f) / dv of
    its spectrum (:meth:`WidthReading.sample_pull`).

    The transform is linear in the samples, so the combinations are taken
    of the kernel's rows on the profile's grid, and one pass backwards
    through the resampling carries one row per combination, not two per
    frequency; the width's rows share it where the width was read off the
    same resampling."""
    lsf, profile = estimate.lsf, estimate.profile
    resampled, span = profile.resampled, profile.span
    x, window, tail_shape = lsf.x_px, lsf.weights, lsf.tail_shape
    n_out = combination.shape[0]
    on_grid = lsf.adjoint(combination @ _stacked((kernel * window)[:, lsf.measured_at]))
    full = np.zeros((n_out, resampled.grid.size))
    full[:, span[0]: span[1]] = on_grid
    if resampled.adjoint is None:
        raise ParameterError("linearised intervals need the resampling's adjoint, which a stack of weightings "
                             "has not")
    read = estimate.shape_profile
    shared = reading is not None and read.resampled is resampled
    if reading is not None and shared:
        full = np.concatenate([full, reading.grid_weights(resampled.grid.size, read.span)])
    through = resampled.adjoint(full)
    gradient = through[:n_out]
    spectrum_pull = None
    if reading is not None and shared:
        spectrum_pull = reading.background_pull(through[n_out:])
    elif reading is not None and read.resampled.adjoint is not None:
        spectrum_pull = reading.sample_pull(read.resampled.adjoint, read.resampled.grid.size, read.span)
    # through each side's tail amplitude (its least-squares operator), and
    # for a bar through the background under the window
    # (each side's pull spread over every sample, nil off the side: whole rows
    # added cost a tenth of a scatter into a side's columns)
    left = x < estimate.centre_px
    for i, side in enumerate(lsf.sides):
        in_side = left if i == 0 else ~left
        per_amplitude = combination @ _stacked(kernel @ ((1.0 - window) * tail_shape * in_side))
        pull = np.zeros(gradient.shape[1])
        pull[side.mask] = lsf.to_amplitude[i] @ side.operator
        gradient += per_amplitude[:, None] * pull
        if estimate.subtracts_background:
            pull = np.zeros(gradient.shape[1])
            pull[side.mask] = side.operator[0]
            gradient -= 0.5 * (combination @ _stacked(kernel @ window))[:, None] * pull
    return gradient, spectrum_pull


def _residuals(estimate: Estimate) -> np.ndarray:
    """Each sample's residual from the profile: the resampled one where it
    was resampled, the side's model beyond; scaled up by its leverage."""
    samples, sides, resampled = estimate.samples, estimate.lsf.sides, estimate.profile.resampled
    distance, centre = samples.distance_px, estimate.centre_px
    run_grid, run_values = estimate.profile.grid, estimate.profile.values
    far = np.abs(distance - centre) ** -float(estimate.tail_power)
    model_dn = np.where(distance < centre, sides[0].coef[0] + sides[0].coef[1] * far,
                        sides[1].coef[0] + sides[1].coef[1] * far)
    inside = (distance >= run_grid[0]) & (distance <= run_grid[-1])
    residual = samples.values_dn - np.where(inside, np.interp(distance, run_grid, run_values), model_dn)
    if resampled.leverage is not None:
        residual = residual / np.sqrt(1.0 - np.minimum(resampled.leverage, LEVERAGE_CAP))
    return residual


def _width_pull(reading: WidthReading, spectrum_pull: np.ndarray, residual: np.ndarray, rows: np.ndarray,
                confidence: float) -> tuple[np.ndarray, Callable[[np.ndarray], np.ndarray]]:
    """The read width's pull on the samples, dW / dv, widened where Fieller's
    set for its zero is wider than the linearised interval, and
    d ln|divisor(f)| / dW."""
    width_change = reading.width_change(spectrum_pull[0])
    sds, n_rows = influence_sds(np.concatenate([(width_change * residual)[None, :], spectrum_pull[1:] * residual]),
                                rows)
    width_sd, spectrum_sd = float(sds[0]), sds[1:]
    t = t_quantile(0.5 + confidence / 2, max(n_rows - 1, 1))
    spread = reading.spread_px(spectrum_sd, t)
    widen = max(1.0, spread / (t * width_sd)) if width_sd > 0 else 1.0
    return widen * width_change, reading.log_slope
