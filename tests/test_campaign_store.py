"""The campaign store: a GeoPackage GDAL reads back, rows replaced per
acquisition in one transaction, concurrent writers losing nothing."""
import multiprocessing
import sqlite3
from pathlib import Path

import fiona
import numpy as np
import pytest

from imgmtf.campaign.acquisitions import read_acquisition
from imgmtf.campaign.store import (
    SCHEMA,
    SCHEMA_VERSION,
    StoreError,
    read_layer,
    schema_version,
    write_acquisition,
)
from imgmtf.errors import FileWriteError, ParameterError
from imgmtf.io import write_geotiff
from imgmtf.records import Record


def half_edge(edge_id, target_id, normal, nyquist=0.2):
    return Record("scene.tif", 1, "edge", "ESF", "accepted",
                  figures={"direction": "across-track", "normal_angle_deg": normal, "mtf_nyquist": nyquist,
                           "mtf_nyquist_ci": [nyquist - 0.01, nyquist + 0.01], "mtf50_cy_px": 0.3,
                           "mtf50_ci_cy_px": [0.29, 0.31], "fwhm_px": 1.5, "rer": 0.6, "snr": 80.0,
                           "rows_used": 40},
                  site={"id": edge_id, "scope": "edge", "target_id": target_id,
                        "x0_px": 2.0, "y0_px": 3.0, "x1_px": 12.0, "y1_px": 3.0})


def summary(scope, direction, method=None, target_id=None, nyquist=0.21):
    figures = {"direction": direction, "normal_angle_deg": 0.0 if direction == "across-track" else 90.0,
               "mtf_nyquist": nyquist, "mtf_nyquist_ci": [nyquist - 0.01, nyquist + 0.01],
               "mtf50_cy_px": 0.31, "mtf50_ci_cy_px": [None, None], "fwhm_px": 1.4, "rer": float("nan"),
               "n_edges": 2, "edge_ids": ["e1", "e2"], "consistency": 0.8}
    if method:
        figures["summary"] = method
    site = {"scope": scope, **({"target_id": target_id, "x_px": 7.0, "y_px": 3.0} if target_id is not None else {})}
    return Record("scene.tif", 1, "edge", "ESF", "combined", figures=figures, site=site)


@pytest.fixture
def acquisition(tmp_path):
    path = tmp_path / "LC09_L1TP_181040_20211121_20211122_02_T1_B8.TIF"
    write_geotiff(path, np.full((16, 16), 500, np.uint16), gsd_m=15.0)
    return read_acquisition(path, band=1, settings={"method": "ESF"})


def rows(store, layer):
    """The rows as GDAL reads them, straight through Fiona."""
    with fiona.open(store, layer=layer) as features:
        return [dict(f.properties) for f in features]


def test_a_store_is_a_geopackage_gdal_reads(tmp_path, acquisition):
    store = tmp_path / "site.gpkg"
    edges = [half_edge("e1", 0, 0.0), half_edge("e2", 0, 1.0, 0.22)]
    targets = [summary("target", "across-track", target_id=0), summary("scene", "along-track", "fit")]
    write_acquisition(store, acquisition, edges, targets)
    assert fiona.listlayers(store) == ["acquisitions", "edges", "targets", "store_info"] or \
        set(fiona.listlayers(store)) == {"acquisitions", "edges", "targets", "store_info"}
    with fiona.open(store, layer="edges") as layer:
        assert layer.driver == "GPKG" and layer.crs.to_epsg() == 4326
        assert set(SCHEMA["edges"]) <= set(layer.schema["properties"])
    [acq] = rows(store, "acquisitions")
    assert acq["acquisition_id"] == acquisition.acquisition_id and acq["platform"] == "Landsat 9"
    assert acq["acquired_utc"] == "2021-11-21" and acq["gsd_m"] == 15.0 and acq["sha256"] == acquisition.sha256
    assert '"method": "ESF"' in acq["settings"] and acq["imgmtf_version"] and acq["run_utc"]
    got = rows(store, "edges")
    assert [(r["edge_id"], r["mtf_nyquist"], r["mtf_nyquist_ci_high"]) for r in got] == [
        ("e1", 0.2, pytest.approx(0.21)), ("e2", 0.22, pytest.approx(0.23))]
    assert got[0]["resampling"] == "ESF" and got[0]["band_name"] == "B8" and got[0]["rows_used"] == 40
    by_method = {r["method"]: r for r in rows(store, "targets")}
    assert set(by_method) == {"combined", "fit"}
    fit = by_method["fit"]
    assert (fit["scope"], fit["direction"], fit["target_id"], fit["rer"], fit["mtf50_ci_low_cy_px"]) == (
        "scene", "along-track", None, None, None)
    assert by_method["combined"]["target_id"] == 0 and by_method["combined"]["n_edges"] == 2
    assert read_layer(store, "targets")[0].keys() >= set(SCHEMA["targets"])
    assert schema_version(store) == SCHEMA_VERSION


