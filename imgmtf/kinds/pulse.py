"""The pulse: a bar of a width on a uniform background (a bridge, a tarp
strip, a painted line)."""
from __future__ import annotations

from .kind import Column, Kind


def bar_response(d_px, esf, width_px: float):
    """A bar ``width_px`` wide seen through the sensor: the difference of
    the edge responses ``esf`` of its two sides, at signed distances
    ``d_px`` (px) from its centre line."""
    return esf(d_px + width_px / 2.0) - esf(d_px - width_px / 2.0)


PULSE = Kind(
    name="pulse", noun="bar", has_width=True,
    column=Column("pulse_width_px", "W", "px"), record_fields=("pulse_width_px",),
    estimator="imgmtf.estimate.pulse:PulseEstimator", result="imgmtf.estimate.pulse:PulseResult",
    measuring="imgmtf.estimate.pulse:PulseKind",
    scene_response=bar_response,
    profile_label="PRF, bar {width_px:.2f} px", lsf_label="pulse response", lsf_scale="peak 1",
    described="{width_px:g} px bar", masked_by="the bar's sinc",
    lone_line=("not-a-bar", "a lone edge, not the two sides of a bar"),
)
