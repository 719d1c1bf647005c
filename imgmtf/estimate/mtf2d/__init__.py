"""What is two-dimensional about an MTF: the 2-D MTF from its measured
1-D sections (:mod:`.sections`; the inversions in :mod:`.inversion`, the
choice of assumption in :mod:`.assumptions`), and the 2-D PSF and MTF of
arrays of point targets stacked by their sub-pixel phases (:mod:`.points`,
:func:`measure_points`), beside the 1-D pipeline of edges and bars
(:mod:`imgmtf.estimate.pipeline`)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .inversion import EllipticalModel, SeparableModel, elliptical_model, separable_model
from .sections import (
    ASSUMPTIONS,
    BRACKET,
    ELLIPTICAL,
    MTF2D,
    SEPARABLE,
    TrackSection,
    mtf2d_from_sections,
    mtf2d_from_sections_many,
    sd_from_nyquist,
)

if TYPE_CHECKING:
    from .estimator import PointsEstimator
    from .points import DirectionMTF, PointsResult, measure_points

#: the point stack's names, loaded when first asked for: it needs SciPy, which the scan's workers (the
#: sections' only users there) must not load
_POINTS = {"PointsEstimator": ".estimator", "DirectionMTF": ".points", "PointsResult": ".points",
           "measure_points": ".points"}


def __getattr__(name: str) -> Any:
    if name in _POINTS:
        from importlib import import_module
        return getattr(import_module(_POINTS[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "ASSUMPTIONS",
    "BRACKET",
    "ELLIPTICAL",
    "MTF2D",
    "SEPARABLE",
    "DirectionMTF",
    "EllipticalModel",
    "PointsEstimator",
    "PointsResult",
    "SeparableModel",
    "TrackSection",
    "elliptical_model",
    "measure_points",
    "mtf2d_from_sections",
    "mtf2d_from_sections_many",
    "sd_from_nyquist",
    "separable_model",
]
