"""Point arrays found in a whole scene, measured and stored: ``imgmtf scan
--target points`` (imgmtf.scene.points), against the exact renderer's truth."""
import json

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner

import imgmtf as im
from imgmtf.campaign.recommended import mark_recommended
from imgmtf.campaign.store import read_layer
from imgmtf.cli.main import main
from imgmtf.errors import ParameterError
from imgmtf.scene.points import scan_point_arrays
from imgmtf.scene.settings import ScanSettings
from imgmtf.sensor.points import PointArray, render_points
from imgmtf.sensor.scenes import QuadrantTarget, render_quadrants, texture
from imgmtf.sensor.stages import Detector, GaussianOptics

SENSOR = im.Sensor(stages=[GaussianOptics(0.45, 0.55), Detector(1.0, 1.0)])
ARRAY = PointArray(4, 4, spacing_px=12.0, low_dn=0.0, high_dn=3000.0)
TRUTH = {d: float(render_points(SENSOR, ARRAY, 60, bits=None).true_mtf(0.5, d.split("-")[0]))
         for d in ("across-track", "along-track")}


def write(path, image):
    with rasterio.open(path, "w", driver="GTiff", width=image.shape[1], height=image.shape[0], count=1,
                       dtype="uint16") as out:
        out.write(np.clip(np.rint(image), 0, 65535).astype("uint16"), 1)
    return str(path)


@pytest.fixture(scope="module")
def field_scene(tmp_path_factory):
    """A textured field holding a bright array, a dark one, a bar and a lone point."""
    image = 1000.0 + texture((140, 220), 10.0, seed=3)
    image[10:70, 10:70] += render_points(SENSOR, ARRAY, 60, bits=None).image
    dark = PointArray(4, 4, spacing_px=12.0, low_dn=0.0, high_dn=-1500.0)
    image[70:130, 150:210] += render_points(SENSOR, dark, 60, bits=None).image
    image[100:102, 20:120] += 600.0                   # a bar: compact nowhere along it
    image[30, 150] += 900.0                           # a lone point: no array
    return write(tmp_path_factory.mktemp("points") / "field.tif", np.random.default_rng(0).normal(image, 4.0))


def test_arrays_on_a_textured_field_are_found_and_measured_within_their_intervals(field_scene):
    records, summaries = scan_point_arrays(field_scene, ScanSettings("points"))
    assert {(r.site["target_id"], r.site["polarity"], r.status) for r in records} == {
        (1, "bright", "accepted"), (2, "dark", "accepted")}
    assert all(r.site["points_found"] == 16 and r.figures["points_used"] == 16 for r in records)
    for r in records:       # each target in the scene's pixels, the used ones about the peaks the scan grouped
        xy = np.array([(t["x_px"], t["y_px"]) for t in r.site["point_targets"] if t["status"] == "used"])
        assert len(xy) == 16 and len(r.site["point_targets"]) == 16 + r.figures["points_refused"]
        assert np.allclose(xy.mean(axis=0), (r.site["x_px"], r.site["y_px"]), atol=0.5)
    covered = 0
    for r in records:
        truth = TRUTH[r.figures["direction"]]
        low, high = r.figures["mtf_nyquist_ci"]
        assert abs(r.figures["mtf_nyquist"] - truth) < 0.02, r                # 2.5 sd at these SNRs
        covered += low <= truth <= high
        assert r.target == r.method == "points" and r.site["scope"] == "edge"
    assert covered >= 3                                 # 95 % intervals, which cover about 9 rows in 10 here
    assert sorted(r.site["id"] for r in records) == [1, 2, 3, 4]
    for s in summaries:                               # the scene's row per direction: both arrays combined
        assert s.figures["summary"] == "points" and s.figures["n_arrays"] == 2 and s.site == {"scope": "scene"}
        assert abs(s.figures["mtf_nyquist"] - TRUTH[s.figures["direction"]]) < 0.015


def test_points_apart_by_more_than_the_spacing_asked_for_are_no_array(field_scene):
    records, _ = scan_point_arrays(field_scene, ScanSettings("points", point_spacing_px=8.0))
    assert records == []
    with pytest.raises(ParameterError, match="point_spacing_px"):
        ScanSettings("points", point_spacing_px=1.0)


