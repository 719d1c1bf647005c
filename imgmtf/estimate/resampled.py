"""A profile resampled onto a uniform grid (:class:`Resampled`), and the
grid, binning and weighting every resampling method shares
(:mod:`.resampling`, :mod:`.local_polynomial`)."""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError


@dataclass(frozen=True, eq=False)
class Resampled:
    """A profile on a uniform grid.

    ``grid`` (px) and ``values`` (DN) have equal length; ``transfer(f)`` is
    the method's transfer function at ``f`` cycles/pixel; ``params`` the
    settings actually used (recorded as provenance).  The resampling is
    linear in the sample values, ``values = S v``: ``adjoint(h)`` returns
    ``S^T h`` for grid weights ``h`` (..., grid size), one weight per input
    sample, and ``leverage`` each sample's weight in the fit at its own
    position (about S[i, i]).  Both are for the linearised intervals
    (:mod:`imgmtf.estimate.intervals`); they are None for stacked weights.
    """

    grid: np.ndarray
    values: np.ndarray
    transfer: Callable[[np.ndarray], np.ndarray]
    params: dict = field(default_factory=dict)
    adjoint: Callable[[np.ndarray], np.ndarray] | None = None
    leverage: np.ndarray | None = None

    @property
    def step(self) -> float:
        return float(self.grid[1] - self.grid[0])


def _bins(distance, grid, step):
    """Nearest grid index of every sample, and which samples fall on the grid."""
    bins = np.rint((distance - grid[0]) / step).astype(int)
    keep = (bins >= 0) & (bins < grid.size)
    return bins[keep], keep


def _weights(weights, n: int) -> np.ndarray:
    """Sample weights as an array of shape (n,) or (replicates, n)."""
    if weights is None:
        return np.ones(n)
    w = np.asarray(weights, float)
    if w.shape[-1] != n or w.ndim > 2:
        raise ParameterError(f"weights must have shape ({n},) or (replicates, {n}), got {w.shape}")
    return w


def _unit_weight(w: np.ndarray):
    """The weight one sample counts with: 1 for counts, the mean otherwise,
    so that minimum-count rules mean samples whatever the weights' scale."""
    mean = w.mean(axis=-1, keepdims=True) if w.size else np.ones(1)
    return np.where(mean > 0, mean, 1.0)


def _bin_sums(bins: np.ndarray, n_bins: int, features: np.ndarray) -> np.ndarray:
    """Per-bin sums of ``features`` (..., F, n_samples) -> (..., F, n_bins)."""
    lead = features.shape[:-1]
    flat = features.reshape(-1, features.shape[-1])
    if flat.shape[0] <= 16:
        # a count of each feature alone: each bin gathers its samples in their order (cheaper than one
        # count over every feature's bins side by side, whose indices cost as much as the counting)
        sums = np.empty((flat.shape[0], n_bins))
        for row, feature in zip(sums, flat):
            row[:] = np.bincount(bins, weights=feature, minlength=n_bins)
    else:
        from scipy import sparse  # only for stacks of weights (the bootstrap)
        # one 1 per sample, in its bin's column: built as the compressed rows it is (a row pointer
        # of 0, 1, 2...), not converted from coordinates, which sorts and sums what has no duplicates
        onehot = sparse.csr_array((np.ones(bins.size), bins, np.arange(bins.size + 1)),
                                  shape=(bins.size, n_bins))
        sums = (onehot.T @ flat.T).T
    return sums.reshape(*lead, n_bins)


def sample_gap(distance: np.ndarray, near_px: float = 2.0) -> float:
    """Largest gap (px) between consecutive sample distances within
    ``near_px`` of the edge: the coarsest sampling of the profile where it
    matters.  A slope tan a = 1/q puts the samples on a lattice 1/q apart."""
    near = np.sort(distance[np.abs(distance) < near_px])
    if near.size < 2:
        return 2.0 * near_px
    return float(np.diff(np.concatenate([[-near_px], near, [near_px]])).max())


def _grid(step: float, half_range: float) -> np.ndarray:
    n = int(math.floor(half_range / step))
    return np.arange(-n, n + 1) * step
