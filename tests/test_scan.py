"""Scanning a scene: data/scene.tif holds one target per verdict, with its
truth in the IMGMTF tag."""
import json
from pathlib import Path

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner

import imgmtf as im
from imgmtf.cli import main
from imgmtf.scene.combine import summarise_scan
from imgmtf.scene.measure import scan_scene
from imgmtf.scene.settings import ScanSettings

SCENE = Path(__file__).parent.parent / "data" / "scene.tif"
TRUTH = json.loads(im.read_raster(SCENE).tags["IMGMTF"])["tiles"]


def tile_of(record):
    x = (record["x0_px"] + record["x1_px"]) / 2
    y = (record["y0_px"] + record["y1_px"]) / 2
    for t in TRUTH:
        tx, ty, tw, th = t["tile_xywh"]
        if tx <= x < tx + tw and ty <= y < ty + th:
            return t


@pytest.fixture(scope="module")
def scan_records():
    # the sample scene is map-projected for its GeoJSON, but rendered with rows along track
    return scan_scene(str(SCENE), ScanSettings(track_azimuth_deg=0.0))


@pytest.fixture(scope="module")
def edge_scan(scan_records):
    return [r.to_dict() for r in scan_records]


def test_scan_accepts_the_good_edges_with_true_mtf_in_their_intervals(edge_scan):
    accepted = [r for r in edge_scan if r["status"] == "accepted"]
    assert [r["rank"] for r in accepted] == [1, 2]
    assert {tile_of(r)["verdict"] for r in accepted} == {"accepted"}
    assert {r["direction"] for r in accepted} == {"across-track", "along-track"}
    for r in accepted:
        truth = tile_of(r)
        assert abs(r["mtf_nyquist"] - truth["true_mtf_nyquist"]) < 0.006
        lo, hi = r["mtf50_ci_cy_px"]
        assert lo - 0.002 <= truth["true_mtf50_cy_px"] <= hi + 0.002
        assert r["line_rms_px"] < 0.1 and r["side_variation"] < 0.1


@pytest.mark.parametrize("verdict", ["angle", "saturated", "non-uniform", "two-targets", "too-short"])
def test_scan_rejects_each_unsuitable_target_with_its_reason(edge_scan, verdict):
    slanted = [r for r in edge_scan if r["tilt_deg"] > 1.0 and tile_of(r)["verdict"] == verdict]
    assert slanted and all(r["status"] == "rejected" and r["reason"] == verdict for r in slanted)
    assert all(r["error"] for r in slanted)


def test_scan_rejects_the_mosaic_seams_as_axis_aligned(edge_scan):
    seams = [r for r in edge_scan if r["tilt_deg"] < 0.5]
    assert len(seams) >= 5 and all(r["reason"] == "angle" for r in seams)


def test_scan_measures_the_bar_as_a_pulse_target():
    records = [r.to_dict() for r in scan_scene(str(SCENE), ScanSettings(target="pulse", pulse_width=(3.0, "px")))]
    accepted = [r for r in records if r["status"] == "accepted"]
    assert len(accepted) == 1 and tile_of(accepted[0])["verdict"] == "bar"
    assert accepted[0]["bar_width_px"] == pytest.approx(3.0, abs=0.6)
    assert abs(accepted[0]["mtf_nyquist"] - tile_of(accepted[0])["true_mtf_nyquist"]) < 0.006


def test_cli_scan_accepts_a_lone_bar_at_its_default_margin(tmp_path):
    # the self-test's 1.5 px bar: its ROI once fell a pixel short of the background the bar's rows need
    chip = im.render(im.Sensor(), im.Target("pulse", 6.0, 200.0, 1200.0, 0.17, 1.5), 200)
    im.write_geotiff(tmp_path / "bar.tif", chip.image)
    result = CliRunner().invoke(main, ["scan", str(tmp_path / "bar.tif"), "--target", "pulse", "--format", "json"])
    assert result.exit_code == 0, result.output
    row = json.loads(result.stdout.splitlines()[0])
    assert row["status"] == "accepted" and row["width_estimated"] is True
    assert abs(row["mtf_nyquist"] - float(chip.true_mtf(0.5))) < 0.02


