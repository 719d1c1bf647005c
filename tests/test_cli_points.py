"""The point kind on the command line: simulate --target points writes the
truth in its tags, measure --target points prints one record per direction,
a point chip measured as an edge or a bar is refused naming what it holds
and pointing to --target points, --plot draws the point figure."""
import json

import pytest
from click.testing import CliRunner

import imgmtf as im
from imgmtf.cli import main


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def points_chip(tmp_path_factory):
    path = tmp_path_factory.mktemp("points") / "points.tif"
    result = run("simulate", "--target", "points", "--size", 56, "--noise-std", 3, "--seed", 2, "--out", path)
    assert result.exit_code == 0, result.output
    assert "true MTF at Nyquist across track 0.2665, along track 0.2597" in result.output
    return path


def test_simulate_writes_the_truth_in_the_tags(points_chip):
    raster = im.read_raster(points_chip)
    assert raster.tags["TARGET_KIND"] == "points"
    assert float(raster.tags["TRUE_MTF_NYQUIST_ACROSS"]) == pytest.approx(im.Sensor().mtf_nyquist("across"), abs=1e-6)
    assert float(raster.tags["TRUE_MTF_NYQUIST_ALONG"]) == pytest.approx(im.Sensor().mtf_nyquist("along"), abs=1e-6)


def test_measure_points_prints_a_record_per_direction(points_chip, tmp_path):
    plot = tmp_path / "points_mtf.png"
    result = run("measure", "--target", "points", "--format", "json", "--plot", plot, points_chip)
    assert result.exit_code == 0, result.output
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert [r["direction"] for r in rows] == ["across-track", "along-track"]
    truth = {"across-track": im.Sensor().mtf_nyquist("across"), "along-track": im.Sensor().mtf_nyquist("along")}
    for row in rows:
        assert row["target"] == "points" and row["points_used"] == 16 and row["status"] == "ok"
        assert abs(row["mtf_nyquist"] - truth[row["direction"]]) < 0.02
        assert row["mtf_nyquist_ci"][0] < row["mtf_nyquist"] < row["mtf_nyquist_ci"][1]
        assert row["plot"] == str(plot)
    assert plot.stat().st_size > 10_000


@pytest.mark.parametrize("kind", ["edge", "pulse"])
def test_a_point_chip_measured_as_a_line_is_refused_naming_points(points_chip, kind):
    result = run("measure", "--target", kind, points_chip)
    assert result.exit_code == 1
    assert "holds 16 compact bright point targets" in result.output
    assert "--target points" in result.output


def test_an_edge_measured_as_points_is_refused_as_lines(tmp_path):
    path = tmp_path / "edge.tif"
    assert run("simulate", "--size", 50, "--noise-std", 3, "--seed", 1, "--out", path).exit_code == 0
    result = run("measure", "--target", "points", "--format", "json", path)
    row = json.loads(result.stdout)
    assert result.exit_code == 1 and row["reason"] == "not-points"
    assert "an edge or a bar, not point targets" in row["error"]


def test_point_options_are_refused_where_they_do_not_apply(tmp_path, points_chip):
    out = tmp_path / "x.tif"
    assert "does not apply" in run("simulate", "--target", "points", "--angle", 5, "--out", out).output
    assert "does not apply" in run("simulate", "--point-size", 1, "--out", out).output
    assert "--point-size applies to --target points only" in run("measure", "--point-size", 1, points_chip).output
