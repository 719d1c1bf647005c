"""How to measure every file of a batch (:class:`MeasureSettings`), the
settings a scan's measurements read too: below both :mod:`imgmtf.batch`
and :mod:`imgmtf.scene`."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from .errors import ParameterError
from .estimate.field import parse_centre
from .estimate.intervals import Intervals, as_intervals
from .estimate.resampling import check_method
from .inputs import check_width, parse_length
from .kinds import get_kind
from .records import Record
from .transfer import parse_transfer
from .vectors import VectorROIs, as_rois

if TYPE_CHECKING:
    from .estimate.results import MTFResult
    from .io import Raster


@dataclass(frozen=True)
class MeasureSettings:
    """How to measure every file of a batch.

    Parameters
    ----------
    target : {"edge", "pulse"}, optional
        The target (default "edge").
    method : str, optional
        Resampling method (see :data:`imgmtf.estimate.resampling.METHODS`;
        default "msg").
    band : int or str, optional
        1-based band, "all" for every band, None (default) for the only
        band or RGB luminance.
    roi : (int, int, int, int), str, os.PathLike or VectorROIs, optional
        (x, y, width, height) window read from every file, px; or a vector
        layer (a file any GDAL vector driver reads, or
        :class:`imgmtf.vectors.VectorROIs`) whose polygons and lines,
        reprojected onto each file, are measured one window each, their
        attributes in the records (``feature_id``, ``feature``).
    pulse_width : (float, str), float or str, optional
        (value, "px" or "m"), a number of px, a string as the CLI takes it
        ("1.4", "1.4px", "18.3m"), or None (default) to estimate it.
    intervals : Intervals, str or int, optional
        Confidence-interval settings (linearised by default): an
        :class:`~imgmtf.Intervals`, or what ``--intervals`` takes
        ("influence", "bootstrap", "none"), or a number of bootstrap
        replicates (0: none).
    force : bool, optional
        Measure even where a quality check fails (each a warning).
    saturation : (float, float), optional
        (low, high) DN the sensor records; None for an integer file's type
        range (floats: none declared).
    track_azimuth_deg : float, optional
        The ground track's direction in the image, degrees clockwise from
        up; None: rows along track for images in sensor geometry, unknown
        for map-projected ones, and for an image with no georeference (no
        CRS, no pixel size: a photo) its own axes, the directions named
        "horizontal" and "vertical".
    transfer : str, optional
        How the stored values relate to light, "linear" (as stored), "srgb"
        or "gamma:G" (:mod:`imgmtf.transfer`): linearised before measuring.
    point_size : (float, str), float or str, optional
        Each point target's known size (a square's side), as
        ``pulse_width`` takes it; for the kinds that take one (points).
    gap : (float, str), float or str, optional
        A double bar's gap between its bars (edge to edge), as
        ``pulse_width`` takes it; for the kinds with one (double bars),
        which need it.
    optical_centre : (float, float) or str, optional
        A lens's optical centre (x, y), px (pixel centres at integers), or
        ``"centre"`` for the image's: each edge's record then says how far
        from it the edge lies and whether it measures the sagittal or the
        meridional MTF (:func:`imgmtf.estimate.field.field_position`).

    Raises
    ------
    ParameterError
        A setting out of range, a pulse width for an edge, or a point size
        for a kind without one.

    Examples
    --------
    >>> from imgmtf import MeasureSettings
    >>> settings = MeasureSettings(target="pulse", pulse_width="18.3m", intervals="none")
    >>> settings.pulse_width, settings.intervals.method
    ((18.3, 'm'), 'none')
    """

    target: str = "edge"
    method: str = "msg"
    band: int | str | None = None
    roi: tuple[int, int, int, int] | VectorROIs | None = None
    pulse_width: tuple[float, str] | None = None
    intervals: Intervals = field(default_factory=Intervals)
    force: bool = False
    saturation: tuple[float, float] | None = None
    track_azimuth_deg: float | None = None
    transfer: str = "linear"
    point_size: tuple[float, str] | None = None
    gap: tuple[float, str] | None = None
    optical_centre: tuple[float, float] | str | None = None

    def __post_init__(self):
        object.__setattr__(self, "intervals", as_intervals(self.intervals))
        object.__setattr__(self, "roi", as_rois(self.roi))     # a vector file read once, here
        if self.pulse_width is not None:
            object.__setattr__(self, "pulse_width", parse_length(self.pulse_width))
        if not get_kind(self.target, "target").has_width and self.pulse_width is not None:
            raise ParameterError("a pulse width applies to pulse targets only")
        if self.pulse_width is not None and self.pulse_width[1] == "px":
            check_width(self.pulse_width[0])
        if self.point_size is not None:
            object.__setattr__(self, "point_size", parse_length(self.point_size))
            if get_kind(self.target, "target").size_keyword is None:
                raise ParameterError(f"a point size applies to point targets only, not to a {self.target}")
            if not 0.0 <= self.point_size[0] <= 20.0 and self.point_size[1] == "px":
                raise ParameterError(f"a point size must be 0 to 20 px, got {self.point_size[0]:g}")
        if self.gap is not None:
            object.__setattr__(self, "gap", parse_length(self.gap))
            if get_kind(self.target, "target").gap_keyword is None:
                raise ParameterError(f"a gap applies to double bars only, not to a {self.target}")
            if not self.gap[0] > 0:
                raise ParameterError(f"a double bar's gap must be > 0, got {self.gap[0]:g}")
        elif get_kind(self.target, "target").gap_keyword is not None:
            raise ParameterError(f"a {self.target} needs the gap between its bars (and their width): "
                                 "neither can be read off its profile")
        if get_kind(self.target, "target").gap_keyword is not None and self.pulse_width is None:
            raise ParameterError(f"a {self.target} needs its bars' width: it cannot be read off two bars' profile")
        if self.optical_centre is not None:
            centre = self.optical_centre
            object.__setattr__(self, "optical_centre", parse_centre(centre if isinstance(centre, str)
                                                                    else ",".join(map(str, centre))))
        check_method(self.method)   # an unknown method fails here, before any file is read
        object.__setattr__(self, "transfer", str(parse_transfer(self.transfer)))

    def estimator(self) -> Callable[..., MTFResult]:
        # the estimators load SciPy and OpenCV: imported by the processes
        # that measure (imgmtf.preloads.MEASURING_MODULES), not by a batch's parent
        return get_kind(self.target).make_estimator(self.method, intervals=self.intervals, force=self.force,
                                                    transfer=self.transfer)

    def target_keywords(self, raster: Raster) -> dict:
        """What the target's estimator takes beyond the keywords every
        kind's takes (:meth:`imgmtf.kinds.Kind.estimator_keywords`).

        Parameters
        ----------
        raster : imgmtf.io.Raster
            The raster measured (a width in metres needs its GSD).

        Returns
        -------
        dict
            ``{"width_px": ...}`` for a kind with a width (None: estimated
            from the profile), nothing for an edge.

        Raises
        ------
        ParameterError
            A width in metres on a raster without a GSD.
        """
        return get_kind(self.target).estimator_keywords(pulse_width_px(self.pulse_width, raster),
                                                        point_size_px(self.point_size, raster),
                                                        gap_px(self.gap, raster))

    def params(self) -> dict:
        """The run's settings, as records carry them."""
        roi = self.roi.source if isinstance(self.roi, VectorROIs) else list(self.roi) if self.roi else None
        return {"intervals": self.intervals.as_dict(), "roi": roi,
                "band": self.band, "force": self.force,
                "saturation": list(self.saturation) if self.saturation else None,
                "track_azimuth_deg": self.track_azimuth_deg, "transfer": self.transfer,
                "pulse_width": list(self.pulse_width) if self.pulse_width else None,
                **({"point_size": list(self.point_size)} if self.point_size else {}),
                **({"gap": list(self.gap)} if self.gap else {}),
                **({"optical_centre": self.optical_centre if isinstance(self.optical_centre, str)
                    else list(self.optical_centre)} if self.optical_centre is not None else {})}

    def failed(self, path: str, band: int | str | None, exc: BaseException, run_utc: str, **fields: Any) -> Record:
        """The error record of a file (or band) that could not be measured.

        Parameters
        ----------
        path : str
            The file.
        band : int, str or None
            Its band (None: the only one, or the luminance).
        exc : BaseException
            What the measurement raised.
        run_utc : str
            The run's start, UTC, ISO 8601.
        **fields
            Other fields of the record (``site``: a vector feature's id and
            attributes).

        Returns
        -------
        Record
            An error record with these settings, the reason and message.
        """
        return Record.failed(path, band, self.target, self.method, exc, params=self.params(),
                             run_utc=run_utc, **fields)


