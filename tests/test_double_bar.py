"""Double bars (imgmtf.estimate.double_bar, .fit.bars, .bar_pair): the
pair's transfer and image against closed forms; MTF at Nyquist of issue
34's two pairs through Gaussian sigma 0.39 px + pixel, tilted 5 deg (the
second pair's transfer is zero at Nyquist: only the model fit reads it);
the same chips refused as one bar; the fit of bars; the command line."""
import json

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.special import erf

import imgmtf
from imgmtf.cli.main import main
from imgmtf.errors import ParameterError, UnsuitableTargetError
from imgmtf.estimate.bar_pair import bar_pair
from imgmtf.estimate.double_bar import pair_transfer
from imgmtf.estimate.fit.bars import bar_profile, fit_bars
from imgmtf.kinds.double_bar import double_bar_response
from imgmtf.kinds.pulse import bar_response
from imgmtf.sensor.stages.detector import Detector
from imgmtf.sensor.stages.optics import GaussianOptics

SENSOR = imgmtf.Sensor(1.0, [GaussianOptics(0.39, 0.39), Detector()])
PAIRS = [(0.6, 1.2), (1.0, 2.0)]
SNR_100_DN = 10.0            # the scene's contrast (1000 DN) over 100


def chip(width, gap, noise=0.0, seed=None, size=48):
    return imgmtf.render(SENSOR, imgmtf.Target("double-bar", 5.0, width_px=width, gap_px=gap), size,
                         noise_std_dn=noise, seed=seed)


def test_the_pair_transfer_is_the_transform_of_two_boxes():
    x = (np.arange(-4000, 4000) + 0.5) * 0.001          # midpoints: the boxes' sides fall between samples
    width, gap = 0.6, 1.2
    boxes = double_bar_response(x, lambda d: (d > 0).astype(float), width, gap)
    f = np.array([0.1, 0.278, 0.5, 0.9])
    transform = np.cos(2 * np.pi * f[:, None] * x[None, :]) @ boxes / boxes.sum()
    assert np.allclose(transform, pair_transfer(f, width, gap), atol=1e-4)
    assert pair_transfer(0.5, 1.0, 2.0) == pytest.approx(0.0, abs=1e-15)


def test_a_double_bar_renders_as_its_two_bars():
    response = SENSOR.line_response(5.0, reach_px=10.0)
    d = np.linspace(-6.0, 6.0, 97)
    pair = imgmtf.Target("double-bar", 5.0, 0.0, 1.0, width_px=1.0, gap_px=2.0).image_values(d, response.esf)
    bars = bar_response(d - 1.5, response.esf, 1.0) + bar_response(d + 1.5, response.esf, 1.0)
    assert np.allclose(pair, bars, atol=1e-12)
    with pytest.raises(ParameterError, match="double-bar gap must be > 0"):
        imgmtf.Target("double-bar", 5.0, width_px=1.0)
    with pytest.raises(ParameterError, match="has no gap"):
        imgmtf.Target("pulse", 5.0, width_px=1.0, gap_px=2.0)


@pytest.mark.parametrize("width, gap", PAIRS)
def test_mtf_at_nyquist_of_the_issues_pairs(width, gap):
    for noise, tolerance in ((0.0, 0.01), (SNR_100_DN, 0.02)):
        c = chip(width, gap, noise, seed=7)
        truth = float(c.true_mtf(0.5))
        result = imgmtf.measure_double_bar(c.image, width_px=width, gap_px=gap)
        assert abs(result.mtf_nyquist - truth) < tolerance
        # the 1 px pair's transfer is 0 at Nyquist: read off the fitted model, never divided
        assert result.model_fitted == (abs(pair_transfer(0.5, width, gap)) < 0.3)
        assert result.to_dict(curves=False)["gap_px"] == gap


@pytest.mark.parametrize("width, gap", PAIRS)
def test_the_same_chips_as_one_bar_give_no_number(width, gap):
    c = chip(width, gap, SNR_100_DN, seed=7)
    for given in (None, width, 2 * width + gap):
        with pytest.raises(UnsuitableTargetError, match=rf"two parallel bars {width + gap:.1f} px apart") as info:
            imgmtf.measure_pulse(c.image, width_px=given)
        assert info.value.reason == "double-bar"
    # asked for as an edge, the refusal names the two bars at once (not "a bar", then "two bars")
    with pytest.raises(UnsuitableTargetError, match=rf"two parallel bars {width + gap:.1f} px apart .*not an edge"
                       ) as info:
        imgmtf.measure_edge(c.image)
    assert info.value.reason == "double-bar"


def test_one_bar_through_a_blur_is_never_two():
    x = np.linspace(-10.0, 10.0, 801)
    for sigma in (0.3, 0.6):
        def esf(d, sigma=sigma):
            return 0.5 * (1.0 + erf(d / (sigma * np.sqrt(2.0))))
        for width in (0.3, 1.0, 2.0, 4.0, 8.0):
            profile = bar_response(x, esf, width)
            assert bar_pair(x, profile / profile.max()) is None
        pair = double_bar_response(x, esf, 0.6, 1.2)
        # the peaks' distance: the bars' centres', drawn together a little by the blur
        assert bar_pair(x, pair / pair.max()).apart_px == pytest.approx(1.8, abs=0.1)


