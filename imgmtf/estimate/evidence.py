"""What the gate's profile checks read: the samples of a measured chip and
the shape the pipeline read off them, in one frozen record.

The checks registered in :mod:`.profile_checks` each take an
:class:`Evidence` and return their :class:`.gate.Check` objects and any
warnings, so that a new check is one module and one registration.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .geometry import TargetGeometry

if TYPE_CHECKING:
    from .kind import Shape, TargetKind
    from .state import Chip, Located, Noise, Samples


@dataclass(frozen=True, eq=False)
class Evidence:
    """A chip's profile samples and what the pipeline read off them.

    Attributes
    ----------
    distance_px : numpy.ndarray
        Each sample's signed distance from the target's line (px).
    values : numpy.ndarray
        Each sample's value as recorded (DN).
    rows : numpy.ndarray
        Each sample's row along the target (vertical frame).
    centre_px : float
        The target's middle along the normal (px, on ``distance_px``'s scale).
    scale_px : float
        The target's width: an edge's 10-90 % rise, a bar's half-width at 10 %.
    plateau_px : float
        How far from the centre the sides begin (px).
    low, high : float
        The reference levels (DN): an edge's left and right level, a bar's
        background and peak.
    pixel_noise : float
        The chip's pixel noise (DN).
    quantum : float
        The DN step of the recorded values (0: not quantised).
    tail_power : int
        p of the sides' tail model, level + A / |s|^p.
    name : str
        The target as a user names it ("edge", "bar").
    profile : str
        "edge" (a step) or "bar" (a pulse).
    side_names : tuple of str
        What the left and the right side are called ("dark", "bright",
        "left background"...).
    geometry : TargetGeometry or None
        The target's line and its per-row locations.
    blur_widths : list or None
        The widths :func:`.blur_along.uniform_blur` reads in the target's
        halves and thirds, when fitted with other chips'
        (:func:`.blur_along.group_widths_many`); None: it fits them.
    """

    distance_px: np.ndarray
    values: np.ndarray
    rows: np.ndarray
    centre_px: float
    scale_px: float
    plateau_px: float
    low: float
    high: float
    pixel_noise: float
    quantum: float
    tail_power: int
    name: str
    profile: str
    side_names: tuple[str, str]
    geometry: TargetGeometry | None = None
    blur_widths: list | None = None     # the blur check's group widths, fitted among other chips' (blur_along)

    @property
    def contrast(self) -> float:
        """The step (edge) or the height (bar), DN, > 0."""
        return abs(self.high - self.low)

    @property
    def rounding_floor(self) -> float:
        """A part of a bin mean's error that does not average down (DN): a
        noise-free quantised profile rounds neighbouring samples alike."""
        return self.quantum / np.sqrt(12.0) if self.pixel_noise < 0.5 * self.quantum else 0.0


def evidence_of(kind: TargetKind, chip: Chip, located: Located, samples: Samples, shape: Shape, noise: Noise
                ) -> Evidence:
    """What the gate's profile checks read of a measured chip: its samples,
    the shape read off them, its noise and its sides' names."""
    side_names = tuple(name for name, _, _ in kind.saturation_sides(side_masks(shape, samples.distance_px
                                                                                - shape.centre)))
    return Evidence(samples.distance_px, samples.raw_dn, samples.rows, shape.centre, shape.scale_px, shape.plateau_px,
                    shape.low, shape.high, noise.noise_dn, chip.quantum_dn, kind.tail_power, kind.name, kind.profile,
                    (side_names[0], side_names[1]), located.geometry)


def side_masks(shape: Shape, offsets: np.ndarray) -> list[tuple[str, np.ndarray, None]]:
    """The left and the right side of a profile as (name, mask, None): the
    samples at ``offsets`` (px from the centre) beyond the plateau's start,
    named "dark" or "bright" by the levels, as
    :meth:`.kind.TargetKind.saturation_sides` takes them (a kind renames them)."""
    return [("dark" if (shape.low <= shape.high) == (i == 0) else "bright", mask, None)
            for i, mask in enumerate((offsets <= -shape.plateau_px, offsets >= shape.plateau_px))]