def pulse_width_px(width: tuple[float, str] | None, raster: Raster) -> float | None:
    """A pulse width (value, unit) in pixels for this raster (metres need
    its GSD)."""
    if width is None:
        return None
    value, unit = width
    if unit == "px":
        return value
    if raster.gsd_m is None:
        raise ParameterError(f"{raster.path}: a width in metres needs a georeferenced image "
                             "(its GSD is unknown); give the width in px")
    check_width(value / raster.gsd_m)
    return value / raster.gsd_m


def point_size_px(size: tuple[float, str] | None, raster: Raster) -> float | None:
    """A point target's size (value, unit) in pixels for this raster
    (metres need its GSD), 0 to 20 px."""
    if size is None:
        return None
    value, unit = size
    if unit == "m":
        if raster.gsd_m is None:
            raise ParameterError(f"{raster.path}: a point size in metres needs a georeferenced image "
                                 "(its GSD is unknown); give the size in px")
        value = value / raster.gsd_m
    if not 0.0 <= value <= 20.0:
        raise ParameterError(f"{raster.path}: a point size of {value:g} px: it must be 0 to 20 px")
    return value


def gap_px(gap: tuple[float, str] | None, raster: Raster) -> float | None:
    """A double bar's gap (value, unit) in pixels for this raster (metres
    need its GSD)."""
    if gap is None:
        return None
    value, unit = gap
    if unit == "m":
        if raster.gsd_m is None:
            raise ParameterError(f"{raster.path}: a gap in metres needs a georeferenced image "
                                 "(its GSD is unknown); give the gap in px")
        value = value / raster.gsd_m
    return value
