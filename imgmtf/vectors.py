"""ROIs from vector layers: the polygons or lines of a GIS layer (any vector
format GDAL reads, through Fiona: a shapefile, GeoJSON, GeoPackage, KML...)
reprojected onto a raster and turned into pixel windows, one per feature,
each carrying the feature's attributes into its records.

A polygon's window is its bounding box in the raster's pixels; a line's
(the edge itself, drawn along it) is its bounding box widened by
``line_buffer_px`` on every side.  Windows are (x, y, width, height) in
the raster's pixels, x right and y down from its top-left corner, as
``--roi`` takes them.

Examples
--------
>>> import imgmtf
>>> from imgmtf.vectors import VectorROIs
>>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 64, gsd_m=10.0)
>>> imgmtf.write_geotiff("chip.tif", chip.image, gsd_m=10.0, crs="EPSG:32632", origin_m=(500000.0, 5000000.0))
>>> square = {"type": "Polygon", "coordinates": [[(500100.0, 4999900.0), (500500.0, 4999900.0),
...                                               (500500.0, 4999500.0), (500100.0, 4999500.0)]]}
>>> rois = VectorROIs.from_geometries([square], "EPSG:32632", attributes=[{"site": "field 7"}])
>>> from imgmtf.io import raster_info
>>> [(w.window, w.attributes) for w in rois.windows(raster_info("chip.tif"))]
[((10, 10, 40, 40), {'site': 'field 7'})]
"""
from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from .errors import ImageReadError, ImgmtfError, ParameterError
from .inputs import MIN_SIZE_PX

if TYPE_CHECKING:
    from .io import RasterInfo

#: a line feature's window reaches this far either side of the line, px (as scan's --margin default)
LINE_BUFFER_PX = 12.0
POLYGONS = ("Polygon", "MultiPolygon")
LINES = ("LineString", "MultiLineString")


@dataclass(frozen=True)
class Feature:
    """One feature of a layer: its id, geometry (GeoJSON-like, in the
    layer's CRS) and attributes."""

    fid: str
    geometry: Mapping[str, Any]
    attributes: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class FeatureWindow:
    """A feature's pixel window on one raster.

    Attributes
    ----------
    fid : str
        The feature's id in its layer.
    attributes : dict
        Its attributes (the layer's fields).
    window : (int, int, int, int)
        (x, y, width, height) in the raster's pixels, clipped to it.
    outline_px : tuple of (float, float)
        Its geometry's vertices in the raster's pixels (x right, y down).
    shape : str
        ``"polygon"`` or ``"line"``.
    clipped : bool
        True when part of the feature lies beyond the raster.
    source : str
        The layer it came from (a file, or ``"geometries"``).
    """

    fid: str
    attributes: Mapping[str, Any]
    window: tuple[int, int, int, int]
    outline_px: tuple[tuple[float, float], ...]
    shape: str
    clipped: bool = False
    source: str = ""

    def record_fields(self) -> dict[str, Any]:
        """What its records carry: ``feature_id``, ``feature`` (the
        attributes) and ``feature_window_px`` (x, y, w, h on the raster)."""
        return {"feature_id": self.fid, "feature": dict(self.attributes), "feature_window_px": list(self.window)}

    def notes(self) -> list[str]:
        """Warnings its measurement carries (a window clipped to the raster)."""
        if not self.clipped:
            return []
        return [f"{self.source}: feature {self.fid} extends beyond the raster: its window is clipped to "
                f"x {self.window[0]}, y {self.window[1]}, {self.window[2]} x {self.window[3]} px"]


@dataclass(frozen=True)
class Unplaced:
    """A feature that has no window on a raster, and why (``error``: it
    lies outside the raster, covers too few of its pixels, or is neither a
    polygon nor a line)."""

    fid: str
    attributes: Mapping[str, Any]
    error: ImgmtfError

    def record_fields(self) -> dict[str, Any]:
        """What its error record carries: ``feature_id`` and ``feature``."""
        return {"feature_id": self.fid, "feature": dict(self.attributes)}


