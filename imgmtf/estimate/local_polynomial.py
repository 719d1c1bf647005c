"""The local polynomial resampling (methods ``msg`` and ``sliding`` of
:mod:`.resampling`): a least-squares polynomial fitted in a window about
each grid point, from per-bin moments summed over the windows."""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from . import weight_stacks
from ._correlation import correlate1d
from ._window_sums import _binomial_shifts, _local_polynomial_transfer, _shifted_powers
from .resampled import Resampled, _bin_sums, _bins, _grid, _unit_weight, _weights, sample_gap


def local_polynomial(distance, values, step: float, half_range: float, *,
                     order: int = 4, window_px: float = 1.0, weights=None) -> Resampled:
    """Least-squares polynomial of ``order`` fitted to the samples within
    ``window_px`` (centred) of each grid point, evaluated there.

    Samples are binned on the output grid and the window is a whole number
    of bins, so every window's moment sums are convolutions of per-bin
    moments (binomial expansion about the grid point): the cost is linear in
    the number of samples, with no loop over grid points.  ``weights`` (see
    :func:`resample_profile`) enter the moment sums linearly, so a stack of
    weight vectors is fitted in one pass.
    """
    if order < 0 or order > 8:
        raise ParameterError(f"local polynomial order must be 0..8, got {order}")
    # at angles whose sample positions repeat (tan a = 1/q), a window must
    # still hold order + 2 distinct positions for a well-posed fit
    window_px = max(window_px, (order + 1.5) * sample_gap(distance))
    half_bins = max(int(round((window_px / step - 1) / 2)), 1)
    # bins reach half a window beyond the output grid so that its end
    # points see full windows
    out = _grid(step, half_range)
    grid = _grid(step, half_range + half_bins * step)
    bins, keep = _bins(distance, grid, step)
    d, v = distance[keep], values[keep]
    w = _weights(weights, distance.size)[..., keep]
    scale = (half_bins + 0.5) * step      # local coordinates in [-1, 1]
    u = (d - grid[bins]) / scale
    nk = 2 * order + 1
    offsets = np.arange(-half_bins, half_bins + 1) * step / scale

    def window_sums(moments):
        """Sum over each grid point's window of (u + offset)^k for every k,
        from the per-bin sums of u^j: sum_j C(k, j) (offset^(k-j) * S_j),
        one correlation per power of the offset for all moments at once,
        combined by one product with the binomials."""
        return _shifted_powers(moments, offsets, _binomial_shifts(moments.shape[-2], False))
    # a stack of weightings (the bootstrap) sums its windows per group of equally weighted samples
    stacked = weight_stacks.window_sums(d, v, w, bins, grid, scale, half_bins, order) if w.ndim > 1 else None
    if stacked is not None:
        m, rhs = stacked
    else:
        powers = np.vander(u, nk, increasing=True).T
        features = np.concatenate([powers, powers[: order + 1] * v])
        sums = _bin_sums(bins, grid.size, features if weights is None else w[..., None, :] * features)
        s, t = sums[..., :nk, :], sums[..., nk:, :]
        m = window_sums(s)
        rhs = np.moveaxis(window_sums(t), -1, -2)
    idx = np.arange(order + 1)
    # a window needs enough samples, spread over it (uniform spread gives
    # a variance of 1/3 in window coordinates), for a well-posed fit
    count = np.where(m[..., 0, :] > 0, m[..., 0, :], 1.0)
    spread = m[..., 2, :] / count - (m[..., 1, :] / count) ** 2
    # ... and order + 1 distinct sample positions (occupied bins), without
    # which its normal matrix is singular (sample lattices, partial windows)
    if weights is None:     # unit weights: a bin is occupied where it counts a sample
        occupied = s[..., 0, :] > 0
    else:
        occupied = _bin_sums(bins, grid.size, (w > 0)[..., None, :].astype(float))[..., 0, :] > 0
    distinct = correlate1d(occupied.astype(float), np.ones(2 * half_bins + 1))
    trim = (grid.size - out.size) // 2
    inner = np.zeros(grid.size, bool)
    inner[trim: trim + out.size] = True
    valid = ((m[..., 0, :] >= 2 * (order + 1) * _unit_weight(w)) & (spread > 0.05)
             & (distinct >= order + 1) & inner)
    width = (2 * half_bins + 1) * step
    params = {"order": order, "window_px": width, "step_px": step}
    transfer = _local_polynomial_transfer(order, width)
    if w.ndim > 1:      # a stack of weightings (the bootstrap): solve each window directly
        level = np.full(valid.shape, np.nan)
        if valid.any():
            level[valid] = weight_stacks.first_levels(m, rhs, valid)
        return Resampled(out, level[..., trim: trim + out.size], transfer, params)
    # one weighting: each window's equivalent-kernel coefficients M^-1 e0,
    # which give the fitted level and, transposed, every sample's weight
    coef = np.zeros((grid.size, order + 1))
    normal = np.moveaxis(m[..., idx[:, None] + idx[None, :], :], -1, -3)
    if valid.any():
        coef[valid] = np.linalg.solve(normal[valid], np.eye(order + 1)[0][None, :, None]
                                      .repeat(valid.sum(), axis=0))[..., 0]
    level = np.where(valid, np.einsum("kj,kj->k", coef, rhs), np.nan)
    u0 = np.vander(u, order + 1, increasing=True)                 # (n_kept, order + 1)

    def adjoint(h):
        """Sample weights S^T h of grid weights ``h`` (..., n_out): what
        each sample contributes to sum_k h_k level_k, per unit value."""
        h = np.asarray(h, float)
        full = np.zeros((*h.shape[:-1], grid.size))
        full[..., trim: trim + out.size] = np.where(valid[trim: trim + out.size], h, 0.0)
        a = full[..., None, :] * coef.T                          # (..., order + 1, n_grid)
        # sum over the windows holding a sample's bin of a_k^(j) (u0 + offset)^j,
        # expanded binomially: G_m = sum_j C(j, m) (a^(j) convolved with offset^(j-m))
        # power p of the offset only meets the coefficients j >= p
        g = _shifted_powers(a, -offsets, _binomial_shifts(order + 1, True))   # (..., order + 1, n_grid)
        kept = np.einsum("...mi,im->...i", g[..., bins], u0)
        if weights is not None:
            kept = kept * w
        result = np.zeros((*h.shape[:-1], distance.size))
        result[..., keep] = kept
        return result

    leverage = np.zeros(distance.size)
    own = np.einsum("ij,ij->i", coef[bins], u0)
    leverage[keep] = own if weights is None else own * w
    return Resampled(out, level[trim: trim + out.size], transfer, params, adjoint, leverage)
