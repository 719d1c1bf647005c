"""How the shared pipeline measures each kind of target (:class:`TargetKind`:
an edge, a bar; the kinds themselves are registered in :mod:`imgmtf.kinds`),
the levels and scale a kind reads off its profile (:class:`Shape`), and the
refusal of a profile of the other kind.  A width a kind reads off its
profile (a bar's) is a :class:`.intervals.width.WidthReading`."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..errors import UnsuitableTargetError
from ..kinds import Kind
from . import gate
from .bar_pair import PAIR_REASON
from .detection import Line
from .fermi import FermiFit, FermiRows
from .geometry import EDGE_FIT_HALF_WINDOW_PX, TargetGeometry, row_windows
from .intervals.width import WidthReading


class TargetKind:
    """How the pipeline measures one registered kind of target (its
    :class:`imgmtf.kinds.Kind`, ``registered``, names this class as its
    ``measuring`` part); see :class:`imgmtf.estimate.edge.EdgeKind` and
    :class:`imgmtf.estimate.pulse.PulseKind`, the two implementations.

    Attributes: ``registered`` the kind's entry in :mod:`imgmtf.kinds`
    (``name`` is its noun, what messages call the target: "edge", "bar");
    ``profile`` what its profile must look like
    (:func:`.gate.classify_profile`); ``tail_power`` p of its profile's
    tails, level + A / |s|^p; ``monotone`` whether the profile only rises
    (a staircase can then be rebuilt, :mod:`.quantisation`);
    ``subtracts_background`` whether its LSF-like profile is the profile
    above a fitted background (a bar) rather than a derivative (an edge);
    ``restore_min_divisor`` the divisor below which the recovered LSF's
    spectrum is bridged rather than divided.
    """

    registered: ClassVar[Kind]
    profile: ClassVar[str]
    tail_power: ClassVar[int]
    monotone: ClassVar[bool]
    subtracts_background: ClassVar[bool]
    restore_min_divisor: ClassVar[float]

    @property
    def name(self) -> str:
        """What messages call the target: its registered kind's noun."""
        return self.registered.noun

    def seed(self, data: np.ndarray, noise: float) -> tuple[Line, list[gate.Check]]:
        """The target's line in the chip and the gate's checks of what else
        was found, the chip's pixel noise being ``noise`` (DN)."""
        raise NotImplementedError

    def locate(self, work: np.ndarray, seed_x: np.ndarray, transposed: bool) -> TargetGeometry:
        """The target's line fitted through its per-row locations."""
        raise NotImplementedError

    def fermi_rows(self, work: np.ndarray, seed_x: np.ndarray) -> FermiRows | None:
        """The rows :meth:`locate` fits a Fermi step to, for fits stacked
        across chips (:mod:`.prefit`); None for a kind that fits none."""
        return None

    def locate_fitted(self, work: np.ndarray, seed_x: np.ndarray, transposed: bool, fit: FermiFit) -> TargetGeometry:
        """:meth:`locate` with the fit of its :meth:`fermi_rows` made."""
        return self.locate(work, seed_x, transposed)

    def shape(self, grid: np.ndarray, values: np.ndarray, d: np.ndarray, v: np.ndarray,
              half_range: float) -> Shape:
        """What the resampled profile (and its samples) say of the target."""
        raise NotImplementedError

    def core_px(self, shape: Shape, snr: float, factor: float | None) -> float:
        """The LSF window's flat half-width at this SNR (``factor``: a
        user's multiple of the target's width)."""
        raise NotImplementedError

    def taper_factor(self, snr: float) -> float:
        """The window's taper as a multiple of its core."""
        raise NotImplementedError

    def confident_snr(self, rows: int) -> float:
        """The SNR below which the estimate carries a warning."""
        raise NotImplementedError

    def lsf(self, grid: np.ndarray, values: np.ndarray,
            background) -> tuple[np.ndarray, np.ndarray, Callable[[np.ndarray], np.ndarray]]:
        """(x, lsf, adjoint): the LSF-like profile on ``x`` and the map of
        weights on ``x`` back to weights on ``grid``."""
        raise NotImplementedError

    def lsf_tail_amplitudes(self) -> list[np.ndarray]:
        """Per side (left, right), the linear map from that side's fitted
        (level, A) to the LSF-like tail's amplitude a (a / s^2)."""
        raise NotImplementedError

    def divisor(self, step: float, transfer, shape: Shape) -> Callable[[np.ndarray], np.ndarray]:
        """The transfer between the system's LSF and the LSF-like profile."""
        raise NotImplementedError

    def noise_gain(self, shape: Shape, contrast: float) -> Callable[[np.ndarray], np.ndarray]:
        """How white sample noise grows with frequency in the MTF."""
        raise NotImplementedError

    def saturation_sides(self, sides: list) -> list:
        """The sides the saturation checks examine, named for the user."""
        raise NotImplementedError

    def peak_mask(self, s: np.ndarray, shape: Shape) -> np.ndarray | None:
        """The samples of a bar's peak (None for an edge)."""
        raise NotImplementedError

    def known_half_width_px(self, shape: Shape) -> float | None:
        """Half the target's width (px) where the caller gave it (a bar's),
        the pivot of the saturation check's mirror of its top; None where
        it is unknown or read off the profile."""
        return None

    def read_width(self, grid: np.ndarray, shape: Shape) -> WidthReading | None:
        """Where the divisor rests on a width read off the profile (a bar's
        estimated width), how it was read (:class:`WidthReading`), so that
        its own noise joins the intervals; None where the divisor is known."""
        return None


