"""The double bar: two parallel bars of one width, a gap apart, on a
uniform background (Storey's Lake Pontchartrain Causeway: two spans of a
bridge).  Its width is each bar's (``width_px``, ``--pulse-width``), its
gap the edge-to-edge distance between them (``gap_px``, ``--gap``): their
centres lie ``width_px + gap_px`` apart, and the pair's transfer along the
normal is sinc(W f) 2 cos(pi f (W + G)) (:mod:`imgmtf.estimate.double_bar`
divides it out where it is well away from zero, and fits the sensor model
to the profile where it is not)."""
from __future__ import annotations

from .kind import Column, Kind


def double_bar_response(d_px, esf, width_px: float, gap_px: float = 0.0):
    """Two bars ``width_px`` wide, their near sides ``gap_px`` apart, seen
    through the sensor: the sum of each bar's difference of edge responses
    ``esf``, at signed distances ``d_px`` (px) from the pair's centre line.

    Examples
    --------
    >>> import numpy as np
    >>> step = lambda d: (np.asarray(d) > 0).astype(float)     # a sensor without blur
    >>> double_bar_response(np.array([-2.0, -1.0, 0.0, 1.0, 2.0]), step, 1.0, 1.0).tolist()
    [0.0, 1.0, 0.0, 1.0, 0.0]
    """
    half_pitch = (width_px + gap_px) / 2.0
    return sum(esf(d_px - centre + width_px / 2.0) - esf(d_px - centre - width_px / 2.0)
               for centre in (-half_pitch, half_pitch))


DOUBLE_BAR = Kind(
    name="double-bar", noun="double bar", has_width=True,
    column=Column("gap_px", "G", "px"), record_fields=("pulse_width_px", "gap_px", "model_fitted"),
    estimator="imgmtf.estimate.double_bar:DoubleBarEstimator",
    result="imgmtf.estimate.double_bar:DoubleBarResult",
    measuring="imgmtf.estimate.double_bar:DoubleBarKind",
    scene_response=double_bar_response,
    profile_label="PRF, two {width_px:.2f} px bars", lsf_label="pulse response", lsf_scale="peak 1",
    described="{width_px:g} px double bar", masked_by="the pair's transfer",
    lone_line=("not-a-bar", "a lone edge, not the two sides of a bar"),
    gap_keyword="gap_px",
)
