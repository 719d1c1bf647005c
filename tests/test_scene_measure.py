"""Scanning four-quadrant targets: half-edges split at the centre, each
measured on its own ROI clear of the junction and of fill, combined per
direction; on synthetic scenes with a known MTF and on real L0R chips."""
import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.preloads import SCAN_TASK_MODULES
from imgmtf.scene.combine import combine, normal_families, summarise_scan
from imgmtf.scene.measure import scan_scene
from imgmtf.scene.settings import ScanSettings
from imgmtf.sensor.scenes import QuadrantTarget, render_quadrants, texture

from conftest import real_scene

# A Baotou-like target: tilted 16.8 deg, two bright quadrants and two dark ones of different levels
TARGET = QuadrantTarget((50.4, 50.3), 16.8, (9300.0, 2000.0, 9200.0, 3900.0), 40.0)


@pytest.fixture(scope="module")
def quadrant_scans(tmp_path_factory):
    """The target on a textured field, and cut out of it with a 0-fill:
    {fill: (scene, records, summaries)}."""
    out = {}
    for fill in (False, True):
        scene = render_quadrants(im.Sensor(), (101, 101), TARGET, field_dn=3000 + texture((101, 101), 600, seed=4),
                                 fill=fill, noise_std_dn=25.0, seed=5)
        path = tmp_path_factory.mktemp("scenes") / f"quadrants_{'fill' if fill else 'field'}.tif"
        im.write_geotiff(path, scene.image)
        records = scan_scene(str(path))
        out[fill] = scene, records, summarise_scan(records)
    return out


BOTH = pytest.mark.parametrize("fill", [False, True], ids=["textured field", "0-fill"])


def inner_half_edge(record, tolerance_px=3.0):
    """The inner half-edge of TARGET a record lies on (its index), or None."""
    ends = [(record.site["x0_px"], record.site["y0_px"]), (record.site["x1_px"], record.site["y1_px"])]
    for k, half in enumerate(TARGET.half_edges()):
        centre, far = (half["x0_px"], half["y0_px"]), (half["x1_px"], half["y1_px"])
        if min(math.dist(e, centre) for e in ends) < tolerance_px and \
                min(math.dist(e, far) for e in ends) < 8.0 and \
                abs((record.site["normal_angle_deg"] - half["normal_angle_deg"] + 90) % 180 - 90) < 2.0:
            return k
    return None


@BOTH
def test_the_inner_half_edges_are_accepted_within_0015_of_the_true_mtf(quadrant_scans, fill):
    scene, records, _ = quadrant_scans[fill]
    accepted = [r for r in records if r.ok]
    assert len({inner_half_edge(r) for r in accepted} - {None}) >= 3
    for r in accepted:
        assert inner_half_edge(r) is not None                 # no field or fill boundary
        truth = float(scene.true_mtf(0.5, r.figures["normal_angle_deg"]))
        assert abs(r.figures["mtf_nyquist"] - truth) < 0.015
        # its ROI stops short of the centre: no accepted edge runs across it
        assert r.site["target_id"] == 1 and "junction" in " ".join(r.site["ends"])


def test_a_boundary_against_fill_is_fill_never_saturated_nor_measured(quadrant_scans):
    _, records, _ = quadrant_scans[True]
    outer = [r for r in records if inner_half_edge(r, tolerance_px=8.0) is None]
    assert outer and all(r.reason == "fill" and r.site["verdict_by"] == "screen" for r in outer)
    assert not any(r.reason == "saturated" for r in records)


@BOTH
def test_one_result_per_direction_combines_the_target_within_its_interval(quadrant_scans, fill):
    scene, _, summaries = quadrant_scans[fill]
    targets = [s for s in summaries if s.site["scope"] == "target"]
    assert sorted(round(s.figures["normal_angle_deg"]) for s in targets) == [-73, 17]
    for s in targets:
        truth = float(scene.true_mtf(0.5, s.figures["normal_angle_deg"]))
        low, high = s.figures["mtf_nyquist_ci"]
        assert s.figures["direction"] == "oblique" and s.figures["n_edges"] >= 1
        assert abs(s.figures["mtf_nyquist"] - truth) < 0.01 and low < s.figures["mtf_nyquist"] < high
    assert [s.figures["n_edges"] for s in summaries if s.site["scope"] == "scene"] == \
        [s.figures["n_edges"] for s in targets]