def test_overview_draws_collections_labels_targets_and_fills_its_figure(scan_records):
    from matplotlib.collections import LineCollection, PolyCollection

    from imgmtf.plot import plot_scan
    summaries = [s.to_dict() for s in summarise_scan(scan_records)]
    rows = [r.to_dict() for r in scan_records]
    # records as scan_scene returns them draw as their dicts do
    as_records = plot_scan(np.zeros((128, 256)), 2.0, scan_records, summarise_scan(scan_records)).axes[0].texts
    fig = plot_scan(np.zeros((128, 256)), 2.0, rows, summaries)
    ax = fig.axes[0]
    assert len(as_records) == len(ax.texts)
    reasons = {r["reason"] for r in rows if r["status"] == "rejected"}
    lines = [c for c in ax.collections if isinstance(c, LineCollection) and not isinstance(c, PolyCollection)]
    assert len(lines) == len(reasons) + 1 and not ax.patches          # one collection per reason, no boxes
    assert len([c for c in ax.collections if isinstance(c, PolyCollection)]) == 1
    # every candidate carries its id (few per reason here), as the table lists them; the targets their figures
    labels = sorted(t.get_text().split()[0] for t in ax.texts)
    assert labels == sorted([str(r["id"]) for r in rows] + [f"T{s['target_id']}" for s in summaries
                                                            if s["scope"] == "target"], key=str)
    # the accepted drawn above the rejected, both outlined so that they read on black and on white
    accepted_line = lines[-1]
    assert all(accepted_line.get_zorder() > c.get_zorder() for c in lines[:-1])
    assert all(c.get_path_effects() for c in lines)
    assert ax.get_xlabel() == "column (px)" and ax.get_ylabel() == "row (px)"
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    n_angle = sum(r["reason"] == "angle" for r in rows)
    assert legend[0].startswith("accepted (2)\n") and any(t.startswith(f"angle ({n_angle})") for t in legend)
    # the legend lies outside the image, on its right
    fig.canvas.draw()
    assert ax.get_legend().get_window_extent().x0 > ax.get_window_extent().x1
    x0, y0, x1, y1 = ax.get_position().extents          # the image fills its axes: no blank band
    assert (x1 - x0) * fig.get_figwidth() / ((y1 - y0) * fig.get_figheight()) == pytest.approx(2.0)


