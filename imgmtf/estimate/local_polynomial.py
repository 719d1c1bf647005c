"""The local polynomial resampling (methods ``msg`` and ``sliding`` of
:mod:`.resampling`): a least-squares polynomial fitted in a window about
each grid point, from per-bin moments summed over the windows."""
from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from ..errors import ParameterError
from . import weight_stacks
from ._correlation import ROW_BY_ROW_TAPS, correlate1d
from ._window_sums import (
    SHIFTED_ELEMENTS,
    _binomial_shifts,
    _local_polynomial_transfer,
    _shifted_powers,
    _shifted_powers_by_power,
    _shifted_powers_folded,
    window_sums_each,
)
from .resampled import Resampled, _bin_sums, _bins, _grid, _unit_weight, _weights, sample_gap

SIDE_BY_SIDE = 32      # profiles fitted side by side at once: their arrays (9 x 32 x ~440 bins) stay in cache


class LocalFit(NamedTuple):
    """One profile's local polynomial fit (:func:`local_polynomial`'s
    arguments, one weighting or none)."""

    distance: np.ndarray
    values: np.ndarray
    step: float
    half_range: float
    order: int = 4
    window_px: float = 1.0
    weights: np.ndarray | None = None


class _Windows(NamedTuple):
    """A profile's samples binned on its fit's grid."""

    out: np.ndarray         # the output grid, px
    grid: np.ndarray        # the bins' grid: the output's and half a window beyond each end
    bins: np.ndarray        # each kept sample's bin
    keep: np.ndarray        # the samples on the grid
    v: np.ndarray           # the kept samples' values
    w: np.ndarray           # their weights (ones, or a stack of weightings)
    u: np.ndarray           # their offsets from their bins' centres, in window coordinates
    offsets: np.ndarray     # the window's taps in window coordinates
    half_bins: int


def local_polynomial(distance, values, step: float, half_range: float, *,
                     order: int = 4, window_px: float = 1.0, weights=None) -> Resampled:
    """Least-squares polynomial of ``order`` fitted to the samples within
    ``window_px`` (centred) of each grid point, evaluated there.

    Samples are binned on the output grid and the window is a whole number
    of bins, so every window's moment sums are convolutions of per-bin
    moments (binomial expansion about the grid point): the cost is linear in
    the number of samples, with no loop over grid points.  ``weights`` (see
    :func:`.resampling.resample_profile`) enter the moment sums linearly, so
    a stack of weight vectors is fitted in one pass.  One weighting (or
    none) is fitted as :func:`local_polynomial_many` fits it among others.
    """
    if weights is None or np.ndim(weights) < 2:
        fitted = local_polynomial_many([LocalFit(distance, values, step, half_range, order, window_px, weights)])[0]
        if isinstance(fitted, Exception):
            raise fitted
        return fitted
    _check_order(order)
    win = _windows(np.asarray(distance, float), np.asarray(values, float), step, half_range, order, window_px,
                   weights)
    # a stack of weightings (the bootstrap) sums its windows per group of equally weighted samples
    d = np.asarray(distance, float)[win.keep]
    stacked = weight_stacks.window_sums(d, win.v, win.w, win.bins, win.grid, (win.half_bins + 0.5) * step,
                                        win.half_bins, order)
    if stacked is not None:
        m, rhs = stacked
    else:
        window_sums = functools.partial(_shifted_powers, offsets=win.offsets)
        sums = _bin_sums(win.bins, win.grid.size, win.w[..., None, :] * _features(win.u, win.v, order))
        m = window_sums(sums[..., : 2 * order + 1, :], binomials=_binomial_shifts(2 * order + 1, False))
        rhs = np.moveaxis(window_sums(sums[..., 2 * order + 1:, :], binomials=_binomial_shifts(order + 1, False)),
                          -1, -2)
    occupied = _bin_sums(win.bins, win.grid.size, (win.w > 0)[..., None, :].astype(float))[..., 0, :] > 0
    trim = (win.grid.size - win.out.size) // 2
    inner = np.zeros(win.grid.size, bool)
    inner[trim: trim + win.out.size] = True
    valid = _valid_windows(m, occupied, win.half_bins, order, _unit_weight(win.w), inner)
    level = np.full(valid.shape, np.nan)
    if valid.any():     # solved window by window directly
        level[valid] = weight_stacks.first_levels(m, rhs, valid)
    width = (2 * win.half_bins + 1) * step
    return Resampled(win.out, level[..., trim: trim + win.out.size], _local_polynomial_transfer(order, width),
                     {"order": order, "window_px": width, "step_px": step})


