"""The local polynomial's window sums (:func:`.resampling.local_polynomial`):
each grid point's window sums of (u + offset)^k from per-bin moments, by
binomial expansion over the powers of the offsets, and the fit's transfer
function (its equivalent kernel's transform)."""
from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np

from ._correlation import ROW_BY_ROW_TAPS, correlate1d


def _shifted_powers(moments: np.ndarray, offsets: np.ndarray, binomials: np.ndarray) -> np.ndarray:
    """``binomials`` applied to the correlations of ``moments`` (..., n, grid)
    with every power 0..n-1 of ``offsets``: (..., n, grid).

    Both steps are linear, so they fold into one kernel per output and
    input moment, ``sum_p binomials[k, p n + j] offsets ** p`` over the
    taps (:func:`_folded_kernel`): each window's sums are then one matrix
    product of that (n, n taps) kernel with the moments shifted by every
    tap, for every grid point at once, where one correlation per power and
    the binomials' product cost about twice as much.  Stacks (the adjoint's
    grid weights, the bootstrap's weightings), whose shifted copies leave
    the cache, and moments whose copies would fill more than
    ``SHIFTED_ELEMENTS``, are correlated power by power instead."""
    if moments.ndim > 2 or moments.size * offsets.size > SHIFTED_ELEMENTS:
        return _shifted_powers_by_power(moments, offsets, binomials)
    return _shifted_powers_folded(moments, offsets, binomials)


def _shifted_powers_folded(moments: np.ndarray, offsets: np.ndarray, binomials: np.ndarray) -> np.ndarray:
    """:func:`_shifted_powers` by one product of the folded kernel with the
    moments shifted by every tap (a stack of moments, each its own
    product: for the few rows of an adjoint, whose shifted copies stay
    small)."""
    n, size = moments.shape[-2], moments.shape[-1]
    taps = offsets.size
    kernel = _folded_kernel(binomials.tobytes(), n, offsets.tobytes())
    half = taps // 2
    padded = np.zeros((*moments.shape[:-1], size + 2 * half))
    padded[..., half: half + size] = moments
    # shifted[..., j, o, g] = moments[..., j, g + o - half], zeros beyond the ends
    shifted = np.lib.stride_tricks.sliding_window_view(padded, size, axis=-1)
    return kernel @ shifted.reshape(*moments.shape[:-2], n * taps, size)


#: the moments' shifted copies (moments x taps x grid) up to which the window sums are one product
#: with the folded kernel (16 MB); beyond, one correlation per power
SHIFTED_ELEMENTS = 1 << 21


@functools.lru_cache(maxsize=64)
def _folded_kernel(binomials_bytes: bytes, n: int, offsets_bytes: bytes) -> np.ndarray:
    """The (n, n * taps) matrix whose row k, column j taps + o, is
    sum_p binomials[k, p n + j] offsets[o] ** p (from the arrays' bytes:
    the profiles of a scan share their offsets and binomials)."""
    binomials = np.frombuffer(binomials_bytes).reshape(n, n, n)      # (k, p, j)
    offsets = np.frombuffer(offsets_bytes)
    powers = offsets[None, :] ** np.arange(n)[:, None]                # (p, taps)
    return np.einsum("kpj,po->kjo", binomials, powers).reshape(n, n * offsets.size)


def _shifted_powers_by_power(moments: np.ndarray, offsets: np.ndarray, binomials: np.ndarray) -> np.ndarray:
    """:func:`_shifted_powers` by one correlation per power of the offsets
    (for stacks of weightings: no shifted copies)."""
    n = moments.shape[-2]
    moments = np.ascontiguousarray(moments)     # one copy for every power, not one in each correlation
    shifted = np.empty((*moments.shape[:-2], n, n, moments.shape[-1]))
    # only the moments whose correlation with offset^p a binomial takes (j <= n - 1 - p, or for the
    # adjoint j >= p: about half of them), where each row's correlation is its own
    taken: list[list[bool]] | None = None
    if offsets.size < ROW_BY_ROW_TAPS:
        taken = np.asarray(binomials.reshape(-1, n, n).any(axis=0)).tolist()
    for p in range(n):
        lo, hi = (taken[p].index(True), n - taken[p][::-1].index(True)) if taken and any(taken[p]) else (0, n)
        shifted[..., p, lo:hi, :] = correlate1d(moments[..., lo:hi, :], offsets ** p)
        if lo:
            shifted[..., p, :lo, :] = 0.0
        if hi < n:
            shifted[..., p, hi:, :] = 0.0
    return binomials @ shifted.reshape(*moments.shape[:-2], n * n, moments.shape[-1])


