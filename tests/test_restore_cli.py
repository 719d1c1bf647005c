"""``imgmtf restore``: the issue's acceptance run, outputs and refusals."""
import json

import numpy as np
import pytest
from click.testing import CliRunner

import imgmtf as im
from imgmtf.cli import main
from imgmtf.sensor.stages import Detector, GaussianOptics


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def chip(tmp_path_factory):
    """An edge chip: 16-bit, Gaussian sigma 0.6 px and pixel, SNR 300, 160 x 160 px."""
    folder = tmp_path_factory.mktemp("restore")
    sensor = im.Sensor(1.0, [GaussianOptics(0.6, 0.6), Detector(1.0, 1.0)])
    rendered = im.render(sensor, im.Target("edge", 5.0, 200.0, 1200.0), 160, noise_std_dn=1000 / 300, seed=4)
    path = folder / "chip.tif"
    im.write_geotiff(path, rendered.image, provenance=rendered.provenance())
    sensor.to_toml(folder / "true.toml")
    return path


def test_fit_restore_measure_meets_the_target_and_the_noise_gain_holds(chip, tmp_path):
    fitted = tmp_path / "s.toml"
    assert run("fit", chip, "--stages", "optics,detector", "--out", fitted).exit_code == 0
    result = run("restore", chip, "--sensor", fitted, "--target-nyquist", 0.25, "--out", tmp_path / "r.tif",
                 "--format", "json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    assert report["status"] == "ok" and report["written"] == [str(tmp_path / "r.tif")]
    assert report["axes"]["across"]["achieved_mtf_nyquist"] == pytest.approx(0.25, abs=0.005)
    measured = json.loads(run("measure", "--format", "json", tmp_path / "r.tif").stdout)
    assert measured["mtf_nyquist"] == pytest.approx(0.25, abs=0.03)
    f, mtf = np.array(measured["frequencies_cy_px"]), np.array(measured["mtf"])
    assert mtf[f <= 0.5].max() < 1.10
    # a flat noise image restored alike (the same filter: the chip's noise and contrast given)
    noise = np.random.default_rng(5).normal(1000.0, 20.0, (300, 300))
    im.write_geotiff(tmp_path / "flat.tif", np.rint(noise).astype(np.uint16))
    design = report["filter"]
    result = run("restore", tmp_path / "flat.tif", "--sensor", fitted, "--target-nyquist", 0.25,
                 "--noise-std", repr(design["noise_std_dn"]), "--signal-std", repr(design["signal_std_dn"]),
                 "--out", tmp_path / "flat_r.tif", "--format", "json")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["noise_gain"] == pytest.approx(report["noise_gain"], rel=1e-9)
    before = im.read_raster(tmp_path / "flat.tif").data[40:-40, 40:-40]
    after = im.read_raster(tmp_path / "flat_r.tif").data[40:-40, 40:-40]
    # the issue asks for 25 %; white noise gives the closed form to its sampling scatter
    assert after.std() / before.std() == pytest.approx(report["noise_gain"], rel=0.05)


def test_text_report_kernel_and_figure(chip, tmp_path):
    result = run("restore", chip, "--sensor", chip.parent / "true.toml", "--target-nyquist", 0.3,
                 "--kernel-size", 9, "--max-noise-gain", 1.5, "--kernel", tmp_path / "k.npy",
                 "--plot", tmp_path / "r.png", "--out", tmp_path)
    assert result.exit_code == 0, result.output
    assert "9 x 9 kernel" in result.stdout and "limited to 1.5" in result.stdout
    assert "warning: the noise-gain limit 1.5 won over the target" in result.stdout
    taps = np.load(tmp_path / "k.npy")
    assert taps.shape == (9, 9) and np.sqrt((taps ** 2).sum()) == pytest.approx(1.5, abs=1e-3)
    assert (tmp_path / "chip_restored.tif").exists() and (tmp_path / "r.png").stat().st_size > 20_000


def test_a_batch_keeps_going_past_a_bad_file(chip, tmp_path):
    bad = tmp_path / "bad.tif"
    bad.write_text("junk")
    result = run("restore", bad, chip, "--sensor", chip.parent / "true.toml", "--target-nyquist", 0.3,
                 "--out", tmp_path / "out", "--format", "json")
    assert result.exit_code == 1
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert [r["status"] for r in rows] == ["error", "ok"] and rows[0]["reason"] == "unreadable"
    assert (tmp_path / "out" / "chip_restored.tif").exists() and not (tmp_path / "out" / "bad_restored.tif").exists()


@pytest.mark.parametrize("options, words", [
    (["--target-nyquist", "0"], "--target-nyquist"),
    (["--target-nyquist", "1.5"], "--target-nyquist"),
    (["--target-nyquist", "nan"], "not a finite number"),
    (["--target-nyquist", "0.3", "--kernel-size", "8"], "must be odd"),
    (["--target-nyquist", "0.3", "--kernel-size", "1"], "--kernel-size"),
    (["--target-nyquist", "0.3", "--max-noise-gain", "0.5"], "--max-noise-gain"),
    (["--target-nyquist", "0.3", "--tile", "10"], "--tile"),
    (["--target-nyquist", "0.3", "--noise-std", "-1"], "--noise-std"),
    (["--target-nyquist", "0.3", "--saturation", "9,1"], "LO < HI"),
    ([], "Missing option '--target-nyquist'"),
])
def test_bad_options_exit_2(chip, tmp_path, options, words):
    result = run("restore", chip, "--sensor", chip.parent / "true.toml", "--out", tmp_path / "r.tif", *options)
    assert result.exit_code == 2 and words in result.output


@pytest.mark.parametrize("make, words", [
    (lambda p: p / "missing.tif", "no such file"),
    (lambda p: (p / "notes.tif").write_text("junk") and p / "notes.tif", "not an image GDAL can read"),
    (lambda p: p, "no image files"),
])
def test_unreadable_inputs_exit_1(chip, tmp_path, make, words):
    result = run("restore", make(tmp_path), "--sensor", chip.parent / "true.toml", "--target-nyquist", 0.3,
                 "--out", tmp_path / "r.tif")
    assert result.exit_code == 1 and words in result.output and "Traceback" not in result.output


def test_bad_sensor_and_outputs_exit_1(chip, tmp_path):
    (tmp_path / "bad.toml").write_text("gsd_m = [")
    common = [chip, "--target-nyquist", 0.3]
    cases = [
        (["--sensor", tmp_path / "bad.toml", "--out", tmp_path / "r.tif"], "malformed TOML"),
        (["--sensor", tmp_path / "none.toml", "--out", tmp_path / "r.tif"], "cannot read sensor file"),
        (["--sensor", chip.parent / "true.toml", "--out", tmp_path / "no" / "r.tif"], "does not exist"),
        (["--sensor", chip.parent / "true.toml", "--out", chip], "overwrite its own input"),
    ]
    for options, words in cases:
        result = run("restore", *common, *options)
        assert result.exit_code == 1 and words in result.output, (options, result.output)
    # malformed options are usage errors (exit 2), as in every command
    for options, words in ((["--kernel", tmp_path / "k.csv"], ".npy (NumPy) or .txt"),
                           (["--plot", tmp_path / "r.xyz"], "a figure is written as")):
        result = run("restore", *common, "--sensor", chip.parent / "true.toml", "--out", tmp_path / "r.tif", *options)
        assert result.exit_code == 2 and words in result.output, (options, result.output)
    assert run("restore", chip, chip, "--sensor", chip.parent / "true.toml", "--target-nyquist", 0.3,
               "--out", tmp_path / "r.tif").exit_code == 2          # two images, one file: a contradiction


MISFIT_TOML = """[fit]
misfit = true
reduced_chi_square = 3.8
misfit_p = 0.0
misfit_fraction = 0.025
stages = ["optics", "detector"]
sources = ["chip.tif"]

[sensor]
gsd_m = 1.0

[[sensor.stages]]
stage = "optics"
sigma_x_m = 0.6
sigma_y_m = 0.6

[[sensor.stages]]
stage = "detector"
width_x_m = 1.0
width_y_m = 1.0
"""


def test_a_misfit_sensor_is_refused_unless_allowed_and_the_report_says_so(chip, tmp_path):
    toml = tmp_path / "misfit.toml"
    toml.write_text(MISFIT_TOML)
    result = run("restore", chip, "--sensor", toml, "--target-nyquist", 0.25, "--out", tmp_path / "r.tif")
    assert result.exit_code == 1 and not (tmp_path / "r.tif").exists()
    assert result.output == (f"imgmtf: error: {toml}: the model (optics, detector) does not fit the 1 edge(s) it was "
                             "fitted to (reduced chi-square 3.8, misfit p 0, structure 2.50 % of the step): a filter "
                             "designed from it inverts a blur the sensor does not have (--allow-misfit restores with "
                             "it anyway)\n")
    result = run("restore", chip, "--sensor", toml, "--target-nyquist", 0.25, "--out", tmp_path / "r.tif",
                 "--allow-misfit")
    assert result.exit_code == 0, result.output
    assert "sensor: the model (optics, detector) does not fit the 1 edge(s)" in result.output
    assert "warning: MISFIT SENSOR, restored with anyway: " in result.output
    result = run("restore", chip, "--sensor", toml, "--target-nyquist", 0.25, "--out", tmp_path / "r.tif",
                 "--allow-misfit", "--format", "json")
    report = json.loads(result.stdout)
    assert report["sensor_fit"]["misfit"] is True and report["warnings"][0].startswith("MISFIT SENSOR")
    # a sensor that fits says so; one without a record (written by hand) makes no claim
    result = run("restore", chip, "--sensor", chip.parent / "true.toml", "--target-nyquist", 0.25,
                 "--out", tmp_path / "t.tif")
    assert result.exit_code == 0 and "sensor:" not in result.output and "MISFIT" not in result.output
    # (a fitted sensor that fits says so: docs/restore.md's examples show it)


def test_a_restoration_whose_noise_dominates_is_refused_unless_a_noise_budget_is_given(chip, tmp_path):
    # the chip's sensor (MTF 0.107 at Nyquist) lifted to 0.6: a noise gain of 5.3 (0.5 asks 4.2, 0.4 asks 3.2)
    true = chip.parent / "true.toml"
    result = run("restore", chip, "--sensor", true, "--target-nyquist", 0.6, "--out", tmp_path / "r.tif")
    assert result.exit_code == 1 and not (tmp_path / "r.tif").exists()
    assert "the filter multiplies the noise by 5.3 (over 4)" in result.output
    assert "(--max-noise-gain G sets the noise budget" in result.output
    result = run("restore", chip, "--sensor", true, "--target-nyquist", 0.6, "--out", tmp_path / "r.tif",
                 "--max-noise-gain", 6)
    assert result.exit_code == 0 and "warning: NOISE DOMINATES: the filter multiplies the noise by 5.3" in result.output
    result = run("restore", chip, "--sensor", true, "--target-nyquist", 0.4, "--out", tmp_path / "r.tif")
    assert result.exit_code == 0 and "NOISE" not in result.output
    # a batch reports each refusal with its hint and goes on
    result = run("restore", chip, tmp_path / "r.tif", "--sensor", true, "--target-nyquist", 0.6,
                 "--out", tmp_path / "b")
    assert result.exit_code == 1 and result.output.count("(--max-noise-gain G sets the noise budget") == 2
    assert "0 restored, 2 failed" in result.output


def test_a_target_below_the_sensor_s_own_mtf_is_noted_as_blurring(chip, tmp_path):
    result = run("restore", chip, "--sensor", chip.parent / "true.toml", "--target-nyquist", 0.05,
                 "--out", tmp_path / "r.tif")
    assert result.exit_code == 0
    assert ("warning: the target MTF at Nyquist, 0.05, is below the sensor's own across track, 0.1077: the filter "
            "blurs across track rather than sharpening") in result.output
    assert "below the sensor's own along track, 0.1077" in result.output
    result = run("restore", chip, "--sensor", chip.parent / "true.toml", "--target-nyquist", 0.2,
                 "--out", tmp_path / "r.tif")
    assert result.exit_code == 0 and "blurs" not in result.output


def test_baotou_is_refused_whole_by_fit_with_the_flag_that_forces_it():
    """The real Baotou L0R chip (JorgeGIlG/MTF_Estimator, GPL-3.0, read in place) fitted whole is
    refused for its fill; fitted to its four half-edges and restored from the fitted TOML, it is
    refused twice and then forced: docs/restore.md shows that session and tests/test_docs.py runs it."""
    from conftest import real_scene
    path = real_scene("baotou_l0r_checkerboard.tif", "JorgeGIlG/MTF_Estimator (GPL-3.0, read in place)")
    result = run("fit", path)
    assert result.exit_code == 1 and "--force measures it anyway" in result.output
