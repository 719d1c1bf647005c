"""Block compression seen in the pixels: JPEG (and other block codecs)
code each 8 x 8 block on its own, so the target's per-row locations jump
where one block row ends and the next begins and run smoothly within a
block.  The target's geometry shows it without knowing where the block
grid lies: of the 8 phases of the rows, a codec's boundary phase stands
out (on exact 8-bit edges: mean jumps of 0.01-0.02 px at every phase;
at JPEG quality 75, 0.04-0.05 px at the boundaries against 0.02 inside;
at quality 50 and below 0.12 against 0.04, and the MTF at Nyquist reads
0.05-0.24 low).  The jumps are taken less the row locator's bias with the
sub-pixel phase (:mod:`.phase`), which repeats with the phase, not the
rows.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .evidence import Evidence
from .gate import Check, not_run
from .phase import PHASE_HARMONICS, phase_bias_many

BLOCK_PX = 8
MIN_BOUNDARIES = 6             # boundary jumps needed to judge
WARN_RATIO = 1.8               # boundary jumps this many times the inside ones...
WARN_EXCESS_PX = 0.02          # ...and this much larger: said
MAX_RATIO = 2.0                # and this much...
MAX_EXCESS_PX = 0.045          # ...refused (reason compression)
SIGNIFICANCE = 5.0             # standard errors


def block_boundaries(ev: Evidence) -> tuple[list[Check], list[str]]:
    """The row-to-row jumps of the target's location, by the rows' phase
    in an 8-row block grid: where one phase's mean jump stands out above
    the others', the codec's blocks shape the target.  Returns the
    ``compression`` check and a warning for visible but smaller blocks.
    A batch of one of :func:`block_boundaries_many`."""
    return block_boundaries_many([ev])[0]


def block_boundaries_many(evidences: Sequence[Evidence]) -> list[tuple[list[Check], list[str]]]:
    """:func:`block_boundaries` of many chips, their rows' biases with the
    sub-pixel phase fitted together (:func:`.phase.phase_bias_many`): each
    chip's outcome the same, to the bit, as alone.

    Parameters
    ----------
    evidences : sequence of Evidence
        The chips' samples, shapes and geometries.

    Returns
    -------
    list of (list of Check, list of str)
        Each chip's check and warnings, in order.
    """
    residuals: list[np.ndarray | None] = []
    lines = []
    for ev in evidences:
        geometry = ev.geometry
        if geometry is None:
            residuals.append(None)
            continue
        line = geometry.slope * geometry.rows + geometry.intercept
        residual = geometry.locations - line
        residuals.append(residual)
        # less the locator's bias with the sub-pixel phase, which jumps where the phase wraps (every
        # 1 / tan(angle) rows: a sharpened edge's up to 0.3 px), not with an 8-row grid
        if _phase_apart_from_blocks(geometry.slope, geometry.rows.size):
            lines.append((len(residuals) - 1, residual, line, geometry.kept))
    biases = phase_bias_many([(residual, line, kept) for _, residual, line, kept in lines])
    for (k, residual, _, _), bias in zip(lines, biases):
        residuals[k] = residual - bias
    return [_block_jumps(ev, residual) for ev, residual in zip(evidences, residuals)]


def _block_jumps(ev: Evidence, residual: np.ndarray | None) -> tuple[list[Check], list[str]]:
    """:func:`block_boundaries` given the rows' ``residual`` about the line
    (px; less their phase bias where it is told from the blocks)."""
    if residual is None or ev.geometry is None:
        return [not_run("compression", f"the {ev.name}'s row locations are not known")], []
    rows, kept = ev.geometry.rows, ev.geometry.kept
    adjacent = kept[:-1] & kept[1:] & (np.diff(rows) == 1)
    jumps = np.abs(np.diff(residual))[adjacent]
    phase = (rows[:-1] % BLOCK_PX)[adjacent]
    counts = np.bincount(phase, minlength=BLOCK_PX)
    if counts.min() < MIN_BOUNDARIES:
        return [not_run("compression", f"{int(counts.min())} row-to-row jumps at some phase of an {BLOCK_PX}-row "
                        f"grid (at least {MIN_BOUNDARIES} needed): too few rows to see {BLOCK_PX} x {BLOCK_PX} "
                        "blocks")], []
    means = np.bincount(phase, weights=jumps, minlength=BLOCK_PX) / counts
    boundary = int(np.argmax(means))
    others = phase != boundary
    inside = float(np.mean(jumps[others]))
    excess, ratio = float(means[boundary]) - inside, float(means[boundary]) / max(inside, 1e-9)
    # the largest of 8 phase means stands out by chance too: its excess must
    # be many standard errors of the jumps' own scatter (noise)
    error = float(np.std(jumps[others])) * math.sqrt(1.0 / counts[boundary] + 1.0 / others.sum())
    significant = excess > SIGNIFICANCE * error
    blocky = significant and ratio > MAX_RATIO and excess > MAX_EXCESS_PX
    check = Check("compression", not blocky,
                  f"the {ev.name}'s row locations jump by {means[boundary]:.3f} px every {BLOCK_PX} rows against "
                  f"{inside:.3f} px between (at most {MAX_EXCESS_PX} px more): {BLOCK_PX} x {BLOCK_PX} blocks of a "
                  "lossy codec (JPEG) shape the target, and its MTF is the codec's", excess, MAX_EXCESS_PX)
    said = []
    if not blocky and significant and ratio > WARN_RATIO and excess > WARN_EXCESS_PX:
        said.append(f"the {ev.name}'s row locations jump every {BLOCK_PX} rows ({means[boundary]:.3f} px against "
                    f"{inside:.3f} px): block compression (JPEG), whose loss the MTF includes")
    return [check], said


def _phase_apart_from_blocks(slope: float, rows: int) -> bool:
    """Whether the rows' sub-pixel phase (its harmonics) drifts against an
    8-row grid by a cycle or more over the rows, so that a bias with the
    phase cannot stand in for the blocks (near 7.1 or 14 deg, where the
    phase repeats every 8 or 4 rows, it could: the phase model would take
    the codec's jumps)."""
    drift = [abs(k * BLOCK_PX * slope - round(k * BLOCK_PX * slope)) for k in range(1, PHASE_HARMONICS + 1)]
    return min(drift) * rows / BLOCK_PX >= 1.0
