"""Cheap screens: what rejects a candidate before any pixel is read."""
from __future__ import annotations

from ..estimate.geometry import MAX_ANGLE_DEG, MIN_ANGLE_DEG
from .detect import Segment
from .settings import ScanSettings


def screen(segment: Segment, settings: ScanSettings) -> tuple[str, str] | None:
    """(reason, message) when the segment can be rejected unread."""
    if segment.length_px < settings.min_length_px:
        return "too-short", (f"{segment.length_px:.0f} px long, shorter than the minimum "
                             f"{settings.min_length_px:g} px")
    if segment.tilt_deg < MIN_ANGLE_DEG:
        return "angle", (f"{segment.tilt_deg:.2f} deg from the image axis: too close for "
                         f"sub-pixel sampling (needs {MIN_ANGLE_DEG:g} to {MAX_ANGLE_DEG:g} deg)")
    if segment.tilt_deg > MAX_ANGLE_DEG:
        return "angle", (f"{segment.tilt_deg:.2f} deg from the image axis: too close to 45 deg "
                         f"for sub-pixel sampling (needs {MIN_ANGLE_DEG:g} to {MAX_ANGLE_DEG:g} deg)")
    return None