def local_polynomial_many(fits: list[LocalFit]) -> list[Resampled | Exception]:
    """Many profiles' local polynomial fits of one weighting (or none),
    those of a window alike made together (their grids side by side, each
    grid point's sums and solve its own): each the same, to the bit, as
    the profile's fitted alone, or the exception its fit raises.

    Parameters
    ----------
    fits : list of LocalFit
        The profiles and their fits' settings.

    Returns
    -------
    list of Resampled or Exception
        One per fit, in order (with the adjoint and the leverages).

    Examples
    --------
    >>> d = np.random.default_rng(0).uniform(-6.0, 6.0, (2, 3000))
    >>> fits = [LocalFit(x, np.tanh(x), 0.05, 4.0) for x in d]
    >>> together = local_polynomial_many(fits)
    >>> all(np.array_equal(r.values, local_polynomial_many([f])[0].values, equal_nan=True)
    ...     for r, f in zip(together, fits))
    True
    """
    out: list = [None] * len(fits)
    groups: dict[tuple, list[tuple[int, _Windows]]] = {}
    for k, fit in enumerate(fits):
        try:
            _check_order(fit.order)
            win = _windows(np.asarray(fit.distance, float), np.asarray(fit.values, float), fit.step, fit.half_range,
                           fit.order, fit.window_px, fit.weights)
        except Exception as exc:        # its own fit raises it: returned in its place
            out[k] = exc
            continue
        # wide windows' correlations round by blocks of rows: such a profile is fitted alone
        alike = 2 * win.half_bins + 1 < ROW_BY_ROW_TAPS
        groups.setdefault((fit.order, fit.step, win.half_bins) if alike else (k,), []).append((k, win))
    for group in groups.values():
        for start in range(0, len(group), SIDE_BY_SIDE):
            _fit_members(fits, group[start: start + SIDE_BY_SIDE], out)
    return out


def _fit_members(fits: list[LocalFit], members: list[tuple[int, _Windows]], out: list) -> None:
    """``out[k]`` for the ``members`` (fit k and its binned samples) fitted side by side."""
    first = fits[members[0][0]]
    try:
        fitted: list = _fit_side_by_side([(win, fits[k].weights is not None) for k, win in members],
                                         first.order, first.step)
    except Exception as exc:
        if len(members) > 1:    # which of them: each alone
            fitted = [local_polynomial_many([fits[k]])[0] for k, _ in members]
        else:
            fitted = [exc]
    for (k, _), result in zip(members, fitted):
        out[k] = result


def _check_order(order: int) -> None:
    if order < 0 or order > 8:
        raise ParameterError(f"local polynomial order must be 0..8, got {order}")


def _windows(distance: np.ndarray, values: np.ndarray, step: float, half_range: float, order: int,
             window_px: float, weights) -> _Windows:
    """The samples binned on the fit's grid (:class:`_Windows`)."""
    # at angles whose sample positions repeat (tan a = 1/q), a window must
    # still hold order + 2 distinct positions for a well-posed fit
    window_px = max(window_px, (order + 1.5) * sample_gap(distance))
    half_bins = max(int(round((window_px / step - 1) / 2)), 1)
    # bins reach half a window beyond the output grid so that its end
    # points see full windows
    out = _grid(step, half_range)
    grid = _grid(step, half_range + half_bins * step)
    bins, keep = _bins(distance, grid, step)
    scale = (half_bins + 0.5) * step      # local coordinates in [-1, 1]
    u = (distance[keep] - grid[bins]) / scale
    offsets = np.arange(-half_bins, half_bins + 1) * step / scale
    return _Windows(out, grid, bins, keep, values[keep], _weights(weights, distance.size)[..., keep], u, offsets,
                    half_bins)