@dataclass(frozen=True)
class VectorROIs:
    """The features of a vector layer, to be measured one window each.

    Parameters
    ----------
    source : str
        The file the layer came from (named in every message), or
        ``"geometries"``.
    crs : str
        The layer's coordinate reference system (WKT, ``"EPSG:4326"``...).
    features : tuple of Feature
        Its polygons and lines.
    line_buffer_px : float, optional
        How far a line feature's window reaches either side of it, px.

    Raises
    ------
    ParameterError
        No CRS, no features, or a buffer out of range.

    Examples
    --------
    >>> rois = VectorROIs.from_geometries([{"type": "LineString", "coordinates": [(0.0, 0.0), (1.0, 1.0)]}],
    ...                                   "EPSG:4326")
    >>> len(rois.features), rois.crs
    (1, 'EPSG:4326')
    """

    source: str
    crs: str | None
    features: tuple[Feature, ...]
    line_buffer_px: float = LINE_BUFFER_PX

    def __post_init__(self):
        object.__setattr__(self, "features", tuple(self.features))
        if not self.crs:
            raise ParameterError(f"{self.source}: the layer has no coordinate reference system: it cannot be "
                                 "placed on a raster (give the layer a CRS, e.g. a .prj beside a shapefile)")
        if not self.features:
            raise ParameterError(f"{self.source}: the layer holds no features")
        if not (math.isfinite(self.line_buffer_px) and 1.0 <= self.line_buffer_px <= 1000.0):
            raise ParameterError(f"a line's buffer must be 1 to 1000 px, got {self.line_buffer_px!r}")

    @classmethod
    def read(cls, path: str | os.PathLike, layer: str | int | None = None, *,
             line_buffer_px: float = LINE_BUFFER_PX) -> VectorROIs:
        """The features of a vector file (any format GDAL reads).

        Parameters
        ----------
        path : str or os.PathLike
            The file (``.shp``, ``.geojson``, ``.gpkg``, ``.kml``...).
        layer : str or int, optional
            The layer of a file holding several (default: its only one).
        line_buffer_px : float, optional
            How far a line's window reaches either side of it, px.

        Returns
        -------
        VectorROIs
            Its features in the layer's CRS.

        Raises
        ------
        ImageReadError
            The file is missing or not a vector layer GDAL reads.
        ParameterError
            Several layers and none named, no CRS, or no features.
        """
        import fiona
        from fiona.errors import FionaError

        source = os.fspath(path)
        if not os.path.exists(source):
            raise ImageReadError(f"{source}: no such vector file")
        try:
            if layer is None:
                layers = fiona.listlayers(source)
                if len(layers) > 1:
                    raise ParameterError(f"{source}: holds {len(layers)} layers ({', '.join(layers)}): name "
                                         "the one whose features are the ROIs")
            with fiona.open(source, layer=layer) as collection:
                crs = collection.crs.to_wkt() if collection.crs else None
                features = tuple(Feature(str(f.id), _plain(f.geometry), dict(f.properties or {}))
                                 for f in collection)
        except (FionaError, OSError, ValueError) as exc:
            if isinstance(exc, ImgmtfError):
                raise
            detail = " ".join(str(exc).split()) or type(exc).__name__
            raise ImageReadError(f"{source}: cannot read it as a vector layer: {detail}") from None
        return cls(source, crs, features, line_buffer_px)

    @classmethod
    def from_geometries(cls, geometries: Iterable[Mapping[str, Any]], crs: str, *,
                        attributes: Sequence[Mapping[str, Any]] | None = None,
                        line_buffer_px: float = LINE_BUFFER_PX) -> VectorROIs:
        """Features from GeoJSON-like geometries (``{"type": "Polygon",
        "coordinates": ...}``, or objects with ``__geo_interface__``) in
        ``crs``, numbered from 0.

        Parameters
        ----------
        geometries : iterable of mapping
            Polygons, lines (and their multi- forms), GeoJSON-like.
        crs : str
            Their coordinate reference system (``"EPSG:4326"``, WKT...).
        attributes : sequence of mapping, optional
            One mapping per geometry (default: none).
        line_buffer_px : float, optional
            How far a line's window reaches either side of it, px.

        Returns
        -------
        VectorROIs
            The features, source ``"geometries"``.

        Raises
        ------
        ParameterError
            No CRS, no geometries, or attributes of another length.
        """
        shapes = [_plain(getattr(g, "__geo_interface__", g)) for g in geometries]
        attributes = list(attributes) if attributes is not None else [{} for _ in shapes]
        if len(attributes) != len(shapes):
            raise ParameterError(f"{len(attributes)} attribute mappings for {len(shapes)} geometries")
        return cls("geometries", crs, tuple(Feature(str(i), g, dict(a))
                                            for i, (g, a) in enumerate(zip(shapes, attributes))), line_buffer_px)

    def windows(self, info: RasterInfo) -> list[FeatureWindow | Unplaced]:
        """Each feature's window on a raster, or why it has none.

        Parameters
        ----------
        info : imgmtf.io.RasterInfo
            The raster's header (:func:`imgmtf.io.raster_info`).

        Returns
        -------
        list of FeatureWindow or Unplaced
            In the layer's order: the window, or (:class:`Unplaced`) why a
            feature has none: it lies outside the raster, covers too few of
            its pixels, or is neither a polygon nor a line.

        Raises
        ------
        ParameterError
            The raster has no CRS: the layer cannot be placed on it
            (reason ``no-crs``).
        """
        if not info.crs:
            raise ParameterError(f"{info.path}: the image has no coordinate reference system, so the features "
                                 f"of {self.source} cannot be placed on it", reason="no-crs")
        from rasterio.warp import transform_geom
        to_pixels = ~info.transform
        out: list[FeatureWindow | Unplaced] = []
        for feature in self.features:
            kind = feature.geometry.get("type")
            if kind not in POLYGONS + LINES:
                out.append(Unplaced(feature.fid, dict(feature.attributes), ParameterError(
                    f"{self.source}: feature {feature.fid} is a {kind or 'null geometry'}; a window is made "
                    "from a polygon or a line")))
                continue
            projected = transform_geom(self.crs, info.crs, feature.geometry)
            points = [to_pixels @ (float(p[0]), float(p[1])) for p in _vertices(projected)]
            out.append(self._window(feature, points, "polygon" if kind in POLYGONS else "line", info))
        return out

    def _window(self, feature: Feature, points, shape: str, info: RasterInfo) -> FeatureWindow | Unplaced:
        """One feature's window (its bounds, a line's widened), clipped to
        the raster, or the error of one that lies outside it."""
        xs, ys = [p[0] for p in points], [p[1] for p in points]
        pad = self.line_buffer_px if shape == "line" else 0.0
        x0, y0 = math.floor(min(xs) - pad), math.floor(min(ys) - pad)
        x1, y1 = math.ceil(max(xs) + pad), math.ceil(max(ys) + pad)
        cx0, cy0, cx1, cy1 = max(x0, 0), max(y0, 0), min(x1, info.width), min(y1, info.height)
        where = f"{self.source}: feature {feature.fid}"
        if cx1 <= cx0 or cy1 <= cy0:
            return Unplaced(feature.fid, dict(feature.attributes), ParameterError(
                f"{where} lies outside {info.path} (at x {x0} to {x1}, y {y0} to {y1} px of its "
                f"{info.width} x {info.height})"))
        if cx1 - cx0 < MIN_SIZE_PX or cy1 - cy0 < MIN_SIZE_PX:
            return Unplaced(feature.fid, dict(feature.attributes), ParameterError(
                f"{where} covers {cx1 - cx0} x {cy1 - cy0} px of {info.path}; a chip needs at least "
                f"{MIN_SIZE_PX} x {MIN_SIZE_PX}"))
        clipped = (cx0, cy0, cx1, cy1) != (x0, y0, x1, y1)
        return FeatureWindow(feature.fid, dict(feature.attributes), (cx0, cy0, cx1 - cx0, cy1 - cy0),
                             tuple((round(x, 3), round(y, 3)) for x, y in points), shape, clipped, self.source)


def as_rois(roi: Any) -> Any:
    """``roi`` as measuring settings take it: a vector file's path read as
    :class:`VectorROIs`, a VectorROIs kept, anything else (a pixel window,
    None) returned as it is."""
    if isinstance(roi, (str, os.PathLike)):
        return VectorROIs.read(roi)
    return roi


def _plain(geometry) -> dict[str, Any]:
    """A geometry as a plain GeoJSON-like dict (Fiona's are objects): picklable
    for the workers, and JSON-able."""
    if geometry is None:
        return {"type": None, "coordinates": []}
    if hasattr(geometry, "__geo_interface__"):
        geometry = geometry.__geo_interface__
    return {"type": geometry.get("type"), "coordinates": _lists(geometry.get("coordinates", []))}


def _lists(value):
    if isinstance(value, (list, tuple)):
        return [_lists(v) for v in value]
    return value


def _vertices(geometry: Mapping[str, Any]) -> list[Sequence[float]]:
    """Every vertex of a (multi)polygon or (multi)line, flattened."""
    out: list[Sequence[float]] = []

    def walk(value):
        if value and isinstance(value[0], (int, float)):
            out.append(value)
        else:
            for v in value:
                walk(v)
    walk(geometry["coordinates"])
    return out
