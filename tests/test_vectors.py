"""ROIs from vector layers (--roi-file, roi= a layer): features written by
Fiona in EPSG:4326 over a small UTM GeoTIFF, reprojected onto it, one
measurement per feature with its attributes; the errors of a layer or
raster that cannot be matched; the Bagnolo site on the Sentinel-2 scene."""
import json

import fiona
import numpy as np
import pytest
from click.testing import CliRunner
from fiona.transform import transform_geom

import imgmtf as im
from imgmtf.cli import main
from imgmtf.io import raster_info, write_geotiff
from imgmtf.vectors import FeatureWindow, Unplaced, VectorROIs

from conftest import exact_edge_chip, gaussian_pixel_transfer, real_scene

GSD_M = 10.0
ORIGIN_M = (600000.0, 5000000.0)         # EPSG:32632, top-left corner of the scene
SCHEMA = {"geometry": "Unknown", "properties": {"name": "str", "field": "int"}}


def to_map(x_px, y_px):
    """A pixel position (x right, y down, from the top-left corner) in EPSG:32632."""
    return ORIGIN_M[0] + GSD_M * x_px, ORIGIN_M[1] - GSD_M * y_px


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """A 64 x 144 px UTM scene: an edge 6 deg off vertical in each half."""
    folder = tmp_path_factory.mktemp("vectors")
    transfer = gaussian_pixel_transfer(0.5, 6.0)
    left = exact_edge_chip(transfer, 6.0, (64, 72), noise_std=2.0, seed=1)
    right = exact_edge_chip(transfer, 6.0, (64, 72), noise_std=2.0, seed=2, low=300.0, high=1500.0)
    path = folder / "scene.tif"
    write_geotiff(path, np.hstack([left, right]), gsd_m=GSD_M, crs="EPSG:32632", origin_m=ORIGIN_M)
    return path


def write_layer(path, features, driver="GeoJSON", crs="EPSG:4326"):
    """Features (geometry in scene pixels, properties) written by Fiona, in ``crs``."""
    kinds = {kind for kind, _, _ in features}
    schema = {**SCHEMA, "geometry": kinds.pop() if len(kinds) == 1 else "Unknown"}
    with fiona.open(path, "w", driver=driver, crs=crs, schema=schema) as out:
        for kind, points, properties in features:
            mapped = [to_map(x, y) for x, y in points]
            geometry = {"type": kind, "coordinates": [mapped] if kind == "Polygon" else mapped}
            if crs:
                geometry = transform_geom("EPSG:32632", crs, geometry)
            out.write({"geometry": geometry, "properties": properties})
    return path


def box(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]


SITES = [("Polygon", box(8, 4, 64, 60), {"name": "west", "field": 7}),
         ("LineString", [(112.4, 2.0), (105.7, 62.0)], {"name": "east", "field": 8})]


def test_polygons_and_lines_are_reprojected_onto_the_raster_as_windows(scene, tmp_path):
    layer = write_layer(tmp_path / "sites.gpkg", SITES, driver="GPKG")
    windows = VectorROIs.read(layer).windows(raster_info(scene))
    assert [type(w) for w in windows] == [FeatureWindow, FeatureWindow]
    west, east = windows
    # the polygon's bounds (to a millimetre of reprojection), the line's widened by 12 px and clipped
    assert west.window == (8, 4, 56, 56) and west.attributes == {"name": "west", "field": 7}
    assert east.window == (93, 0, 32, 64) and east.shape == "line" and east.clipped


def test_measure_gives_one_record_per_feature_with_its_attributes(scene, tmp_path):
    layer = write_layer(tmp_path / "sites.geojson", SITES)
    records = im.measure_file(scene, roi=str(layer), intervals="none")
    assert [r.status for r in records] == ["ok", "ok"]
    assert [r.get("feature") for r in records] == [{"name": "west", "field": 7}, {"name": "east", "field": 8}]
    assert records[0].get("roi") == [8, 4, 56, 56]
    # the same edge response in both halves: the same MTF within the noise
    assert abs(records[0].get("mtf_nyquist") - records[1].get("mtf_nyquist")) < 0.02
    assert "clipped" in " ".join(records[1].get("warnings"))
    row = records[1].csv_row()
    assert json.loads(row["feature"]) == {"field": 8, "name": "east"} and row["feature_id"] == "1"


def test_geometries_in_python_are_windows_as_a_file_s(scene):
    geometry = transform_geom("EPSG:32632", "EPSG:4326",
                              {"type": "Polygon", "coordinates": [[to_map(x, y) for x, y in box(8, 4, 64, 60)]]})
    rois = VectorROIs.from_geometries([geometry], "EPSG:4326", attributes=[{"site": "w"}])
    [record] = im.measure_file(scene, roi=rois, intervals="none")
    assert record.get("roi") == [8, 4, 56, 56] and record.get("feature") == {"site": "w"}


def test_cli_measure_prints_each_feature_and_stores_them_as_one_acquisition(scene, tmp_path):
    layer = write_layer(tmp_path / "sites.geojson", SITES)
    store = tmp_path / "site.gpkg"
    result = CliRunner().invoke(main, ["measure", str(scene), "--roi-file", str(layer), "--intervals", "none",
                                       "--campaign", str(store), "--acquired", "2025-06-19"])
    assert result.exit_code == 0, result.output
    assert "feature 0 (x 8, y 4, 56 x 56 px): name=west, field=7" in result.output
    rows = im.read_layer(store, "edges")
    assert sorted(json.loads(r["feature"])["name"] for r in rows) == ["east", "west"]
    assert len(im.read_layer(store, "acquisitions")) == 1