def test_an_overview_of_hundreds_of_candidates_reads_and_its_target_label_leaves_the_junction_clear():
    from matplotlib.collections import LineCollection, PolyCollection

    from imgmtf.plot import plot_scan
    from imgmtf.plot.scan import CROWD_ALPHA, MAX_LISTED
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, 400, (2, 300))
    crowd = [{"id": k + 10, "status": "rejected", "reason": "too-short", "x0_px": a, "y0_px": b, "x1_px": a + 12,
              "y1_px": b + 4} for k, (a, b) in enumerate(zip(x, y))]
    # a checkerboard's four half-edges meeting at (200, 200), each with its ROI
    ends = [(200, 120), (120, 200), (200, 280), (280, 200)]
    accepted = [{"id": k + 1, "status": "accepted", "x0_px": 200.0, "y0_px": 200.0, "x1_px": float(a),
                 "y1_px": float(b), "roi_polygon_px": [(200 - 10 * (b != 200), 200 - 10 * (a != 200)),
                                                       (a + 10 * (b != 200), b + 10 * (a != 200)),
                                                       (a - 10 * (b != 200), b - 10 * (a != 200))]}
                for k, (a, b) in enumerate(ends)]
    target = [{"scope": "target", "target_id": 1, "x_px": 200.0, "y_px": 200.0, "direction": d,
               "normal_angle_deg": 0.0, "mtf_nyquist": 0.2, "mtf50_cy_px": 0.3} for d in ("oblique", "unknown")]
    fig = plot_scan(np.zeros((400, 400)), 1.0, [*accepted, *crowd], target)
    ax = fig.axes[0]
    lines = [c for c in ax.collections if isinstance(c, LineCollection) and not isinstance(c, PolyCollection)]
    # the rejected faint (too many to label: bare, no outline), the accepted opaque; the ROIs unfilled
    assert len(crowd) > MAX_LISTED and lines[0].get_alpha() == CROWD_ALPHA and not lines[0].get_path_effects()
    assert lines[-1].get_alpha() is None and lines[-1].get_path_effects()
    roi = next(c for c in ax.collections if isinstance(c, PolyCollection))
    assert np.all(roi.get_facecolor()[:, 3] == 0)
    # the target's label covers neither the junction nor its half-edges; its title says what the labels hold
    label = next(t for t in ax.texts if t.get_text().startswith("T1"))
    box = label.get_window_extent()
    for (a, b) in ends:
        for f in np.linspace(0.0, 1.0, 30):
            px, py = ax.transData.transform((200 + f * (a - 200), 200 + f * (b - 200)))
            assert not (box.x0 < px < box.x1 and box.y0 < py < box.y1)
    assert ax.get_title(loc="left").splitlines()[1].startswith("target labels: MTF at Nyquist | MTF50")
    assert "300 rejected (coloured by reason)" in ax.get_title(loc="left")


def test_cli_scan_writes_csv_geojson_overview_and_edge_figures(tmp_path):
    out = tmp_path / "scan"
    result = CliRunner().invoke(main, ["scan", str(SCENE), "--out", str(out), "--workers", "2", "--edge-figures"])
    assert result.exit_code == 0, result.output
    # the table names the scene once; an accepted edge's warnings stand beneath it
    rejected = [line for line in result.stdout.splitlines() if line.startswith("rejected ")]
    assert rejected and not any(f"{SCENE}:" in line for line in rejected)
    assert "warning: the image is not in sensor geometry" in result.stdout
    assert "give the track's azimuth to label it (--track-azimuth DEG gives it)" in " ".join(result.stdout.split())
    geo = json.loads((out / "targets.geojson").read_text())
    assert geo["imgmtf_coordinates"].startswith("longitude/latitude")
    first = geo["features"][0]
    lon, lat = first["geometry"]["coordinates"][0]
    assert 14.9 < lon < 15.1 and 41.9 < lat < 42.1          # EPSG:32633 at 500000, 4650000
    props = first["properties"]
    assert props["status"] == "accepted" and props["imgmtf_version"] == im.__version__
    assert props["params"]["scan"]["min_length_px"] == 40.0 and props["path"] == str(SCENE)
    assert props["map_x0"] == pytest.approx(500000 + props["x0_px"] + 0.5)
    assert (out / "targets.csv").read_text().count("\n") == len(geo["features"]) + 1
    # without --track-azimuth a map-projected scene has no known direction; its summaries follow the edges
    assert props["direction"] == "unknown"
    targets = [f for f in geo["features"] if f["properties"]["scope"] == "target"]
    assert len(targets) == 2 and all(f["geometry"]["type"] == "Point" for f in targets)
    assert geo["features"][-1]["properties"]["scope"] == "scene" and geo["features"][-1]["geometry"] is None
    assert (out / "overview.png").stat().st_size > 20_000
    # a figure per accepted half-edge, named by its id, drawn in the workers; none for the rejected
    edges = [f["properties"] for f in geo["features"] if f["properties"]["scope"] == "edge"]
    accepted = [r for r in edges if r["status"] == "accepted"]
    assert accepted and sorted(p.name for p in (out / "edges").iterdir()) == sorted(
        f"edge{r['id']}.png" for r in accepted)
    assert all(r["plot"] == str(out / "edges" / f"edge{r['id']}.png") for r in accepted)
    assert not any(r.get("plot") for r in edges if r["status"] == "rejected")
    refused = CliRunner().invoke(main, ["scan", str(SCENE), "--edge-figures"])
    assert refused.exit_code == 2 and "give --out DIR" in refused.output


