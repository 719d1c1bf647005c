"""How to scan a scene: the settings every stage of a scan reads."""
from __future__ import annotations

from dataclasses import dataclass, field

from ..batch import MeasureSettings
from ..errors import ParameterError
from ..estimate.intervals import Intervals


@dataclass(frozen=True)
class ScanSettings:
    """How to scan a scene.

    target : "edge" or "pulse".
    min_length_px : shortest usable target (px along it).
    max_length_px : longer targets are measured over their central part.
    margin_px : ROI extent beyond the target across it (px).
    max_side_variation : largest level change (trend or spread) of a side,
        as a fraction of the target's contrast, for a uniform side.
    max_line_rms_px : largest RMS scatter of the per-row target locations
        about their line (px) for a straight target.
    tile_px : side of the tiles read for detection (px).
    method, band, pulse_width, intervals, track_azimuth_deg : as in
        :class:`imgmtf.batch.MeasureSettings`.
    """

    target: str = "edge"
    min_length_px: float = 40.0
    max_length_px: float = 300.0
    margin_px: int = 12
    max_side_variation: float = 0.1
    max_line_rms_px: float = 0.25
    tile_px: int = 1024
    method: str = "msg"
    band: int | None = None
    pulse_width: tuple[float, str] | None = None
    intervals: Intervals = field(default_factory=Intervals)
    track_azimuth_deg: float | None = None

    def __post_init__(self):
        if not self.min_length_px >= 16:
            raise ParameterError(f"--min-length must be at least 16 px, got {self.min_length_px}")
        if self.margin_px < 6:
            raise ParameterError(f"the ROI margin must be at least 6 px, got {self.margin_px}")
        if self.band == "all":
            raise ParameterError("scan one band at a time (--band N)")
        self.measure_settings()

    def measure_settings(self) -> MeasureSettings:
        return MeasureSettings(self.target, self.method, self.band, None, self.pulse_width, self.intervals,
                               track_azimuth_deg=self.track_azimuth_deg)