# -- real L0R chips ---------------------------------------------------------------------
def hand_roi(shape, centre, far, half_width=12.0, start=5.0, stop=4.0):
    """A hand-chosen tilted ROI along a half-edge: from ``start`` px off the
    target's centre to ``stop`` px short of its far corner (or fill),
    ``half_width`` px either side: (x, y, w, h) and the mask."""
    y, x = np.mgrid[0:shape[0], 0:shape[1]].astype(float)
    u = np.subtract(far, centre) / math.dist(far, centre)
    t = (x - centre[0]) * u[0] + (y - centre[1]) * u[1]
    d = -(x - centre[0]) * u[1] + (y - centre[1]) * u[0]
    mask = (np.abs(d) <= half_width) & (t >= start) & (t <= math.dist(far, centre) - stop)
    rows, cols = np.nonzero(mask)
    return (cols.min(), rows.min(), np.ptp(cols) + 1, np.ptp(rows) + 1), mask


# (file, provenance, target centre, far ends of its four inner half-edges), read off the images
REAL_TARGETS = [
    ("baotou_l0r_checkerboard.tif", "JorgeGIlG/MTF_Estimator data/baotou_CALVAL_L0R_... (GPL-3.0, read in place)",
     (51.5, 50.4), [(63.1, 11.6), (11.1, 38.2), (89.9, 61.9), (39.9, 88.5)]),
    ("pan_l0r_checkerboard.tif", "rdegoul/qgis-image-quality-toolset test/data/target2 (Apache-2.0)",
     (41.6, 36.2), [(35.2, 4.0), (9.8, 43.0), (47.9, 68.6), (72.9, 29.4)]),
]


@pytest.mark.parametrize("name, provenance, centre, ends", REAL_TARGETS, ids=[t[0] for t in REAL_TARGETS])
def test_real_checkerboards_agree_with_measure_on_hand_chosen_rois(name, provenance, centre, ends):
    path = real_scene(name, provenance)
    records = scan_scene(str(path))
    accepted = [r for r in records if r.ok]
    assert len(accepted) >= 3
    assert all(r.reason == "fill" for r in records if not r.ok and "baotou" in name)
    raster = im.read_raster(path)
    hand = []
    for far in ends:
        roi, mask = hand_roi(raster.data.shape, centre, far)
        try:
            hand.append(im.measure_edge(raster.data, roi=roi, mask=mask, dtype=raster.dtype))
        except im.ImgmtfError:
            continue
    families = normal_families([r.figures["normal_angle_deg"] for r in accepted]
                               + [h.normal_angle_deg for h in hand])
    scanned, by_hand = families[:len(accepted)], families[len(accepted):]
    for family in set(scanned):
        mine = [h for h, f in zip(hand, by_hand) if f == family]
        ours = [r for r, f in zip(accepted, scanned) if f == family]
        expected = combine([h.mtf50_cy_px for h in mine], [(h.mtf50_ci_cy_px.low, h.mtf50_ci_cy_px.high)
                                                            for h in mine], [h.rows_used for h in mine])
        got = combine([r.figures["mtf50_cy_px"] for r in ours], [r.figures["mtf50_ci_cy_px"] for r in ours],
                      [r.figures["rows_used"] for r in ours])
        assert got.value == pytest.approx(expected.value, rel=0.03)
    summary = [s for s in summarise_scan(records) if s.site["scope"] == "scene"]
    assert len(summary) == 2 and {s.figures["direction"] for s in summary} == {"oblique"}