def test_cli_scan_of_a_featureless_image_exits_1(tmp_path):
    flat = tmp_path / "noise.tif"
    rng = np.random.default_rng(0)
    im.write_geotiff(flat, (1000 + rng.normal(0, 5, (128, 128))).astype(np.uint16))
    result = CliRunner().invoke(main, ["scan", str(flat)])
    assert result.exit_code == 1 and f"{flat}: no usable edge found" in result.output


def test_cli_scan_of_values_no_sensor_records_is_refused_for_the_scene(tmp_path):
    huge = tmp_path / "huge.tif"
    image = im.render(im.Sensor(), im.Target("edge", 6.0), 64).image * 1e300
    with rasterio.open(huge, "w", driver="GTiff", width=64, height=64, count=1, dtype="float64",
                       transform=rasterio.Affine(1, 0, 0, 0, -1, 64)) as dst:
        dst.write(image, 1)
    result = CliRunner().invoke(main, ["scan", str(huge)])
    assert result.exit_code == 1 and "Warning" not in result.output
    assert result.stderr.strip() == (f"imgmtf: error: {huge}: pixel values reach 1.2e+303: beyond 1e+15 they are "
                                     "not DN an imaging sensor records; rescale the image")


def test_cli_scan_max_length_below_min_length_is_a_usage_error():
    result = CliRunner().invoke(main, ["scan", str(SCENE), "--min-length", "40", "--max-length", "20"])
    assert result.exit_code == 2 and "--max-length (20 px) is below --min-length (40 px)" in result.output


def test_cli_scan_for_pulses_prints_its_table_and_json_rows(tmp_path):
    result = CliRunner().invoke(main, ["scan", str(SCENE), "--target", "pulse", "--bootstrap", "0"])
    assert result.exit_code == 0, result.output
    assert "1 accepted" in result.stdout and "Traceback" not in result.output
    result = CliRunner().invoke(main, ["scan", str(SCENE), "--target", "pulse", "--bootstrap", "0",
                                       "--format", "json", "--out", str(tmp_path)])
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    accepted = [r for r in rows if r["status"] == "accepted"]
    assert len(accepted) == 1 and accepted[0]["mtf50_cy_px"] is None and accepted[0]["rank"] == 1
    header = (tmp_path / "targets.csv").read_text().splitlines()[0].split(",")
    assert header[:3] == ["id", "rank", "path"] and "bar_width_px" in header and "run_utc" in header


