"""A restoration designed from the MTF a scan measured without a model: the
tabulated stage against the transfer it was read from, the scan's rows it
takes, and restore --measured end to end."""
import json

import numpy as np
import pytest
from click.testing import CliRunner
from numpy.testing import assert_allclose

import imgmtf as im
from imgmtf.cli import main
from imgmtf.errors import ImgmtfError, ParameterError
from imgmtf.restore.measured import measured_sensor, read_scan_rows
from imgmtf.sensor import stages as st

TRUTH = im.Sensor(1.0, [st.GaussianOptics(0.35, 0.45), st.Detector(1.0, 1.0)])      # separable
F = np.linspace(0.0, 0.8, 161)


def rows(sensor=TRUTH, assumption="separable", scope="scene"):
    return [{"summary": "sections", "scope": scope, "direction": f"{d}-track", "assumption": assumption,
             "chosen_assumption": assumption, "frequencies_cy_px": F.tolist(),
             "mtf": sensor.mtf(F, d).tolist(), "aspect": 1.0} for d in ("across", "along")]


def test_a_separable_table_is_the_transfer_it_was_read_from():
    stage = measured_sensor(rows()).stages[0]
    u, v = np.meshgrid(np.linspace(-0.5, 0.5, 11), np.linspace(-0.5, 0.5, 11))
    assert_allclose(stage.transfer(u, v, 1.0), TRUTH.transfer(u, v), atol=2e-4)   # linear between 0.005 cy/px
    beyond = stage.transfer(np.array([0.8, 0.9, 1.2]), 0.0, 1.0)
    assert beyond[0] == pytest.approx(float(TRUTH.mtf(0.8)), rel=1e-9) and beyond[1] < beyond[0] and beyond[2] < 1e-6


def test_an_elliptical_table_is_the_pixel_times_a_stretched_remainder():
    # an isotropic Butterworth over the pixel is elliptical with aspect 1: its 2-D MTF off the axes too
    truth = im.Sensor(1.0, [st.Electronics(0.6), st.Detector(1.0, 1.0)])
    stage = measured_sensor(rows(truth, "elliptical")).stages[0]
    assert stage.combination == "elliptical"
    u, v = np.meshgrid(np.linspace(-0.5, 0.5, 11), np.linspace(-0.5, 0.5, 11))
    assert_allclose(stage.transfer(u, v, 1.0), truth.transfer(u, v), atol=5e-4)


def test_the_rows_the_scan_chose_are_taken_and_none_is_refused(tmp_path):
    chosen = rows()
    other = [{**r, "assumption": "elliptical", "mtf": [1.0] * F.size} for r in chosen]
    sensor = measured_sensor(other + chosen + rows(scope="target"))
    assert sensor.mtf_nyquist("across") == pytest.approx(TRUTH.mtf_nyquist("across"), abs=1e-9)
    # an image without track information names its axes: horizontal across its columns, vertical along
    axes = [{**r, "direction": {"across-track": "horizontal", "along-track": "vertical"}[r["direction"]]}
            for r in chosen]
    assert measured_sensor(axes).mtf_nyquist("along") == pytest.approx(TRUTH.mtf_nyquist("along"), abs=1e-9)
    with pytest.raises(ImgmtfError, match="no across- and along-track") as refused:
        measured_sensor(chosen[:1], "scan.jsonl")
    assert refused.value.reason == "no-target"
    path = tmp_path / "scan.jsonl"
    path.write_text("not json\n")
    with pytest.raises(ImgmtfError, match="scan.jsonl: line 1 is not JSON"):
        read_scan_rows(path)
    with pytest.raises(ParameterError, match="combination"):
        st.MeasuredMTF((0.0, 1.0), (1.0, 0.5), (1.0, 0.5), "radial")


def test_restore_measured_brings_the_measured_mtf_to_the_target(tmp_path):
    chip = im.render(TRUTH, im.Target("edge", 6.0, 200.0, 1200.0), 100, noise_std_dn=1.0, seed=2)
    image, scan = tmp_path / "edge.tif", tmp_path / "scan.jsonl"
    im.write_geotiff(image, chip.image)
    scan.write_text("".join(json.dumps(r) + "\n" for r in rows()))
    runner = CliRunner()
    result = runner.invoke(main, ["restore", str(image), "--measured", str(scan), "--target-nyquist", "0.3",
                                  "--out", str(tmp_path / "restored.tif"), "--format", "json"])
    assert result.exit_code == 0, result.output
    done = json.loads(result.output.splitlines()[-1])
    assert done["sensor_file"] == str(scan)
    for axis in ("across", "along"):
        assert done["axes"][axis]["achieved_mtf_nyquist"] == pytest.approx(0.3, abs=0.01)
        assert done["axes"][axis]["system_mtf_nyquist"] == pytest.approx(TRUTH.mtf_nyquist(axis), abs=1e-4)
    for given in ([], ["--sensor", str(tmp_path / "s.toml"), "--measured", str(scan)]):
        refused = runner.invoke(main, ["restore", str(image), *given, "--target-nyquist", "0.3",
                                       "--out", str(tmp_path / "r2.tif")])
        assert refused.exit_code == 2 and "--sensor FILE" in refused.output


def test_a_measured_sensor_is_listed_drawn_and_saved_by_imgmtf_sensor(tmp_path):
    path, again = tmp_path / "measured.toml", tmp_path / "again.toml"
    measured_sensor(rows()).to_toml(path)
    result = CliRunner().invoke(main, ["sensor", "--sensor", str(path), "--plot", str(tmp_path / "s.png"),
                                       "--save", str(again)])
    assert result.exit_code == 0, result.output
    assert "frequencies_cy_px [161 values, 0 to 0.8] cy/px, across [161 values, 1 to" in result.output
    assert "combination separable" in result.output and (tmp_path / "s.png").is_file()
    assert again.read_text().split("\n")[1:] == path.read_text().split("\n")[1:]


def test_a_measured_mtf_is_no_stage_to_fit():
    chip = im.render(TRUTH, im.Target("edge", 6.0), 60).image
    with pytest.raises(ParameterError, match="stage 'measured' has no parameter to fit"):
        im.fit_sensor([chip], stages="optics,measured")
