"""scan over many scenes into a campaign store: every finished acquisition
kept, none twice, none lost to a second writer or to Ctrl-C; the fit rows
beside the combined ones in every output."""
import csv
import json
import os
import signal
import subprocess
import sys
import time

import pytest
from click.testing import CliRunner

import imgmtf as im
from imgmtf.campaign.store import figure_path, read_layer
from imgmtf.cli.main import main
from imgmtf.sensor.scenes import QuadrantTarget, render_quadrants
from imgmtf.sensor.series import SyntheticCampaign
from imgmtf.sensor.stages import Detector, GaussianOptics
from imgmtf.synthetic import write_campaign

from conftest import ctrl_c_as_at_a_terminal


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """Three yearly 128 px scenes tagged with their time, platform and band."""
    folder = tmp_path_factory.mktemp("campaign")
    spec = SyntheticCampaign(acquisitions=3, size_px=128, seed=5)
    return folder, write_campaign(folder, spec), spec


def layer_counts(store):
    return {layer: len(read_layer(store, layer)) for layer in ("acquisitions", "edges", "targets")}


def test_a_folder_of_scenes_goes_into_the_store_once_whatever_is_added_again(campaign, tmp_path):
    folder, paths, spec = campaign
    store = str(tmp_path / "site.gpkg")
    result = CliRunner().invoke(main, ["scan", str(folder), "--campaign", store, "--fit-stages", "none",
                                       "--format", "json"])
    assert result.exit_code == 0, result.output
    counts = layer_counts(store)
    assert counts["acquisitions"] == 3 and counts["edges"] > 3 * 4
    stored = {row["path"]: row for row in read_layer(store, "acquisitions")}
    for k, path in enumerate(paths):
        row = stored[str(path)]
        assert (row["acquired_utc"], row["platform"], row["band_name"]) == (spec.acquired_utc(k), "SYNTHSAT-1", "PAN")
    # the same scene again, alone or with the others: its rows replaced, none added
    again = CliRunner().invoke(main, ["scan", str(paths[1]), "--campaign", store, "--fit-stages", "none",
                                      "--platform", "ignored: the file says"])
    assert again.exit_code == 0, again.output
    assert layer_counts(store) == counts
    assert "no acquisition time" not in again.output
    assert f"1 acquisition(s) written to {store}" in again.output          # as measure --campaign says it