def test_readding_an_acquisition_replaces_its_rows(tmp_path, acquisition):
    store = tmp_path / "site.gpkg"
    write_acquisition(store, acquisition, [half_edge("e1", 0, 0.0)] * 3, [summary("scene", "across-track")])
    write_acquisition(store, acquisition, [half_edge("e1", 0, 0.0, 0.25)], [summary("scene", "across-track")])
    assert [r["mtf_nyquist"] for r in rows(store, "edges")] == [0.25]
    assert len(rows(store, "acquisitions")) == 1 and len(rows(store, "targets")) == 1
    other = read_acquisition(acquisition.path, band=1, settings={"method": "LSF"})
    write_acquisition(store, other, [half_edge("e1", 0, 0.0)], [])
    assert len(rows(store, "acquisitions")) == 2 and len(rows(store, "edges")) == 2
    with fiona.open(store, layer="edges") as layer:       # GDAL's own count, kept by the GeoPackage's triggers
        assert len(layer) == 2


def test_georeferenced_rows_are_placed_in_longitude_latitude(tmp_path):
    path = tmp_path / "geo.tif"          # a geographic grid: pixel -> longitude/latitude is the geotransform
    write_geotiff(path, np.full((16, 16), 500, np.uint16), gsd_m=0.001, crs="EPSG:4326", origin_m=(10.0, 45.0))
    store = tmp_path / "site.gpkg"
    chip = Record(str(path), 1, "edge", "ESF", "ok", figures={"mtf_nyquist": 0.2, "roi": [2, 4, 8, 6]})
    write_acquisition(store, read_acquisition(path, band=1), [chip, half_edge("e1", 0, 0.0)],
                      [summary("target", "across-track", target_id=0)])
    with fiona.open(store, layer="edges") as layer:
        polygon, line = (f.geometry for f in layer)
    assert polygon.type == "Polygon" and np.allclose(polygon.coordinates[0][:3],
                                                     [(10.002, 44.996), (10.010, 44.996), (10.010, 44.990)])
    assert line.type == "LineString" and np.allclose(line.coordinates, [(10.0025, 44.9965), (10.0125, 44.9965)])
    with fiona.open(store, layer="targets") as layer:
        [point] = (f.geometry for f in layer)
    assert np.allclose(point.coordinates, (10.0075, 44.9965))


def test_rows_of_a_scene_without_crs_have_pixel_columns_and_no_geometry(tmp_path, acquisition):
    store = tmp_path / "site.gpkg"
    write_acquisition(store, acquisition, [half_edge("e1", 0, 0.0)], [])
    with fiona.open(store, layer="edges") as layer:
        [feature] = list(layer)
    assert feature.geometry is None and (feature.properties["x0_px"], feature.properties["x1_px"]) == (2.0, 12.0)