def test_a_scan_without_fits_loads_no_scipy():
    """What the workers run (tile search, a batch of candidates) and what
    their fork server preloads (imgmtf.cli.scan's lists, without the
    fits'), and the scan's own steps in the calling process (the segment
    graph: merging, junctions, the targets' grouping), load no SciPy:
    its sparse and spatial packages cost 0.2-0.3 s of a chart's start-up.
    Only a sensor fit does (its optimizer)."""
    import subprocess
    import sys

    from imgmtf.preloads import SCANNING_MODULES, WHOLE_SCAN_MODULES
    graph = ("from imgmtf.scene.segments import SampledSegments, find_junctions, merge_segments; "
             "s = SampledSegments.of([[0, 50, 100, 50], [50, 0, 50, 100], [101, 50, 160, 50]]); "
             "j, _ = find_junctions(s); assert len(j) == 1, j; assert len(merge_segments(s.segments)) == 2; "
             "from imgmtf.scene.neighbours import components; assert components(3, [0], [2])[0] == 2; ")
    code = (f"import sys; import {', '.join(SCANNING_MODULES + WHOLE_SCAN_MODULES)}; {graph}"
            "print(sorted(m for m in sys.modules if m == 'scipy'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_a_candidate_that_breaks_the_estimator_is_rejected_as_internal(monkeypatch):
    # (inside the pipeline: the candidates' estimates are made together, each failure its own)
    import imgmtf.estimate.pipeline as pipeline
    calls = []

    def breaks_once(*args, **keywords):
        calls.append(args)
        if len(calls) == 1:
            raise ZeroDivisionError("float division by zero")
        return (yield from real(*args, **keywords))
    real = pipeline.transform_steps
    monkeypatch.setattr(pipeline, "transform_steps", breaks_once)
    records = scan_scene(str(SCENE), ScanSettings(intervals=im.Intervals("none")))
    internal = [r for r in records if r.reason == "internal"]
    assert len(internal) == 1 and "ZeroDivisionError: float division by zero" in internal[0].error
    assert internal[0].error.startswith(str(SCENE))
    assert sum(r.ok for r in records) >= 1


def test_a_scene_without_a_crs_gives_features_without_geometry(scan_records, tmp_path):
    from imgmtf.io import raster_info
    from imgmtf.scene.export import to_geojson
    plain = tmp_path / "plain.tif"
    im.write_geotiff(plain, im.read_raster(SCENE).data.astype(np.uint16))     # the pixels, no georeference
    geo = to_geojson(scan_records, raster_info(str(plain)), summarise_scan(scan_records))
    assert geo["imgmtf_coordinates"].startswith("none")
    assert all(f["geometry"] is None for f in geo["features"])      # never pixels read as degrees
    assert all("x0_px" in f["properties"] for f in geo["features"] if f["properties"]["scope"] == "edge")


@pytest.mark.parametrize("make, message", [
    (lambda: ScanSettings(margin_px="12"), "margin_px must be a number, got '12'"),
    (lambda: ScanSettings(margin_px=12.5), "margin_px must be a whole number"),
    (lambda: ScanSettings(min_length_px=None), "min_length_px must be a number"),
    (lambda: ScanSettings(band=0), "band must be at least 1, got 0"),
    (lambda: ScanSettings(band="all"), "scan one band at a time"),
    (lambda: scan_scene(np.zeros((64, 64))), r"path must be the scene's file name \(str or os.PathLike\), got ndarray"),
    (lambda: scan_scene(str(SCENE), {"target": "edge"}), "settings must be a ScanSettings"),
    (lambda: summarise_scan(None), "records must be a list of a scan's Records, got None"),
    (lambda: summarise_scan([1]), r"records must be a scan's Records \(imgmtf.scan_scene\), got 1"),
])
def test_api_arguments_of_the_wrong_kind_are_named(make, message):
    with pytest.raises(im.ParameterError, match=message):
        make()


def test_the_text_table_tallies_rejections_by_reason_and_verbose_lists_every_candidate():
    rows = [json.loads(line) for line in CliRunner().invoke(
        main, ["scan", str(SCENE), "--format", "json", "--fit-stages", "none"]).stdout.splitlines()]
    candidates = [r for r in rows if r.get("scope") == "edge"]
    counts = {}
    for r in candidates:
        if r["status"] == "rejected":
            counts[r["reason"]] = counts.get(r["reason"], 0) + 1
    brief = CliRunner().invoke(main, ["scan", str(SCENE), "--fit-stages", "none"]).stdout.splitlines()
    tally = {line.split()[2]: int(line.split()[1]) for line in brief if line.startswith("rejected ")}
    assert tally == counts and sum(tally.values()) == len(candidates) - 2
    assert brief[0].endswith(f"{len(candidates)} candidate edges, 2 accepted")
    # one line per reason, the most frequent first; the option that moves a limit is named
    assert list(tally.values()) == sorted(tally.values(), reverse=True)
    joined = "\n".join(brief).replace("\n" + " " * 14, " ")            # a long line wraps under its words
    assert any("(--min-length sets the minimum)" in line for line in joined.splitlines() if " too-short " in line)
    verbose = CliRunner().invoke(main, ["scan", str(SCENE), "--fit-stages", "none", "--verbose"]).stdout
    lines = verbose.splitlines()
    listed = [line for line in lines if " rejected  " in line]
    assert len(listed) == sum(counts.values()) and not any(line.startswith("rejected ") for line in lines)


def test_a_count_names_one_thing_in_the_singular():
    from imgmtf.cli.tables import plural
    assert (plural(1, "candidate edge"), plural(0, "candidate edge"), plural(17, "candidate bar")) == (
        "1 candidate edge", "0 candidate edges", "17 candidate bars")


def test_a_strip_one_pixel_high_is_refused_before_any_tile_is_read(tmp_path):
    strip = np.where(np.arange(50000) > 25000, 1200, 200)[None, :].astype(np.uint16)
    path = tmp_path / "strip.tif"
    with rasterio.open(path, "w", driver="GTiff", width=50000, height=1, count=1, dtype="uint16") as dst:
        dst.write(strip, 1)
    with pytest.raises(im.ImgmtfError) as info:
        scan_scene(str(path))
    assert info.value.reason == "image" and "50000 x 1 px" in str(info.value)
    result = CliRunner().invoke(main, ["scan", str(path)])
    assert result.exit_code == 1 and "at least 16 x 16" in result.output and "Traceback" not in result.output


def test_a_scene_whose_one_candidate_is_rejected_says_so_in_the_singular(tmp_path):
    chip = tmp_path / "one.tif"
    assert CliRunner().invoke(main, ["simulate", "--size", "60", "--out", str(chip)]).exit_code == 0
    result = CliRunner().invoke(main, ["scan", str(chip), "--min-length", "100"])
    assert result.exit_code == 1
    assert f"{chip}: no usable edge found (1 candidate, rejected)" in result.stderr     # not "1 candidates, all"


def test_one_scene_with_fits_has_the_fork_server_load_the_optimizer_for_its_workers(monkeypatch):
    """One scene, workers chosen automatically: the fork server starts as the scan does, the fits' modules
    (SciPy's optimizer) among its imports, loaded on another core while this process detects and measures,
    and the scene's few fits go to its workers; not without fits, nor with --workers 1, nor with no
    fork server, when they run here."""
    from types import SimpleNamespace

    import imgmtf.parallel as parallel
    from imgmtf.errors import ParameterError
    from imgmtf.preloads import FITTING_MODULES
    from imgmtf.scene.afterscan import fit_workers
    started = []

    def prestart(workers, modules):
        started.append((workers, set(FITTING_MODULES) <= set(modules)))
        raise ParameterError("stopped here")
    monkeypatch.setattr(parallel, "prestart_workers", prestart)
    monkeypatch.setattr(parallel, "available_cores", lambda: 2)
    monkeypatch.setattr(parallel, "can_preload", lambda: True)
    for options in ([], ["--fit-stages", "none"], ["--workers", "1"]):
        CliRunner().invoke(main, ["scan", "chart.tif", *options])
    monkeypatch.setattr(parallel, "can_preload", lambda: False)
    CliRunner().invoke(main, ["scan", "chart.tif"])
    assert started == [(2, True), (1, False), (1, True), (1, True)]
    records = [SimpleNamespace(ok=True)] * 16 + [SimpleNamespace(ok=False)] * 3
    monkeypatch.setattr(parallel, "preloaded", lambda modules: False)
    assert fit_workers(records, None) == 1 and fit_workers(records, 3) == 3
    monkeypatch.setattr(parallel, "preloaded", lambda modules: set(modules) == set(FITTING_MODULES))
    assert fit_workers(records, None) == 2 and fit_workers(records[:1], None) == 1 and fit_workers(records, 1) == 1
