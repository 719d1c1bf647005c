"""What is two-dimensional: the 2-D PSF and MTF of a target, and its
sections across and along track.  :mod:`.points` stacks arrays of point
targets by their sub-pixel phases (:func:`measure_points`), beside the 1-D
pipeline of edges and bars (:mod:`imgmtf.estimate.pipeline`)."""
from __future__ import annotations

from .estimator import PointsEstimator
from .points import DirectionMTF, PointsResult, measure_points

__all__ = ["DirectionMTF", "PointsEstimator", "PointsResult", "measure_points"]