def test_a_campaign_scene_point_array_settles_the_edges_across_along_choice(tmp_path):
    """Edges of a tilted four-quadrant target beside a point array, in one
    image scanned twice into one store: the array's direct across/along
    rows are quoted for the points' acquisition and confirm the edges'."""
    scene = render_quadrants(SENSOR, (120, 200), QuadrantTarget((60.0, 60.0), angle_deg=12.0, half_size_px=40.0,
                                                               levels_dn=(1000.0, 3000.0, 1000.0, 3000.0)),
                             field_dn=2000.0)
    image = scene.image.astype(float)
    image[30:90, 130:190] += render_points(SENSOR, PointArray(4, 4, 12.0, low_dn=0.0, high_dn=6000.0), 60,
                                           bits=None).image
    path = write(tmp_path / "mixed.tif", np.random.default_rng(1).normal(image, 4.0))
    store, out = str(tmp_path / "site.gpkg"), tmp_path / "out"
    runner = CliRunner()
    edges = runner.invoke(main, ["scan", path, "--fit-stages", "none", "--campaign", store, "--acquired",
                                 "2024-01-01"])
    assert edges.exit_code == 0, edges.output
    points = runner.invoke(main, ["scan", "--target", "points", path, "--campaign", store, "--acquired",
                                  "2024-01-01", "--format", "json", "--out", str(out)])
    assert points.exit_code == 0, points.output
    rows = [json.loads(line) for line in points.stdout.splitlines()]
    assert [(r["scope"], r["direction"], r["method"]) for r in rows if r["scope"] == "scene"] == [
        ("scene", "horizontal", "points"), ("scene", "vertical", "points")]
    assert {p.name for p in out.iterdir()} == {"targets.csv", "targets.geojson", "overview.png"}
    marked = [r for r in mark_recommended(read_layer(store, "targets"))
              if r["scope"] == "scene" and r["direction"] == "horizontal" and r["recommended"]]
    assert {r["method"] for r in marked} == {"points", "sections"}
    quoted_points = next(r for r in marked if r["method"] == "points")
    quoted_edges = next(r for r in marked if r["method"] == "sections")
    assert quoted_edges["recommended_because"].endswith("the point array's MTF at Nyquist "
                                                        f"{quoted_points['mtf_nyquist']:.3f} "
                                                        f"[{quoted_points['mtf_nyquist_ci_low']:.3f}, "
                                                        f"{quoted_points['mtf_nyquist_ci_high']:.3f}] agrees")
    assert abs(quoted_points["mtf_nyquist"] - TRUTH["across-track"]) < 0.01
    edge_rows = read_layer(store, "edges")
    assert sum(r["target"] == "points" for r in edge_rows) == 2          # the array, across and along


def test_a_rejected_array_tells_the_scans_peaks_from_the_features_measured(capsys):
    from types import SimpleNamespace

    from imgmtf.cli.point_tables import print_point_scan
    from imgmtf.errors import ImageContentError
    from imgmtf.records import Record
    error = ImageContentError("s.tif: the array at (10, 20) has 3 usable targets of the 21 features found in its "
                              "window (18 faint); an array needs 4", reason="few-points")
    record = Record.failed("s.tif", 1, "points", "points", error, params={}, run_utc="2026-01-01T00:00:00Z",
                           status="rejected", site={"target_id": 1, "x_px": 10.0, "y_px": 20.0, "points_found": 4})
    print_point_scan("s.tif", SimpleNamespace(width=64, height=64), [record], [], [], "text")
    line = capsys.readouterr().out.splitlines()[-1]
    assert "grouped from 4 peaks the scan found" in line and "4 points found" not in line


def test_a_run_of_several_scenes_counts_those_with_a_point_array(tmp_path):
    array = render_points(SENSOR, ARRAY, 60, bits=None).image + 100.0
    paths = [write(tmp_path / f"array{i}.tif", np.random.default_rng(i).normal(array, 2.0)) for i in (1, 2)]
    result = CliRunner().invoke(main, ["scan", "--target", "points", *paths, "--format", "json", "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert "2 of 2 scenes scanned: 2 with a usable point array, 0 without or failed" in result.stderr
