import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import imgmtf as im
from imgmtf.errors import ConfigError, FileWriteError, ParameterError


def test_psf_fft_matches_analytic_transfer_to_twice_nyquist(paper_sensor):
    psf = paper_sensor.psf(20)
    n = psf.data.shape[0]
    f = np.fft.fftfreq(n, d=psf.step_m)
    measured = np.fft.fft2(np.fft.ifftshift(psf.data)).real
    analytic = paper_sensor.transfer(f[None, :], f[:, None])
    band = (np.abs(f[None, :]) <= 1.0) & (np.abs(f[:, None]) <= 1.0)   # 2 x Nyquist at 1 m GSD
    assert np.abs(measured - analytic)[band].max() < 1e-3
    assert psf.data.sum() == pytest.approx(1.0)
    assert n % 2 == 1 and psf.data.argmax() == (n // 2) * n + n // 2


def test_gaussian_only_fwhm_is_2_3548_sigma():
    for sigma in (0.3, 0.39, 0.8):
        s = im.Sensor(optics_sigma_x_m=sigma, optics_sigma_y_m=sigma, detector_width_x_m=0,
                      detector_width_y_m=0, motion_m=0, electronics_cutoff_cy_m=0)
        expected = 2 * math.sqrt(2 * math.log(2)) * sigma
        assert abs(s.fwhm_m("across") - expected) < 1e-3
        assert abs(s.fwhm_m("along") - expected) < 1e-3


def test_motion_makes_along_track_wider_and_softer(paper_sensor):
    assert paper_sensor.fwhm_m("along") > paper_sensor.fwhm_m("across")
    assert paper_sensor.mtf_nyquist("along") < paper_sensor.mtf_nyquist("across")


def test_mtf_nyquist_is_product_of_stages(paper_sensor):
    f = 0.5
    expected = (math.exp(-2 * math.pi**2 * 0.39**2 * f**2) * np.sinc(f) * np.sinc(0.0)
                / (1 + (f / 1.4) ** 2))
    assert paper_sensor.mtf_nyquist("across") == pytest.approx(expected, rel=1e-12)
    assert paper_sensor.mtf_nyquist("along") == pytest.approx(expected * np.sinc(0.25 * 0.5), rel=1e-12)


def test_normal_transfer_rotates_between_axes(paper_sensor):
    f = np.linspace(0, 1, 11)
    assert_allclose(paper_sensor.normal_transfer(f, 0.0), paper_sensor.mtf(f, "across"))
    assert_allclose(paper_sensor.normal_transfer(f, 90.0), paper_sensor.mtf(f, "along"), atol=1e-15)


def test_lsf_integrates_to_one(paper_sensor):
    x, lsf = paper_sensor.lsf("along")
    assert np.sum(lsf) * (x[1] - x[0]) == pytest.approx(1.0, abs=1e-9)


def test_components_each_keep_one_stage(paper_sensor):
    parts = paper_sensor.components()
    assert set(parts) == {"optics", "detector", "motion", "electronics"}
    assert parts["motion"].mtf_nyquist("across") == 1.0
    assert parts["optics"].fwhm_m() == pytest.approx(2.35482 * 0.39, rel=1e-4)


def test_toml_round_trip(tmp_path):
    s = im.Sensor(gsd_m=0.5, motion_m=0.1)
    path = tmp_path / "s.toml"
    s.to_toml(path)
    assert im.Sensor.from_toml(path) == s


def test_toml_top_level_keys_and_defaults(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text("gsd_m = 2.0\n")
    assert im.Sensor.from_toml(path) == im.Sensor(gsd_m=2.0)


@pytest.mark.parametrize("text, message", [
    ("[sensor\ngsd_m = 1", "malformed TOML"),
    ("[sensor]\nfocal = 3\n", r"unknown sensor parameter\(s\) focal"),
    ("[sensor]\nmotion_m = -1\n", "motion_m must be finite and >= 0"),
    ("[sensor]\ngsd_m = 'x'\n", "gsd_m must be a number"),
])
def test_bad_toml_is_a_config_error_naming_the_file(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=message) as err:
        im.Sensor.from_toml(path)
    assert str(path) in str(err.value)


def test_missing_and_unwritable_files(tmp_path):
    with pytest.raises(ConfigError, match="cannot read"):
        im.Sensor.from_toml(tmp_path / "none.toml")
    with pytest.raises(FileWriteError):
        im.Sensor().to_toml(tmp_path / "no" / "dir" / "s.toml")


def test_invalid_parameters():
    with pytest.raises(ParameterError, match="gsd_m must be > 0"):
        im.Sensor(gsd_m=0)
    with pytest.raises(ParameterError, match="finite"):
        im.Sensor(optics_sigma_x_m=float("nan"))
    with pytest.raises(ParameterError, match="direction"):
        im.Sensor().mtf(0.5, "diagonal")
