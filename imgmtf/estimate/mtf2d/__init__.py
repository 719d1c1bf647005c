"""What is two-dimensional about an MTF: the 2-D MTF from its measured
1-D sections (:mod:`.sections`; the inversions in :mod:`.inversion`, the
choice of assumption in :mod:`.assumptions`)."""
from .inversion import EllipticalModel, SeparableModel, elliptical_model, separable_model
from .sections import (
    ASSUMPTIONS,
    BRACKET,
    ELLIPTICAL,
    MTF2D,
    SEPARABLE,
    TrackSection,
    mtf2d_from_sections,
    sd_from_nyquist,
)

__all__ = [
    "ASSUMPTIONS",
    "BRACKET",
    "ELLIPTICAL",
    "MTF2D",
    "SEPARABLE",
    "EllipticalModel",
    "SeparableModel",
    "TrackSection",
    "elliptical_model",
    "mtf2d_from_sections",
    "sd_from_nyquist",
    "separable_model",
]