def test_a_feature_outside_the_raster_is_an_error_record_the_others_go_on(scene, tmp_path):
    layer = write_layer(tmp_path / "sites.geojson", [SITES[0], ("Polygon", box(500, 500, 540, 540),
                                                                 {"name": "far", "field": 9})])
    good, far = im.measure_file(scene, roi=str(layer), intervals="none")
    assert good.ok and far.reason == "parameter"
    assert far.error.startswith(str(scene)) and "sites.geojson: feature 1 lies outside" in far.error
    assert far.get("feature") == {"name": "far", "field": 9}


@pytest.mark.parametrize("case", ["missing", "not a layer", "no CRS on the layer", "no CRS on the raster"])
def test_a_layer_or_raster_that_cannot_be_matched_is_a_one_line_error(scene, tmp_path, case):
    layer = tmp_path / "sites.geojson"
    image = scene
    if case == "not a layer":
        layer.write_text("no vector here\n")
    elif case == "no CRS on the layer":
        layer = write_layer(tmp_path / "sites.shp", SITES[:1], driver="ESRI Shapefile", crs=None)
    elif case == "no CRS on the raster":
        write_layer(layer, SITES[:1])
        image = tmp_path / "plain.png"
        im.write_png(image, exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0, (64, 64)).astype(np.uint8))
    result = CliRunner().invoke(main, ["measure", str(image), "--roi-file", str(layer)])
    assert result.exit_code == 1
    message = result.output.strip().splitlines()[-1]
    assert str(layer) in message and "Traceback" not in result.output
    assert {"missing": "no such vector file", "not a layer": "cannot read it as a vector layer",
            "no CRS on the layer": "no coordinate reference system",
            "no CRS on the raster": "the image has no coordinate reference system"}[case] in message
    if case == "no CRS on the raster":
        assert "(--roi X,Y,W,H measures a window in pixels)" in message


def test_roi_and_roi_file_together_are_a_usage_error(scene, tmp_path):
    layer = write_layer(tmp_path / "sites.geojson", SITES)
    result = CliRunner().invoke(main, ["measure", str(scene), "--roi", "0,0,64,64", "--roi-file", str(layer)])
    assert result.exit_code == 2 and "not both" in result.output
    bars = CliRunner().invoke(main, ["fit", str(scene), "--target", "pulse", "--roi-file", str(layer)])
    assert bars.exit_code == 2 and "--roi-file gives the windows of edges" in bars.output


def test_scan_measures_only_the_candidates_crossing_a_feature(scene, tmp_path):
    layer = write_layer(tmp_path / "sites.geojson", SITES[:1])
    records = im.scan_scene(str(scene), im.ScanSettings(roi=str(layer), intervals="none"))
    assert records and all(r.site["feature"] == {"name": "west", "field": 7} for r in records)
    assert all(r.site["x0_px"] < 72 for r in records)     # the east half's edge is left out
    assert any(r.ok for r in records)


def test_fit_measures_each_file_in_each_feature_s_window(scene, tmp_path):
    layer = write_layer(tmp_path / "sites.geojson", SITES)
    result = CliRunner().invoke(main, ["fit", str(scene), "--roi-file", str(layer), "--stages", "optics,detector",
                                       "--format", "json"])
    assert result.exit_code == 0, result.output
    edges = json.loads(result.output)["edges"]
    assert [e["feature"]["name"] for e in edges] == ["west", "east"]
    assert edges[0]["path"] == f"{scene}[8,4,56,56]"


def test_unplaced_features_say_why(scene):
    point = VectorROIs.from_geometries([{"type": "Point", "coordinates": to_map(10, 10)}], "EPSG:32632")
    [unplaced] = point.windows(raster_info(scene))
    assert isinstance(unplaced, Unplaced) and "is a Point" in str(unplaced.error)


def test_the_bagnolo_site_drives_measure_and_scan_on_the_sentinel2_scene(tmp_path):
    """Sentinel-2 B04 over Bagnolo (EPSG:32632) and the site's shapefile (EPSG:4326), from
    rdegoul/qgis-image-quality-toolset test/data/target1 (Apache-2.0)."""
    image = real_scene("sentinel2_b04_bagnolo.tif", "rdegoul/qgis-image-quality-toolset")
    layer = image.parent / "bagnolo_roi" / "mtf_al_bagnolo.shp"
    [record] = im.measure_file(image, roi=str(layer))
    # the polygon lands where the source's configuration puts its ROI (x 155, y 480, 29 x 34 px)
    assert record.get("roi") is None and record.get("feature_id") == "0" and record.get("feature") == {"id": None}
    assert record.params["roi"] == str(layer)
    [window] = VectorROIs.read(layer).windows(raster_info(image))
    assert window.window == (155, 480, 29, 34)
    # the field's two sides are not uniform (the dark one drifts by half the contrast)
    assert record.reason == "non-uniform"
    scanned = im.scan_scene(str(image), im.ScanSettings(roi=str(layer)))
    assert [(r.site["feature_id"], r.reason) for r in scanned] == [("0", "two-targets")]