@pytest.mark.parametrize("name, provenance", [
    ("sentinel2_b04_bagnolo.tif", "rdegoul/qgis-image-quality-toolset test/data/target1 (Apache-2.0)"),
    ("landsat9_b5_radiance_desert.tif", "rdegoul/qgis-image-quality-toolset test/data/target4 (Apache-2.0)"),
])
def test_map_projected_crops_scan_without_error_and_without_a_direction(name, provenance):
    path = real_scene(name, provenance)
    records = scan_scene(str(path), ScanSettings(intervals=im.Intervals("none")))
    assert records and not any(r.reason == "internal" for r in records)
    assert {r.site["direction"] for r in records} == {"unknown"}         # a CRS: rows are not along track


def test_accepted_half_edges_and_their_combination_carry_the_mtf_curve(quadrant_scans):
    _, records, summaries = quadrant_scans[False]
    accepted = [r for r in records if r.ok]
    for r in [*accepted, *summaries]:
        f, mtf = np.asarray(r.figures["frequencies_cy_px"]), np.asarray(r.figures["mtf"], float)
        assert mtf[0] == pytest.approx(1.0) and mtf[np.argmin(abs(f - 0.5))] == pytest.approx(
            r.figures["mtf_nyquist"], abs=1e-6)
    row = accepted[0].csv_row()
    assert row["mtf_at_0.50_cy_px"] == pytest.approx(accepted[0].figures["mtf_nyquist"], abs=1e-6)


def test_a_low_contrast_boundary_on_a_textured_field_is_not_accepted(tmp_path):
    # the target's dark quadrants meet a field of about their level: a short, noisy outer
    # boundary (SNR 37 on 21 rows, where 173 is needed) that read 0.036 low when accepted
    target = QuadrantTarget((60.52, 61.94), 10.6, (9300.0, 2000.0, 9200.0, 3900.0), 45.0)
    scene = render_quadrants(im.Sensor(), (121, 121), target, field_dn=3000 + texture((121, 121), 600, seed=2),
                             noise_std_dn=25.0, seed=2)
    path = tmp_path / "field.tif"
    im.write_geotiff(path, scene.image)
    records = scan_scene(str(path))
    for r in records:
        if r.ok:
            assert abs(r.figures["mtf_nyquist"] - float(scene.true_mtf(0.5, r.figures["normal_angle_deg"]))) < 0.015
    assert any(r.reason == "snr" and "too noisy for its length" in r.error for r in records)


def test_candidates_ends_are_rounded_as_before_a_half_edges_as_numpy_rounds_them():
    from imgmtf.scene.measure import _rounded_ends
    from imgmtf.scene.segments import Segment
    # the two roundings of 3846.965 differ: Python rounds its exact binary value, NumPy its product by 100
    value = 3846.965
    split = Segment(value, 1.0, value, 80.0)                        # a half-edge
    bar = Segment(value, 1.0, value, 80.0, width_px=3.0)           # a bar's centre line
    assert _rounded_ends([split, bar]) == [[round(np.float64(value), 2), 1.0, round(np.float64(value), 2), 80.0],
                                           [round(value, 2), 1.0, round(value, 2), 80.0]]
    assert round(np.float64(value), 2) != round(value, 2)


def test_the_records_are_the_same_measured_in_the_pieces_a_pool_of_workers_gets(quadrant_scans, monkeypatch):
    # with workers each tile's candidates are split into tasks, each reading the tile's window: one
    # candidate a task here, measured in this process, gives every record as the whole tile did
    import json

    import imgmtf.scene.measure as measure
    from imgmtf.records import to_json
    _, records, _ = quadrant_scans[True]
    whole = measure._batches
    pieces = []
    monkeypatch.setattr(measure, "_batches", lambda *a: pieces.extend(measure._split_batches(whole(*a), 100)) or pieces)

    def plain(rs):
        return [{k: v for k, v in json.loads(to_json(r)).items() if k != "run_utc"} for r in rs]
    assert plain(scan_scene(records[0].path)) == plain(records)
    assert len(pieces) > 1 and all(len(batch) == 1 for _, batch in pieces)


