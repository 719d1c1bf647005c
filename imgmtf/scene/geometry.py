"""Segments as arrays (rows x0, y0, x1, y1, px): their lengths, directions
and points sampled along them.  Shared by detection (on the workers) and
the segment graph (:mod:`.segments`), and free of SciPy, which only the
graph needs.
"""
from __future__ import annotations

import numpy as np

SAMPLE_STEP_PX = 2.0         # contacts are sought between points this far apart along segments


def segment_lengths(s: np.ndarray) -> np.ndarray:
    """Lengths (px) of segments (rows x0, y0, x1, y1)."""
    return np.hypot(s[:, 2] - s[:, 0], s[:, 3] - s[:, 1])


def unit_vectors(s: np.ndarray) -> np.ndarray:
    """Unit vectors along segments (rows x0, y0, x1, y1), from start to end."""
    d = s[:, 2:] - s[:, :2]
    return d / np.maximum(np.linalg.norm(d, axis=1), 1e-12)[:, None]


def sample_points(s: np.ndarray, step: float = SAMPLE_STEP_PX) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``step`` px or closer along each segment (ends
    included): (points n x 2, the segment of each)."""
    counts = np.ceil(segment_lengths(s) / step).astype(int) + 1
    owner = np.repeat(np.arange(len(s)), counts)
    first = np.cumsum(counts) - counts
    fraction = (np.arange(owner.size) - first[owner]) / np.maximum(counts[owner] - 1, 1)
    points = s[owner, :2] + fraction[:, None] * (s[owner, 2:] - s[owner, :2])
    return points, owner