@functools.lru_cache(maxsize=32)
def _binomial_shifts(n: int, adjoint: bool) -> np.ndarray:
    """The (n, n * n) matrix combining the correlations of moments j with
    offset^p (column p n + j): row k takes C(k, j) at p = k - j (a
    window's sums of (u + offset)^k); the adjoint's row m takes C(j, m) at
    p = j - m (its transpose, with the offsets negated)."""
    out = np.zeros((n, n * n))
    for k in range(n):
        for j in range(n):
            p = j - k if adjoint else k - j
            if p >= 0:
                out[k, p * n + j] = math.comb(j, k) if adjoint else math.comb(k, j)
    return out


@functools.lru_cache(maxsize=32)
def _local_polynomial_transfer(order: int, width: float) -> Callable:
    """Transfer function of a centred local polynomial fit over a window of
    ``width`` px with uniform sample density: the Fourier transform of its
    equivalent kernel K(u) = e0' M^-1 phi(u) / width, with phi the monomials
    and M their Gram matrix over the window.  It depends on f * width only,
    so it is read off one table per order (:func:`_equivalent_kernel_table`)."""
    scaled, table = _equivalent_kernel_table(order)

    def transfer(f):
        x = np.abs(np.atleast_1d(np.asarray(f, float))) * width
        out = np.interp(x, scaled, table)
        beyond = x > scaled[-1]
        if beyond.any():
            out[beyond] = _equivalent_kernel_transfer(order, x[beyond])
        return out
    return transfer


TABLE_STEP = 1e-3          # in f * width: interpolation error below 2e-6
TABLE_END = 8.0            # f * width reaches about 4 (1 px windows to 4 cy/px); beyond, computed directly


@functools.lru_cache(maxsize=16)
def _equivalent_kernel_table(order: int) -> tuple[np.ndarray, np.ndarray]:
    scaled = np.arange(0.0, TABLE_END + TABLE_STEP / 2, TABLE_STEP)
    return scaled, _equivalent_kernel_transfer(order, scaled)


def _equivalent_kernel_transfer(order: int, scaled: np.ndarray) -> np.ndarray:
    """sum_u K(u) cos(2 pi x u) over Gauss-Legendre nodes on [-1/2, 1/2]:
    exact for the polynomial part, accurate for the cosine up to several
    cycles across the window; ``scaled`` x = f * width."""
    nodes, weights = np.polynomial.legendre.leggauss(64)
    u, weights = nodes / 2, weights / 2
    phi = u[None, :] ** np.arange(order + 1)[:, None]
    gram = (phi * weights) @ phi.T
    kernel = np.linalg.solve(gram, np.eye(order + 1)[:, 0]) @ phi * weights
    # the kernel is even and the nodes symmetric: twice the half at u > 0
    half = u > 0
    return np.cos(2 * np.pi * scaled[:, None] * u[None, half]) @ (2 * kernel[half])


def window_sums_each(moments: np.ndarray, offsets: np.ndarray, binomials: np.ndarray) -> np.ndarray:
    """:func:`_shifted_powers` of 2-D ``moments`` (n, grid) with every grid
    point's sums its own, whatever the columns beside it (many profiles'
    grids side by side give each the sums it has alone): one correlation
    per power of the offsets, row by row (fewer than ``ROW_BY_ROW_TAPS``
    taps), and the binomials' non-zero terms added one by one, where a
    matrix product rounds by the blocks its library cuts."""
    n = moments.shape[-2]
    if offsets.size >= ROW_BY_ROW_TAPS:
        raise ValueError(f"{offsets.size} taps: the correlations round by blocks of rows")   # pragma: no cover
    terms = [np.flatnonzero(row) for row in binomials]
    powers = sorted({int(c) // n for row in terms for c in row})
    correlated = {}
    for p in powers:
        rows = sorted({int(c) % n for row in terms for c in row if int(c) // n == p})
        lo, hi = rows[0], rows[-1] + 1
        correlated[p] = (lo, correlate1d(moments[lo:hi], offsets ** p))
    out = np.zeros_like(moments)
    for k, row in enumerate(terms):
        for c in row:
            p, j = divmod(int(c), n)
            lo, values = correlated[p]
            out[k] += binomials[k, c] * values[j - lo]
    return out