def test_a_scan_detecting_on_workers_has_their_fork_server_load_its_tasks_modules_first(tmp_path, monkeypatch):
    # the workers' imports start with the scan, once, not in each pool as its first task arrives;
    # a scan in this process starts none
    import importlib.util

    import imgmtf.parallel as parallel
    import imgmtf.scene.measure as measure
    path = tmp_path / "scene.tif"
    im.write_geotiff(path, (texture((600, 1000), 300, seed=2) + 3000).astype(np.uint16))
    started = []
    monkeypatch.setattr(parallel, "available_cores", lambda: 2)
    monkeypatch.setattr(measure, "prestart_workers", lambda *a: started.append(a))
    monkeypatch.setattr(measure, "detect_segments", lambda *a, **k: (np.zeros((0, 4)), np.zeros(0)))
    # (whether an earlier test of this process left a fork server running with them is set here)
    monkeypatch.setattr(measure, "preloaded", lambda modules: False)
    settings = ScanSettings(tile_px=256)            # 15 tiles: two workers
    assert scan_scene(str(path), settings, workers=1) == [] and started == []
    assert scan_scene(str(path), settings, workers=None) == []
    assert started == [(2, SCAN_TASK_MODULES)]
    # a fork server already running with the scan's modules (the command's) is not started again
    monkeypatch.setattr(measure, "preloaded", lambda modules: set(modules) == set(SCAN_TASK_MODULES))
    assert scan_scene(str(path), settings, workers=None) == [] and started == [(2, SCAN_TASK_MODULES)]
    assert all(importlib.util.find_spec(name) is not None for name in SCAN_TASK_MODULES)


def test_segments_found_here_that_promise_a_pool_start_its_fork_server_before_the_rois_are_planned(monkeypatch):
    import imgmtf.parallel as parallel
    import imgmtf.scene.measure as measure
    started = []
    monkeypatch.setattr(parallel, "available_cores", lambda: 2)
    monkeypatch.setattr(parallel, "can_preload", lambda: True)
    monkeypatch.setattr(measure, "prestart_workers", lambda *a: started.append(a))
    monkeypatch.setattr(measure, "preloaded", lambda modules: False)
    enough = 2 * measure.AUTO_PLANS_PER_WORKER
    # (segments, workers, detecting, scheduler): workers chosen, the tiles searched here, a pool's worth
    for args in [(enough - 1, None, 1, None), (enough, 2, 2, None), (enough, None, 2, None),
                 (enough, None, 1, "local")]:
        measure._prestart_for_candidates(*args)
    assert started == []
    measure._prestart_for_candidates(enough, None, 1, None)
    assert started == [(2, SCAN_TASK_MODULES)]
    monkeypatch.setattr(measure, "preloaded", lambda modules: True)          # (the command's, running)
    measure._prestart_for_candidates(enough, None, 1, None)
    assert len(started) == 1


def test_the_scan_module_loads_without_scipy_so_the_workers_fork_server_starts_first():
    # the segment graph's SciPy is imported by scan_scene once the workers' fork server has started,
    # so that the two imports overlap rather than follow each other
    import subprocess
    import sys
    code = "import sys, imgmtf.scene.measure; print(sorted(m for m in sys.modules if m.split('.')[0] == 'scipy'))"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout == "[]\n"


def test_a_scan_interrupted_before_any_outcome_keeps_every_candidate_unmeasured_ones_interrupted(
        quadrant_scans, monkeypatch):
    # the candidates' records are made as the first outcome arrives: an interrupt before it still gets them all
    import imgmtf.scene.measure as measure
    _, records, _ = quadrant_scans[False]

    def interrupted(*args, **options):
        raise KeyboardInterrupt
        yield
    monkeypatch.setattr(measure, "run_tasks", interrupted)
    with pytest.raises(KeyboardInterrupt) as caught:
        scan_scene(records[0].path)
    kept = caught.value.records
    assert len(kept) == len(records) and not any(r.ok for r in kept)
    assert {r.reason for r in kept if r.site.get("verdict_by") != "screen"} == {"interrupted"}
    assert sorted(r.reason for r in kept if r.site.get("verdict_by") == "screen") == sorted(
        r.reason for r in records if r.site.get("verdict_by") == "screen" and "roi_polygon_px" not in r.site)
