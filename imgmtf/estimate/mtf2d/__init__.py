"""What is two-dimensional about an MTF: the 2-D MTF from its measured
1-D sections (:mod:`.sections`)."""
from .sections import (
    ASSUMPTIONS,
    BRACKET,
    ELLIPTICAL,
    MTF2D,
    SEPARABLE,
    EllipticalModel,
    SeparableModel,
    TrackSection,
    elliptical_model,
    mtf2d_from_sections,
    sd_from_nyquist,
    separable_model,
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
