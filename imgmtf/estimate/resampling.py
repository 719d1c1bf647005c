"""Smooth and resample an over-sampled, unevenly spaced profile (ESF or PRF)
onto a uniform grid: one registry of interchangeable methods behind one
dispatcher, :func:`resample_profile`.

Each method also knows its own transfer function for uniformly dense
samples, so the MTF can be corrected for the blur the method itself adds.

Methods
-------
msg      modified Savitzky-Golay: a least-squares polynomial (order 4 by
         default) in a window about each output point, for unequally spaced
         samples (Choi and Helder).
sliding  the same local fit with a straight line (order 1): for a
         symmetric window this is the window's mean, a box filter.
spline   a cubic smoothing spline (Reinsch's algorithm, :func:`penalised_spline`)
         whose response falls to 1/2 at 2 cycles/pixel.
iso      ISO 12233-style averaging into 1/4-pixel bins; empty bins are
         filled by linear interpolation.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ImageContentError, ParameterError
from .local_polynomial import local_polynomial
from .resampled import Resampled, _bin_sums, _bins, _grid, _weights, sample_gap

__all__ = ["METHODS", "Resampled", "ResamplingMethod", "binned", "check_method", "local_polynomial",
           "penalised_spline", "resample_profile", "sample_gap", "smoothing_spline"]


@dataclass(frozen=True)
class ResamplingMethod:
    name: str
    function: Callable[..., Resampled]
    defaults: dict
    description: str


def smoothing_spline(distance, values, step: float, half_range: float, *,
                     cutoff_cy_px: float = 2.0, weights=None) -> Resampled:
    """Cubic smoothing spline through the samples (exact ties averaged).

    The smoothing weight is set so that the spline's response falls to 1/2
    at ``cutoff_cy_px``: for samples of density rho per pixel a smoothing
    spline with weight lam has the transfer function
    1 / (1 + lam (2 pi f)^4 / rho) (its equivalent kernel), so
    lam = rho / (2 pi f_c)^4.  (Generalised cross-validation would choose
    lam from the data but costs about a second per profile.)  A stack of
    weight vectors costs one spline fit each.
    """
    if not cutoff_cy_px > 0:
        raise ParameterError(f"spline cut-off must be > 0 cycles/pixel, got {cutoff_cy_px}")
    grid = _grid(step, half_range)
    w = _weights(weights, distance.size)
    # samples within 1e-7 px of each other are one knot: nearer ones leave
    # the spline's banded system numerically singular
    ux, inverse = np.unique(np.round(distance, 7), return_inverse=True)
    if ux.size < 5:
        raise ImageContentError("too few distinct profile samples for a spline")
    density = distance.size / (ux[-1] - ux[0])
    lam = density / (2 * np.pi * cutoff_cy_px) ** 4
    inside = (grid >= ux[0]) & (grid <= ux[-1])

    def fit(sample_weights):
        counts = np.bincount(inverse, weights=sample_weights)
        present = counts > 0
        means = np.bincount(inverse, weights=sample_weights * values)[present] / counts[present]
        scale = sample_weights.size / sample_weights.sum()     # lam assumes unit weights
        return np.where(inside, penalised_spline(ux[present], means, counts[present] * scale, lam, grid), np.nan)
    out = fit(w) if w.ndim == 1 else np.stack([fit(row) for row in w])

    def transfer(f):
        return 1.0 / (1.0 + (np.atleast_1d(np.asarray(f, float)) / cutoff_cy_px) ** 4)
    params = {"cutoff_cy_px": cutoff_cy_px, "lam": lam, "step_px": step}
    if w.ndim > 1:
        return Resampled(grid, out, transfer, params)
    # the spline's smoother matrix is not formed; its transpose is taken as
    # the equivalent kernel's (exact for uniformly dense samples)
    local_density = _local_density(distance, w)

    def adjoint(h):
        h = np.where(inside, np.asarray(h, float), 0.0)
        n = 2 * grid.size
        smoothed = np.fft.irfft(np.fft.rfft(h, n=n) * transfer(np.fft.rfftfreq(n, d=step)), n=n)
        at_samples = np.stack([np.interp(distance, grid, s[: grid.size]) for s in
                               smoothed.reshape(-1, n)]).reshape(*h.shape[:-1], distance.size)
        return at_samples * w / (step * local_density)
    kernel_at_zero = np.pi * cutoff_cy_px / math.sqrt(2.0)     # integral of the transfer over all f
    return Resampled(grid, out, transfer, params, adjoint, kernel_at_zero * w / local_density)


def binned(distance, values, step: float, half_range: float, *,
           bin_px: float = 0.25, weights=None) -> Resampled:
    """Average of the samples in each bin of ``bin_px`` pixels (the output
    grid is the bin centres, whatever ``step`` asks for); empty bins are
    filled by linear interpolation.  Transfer: sinc(f * bin_px)."""
    grid = _grid(bin_px, half_range)
    bins, keep = _bins(distance, grid, bin_px)
    w = _weights(weights, distance.size)[..., keep]
    sums = _bin_sums(bins, grid.size, w[..., None, :] * np.stack([np.ones(bins.size), values[keep]]))
    counts, totals = sums[..., 0, :], sums[..., 1, :]
    filled = counts > 0
    if filled.sum(axis=-1).min() < 2:
        raise ImageContentError("too few profile samples to bin")
    means = totals / np.where(filled, counts, 1.0)
    out = np.stack([np.interp(grid, grid[f], m[f]) for f, m in
                    zip(filled.reshape(-1, grid.size), means.reshape(-1, grid.size))])
    out = out.reshape(means.shape)

    def transfer(f):
        return np.sinc(np.atleast_1d(np.asarray(f, float)) * bin_px)
    params = {"bin_px": bin_px, "empty_bins": int((~filled).sum(axis=-1).max())}
    if w.ndim > 1:
        return Resampled(grid, out, transfer, params)
    fill = _interpolation_matrix(grid, filled)

    def adjoint(h):
        per_bin = np.asarray(h, float) @ fill / np.where(filled, counts, 1.0)
        result = np.zeros((*np.shape(h)[:-1], distance.size))
        result[..., keep] = per_bin[..., bins] * w
        return result
    leverage = np.zeros(distance.size)
    leverage[keep] = w / counts[bins]
    return Resampled(grid, out, transfer, params, adjoint, leverage)


def _interpolation_matrix(grid: np.ndarray, filled: np.ndarray) -> np.ndarray:
    """Matrix P with ``P @ means`` = the bin means, empty bins linearly
    interpolated from their filled neighbours (held constant past the ends),
    as ``np.interp`` does."""
    source = np.nonzero(filled)[0]
    right = np.clip(np.searchsorted(source, np.arange(grid.size)), 0, source.size - 1)
    left = np.clip(right - 1, 0, source.size - 1)
    lo, hi = source[left], source[right]
    span = np.where(hi > lo, grid[hi] - grid[lo], 1.0)
    t = np.clip(np.where(hi > lo, (grid - grid[lo]) / span, 1.0), 0.0, 1.0)
    matrix = np.zeros((grid.size, grid.size))
    rows = np.arange(grid.size)
    np.add.at(matrix, (rows, lo), 1.0 - t)
    np.add.at(matrix, (rows, hi), t)
    matrix[filled] = 0.0
    matrix[np.nonzero(filled)[0], np.nonzero(filled)[0]] = 1.0
    return matrix


def penalised_spline(x: np.ndarray, y: np.ndarray, w: np.ndarray, lam: float, at: np.ndarray) -> np.ndarray:
    """The cubic smoothing spline g minimising sum w_i (y_i - g(x_i))^2 +
    lam * integral g''(u)^2 du (natural: g'' = 0 at the ends), evaluated at
    ``at`` (within [x_0, x_-1]); ``x`` strictly increasing, ``w`` > 0.
    Raises ImageContentError where knots so close (under about 1e-8 of
    the span) leave the system singular.

    Reinsch's algorithm (Green and Silverman 1994, section 2.3): the
    second derivatives gamma at the interior knots solve the symmetric
    pentadiagonal system (R + lam Q' W^-1 Q) gamma = Q' y, and the knot
    values are g = y - lam W^-1 Q gamma; O(n), where
    scipy.interpolate.make_smoothing_spline (the same spline) loops over
    the samples in Python.
    """
    from scipy.linalg import LinAlgError, solveh_banded
    h = np.diff(x)
    inv_w = 1.0 / w
    # Q's three non-zeros in each column a (rows a, a + 1, a + 2)
    q0, q2 = 1.0 / h[:-1], 1.0 / h[1:]
    q1 = -q0 - q2
    d0, d1, d2 = inv_w[:-2], inv_w[1:-1], inv_w[2:]
    banded = np.zeros((3, h.size - 1))
    banded[2] = (h[:-1] + h[1:]) / 3.0 + lam * (d0 * q0 ** 2 + d1 * q1 ** 2 + d2 * q2 ** 2)
    banded[1, 1:] = h[1:-1] / 6.0 + lam * (d1[:-1] * q1[:-1] * q0[1:] + d2[:-1] * q2[:-1] * q1[1:])
    banded[0, 2:] = lam * d2[:-2] * q2[:-2] * q0[2:]
    try:
        gamma = solveh_banded(banded, q0 * y[:-2] + q1 * y[1:-1] + q2 * y[2:])
    except LinAlgError as exc:
        raise ImageContentError(f"the smoothing spline's system is singular ({exc}): knots too close "
                                "together; use another method") from exc
    q_gamma = np.zeros(x.size)
    q_gamma[:-2] += q0 * gamma
    q_gamma[1:-1] += q1 * gamma
    q_gamma[2:] += q2 * gamma
    g = y - lam * inv_w * q_gamma
    curvature = np.concatenate([[0.0], gamma, [0.0]])
    # the cubic between each pair of knots, from its end values and curvatures
    i = np.clip(np.searchsorted(x, at, side="right") - 1, 0, x.size - 2)
    left, right, span = at - x[i], x[i + 1] - at, h[i]
    return ((left * g[i + 1] + right * g[i]) / span
            - left * right / 6.0 * ((1.0 + left / span) * curvature[i + 1] + (1.0 + right / span) * curvature[i]))


def _local_density(distance: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Weighted samples per pixel around each sample (1-px bins)."""
    edges = np.floor(distance).astype(int)
    edges -= edges.min()
    counts = np.bincount(edges, weights=weights)
    return np.maximum(counts[edges], 1e-12)




METHODS: dict[str, ResamplingMethod] = {
    m.name: m for m in (
        ResamplingMethod("msg", local_polynomial, {"order": 4, "window_px": 1.0},
                         "modified Savitzky-Golay: local order-4 polynomial, 1 px window"),
        ResamplingMethod("sliding", local_polynomial, {"order": 1, "window_px": 1.0},
                         "sliding window: local straight line, 1 px window"),
        ResamplingMethod("spline", smoothing_spline, {"cutoff_cy_px": 2.0},
                         "cubic smoothing spline, response 1/2 at 2 cy/px"),
        ResamplingMethod("iso", binned, {"bin_px": 0.25},
                         "ISO 12233: average in 1/4-px bins"),
    )
}


def check_method(method: str) -> ResamplingMethod:
    """The registered method of that name.

    Raises
    ------
    ParameterError
        ``method`` is not a key of :data:`METHODS`.

    Examples
    --------
    >>> check_method("iso").defaults
    {'bin_px': 0.25}
    """
    if not isinstance(method, str) or method not in METHODS:
        raise ParameterError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    return METHODS[method]


def resample_profile(distance: np.ndarray, values: np.ndarray, *, method: str = "msg",
                     step: float = 0.05, half_range: float, weights: ArrayLike | None = None,
                     **options: Any) -> Resampled:
    """Resample an over-sampled, unevenly spaced profile onto a uniform grid.

    Parameters
    ----------
    distance : ndarray
        Each sample's signed distance from the target line (px).
    values : ndarray
        Each sample's value (DN).
    method : str
        A key of :data:`METHODS`: "msg", "sliding", "spline" or "iso".
    step : float
        Grid step (px); "iso" always uses its bins.
    half_range : float
        The grid spans +-``half_range`` px, symmetric about 0 (so grids of
        equal step share their points).
    weights : ndarray, optional
        A weight per sample, shape (n_samples,), or a stack (replicates,
        n_samples) fitted at once (the bootstrap), when the result's
        ``values`` has shape (replicates, grid size).
    **options
        Overrides of the method's defaults (``window_px``, ``order``,
        ``cutoff_cy_px``, ``bin_px``).

    Returns
    -------
    Resampled
        The grid, the values, the method's transfer function (cy/px), and
        for one weighting its adjoint and leverages.

    Raises
    ------
    ParameterError
        An unknown method or option, or a step that is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.special import erf
    >>> d = np.random.default_rng(0).uniform(-6, 6, 4000)
    >>> r = resample_profile(d, 0.5 * (1 + erf(d / 0.8)), half_range=4)
    >>> round(float(np.interp(0.0, r.grid, r.values)), 3), round(r.step, 3)
    (0.5, 0.05)
    """
    spec, chosen = method_options(method, step, options)
    return spec.function(np.asarray(distance, float), np.asarray(values, float), step,
                         half_range, weights=weights, **chosen)


def method_options(method: str, step: float, options: dict[str, Any]) -> tuple[ResamplingMethod, dict[str, Any]]:
    """The registered method of that name and its options (its defaults
    overridden by ``options``), checked as :func:`resample_profile` checks them.

    Raises
    ------
    ParameterError
        An unknown method or option, or a step that is not positive.

    Examples
    --------
    >>> method_options("msg", 0.05, {"window_px": 2.0})[1]
    {'order': 4, 'window_px': 2.0}
    """
    spec = check_method(method)
    if not step > 0:
        raise ParameterError(f"resampling step must be > 0 px, got {step}")
    unknown = set(options) - set(spec.defaults)
    if unknown:
        raise ParameterError(f"method {method!r} takes no option(s) {', '.join(sorted(unknown))}")
    return spec, {**spec.defaults, **options}
