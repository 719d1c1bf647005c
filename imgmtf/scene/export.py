"""Outputs of a scan: CSV, GeoJSON and the overview figure.

``targets.csv`` holds every candidate (``scope`` "edge"), then the
per-target and per-scene summaries (``scope`` "target", "scene"), in the
schema :data:`imgmtf.records.SCAN_CSV_COLUMNS`; ``targets.geojson`` the
same records as features (a candidate a LineString, a point array or a
target a Point at its centre, the scene's summaries without geometry); ``overview.png`` the
scene with its targets (:func:`imgmtf.plot.plot_scan`).
"""
from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from ..atomic import atomic_output, ensure_folder
from ..errors import FileWriteError
from ..figures import save_figure
from ..io import RasterInfo, read_raster
from ..records import CANDIDATE_SCOPE, SCAN_CSV_COLUMNS, Record, json_safe, write_csv
from ..version import __version__
from .detect import display_levels

OVERVIEW_MAX_PX = 1024          # the overview is read decimated to at most this many px a side (the figure's own)
_CURVES = ("frequencies_cy_px", "mtf")


def to_geojson(records: Sequence[Record], info: RasterInfo, summaries: Sequence[Record] = ()) -> dict:
    """The candidates and summaries of a scan as a GeoJSON FeatureCollection.

    A candidate is a LineString along its segment, a target's summary a
    Point at the target's centre, a scene's summary a feature without
    geometry.  Georeferenced scenes (a CRS): geometry in
    longitude/latitude (WGS 84, as RFC 7946 requires), the scene's own map
    coordinates in the properties (``map_x0``...).  Scenes without a CRS:
    no geometry (a GIS would read pixel coordinates as degrees; the
    ``imgmtf_coordinates`` member says so).  Every feature's properties
    carry the pixel coordinates and the record's figures.

    Examples
    --------
    >>> geo = to_geojson(records, raster_info("scene.tif"), summarise_scan(records))   # doctest: +SKIP
    >>> geo["features"][0]["geometry"]["type"]                                      # doctest: +SKIP
    'LineString'
    """
    rows = [r.to_dict() for r in (*records, *summaries)]
    pixels = [_points(r) for r in rows]
    points: list[list[list[float]]]
    if info.crs:
        from rasterio.warp import transform as warp
        flat = [info.transform @ (x + 0.5, y + 0.5) for p in pixels for x, y in p]
        lon, lat = warp(info.crs, "EPSG:4326", [x for x, _ in flat], [y for _, y in flat]) if flat else ([], [])
        coordinates = "longitude/latitude (EPSG:4326)"
        lonlat = iter(zip(lon, lat))
        points = [[list(next(lonlat)) for _ in p] for p in pixels]
    else:           # RFC 7946 geometry is longitude/latitude: pixels there would be misplaced
        coordinates = "none: the scene has no CRS; pixel coordinates (x right, y down) are in the properties"
        points = [[] for _ in pixels]
    features = [{"type": "Feature", "id": r.get("id") if r.get("scope") == CANDIDATE_SCOPE else f"{r['scope']}-{k}",
                 "geometry": _geometry(p),
                 "properties": {key: value for key, value in r.items() if key not in _CURVES}}
                for k, (r, p) in enumerate(zip(rows, points))]
    return {"type": "FeatureCollection", "imgmtf_coordinates": coordinates,
            "imgmtf_source": info.path, "imgmtf_version": __version__, "features": features}


def _points(row: dict) -> list[tuple[float, float]]:
    """A record's points (pixel x, y): a segment's ends, a target's centre, or none."""
    if "x0_px" in row:
        return [(row["x0_px"], row["y0_px"]), (row["x1_px"], row["y1_px"])]
    if "x_px" in row:
        return [(row["x_px"], row["y_px"])]
    return []


def _geometry(points: list) -> dict | None:
    if len(points) == 2:
        return {"type": "LineString", "coordinates": points}
    if len(points) == 1:
        return {"type": "Point", "coordinates": points[0]}
    return None


def write_outputs(records: Sequence[Record], info: RasterInfo, out_dir: str, overview_band: int | None = None,
                  summaries: Sequence[Record] = ()) -> list[str]:
    """``targets.csv``, ``targets.geojson`` and ``overview.png`` of a scan
    in ``out_dir`` (each written atomically); their paths.

    Raises
    ------
    FileWriteError
        An output cannot be written.
    """
    from ..plot import plot_point_scan, plot_scan
    out = ensure_folder(out_dir)
    csv_path, json_path, png_path = (str(out / n) for n in ("targets.csv", "targets.geojson", "overview.png"))
    write_csv([*records, *summaries], csv_path, SCAN_CSV_COLUMNS)
    with atomic_output(json_path) as partial:
        try:
            Path(partial).write_text(json.dumps(json_safe(to_geojson(records, info, summaries)), indent=1))
        except OSError as exc:
            raise FileWriteError(f"{json_path}: cannot write: {exc.strerror or exc}") from None
    scale = max(max(info.width, info.height) / OVERVIEW_MAX_PX, 1.0)
    shape = (max(int(info.height / scale), 1), max(int(info.width / scale), 1))
    overview = read_raster(info.path, overview_band, out_shape=shape).data
    levels = display_levels(info.path, overview_band, info)
    rows, summary_rows = [r.to_dict() for r in records], [r.to_dict() for r in summaries]
    # candidates without a segment are point arrays (imgmtf.scene.points): drawn as their ROIs
    draw = plot_scan if not rows or any("x0_px" in r for r in rows) else plot_point_scan
    save_figure(lambda: draw(overview, info.width / shape[1], rows, summary_rows, levels), png_path)
    return [csv_path, json_path, png_path]
