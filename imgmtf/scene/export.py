"""Outputs of a scan: CSV, GeoJSON and the overview figure."""
from __future__ import annotations

import json
from pathlib import Path

from ..atomic import atomic_output, ensure_folder
from ..batch import save_figure
from ..errors import FileWriteError
from ..io import RasterInfo, read_raster
from ..records import SCAN_CSV_COLUMNS, Record, json_safe, write_csv
from ..version import __version__
from .detect import _display_levels


def to_geojson(records: list[Record], info: RasterInfo) -> dict:
    """The candidates as a GeoJSON FeatureCollection of LineStrings.

    Georeferenced scenes (a CRS): geometry in longitude/latitude (WGS 84,
    as RFC 7946 requires), the scene's own map coordinates in the
    properties (``map_x0``...).  Scenes without a CRS: geometry in pixel
    coordinates (x right, y down; the ``imgmtf_coordinates`` member says
    so).  Every feature's properties carry the pixel coordinates and the
    record's figures."""
    rows = [r.to_dict() for r in records]
    if info.crs:
        from rasterio.warp import transform as warp
        xs = [v for r in rows for v in (r["map_x0"], r["map_x1"])]
        ys = [v for r in rows for v in (r["map_y0"], r["map_y1"])]
        lon, lat = warp(info.crs, "EPSG:4326", xs, ys) if xs else ([], [])
        lines = [[[lon[2 * i], lat[2 * i]], [lon[2 * i + 1], lat[2 * i + 1]]] for i in range(len(rows))]
        coordinates = "longitude/latitude (EPSG:4326)"
    else:
        lines = [[[r["x0_px"], r["y0_px"]], [r["x1_px"], r["y1_px"]]] for r in rows]
        coordinates = "pixel (x right, y down, pixel centres at integers)"
    features = [{"type": "Feature", "id": r["id"],
                 "geometry": {"type": "LineString", "coordinates": line},
                 "properties": {k: v for k, v in r.items() if k not in ("frequencies_cy_px", "mtf")}}
                for r, line in zip(rows, lines)]
    return {"type": "FeatureCollection", "imgmtf_coordinates": coordinates,
            "imgmtf_source": info.path, "imgmtf_version": __version__, "features": features}


def write_outputs(records: list[Record], info: RasterInfo, out_dir: str, overview_band=None) -> list[str]:
    """CSV, GeoJSON and overview PNG of a scan in ``out_dir`` (each written
    atomically); their paths."""
    from ..plot import plot_scan
    out = ensure_folder(out_dir)
    csv_path, json_path, png_path = (str(out / n) for n in ("targets.csv", "targets.geojson", "overview.png"))
    write_csv(records, csv_path, SCAN_CSV_COLUMNS)
    with atomic_output(json_path) as partial:
        try:
            Path(partial).write_text(json.dumps(json_safe(to_geojson(records, info)), indent=1))
        except OSError as exc:
            raise FileWriteError(f"{json_path}: cannot write: {exc.strerror or exc}") from None
    scale = max(max(info.width, info.height) / 1500, 1.0)
    shape = (max(int(info.height / scale), 1), max(int(info.width / scale), 1))
    overview = read_raster(info.path, overview_band, out_shape=shape).data
    levels = _display_levels(info.path, overview_band, info)
    rows = [r.to_dict() for r in records]
    save_figure(lambda: plot_scan(overview, info.width / shape[1], rows, levels), png_path)
    return [csv_path, json_path, png_path]
