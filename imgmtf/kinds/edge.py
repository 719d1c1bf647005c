"""The straight edge: a step between two levels."""
from __future__ import annotations

from .kind import Column, Kind


def edge_response(d_px, esf, width_px: float = 0.0):
    """An edge seen through the sensor: its edge response ``esf`` at the
    signed distances ``d_px`` (px); an edge has no width."""
    return esf(d_px)


EDGE = Kind(
    name="edge", noun="edge", has_width=False,
    column=Column("rer", "RER"), record_fields=("rer",),
    estimator="imgmtf.estimate.edge:EdgeEstimator", result="imgmtf.estimate.edge:EdgeResult",
    measuring="imgmtf.estimate.edge:EdgeKind",
    scene_response=edge_response,
    profile_label="ESF", lsf_label="LSF", lsf_scale="1/px", described="edge",
    fits_sensor=True,
)