@dataclass(frozen=True)
class Shape:
    """What a kind reads off its resampled profile: ``centre`` (px, the
    target's middle along the normal), ``scale_px`` (its width: an edge's
    10-90 % rise, a bar's half-width at 10 %), the reference levels
    ``low``/``high`` (DN: an edge's left and right, a bar's background and
    peak), the ``core_px`` the LSF window keeps flat at the given SNR
    factor, where the ``plateau_px`` sides begin, and ``extra`` figures."""

    centre: float
    scale_px: float
    low: float
    high: float
    plateau_px: float
    extra: dict = field(default_factory=dict)


def refuse_other_kind(kind: TargetKind, work: np.ndarray, seed_x: np.ndarray) -> None:
    """Where the target could not be followed row by row (a bar defeats an
    edge's step fits, and leaves its phases too sparse), the rows' mean
    profile about the seed says whether it is the other kind of target:
    that is the reason to give (``not-an-edge``, ``not-a-bar``), or, where
    the whole rows hold a step and a bar, the second target
    (``two-targets``).

    Raises
    ------
    UnsuitableTargetError
        The mean profile is of the other kind."""
    _, values, inside = row_windows(work, seed_x, EDGE_FIT_HALF_WINDOW_PX)
    counts = inside.sum(axis=0)
    if counts.min() > 0:
        mean = values.sum(axis=0) / counts
        check = gate.kind_check(gate.classify_profile(mean), kind.profile, mean)
        if not check.passed:
            # the whole rows say whether the other kind stands beside a target of the wanted kind
            _, wide, wide_inside = row_windows(work, seed_x, work.shape[1])
            wide_counts = wide_inside.sum(axis=0)
            covered = wide_counts >= 0.5 * work.shape[0]
            if covered.sum() > 2 * EDGE_FIT_HALF_WINDOW_PX + 1:
                whole = wide.sum(axis=0)[covered] / wide_counts[covered]
                check = gate.kind_check(gate.classify_profile(mean), kind.profile, whole)
            if check.reason != "two-targets":
                # whole pixels blur two close bars into one: their sub-pixel phases part them
                grid, fine, noise_dn = seed_profile(work, seed_x, EDGE_FIT_HALF_WINDOW_PX)
                pair = gate.kind_check(gate.classify_profile(mean), kind.profile, fine, grid, noise_dn)
                check = pair if pair.reason == PAIR_REASON else check
            raise UnsuitableTargetError(check.message, reason=check.reason) from None


def seed_profile(work: np.ndarray, seed_x: np.ndarray, half_window: int,
                 step_px: float = 0.25) -> tuple[np.ndarray, np.ndarray, float]:
    """The rows' pixels within ``half_window`` of the seed line, binned by
    their signed distance from it (``step_px`` bins): the profile a target
    that could not be followed row by row still shows, its bins' centres
    (px) and the pixels' noise beyond 0.6 ``half_window`` (DN).

    Examples
    --------
    >>> work = np.tile((np.arange(21) == 10) * 100.0, (40, 1))
    >>> grid, values, noise = seed_profile(work, np.full(40, 10.0), 5)
    >>> float(grid[np.argmax(values)]), noise
    (0.125, 0.0)
    """
    cols, values, inside = row_windows(work, seed_x, half_window)
    distance = (cols - seed_x[:, None])[inside]
    values = values[inside]
    edges = np.arange(-half_window, half_window + step_px / 2, step_px)
    index = np.clip(np.searchsorted(edges, distance, side="right") - 1, 0, edges.size - 2)
    counts = np.bincount(index, minlength=edges.size - 1)
    sums = np.bincount(index, weights=values, minlength=edges.size - 1)
    filled = counts > 0
    outer = np.abs(distance) > 0.6 * half_window
    noise_dn = float(np.std(values[outer])) if outer.sum() > 3 else 0.0
    return (edges[:-1] + step_px / 2)[filled], sums[filled] / counts[filled], noise_dn
