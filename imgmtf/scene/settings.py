"""How to scan a scene: the settings every stage of a scan reads."""
from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import ParameterError
from ..estimate.field import parse_centre
from ..estimate.intervals import Intervals, as_intervals
from ..inputs import check_number, parse_length
from ..measure_settings import MeasureSettings
from ..vectors import VectorROIs, as_rois

MIN_TILE_PX = 256
MAX_TILE_PX = 2048      # a batch of candidates reads its tile and their ROIs beyond it: well under one read's limit
MAX_LENGTH_PX = 2048    # longest stretch of a target measured (its middle); beyond, rows add nothing but time


@dataclass(frozen=True)
class ScanSettings:
    """How to scan a scene.

    Parameters
    ----------
    target : str
        "edge" or "pulse".
    min_length_px : float
        Shortest straight line worth measuring (px): a half-edge counts the
        whole line it was split from at junctions (a checkerboard's inner
        line, both halves), so that short texture is left out and the
        half-edges of a small target are not.
    max_length_px : float
        Longer targets are measured over their central part (px).
    margin_px : int
        ROI extent either side of the target, across it (px).
    tile_px : int
        Side of the tiles read for detection (px).
    method : str, optional
        Resampling method (default "msg"; :class:`imgmtf.MeasureSettings`).
    band : int, optional
        1-based band scanned (default the only band, or RGB luminance).
    pulse_width : (float, str), float or str, optional
        A bar's width: (value, "px" or "m"), px, or "1.4px", "18.3m"; None
        (default) to estimate it.
    intervals : Intervals, str or int, optional
        Confidence-interval settings, as :class:`imgmtf.MeasureSettings`
        takes them.
    saturation : (float, float), optional
        (low, high) DN the sensor records (default an integer scene's type
        range).
    track_azimuth_deg : float, optional
        The ground track's direction, degrees clockwise from up; without
        it, a scene in sensor geometry has its rows along track, a
        map-projected one (with a CRS) an unknown direction, and one with
        no georeference (no CRS, no pixel size: a photo) its own axes
        ("horizontal", "vertical").
    roi : VectorROIs, str or os.PathLike, optional
        A vector layer (:class:`imgmtf.vectors.VectorROIs`, or a file any
        GDAL vector driver reads): only the candidates that cross one of
        its features' windows on the scene are measured, each carrying
        that feature's id and attributes (``feature_id``, ``feature``).
    optical_centre : (float, float) or str, optional
        A lens's optical centre (x, y), px, or ``"centre"`` for the
        scene's: each candidate is then placed in the field (its distance
        from the centre, sagittal or meridional:
        :func:`imgmtf.estimate.field.field_position`), what a lens profile
        (:func:`imgmtf.scene.lens_profile.lens_profile`) reads.
    point_spacing_px : float, optional
        Point targets (``target`` "points"): neighbours of one array lie
        within this distance, px; None (default) to group them by their
        own spacing (:func:`imgmtf.scene.points.group_arrays`).

    Raises
    ------
    ParameterError
        A setting out of range.

    Examples
    --------
    >>> ScanSettings(min_length_px=30.0).as_dict()["min_length_px"]
    30.0
    """

    target: str = "edge"
    min_length_px: float = 40.0
    max_length_px: float = 300.0
    margin_px: int = 12
    tile_px: int = 1024
    method: str = "msg"
    band: int | None = None
    pulse_width: tuple[float, str] | None = None
    intervals: Intervals = field(default_factory=Intervals)
    saturation: tuple[float, float] | None = None
    track_azimuth_deg: float | None = None
    roi: VectorROIs | None = None
    optical_centre: tuple[float, float] | str | None = None
    point_spacing_px: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "intervals", as_intervals(self.intervals))    # "bootstrap", as --intervals
        object.__setattr__(self, "roi", as_rois(self.roi))                      # a vector file, read once
        if self.optical_centre is not None:
            centre = self.optical_centre
            object.__setattr__(self, "optical_centre", parse_centre(centre if isinstance(centre, str)
                                                                    else ",".join(map(str, centre))))
        if self.roi is not None and not isinstance(self.roi, VectorROIs):
            raise ParameterError(f"a scan's roi is a vector layer (its file or a VectorROIs), got {self.roi!r}")
        if self.pulse_width is not None:
            object.__setattr__(self, "pulse_width", parse_length(self.pulse_width))     # "1.5m", as --pulse-width
        for name in ("min_length_px", "max_length_px"):
            object.__setattr__(self, name, check_number(name, getattr(self, name)))
        for name in ("margin_px", "tile_px"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), integer=True))
        if self.band == "all":
            raise ParameterError("scan one band at a time (band=N)")
        if self.band is not None:
            object.__setattr__(self, "band", check_number("band", self.band, low=1, integer=True))
        if not self.min_length_px >= 16:
            raise ParameterError(f"min_length_px must be at least 16 px, got {self.min_length_px}")
        if not self.min_length_px <= self.max_length_px <= MAX_LENGTH_PX:
            raise ParameterError(f"max_length_px ({self.max_length_px:g} px) must lie between min_length_px "
                                 f"({self.min_length_px:g} px) and {MAX_LENGTH_PX} px")
        if self.point_spacing_px is not None:
            object.__setattr__(self, "point_spacing_px", check_number("point_spacing_px", self.point_spacing_px))
            if not self.point_spacing_px >= 2:
                raise ParameterError(f"point_spacing_px must be at least 2 px, got {self.point_spacing_px}")
        if self.margin_px < 6:
            raise ParameterError(f"the ROI margin must be at least 6 px, got {self.margin_px}")
        if not (isinstance(self.tile_px, int) and MIN_TILE_PX <= self.tile_px <= MAX_TILE_PX):
            raise ParameterError(f"tiles must be {MIN_TILE_PX} to {MAX_TILE_PX} px, got {self.tile_px!r}")
        self.measure_settings()

    def measure_settings(self) -> MeasureSettings:
        """The settings of each candidate's estimate."""
        return MeasureSettings(self.target, self.method, self.band, None, self.pulse_width, self.intervals,
                               saturation=self.saturation, track_azimuth_deg=self.track_azimuth_deg)

    def as_dict(self) -> dict:
        """The scan's own settings, as records carry them."""
        return {"min_length_px": self.min_length_px, "max_length_px": self.max_length_px,
                "margin_px": self.margin_px, "tile_px": self.tile_px,
                **({"roi_file": self.roi.source} if self.roi is not None else {}),
                **({"optical_centre": self.optical_centre} if self.optical_centre is not None else {}),
                # only when given: an edge scan's acquisition keeps its id
                **({"point_spacing_px": self.point_spacing_px} if self.point_spacing_px is not None else {})}