def _features(u: np.ndarray, v: np.ndarray, order: int) -> np.ndarray:
    """Each sample's u^0..u^(2 order), then v u^0..v u^order: rows of one
    array, each power the one before times u, as :func:`numpy.vander`
    accumulates them (the same floats, without its strided accumulation and
    a transposed copy)."""
    features = np.empty((3 * order + 2, u.size))
    features[0] = 1.0
    for k in range(1, 2 * order + 1):
        np.multiply(features[k - 1], u, out=features[k])
    np.multiply(features[: order + 1], v, out=features[2 * order + 1:])
    return features


def _valid_windows(m: np.ndarray, occupied: np.ndarray, half_bins: int, order: int, unit, inner: np.ndarray
                   ) -> np.ndarray:
    """The windows whose fit is well posed: enough samples (``unit`` is
    one sample's weight), spread over the window (uniform spread gives a
    variance of 1/3 in window coordinates) on order + 1 distinct positions
    (occupied bins), without which the normal matrix is singular (sample
    lattices, partial windows); within the ``inner`` grid."""
    count = np.where(m[..., 0, :] > 0, m[..., 0, :], 1.0)
    spread = m[..., 2, :] / count - (m[..., 1, :] / count) ** 2
    distinct = correlate1d(occupied.astype(float), np.ones(2 * half_bins + 1))
    return (m[..., 0, :] >= 2 * (order + 1) * unit) & (spread > 0.05) & (distinct >= order + 1) & inner


def _fit_side_by_side(members: list[tuple[_Windows, bool]], order: int, step: float) -> list[Resampled]:
    """The fits of profiles of one window (``members``: each binned, and
    whether weighted), their grids side by side with half a window of
    empty bins between them: each grid point's sums, validity and solve its
    own (:func:`._window_sums.window_sums_each`)."""
    wins = [win for win, _ in members]
    half_bins, nk = wins[0].half_bins, 2 * order + 1
    sizes = np.array([win.grid.size for win in wins])
    starts = np.concatenate([[0], np.cumsum(sizes + half_bins)[:-1]])
    total = int(starts[-1] + sizes[-1])
    bins = np.concatenate([win.bins + start for win, start in zip(wins, starts)])
    u, v = np.concatenate([win.u for win in wins]), np.concatenate([win.v for win in wins])
    features = _features(u, v, order)
    u0 = np.ascontiguousarray(features[: order + 1].T)        # (n_kept, order + 1): u^0..u^order
    weighted = any(w for _, w in members)
    if weighted:        # the unweighted's ones change nothing
        features = features * np.concatenate([win.w for win in wins])
    sums = _bin_sums(bins, total, features)
    offsets = wins[0].offsets
    # a wide window's profile is fitted alone (local_polynomial_many), as its correlations round by blocks
    window_sums = window_sums_each if offsets.size < ROW_BY_ROW_TAPS else _shifted_powers
    m = window_sums(sums[:nk], offsets, _binomial_shifts(nk, False))
    rhs = window_sums(sums[nk:], offsets, _binomial_shifts(order + 1, False)).T
    if weighted:
        w_all = np.concatenate([win.w for win in wins])
        occupied = _bin_sums(bins, total, (w_all > 0)[None, :].astype(float))[0] > 0
    else:       # a bin is occupied where it counts a sample
        occupied = sums[0] > 0
    unit = np.repeat([_unit_weight(win.w)[0] for win in wins], sizes + half_bins)[:total]
    trims = (sizes - np.array([win.out.size for win in wins])) // 2
    inner = np.zeros(total, bool)
    for win, start, trim in zip(wins, starts, trims):
        inner[start + trim: start + trim + win.out.size] = True
    valid = _valid_windows(m, occupied, half_bins, order, unit, inner)
    # each window's equivalent-kernel coefficients M^-1 e0, which give the
    # fitted level and, transposed, every sample's weight
    coef = np.zeros((total, order + 1))
    if valid.any():
        coef[valid] = _inverse_first_rows(m[:, valid], order + 1).T
    level = np.where(valid, np.einsum("kj,kj->k", coef, rhs), np.nan)
    own = np.einsum("ij,ij->i", coef[bins], u0)
    width = (2 * half_bins + 1) * step
    transfer = _local_polynomial_transfer(order, width)
    out = []
    first = 0
    for (win, is_weighted), start, size, trim in zip(members, starts, sizes, trims):
        n_kept = win.bins.size
        rows = slice(first, first + n_kept)
        first += n_kept
        grid = slice(start, start + size)
        leverage = np.zeros(win.keep.size)
        leverage[win.keep] = own[rows] * win.w if is_weighted else own[rows]
        adjoint = functools.partial(_adjoint, win=win, valid=valid[grid], coef=coef[grid], trim=int(trim),
                                    weighted=is_weighted)
        out.append(Resampled(win.out, level[grid][trim: trim + win.out.size], transfer,
                             {"order": order, "window_px": width, "step_px": step}, adjoint, leverage))
    return out


