"""The star kind on the command line: simulate --target star writes the truth
in its tags, measure --target star --format json prints one record per
direction (direction_deg, mtf_nyquist and its interval, mtf50_cy_px) within
the truth's reach (its figure, drawn by --plot as the kind names it, is
plot/star.py's, whose examples build it), and a chip with no star is
refused as not-a-star with the hint of the other kinds."""
import json

import pytest
from click.testing import CliRunner

import imgmtf as im
from imgmtf.cli import main


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def star_chip(tmp_path_factory):
    path = tmp_path_factory.mktemp("star") / "star.tif"
    result = run("simulate", "--target", "star", "--size", 121, "--noise-std", 5, "--seed", 2, "--out", path)
    assert result.exit_code == 0, result.output
    assert "sinusoidal Siemens star of 46 cycles (Nyquist at r = 14.6 px)" in result.output
    return path


def test_simulate_writes_the_truth_in_the_tags(star_chip):
    raster = im.read_raster(star_chip)
    assert raster.tags["TARGET_KIND"] == "star" and raster.tags["STAR_CYCLES"] == "46"
    assert float(raster.tags["TRUE_MTF_NYQUIST_ALONG"]) == pytest.approx(im.Sensor().mtf_nyquist("along"), abs=1e-6)
    assert float(raster.tags["TRUE_MTF50_ACROSS_CY_PX"]) == pytest.approx(im.Sensor().mtf50_cy_px("across"), abs=1e-4)


def test_measure_star_prints_a_record_per_direction(star_chip):
    result = run("measure", "--target", "star", "--format", "json", star_chip)
    assert result.exit_code == 0, result.output
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert [r["direction_deg"] for r in rows] == [0.0, 22.5, 45.0, 67.5, 90.0, 112.5, 135.0, 157.5]
    assert rows[0]["direction"] == "across-track" and rows[4]["direction"] == "along-track"
    sensor = im.Sensor()
    for row in rows:
        assert row["target"] == "star" and row["status"] == "ok" and row["star_cycles"] == 46
        truth = float(abs(sensor.normal_transfer(0.5, row["direction_deg"])))
        assert abs(row["mtf_nyquist"] - truth) < 0.03
        assert row["mtf_nyquist_ci"][0] < row["mtf_nyquist"] < row["mtf_nyquist_ci"][1]
    assert rows[0]["mtf50_cy_px"] == pytest.approx(sensor.mtf50_cy_px("across"), rel=0.03)


def test_an_edge_measured_as_a_star_is_refused(tmp_path):
    path = tmp_path / "edge.tif"
    assert run("simulate", "--size", 50, "--noise-std", 3, "--seed", 1, "--out", path).exit_code == 0
    result = run("measure", "--target", "star", path)
    assert result.exit_code == 1
    assert "no Siemens star about" in result.output and "--target edge, pulse, points or double-bar" in result.output


def test_star_options_apply_to_stars_only(tmp_path):
    result = run("simulate", "--cycles", 20, "--out", tmp_path / "edge.tif")
    assert result.exit_code == 2 and "--cycles does not apply to --target edge" in result.output
    result = run("simulate", "--target", "star", "--spacing", 20, "--out", tmp_path / "star.tif")
    assert result.exit_code == 2 and "--spacing does not apply to --target star" in result.output


def test_a_star_measured_as_an_edge_is_refused_naming_the_star(star_chip):
    result = run("measure", "--target", "edge", "--format", "json", star_chip)
    assert result.exit_code == 1
    row = json.loads(result.stdout.splitlines()[0])
    assert row["reason"] == "star" and "sinusoidal Siemens star of 46 cycles" in row["error"]
    assert "--target star" in run("measure", "--target", "edge", star_chip).output


def test_a_star_row_keeps_the_columns_and_shows_no_fwhm_it_lacks():
    from imgmtf.cli.tables import text_row
    record = {"path": "star.tif", "status": "ok", "normal_angle_deg": 112.5, "tilt_deg": None,
              "direction": "112.5deg", "snr": 98.0, "mtf_nyquist": 0.26, "mtf_nyquist_ci": [0.25, 0.27],
              "mtf50_cy_px": 0.36, "fwhm_px": None, "star_cycles": 46, "gsd_m": 1.0, "mtf50_cy_m": 0.36,
              "fwhm_m": None}
    row, ground = text_row(record, "star", path_width=8).splitlines()
    across = text_row({**record, "direction": "across-track"}, "star", path_width=8).splitlines()[0]
    assert len(row) == len(across) and row.index("0.2600") == across.index("0.2600")
    assert ground.endswith("MTF50 0.36 cy/m") and "FWHM" not in ground