def test_a_failed_write_changes_nothing(tmp_path, acquisition):
    store = tmp_path / "site.gpkg"
    write_acquisition(store, acquisition, [half_edge("e1", 0, 0.0)], [summary("scene", "across-track")])
    with sqlite3.connect(store) as db:           # a store whose targets refuse rows: the write fails half-way
        db.execute("CREATE TRIGGER refuse BEFORE INSERT ON targets BEGIN SELECT RAISE(ABORT, 'refused'); END")
    with pytest.raises(FileWriteError, match="site.gpkg: cannot write: refused"):
        write_acquisition(store, acquisition, [half_edge("e9", 0, 0.0, 0.3)], [summary("scene", "across-track")])
    assert [r["edge_id"] for r in rows(store, "edges")] == ["e1"]          # the old rows, not deleted
    assert len(rows(store, "targets")) == 1


def _write_many(store, path, worker, count):
    from imgmtf.campaign.acquisitions import read_acquisition as read
    for k in range(count):
        acquisition = read(path, band=1, settings={"worker": worker, "k": k})
        write_acquisition(store, acquisition, [half_edge(f"{worker}-{k}", 0, 0.0)] * 2,
                          [summary("scene", "across-track")])


def test_two_processes_writing_one_store_lose_nothing(tmp_path, acquisition):
    store = str(tmp_path / "site.gpkg")
    context = multiprocessing.get_context("fork")          # two processes, each with its own connections
    workers = [context.Process(target=_write_many, args=(store, acquisition.path, w, 10)) for w in range(2)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(120)
    assert [w.exitcode for w in workers] == [0, 0]
    assert len(rows(store, "acquisitions")) == 20 and len(rows(store, "edges")) == 40
    assert len(rows(store, "targets")) == 20


def test_an_older_store_is_read_and_upgraded(tmp_path, acquisition):
    store = tmp_path / "site.gpkg"
    write_acquisition(store, acquisition, [half_edge("e1", 0, 0.0)], [summary("scene", "across-track")])
    with sqlite3.connect(store) as db:           # as an imgmtf before schema 1 left it: no resampling, no version
        db.execute("ALTER TABLE targets DROP COLUMN resampling")
        db.execute("DELETE FROM store_info")
    assert schema_version(store) == 0
    [old] = read_layer(store, "targets")
    assert old["resampling"] is None and old["mtf_nyquist"] == 0.21
    other = read_acquisition(acquisition.path, band=1, settings={"other": True})
    write_acquisition(store, other, [], [summary("scene", "across-track")])
    assert schema_version(store) == SCHEMA_VERSION
    assert sorted(str(r["resampling"]) for r in read_layer(store, "targets")) == ["ESF", "None"]


def test_a_newer_store_is_not_written(tmp_path, acquisition):
    store = tmp_path / "site.gpkg"
    write_acquisition(store, acquisition, [], [])
    with sqlite3.connect(store) as db:
        db.execute("UPDATE store_info SET value = ? WHERE key = 'schema_version'", (str(SCHEMA_VERSION + 1),))
    with pytest.raises(StoreError, match="newer imgmtf"):
        write_acquisition(store, acquisition, [], [])
    assert len(read_layer(store, "acquisitions")) == 1                     # but read


def test_bad_stores_and_rows_are_clear_errors(tmp_path, acquisition):
    (tmp_path / "notes.gpkg").write_text("not a database")
    with pytest.raises(StoreError, match="notes.gpkg: not a"):
        write_acquisition(tmp_path / "notes.gpkg", acquisition, [], [])
    with pytest.raises(StoreError, match="notes.gpkg: not a"):
        read_layer(tmp_path / "notes.gpkg", "edges")
    with pytest.raises(StoreError, match="missing.gpkg: no such campaign store"):
        read_layer(tmp_path / "missing.gpkg", "edges")
    with pytest.raises(ParameterError, match="layer must be one of"):
        read_layer(tmp_path / "notes.gpkg", "bridges")
    with pytest.raises(ParameterError, match="summary must be one of combined, sections, fit"):
        write_acquisition(tmp_path / "s.gpkg", acquisition, [], [summary("scene", "across-track", "mean")])
    with pytest.raises(ParameterError, match="must be Records"):
        write_acquisition(tmp_path / "s.gpkg", acquisition, [{"mtf_nyquist": 0.2}], [])
    with pytest.raises(FileWriteError, match="does not exist"):
        write_acquisition(tmp_path / "no" / "s.gpkg", acquisition, [], [])


def test_recommended_rows_their_assumption_and_misfit_are_kept(tmp_path, acquisition):
    store = tmp_path / "site.gpkg"
    sections = summary("scene", "across-track", "sections")
    sections.figures.update(recommended=True, recommended_because="a third orientation decides",
                            assumption="elliptical")
    fit = summary("scene", "across-track", "fit")
    fit.figures.update(recommended=True, misfit=True)          # a misfit is never stored as recommended
    write_acquisition(store, acquisition, [], [sections, fit])
    got = {r["method"]: r for r in read_layer(store, "targets")}
    assert (got["sections"]["recommended"], got["sections"]["assumption"],
            got["sections"]["recommended_because"]) == (1, "elliptical", "a third orientation decides")
    assert (got["fit"]["recommended"], got["fit"]["misfit"]) == (0, 1)
    assert got["fit"]["sensor_key"] == "16 x 16 px uint16, GSD 15 m"


def test_a_schema_1_store_gains_the_new_columns_and_keeps_its_rows(tmp_path, acquisition):
    store = tmp_path / "site.gpkg"
    write_acquisition(store, acquisition, [], [summary("scene", "across-track", "fit")])
    with sqlite3.connect(store) as db:           # as imgmtf's schema 1 left it
        for column in ("recommended", "recommended_because", "assumption", "sensor_key"):
            db.execute(f"ALTER TABLE targets DROP COLUMN {column}")
        db.execute("ALTER TABLE acquisitions DROP COLUMN sensor_key")
        db.execute("UPDATE store_info SET value = '1' WHERE key = 'schema_version'")
    [old] = read_layer(store, "targets")
    assert old["recommended"] is None and old["assumption"] is None and old["method"] == "fit"
    other = read_acquisition(acquisition.path, band=1, settings={"other": True})
    write_acquisition(store, other, [], [summary("scene", "along-track", "combined")])
    assert schema_version(store) == SCHEMA_VERSION == 3
    assert sorted(str(r["sensor_key"]) for r in read_layer(store, "targets")) == [
        "16 x 16 px uint16, GSD 15 m", "None"]


def test_figures_are_kept_relative_to_the_store_and_found_after_it_moves(tmp_path, acquisition, monkeypatch):
    import shutil
    from dataclasses import replace

    from imgmtf.campaign.store import figure_path
    site = tmp_path / "site"
    (site / "out").mkdir(parents=True)
    (site / "out" / "edge1.png").write_bytes(b"png")
    monkeypatch.chdir(tmp_path)                               # figures named relative to the working folder
    edge = half_edge("e1", 0, 0.0)
    edge = Record(edge.path, edge.band, edge.target, edge.method, edge.status, figures=edge.figures,
                  site=edge.site, plot="site/out/edge1.png")
    write_acquisition(site / "s.gpkg", replace(acquisition, overview=str(site / "out" / "edge1.png")), [edge], [])
    assert [r["plot"] for r in read_layer(site / "s.gpkg", "edges")] == ["out/edge1.png"]
    assert read_layer(site / "s.gpkg", "acquisitions")[0]["overview"] == "out/edge1.png"
    shutil.move(site, tmp_path / "moved")
    assert figure_path(tmp_path / "moved" / "s.gpkg", "out/edge1.png").read_bytes() == b"png"
    # an older store's path, relative to where it was written from, is found there too
    assert figure_path(tmp_path / "moved" / "s.gpkg", "moved/out/edge1.png") == Path("moved/out/edge1.png")
    assert figure_path(tmp_path / "moved" / "s.gpkg", "/abs/fig.png") == Path("/abs/fig.png")
    assert figure_path(tmp_path / "moved" / "s.gpkg", None) is None