def test_the_fit_takes_bars_and_double_bars_together():
    pair = chip(1.0, 2.0, size=40)
    bar = imgmtf.render(SENSOR, imgmtf.Target("pulse", 84.0, width_px=0.8), 40)
    profiles = [bar_profile(imgmtf.measure_double_bar(pair.image, width_px=1.0, gap_px=2.0), "pair", 1.0),
                bar_profile(imgmtf.measure_pulse(bar.image, width_px=0.8), "bar", 1.0)]
    fit = fit_bars(profiles)
    assert [p.status for p in fit.parameters] == ["fitted"] * 4      # across from the pair, along from the bar
    assert fit.mtf_nyquist[0] == pytest.approx(float(pair.true_mtf(0.5)), abs=0.003)
    assert fit.mtf_nyquist[1] == pytest.approx(float(bar.true_mtf(0.5)), abs=0.003)
    with pytest.raises(ParameterError, match="takes bars and double bars"):
        bar_profile(imgmtf.measure_edge(imgmtf.render(SENSOR, imgmtf.Target("edge", 5.0), 40).image), "edge")


def test_the_command_line_simulates_measures_fits_and_refuses(tmp_path):
    runner = CliRunner()
    path = str(tmp_path / "pair.tif")
    made = runner.invoke(main, ["simulate", "--target", "double-bar", "--pulse-width", "1", "--gap", "2",
                                "--angle", "5", "--size", "40", "--out", path])
    assert made.exit_code == 0, made.output
    measured = runner.invoke(main, ["measure", "--target", "double-bar", "--pulse-width", "1", "--gap", "2",
                                    "--format", "json", path])
    record = json.loads(measured.output)
    assert measured.exit_code == 0 and record["model_fitted"] is True and record["gap_px"] == 2.0
    fitted = runner.invoke(main, ["fit", "--target", "double-bar", "--pulse-width", "1", "--gap", "2",
                                  "--format", "json", path])
    assert fitted.exit_code == 0, fitted.output
    assert json.loads(fitted.output)["profiles"][0]["mtf_nyquist"] == pytest.approx(record["mtf_nyquist"], abs=1e-3)
    refused = runner.invoke(main, ["measure", "--target", "pulse", "--pulse-width", "1", path])
    assert refused.exit_code == 1
    assert "two parallel bars 3.0 px apart" in refused.output and "--target double-bar" in refused.output
    no_gap = runner.invoke(main, ["measure", "--target", "double-bar", "--pulse-width", "1", path])
    assert no_gap.exit_code == 2 and "--gap" in no_gap.output


def test_where_the_pair_hides_the_mtf_the_model_curve_and_its_band_are_shown():
    c = chip(1.0, 2.0, SNR_100_DN, seed=3, size=40)
    result = imgmtf.measure_double_bar(c.image, width_px=1.0, gap_px=2.0)
    f, model = result.frequencies_cy_px, result.model_mtf
    nyquist = int(np.argmin(np.abs(f - 0.5)))
    assert np.isnan(result.mtf[nyquist]) and result.model_figures == ("mtf_nyquist",)
    assert np.array_equal(model.frequencies_cy_px, f) and np.isfinite(model.mtf).all()
    assert model.mtf[nyquist] == pytest.approx(result.mtf_nyquist, abs=1e-9)
    assert model.low[nyquist] == pytest.approx(result.mtf_nyquist_ci.low, abs=1e-9)
    assert np.all(model.low <= model.mtf) and np.all(model.mtf <= model.high)
    assert np.abs(model.mtf - c.true_mtf(f))[f <= 0.75].max() < 0.02
    record = result.to_dict()
    assert len(record["model_mtf"]) == len(record["mtf"]) == f.size and len(record["model_mtf_ci"]) == f.size
    from imgmtf.plot import plot_mtf
    labels = plot_mtf(result).axes[0].get_legend_handles_labels()[1]
    assert any(label.startswith("sensor model (optics,detector) fitted") for label in labels)
    assert any(label.startswith("MTF@Nyquist") and label.endswith("(model)") for label in labels)
    # where the transfer is divided, nothing is the model's
    divided = imgmtf.measure_double_bar(chip(0.6, 1.2, size=40).image, width_px=0.6, gap_px=1.2)
    assert divided.model_mtf is None and "model_mtf" not in divided.to_dict()


def test_fit_of_bars_writes_the_sensor_starts_from_one_holds_and_refuses_what_is_the_edges(tmp_path):
    runner = CliRunner()
    path, toml = str(tmp_path / "pair.tif"), str(tmp_path / "fitted.toml")
    imgmtf.write_geotiff(path, chip(1.0, 2.0, size=40).image, gsd_m=1.0)
    bars = ["fit", "--target", "double-bar", "--pulse-width", "1", "--gap", "2", path]
    written = runner.invoke(main, [*bars, "--out", toml])
    assert written.exit_code == 0 and f"wrote {toml}" in written.output, written.output
    record, sensor = imgmtf.read_fit_record(toml), imgmtf.Sensor.from_toml(toml)
    assert record.misfit is False and record.sources == (path,) and [s.name for s in sensor.stages] == [
        "optics", "detector"]
    held = runner.invoke(main, [*bars, "--sensor", toml, "--hold", "detector", "--format", "json"])
    assert held.exit_code == 0, held.output
    parameters = {p["name"]: p for p in json.loads(held.output)["parameters"]}
    assert parameters["width_x_m"]["status"] == "held" and parameters["sigma_x_m"]["status"] == "fitted"
    assert parameters["width_x_m"]["value"] == pytest.approx(sensor.stages[1].width_x_m)
    for flag, value, why in (("--plot", "fit.png", "imgmtf measure --plot"), ("--campaign", "store", "misfit test"),
                             ("--hold", "motion", "cannot hold 'motion'")):
        refused = runner.invoke(main, [*bars, flag, value])
        assert refused.exit_code == 2 and why in refused.output, refused.output