def test_a_scene_that_says_not_when_is_stored_with_one_note(tmp_path):
    chip = im.render(im.Sensor(), im.Target("edge", 6.0), 64).image
    paths = [tmp_path / "a.tif", tmp_path / "b.tif"]
    for path in paths:
        im.write_geotiff(path, chip)                        # no ACQUISITION_DATETIME
    store = str(tmp_path / "site.gpkg")
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["scan", *map(str, paths), "--campaign", store, "--fit-stages", "none",
                                       "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output.count("no acquisition time for 2 scene(s)") == 1 and "give --acquired TIME" in result.output
    # several scenes: a folder of outputs each, named after its file
    assert sorted(p.name for p in out.iterdir()) == ["a", "b"] and (out / "b" / "targets.csv").exists()
    # the same pixels in two files are one acquisition (its id is the content's, band's and settings')
    assert layer_counts(store)["acquisitions"] == 1
    given = CliRunner().invoke(main, ["scan", str(paths[0]), "--campaign", store, "--fit-stages", "none",
                                      "--acquired", "2021-03-04T05:06:07Z"])
    assert given.exit_code == 0 and "no acquisition time" not in given.output
    assert [r["acquired_utc"] for r in read_layer(store, "acquisitions")] == ["2021-03-04T05:06:07Z"]


def test_campaign_options_need_a_store_and_one_time_fits_one_scene(campaign, tmp_path):
    folder, _, _ = campaign
    result = CliRunner().invoke(main, ["scan", str(folder), "--platform", "X"])
    assert result.exit_code == 2 and "--platform describes the acquisitions of a campaign store" in result.output
    result = CliRunner().invoke(main, ["scan", str(folder), "--campaign", str(tmp_path / "s.gpkg"),
                                       "--acquired", "2020-01-01"])
    assert result.exit_code == 2 and "--acquired gives one time, for one scene; 3 scenes" in result.output
    result = CliRunner().invoke(main, ["scan", str(folder), "--campaign", str(tmp_path / "s.gpkg"),
                                       "--acquired", "last spring"])
    assert result.exit_code == 2 and "Traceback" not in result.output
    result = CliRunner().invoke(main, ["scan", str(folder), "--fit-stages", "optics,lens"])
    assert result.exit_code == 2 and "unknown stage 'lens'" in result.output
    # measure refuses them alike: given without a store they were silently ignored (exit 0)
    for given in (["--acquired", "2020-01-01"], ["--platform", "X", "--band-name", "B4"]):
        result = CliRunner().invoke(main, ["measure", str(folder), *given])
        assert result.exit_code == 2 and f"{given[0]} describes the acquisitions of a campaign store" in result.output


def test_fit_rows_are_printed_and_written_beside_the_combined_ones(tmp_path):
    # a target cut out of its scene (an L0R chip): its four inner half-edges, a quick fit
    sensor = im.Sensor(1.0, [GaussianOptics(0.32, 0.42), Detector(1.0, 1.0)])
    target = QuadrantTarget((60.4, 60.3), 16.8, (9000.0, 2500.0, 9000.0, 4500.0), 48.0)
    im.write_geotiff(tmp_path / "chip.tif", render_quadrants(sensor, (121, 121), target, fill=True,
                                                             noise_std_dn=25.0, seed=3).image)
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["scan", str(tmp_path / "chip.tif"), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "fitted per target, across and along track (sensor model: optics, detector" in result.output
    rows = list(csv.DictReader((out / "targets.csv").open()))
    fits = {r["direction"]: r for r in rows if r["summary"] == "fit"}
    assert {r["summary"] for r in rows if r["scope"] == "target"} == {"combined", "sections", "fit"}
    for direction, row in fits.items():
        truth = sensor.mtf_nyquist(direction.split("-")[0])
        assert abs(float(row["mtf_nyquist"]) - truth) < 0.006
        assert float(row["mtf_nyquist_ci_low"]) < float(row["mtf_nyquist"]) < float(row["mtf_nyquist_ci_high"])
        assert row["status"] == "fitted" and row["misfit"] == "False" and json.loads(row["stages"])
        # a Gaussian blur over a square pixel is separable and elliptical both: every assumption's
        # sections cover the truth, and the fit, which fits and agrees with them, is the row to quote
        sections = [r for r in rows if r["summary"] == "sections" and r["direction"] == direction
                    and r["scope"] == "target"]
        assert {r["assumption"] for r in sections} == {"separable", "elliptical", "bracket"}
        for r in sections:
            assert float(r["mtf_nyquist_ci_low"]) < truth < float(r["mtf_nyquist_ci_high"])
            assert abs(float(r["mtf_nyquist"]) - truth) < 0.006
        quoted = [r for r in rows if r["direction"] == direction and r["scope"] == "target"
                  and r["recommended"] == "True"]
        assert [r["summary"] for r in quoted] == ["fit"] and "agrees" in quoted[0]["recommended_because"]
    features = json.loads((out / "targets.geojson").read_text())["features"]
    assert sum(f["properties"].get("summary") == "fit" for f in features) == 2


def start_scan(paths, store, *more):
    return subprocess.Popen([sys.executable, "-m", "imgmtf.cli", "scan", *map(str, paths), "--campaign", str(store),
                             "--format", "json", "--no-progress", *more],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=ctrl_c_as_at_a_terminal)


def test_two_scans_writing_one_store_at_once_lose_no_row(campaign, tmp_path):
    _, paths, _ = campaign
    store = tmp_path / "site.gpkg"
    runs = [start_scan(paths[:2], store, "--fit-stages", "none"), start_scan(paths[2:], store, "--fit-stages", "none")]
    outputs = [run.communicate(timeout=120) for run in runs]
    assert [run.returncode for run in runs] == [0, 0], outputs
    accepted = sum(json.loads(line)["status"] == "accepted" for out, _ in outputs for line in out.splitlines())
    counts = layer_counts(store)
    assert counts["acquisitions"] == 3 and counts["edges"] == accepted


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_during_a_scan_of_many_scenes_keeps_every_finished_acquisition(tmp_path):
    folder = tmp_path / "scenes"
    write_campaign(folder, SyntheticCampaign(acquisitions=8, size_px=160, seed=1))
    store = tmp_path / "site.gpkg"
    process = start_scan([folder], store, "--workers", "2", "--fit-stages", "none")
    end = time.monotonic() + 60
    while time.monotonic() < end and process.poll() is None:
        if store.exists() and read_layer(store, "acquisitions"):
            break
        time.sleep(0.1)
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=30)
    assert process.returncode == 130, stderr
    assert "Traceback" not in stderr and "imgmtf: interrupted (SIGINT)" in stderr
    reported = {json.loads(line)["path"] for line in stdout.splitlines()}
    stored = {row["path"] for row in read_layer(store, "acquisitions")}
    assert stored == reported and 1 <= len(stored) < 8
    assert not [p for p in os.listdir(tmp_path) if p.startswith(".imgmtf-store-")]


def test_a_landsat_product_scanned_without_options_is_dated_and_named_by_its_file_name(tmp_path):
    scene = SyntheticCampaign(acquisitions=2, size_px=128).render(0)
    path = tmp_path / "LC09_L1TP_181040_20211121_20211122_02_T1_B8.TIF"
    im.write_geotiff(path, scene.image, gsd_m=15.0)
    store = str(tmp_path / "site.gpkg")
    result = CliRunner().invoke(main, ["scan", str(path), "--campaign", store, "--fit-stages", "none"])
    assert result.exit_code == 0, result.output
    [row] = read_layer(store, "acquisitions")
    assert (row["platform"], row["instrument"], row["acquired_utc"], row["band_name"]) == \
        ("Landsat 9", "OLI-2", "2021-11-21", "B8")
    assert "no acquisition time" not in result.output


def test_scenes_scanned_with_outputs_name_their_overviews_and_edge_figures_in_the_store(tmp_path):
    # the campaign report shows each acquisition's overview and each accepted half-edge's figure from
    # what the store names: one folder per scene (two edge chips, one edge each: a figure costs about
    # 0.7 s, where a campaign scene has twelve half-edges)
    paths = []
    for k, angle in enumerate((6.0, -84.0)):
        paths.append(tmp_path / f"chip{k}.tif")
        im.write_geotiff(paths[-1], im.render(im.Sensor(), im.Target("edge", angle), 64).image)
    store, out = str(tmp_path / "site.gpkg"), tmp_path / "out"
    result = CliRunner().invoke(main, ["scan", *map(str, paths), "--campaign", store, "--out", str(out),
                                       "--edge-figures", "--fit-stages", "none", "--format", "json"])
    assert result.exit_code == 0, result.output
    rows = read_layer(store, "acquisitions")
    assert len(rows) == 2
    for row in rows:                      # kept relative to the store, so that they move with it
        assert not os.path.isabs(row["overview"]) and row["overview"].startswith("out/")
        overview = str(figure_path(store, row["overview"]))
        assert os.path.isfile(overview) and overview.endswith("overview.png")
        assert os.path.basename(os.path.dirname(overview)) == os.path.splitext(os.path.basename(row["path"]))[0]
    plots = [row["plot"] for row in read_layer(store, "edges")]
    assert len(plots) == 2 and all(p.startswith("out/chip") and "/edges/" in p and figure_path(store, p).is_file()
                                   for p in plots)


def test_scenes_finished_out_of_order_on_a_pool_are_yielded_in_the_order_given(monkeypatch):
    from imgmtf import parallel
    from imgmtf.scene.series import SceneOutcome, scan_scenes

    def finishing_backwards(function, tasks, **options):     # a pool where the last scene ends first
        for index in reversed(range(len(tasks))):
            yield index, SceneOutcome(tasks[index][0], error="not scanned")
    monkeypatch.setattr(parallel, "run_tasks", finishing_backwards)
    paths = ["a.tif", "b.tif", "c.tif"]
    assert [o.path for o in scan_scenes(paths, workers=2)] == paths

    def interrupted_after_two(function, tasks, **options):  # c and b finish, then Ctrl-C
        yield 2, SceneOutcome("c.tif", error="not scanned")
        yield 1, SceneOutcome("b.tif", error="not scanned")
        raise KeyboardInterrupt
    monkeypatch.setattr(parallel, "run_tasks", interrupted_after_two)
    seen = []
    with pytest.raises(KeyboardInterrupt):
        for outcome in scan_scenes(paths, workers=2):
            seen.append(outcome.path)
    assert seen == ["b.tif", "c.tif"]       # every finished scene reported before the interrupt goes on