def _inverse_first_rows(moments: np.ndarray, n: int) -> np.ndarray:
    """e0' M^-1 of every window's normal matrix M (M[i, j] = moments[i + j],
    symmetric positive definite; ``moments`` (2 n - 1, windows)): each
    window's (n,) row of coefficients, (n, windows), the identity's columns
    the right-hand sides of :func:`.weight_stacks.first_unknown`."""
    identity = np.zeros((n, n, moments.shape[-1]))
    identity[np.arange(n), np.arange(n)] = 1.0
    return weight_stacks.first_unknown(moments, list(identity))


def _adjoint(h, *, win: _Windows, valid: np.ndarray, coef: np.ndarray, trim: int, weighted: bool) -> np.ndarray:
    """Sample weights S^T h of grid weights ``h`` (..., n_out): what each
    sample contributes to sum_k h_k level_k, per unit value."""
    h = np.asarray(h, float)
    lead, n = h.shape[:-1], coef.shape[1]
    full = np.zeros((*lead, win.grid.size))
    full[..., trim: trim + win.out.size] = np.where(valid[trim: trim + win.out.size], h, 0.0)
    a = full[..., None, :] * coef.T                          # (..., order + 1, n_grid)
    # sum over the windows holding a sample's bin of a_k^(j) (u + offset)^j,
    # expanded binomially: G_m = sum_j C(j, m) (a^(j) convolved with offset^(j-m))
    # power p of the offset only meets the coefficients j >= p
    binomials = _binomial_shifts(n, True)
    if a.size * win.offsets.size > SHIFTED_ELEMENTS:
        g = _shifted_powers_by_power(a, -win.offsets, binomials)      # (..., order + 1, n_grid)
    else:       # a few rows (the figures of the intervals): one product
        g = _shifted_powers_folded(a, -win.offsets, binomials)
    # each sample's polynomial in its offset u, sum_m G_m[bin] u^m, by Horner's rule
    stacks = g.reshape(-1, n * g.shape[-1])
    at_bins = np.take(stacks.reshape(-1, g.shape[-1]), win.bins, axis=1).reshape(stacks.shape[0], n, -1)
    kept = at_bins[:, n - 1].copy()
    for m in range(n - 2, -1, -1):
        kept *= win.u
        kept += at_bins[:, m]
    if weighted:
        kept *= win.w
    result = np.zeros((stacks.shape[0], win.keep.size))
    for row, values in zip(result, kept):       # row by row: a mask on a 2-D array's last axis costs 5 x more
        row[win.keep] = values
    return result.reshape(*lead, win.keep.size)
