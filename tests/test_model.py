import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import imgmtf as im
from imgmtf.errors import ConfigError, FileWriteError, ParameterError
from imgmtf.sensor import stages as st

from conftest import exact_esf


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
    assert list(parts) == ["optics", "detector", "motion", "electronics"]
    assert parts["motion"].mtf_nyquist("across") == 1.0
    assert parts["optics"].fwhm_m() == pytest.approx(2.35482 * 0.39, rel=1e-4)


def test_paper_keywords_build_the_stages_and_zero_removes_one():
    s = im.Sensor(gsd_m=np.int64(2), motion_m=0, electronics_cutoff_cy_m=np.float32(1.5))
    assert s.gsd_m == 2.0 and [x.name for x in s.stages] == ["optics", "detector", "electronics"]
    assert s.stages[2] == st.Electronics(1.5) and s == im.Sensor(2.0, list(s.stages))
    assert im.Sensor() == im.Sensor(1.0, [st.GaussianOptics(), st.Detector(), st.Motion(), st.Electronics()])


def test_toml_round_trip_every_stage(tmp_path):
    s = im.Sensor(0.5, [stage() for stage in st.STAGES.values()] + [st.Electronics(math.inf)])
    path = tmp_path / "s.toml"
    s.to_toml(path, comment="fitted\nby hand")
    text = path.read_text()
    assert text.startswith("# fitted\n# by hand") and text.count("[[stages]]") == len(st.STAGES) + 1
    assert im.Sensor.from_toml(path) == s


def test_old_sensor_tables_still_read(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text("[sensor]\ngsd_m = 0.5\nmotion_m = 0.1\nelectronics_cutoff_cy_m = 0.0\n")
    assert im.Sensor.from_toml(path) == im.Sensor(gsd_m=0.5, motion_m=0.1, electronics_cutoff_cy_m=0)
    path.write_text("gsd_m = 2.0\n")
    assert im.Sensor.from_toml(path) == im.Sensor(gsd_m=2.0)


def test_line_response_keeps_the_diffraction_tail():
    """Edge response of an f/16 diffraction-limited lens: its tail falls as
    1/x, which the closed-form Cauchy part carries without a long grid."""
    s = im.Sensor(1.0, [st.Diffraction(16.0)])
    response = s.line_response(7.0, reach_px=40)
    assert response.esf_remainder.size <= 1 << 15
    x, esf = exact_esf(lambda f: s.normal_transfer(f, 7.0), dx=1 / 64, n=1 << 21)
    d = np.linspace(-40, 40, 801)
    assert np.abs(response.esf(d) - np.interp(d, x, esf)).max() < 1e-5
    assert 1 - response.esf(40.0) > 1e-3            # 40 px out, still 0.1 % short of the plateau
    assert response.lsf(d).sum() * 0.1 == pytest.approx(response.esf(40.0) - response.esf(-40.0), rel=1e-3)


@pytest.mark.parametrize("text, message", [
    ("[sensor\ngsd_m = 1", "malformed TOML"),
    ("[sensor]\nfocal = 3\n", r"unknown sensor parameter\(s\) focal"),
    ("[sensor]\nmotion_m = -1\n", "motion_m must be finite and >= 0"),
    ("[sensor]\ngsd_m = 'x'\n", "gsd_m must be a number"),
    ("gsd_m = 1\n[[stages]]\nstage = 'lens'\n", "unknown stage 'lens'"),
    ("gsd_m = 1\n[[stages]]\nstage = 'olpf'\nsplit_m = -1\n", "olpf split_m must be finite and >= 0"),
    ("gsd_m = 1\nstages = []\n", "at least one stage"),
    ("gsd_m = 1" + "0" * 400 + "\n", "gsd_m must be finite, got an integer of 401 digits"),
    ("gsd_m = 1e-300\n", r"gsd_m must lie in \[1e-12, 1e\+15\]"),
    ("gsd_m = 1\n[[stages]]\nstage = 'optics'\nsigma_x_m = 1e300\n", "optics sigma_x_m must be at most 1e\\+15 m"),
    (b"\x89PNG\r\n\x1a\n\x00\xff\xfe", "not a text"),
])
def test_bad_toml_is_a_config_error_naming_the_file(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
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
    with pytest.raises(ParameterError, match="optics_sigma_x_m must be finite"):
        im.Sensor(optics_sigma_x_m=float("nan"))
    with pytest.raises(ParameterError, match="gsd_m must be a number"):
        im.Sensor(gsd_m=True)
    with pytest.raises(ParameterError, match="direction"):
        im.Sensor().mtf(0.5, "diagonal")
    with pytest.raises(ParameterError, match="not both"):
        im.Sensor(1.0, [st.Detector()], motion_m=0.2)
    with pytest.raises(ParameterError, match="unknown sensor parameter"):
        im.Sensor(focal_m=3)


def test_absurd_blur_is_refused_before_allocating():
    huge = im.Sensor(optics_sigma_x_m=1e5, optics_sigma_y_m=1e5)
    for call in (huge.psf, huge.fwhm_m, lambda: huge.line_response(6.0)):
        with pytest.raises(ParameterError, match="check the stage parameters"):
            call()


@pytest.mark.parametrize("angle", [0.0, 90.0, 20.0])
def test_the_fwhms_spectrum_is_the_transfer_but_for_the_sign_of_a_zero(angle):
    """Sensor.normal_lsf takes each stage's transfer only where those before
    it leave the product non-zero: the same numbers as normal_transfer (a
    one-sided, complex stage and a stage after the optics' underflow
    included), so the same LSF and FWHM as from the full transfer."""
    from imgmtf.sensor.lines import line_grid, line_spread
    from imgmtf.sensor.stages.base import nonzero_transfer
    f = np.linspace(0.0, 200.0, 16385)
    for sensor in (im.Sensor(1.0, [st.GaussianOptics(0.42, 0.45), st.Detector(1.05, 0.97)]),
                   im.Sensor(0.5, [st.GaussianOptics(0.3, 0.3), st.Lag(0.4, 0.2), st.Detector(0.5, 0.5)]),
                   im.Sensor(1.0, [st.Detector(1.0, 1.0), st.Diffraction(), st.GaussianOptics(0.3, 0.3)])):
        a = math.radians(angle)
        spectrum = nonzero_transfer(sensor.stages, f / sensor.gsd_m * math.cos(a), f / sensor.gsd_m * math.sin(a),
                                    sensor.gsd_m)
        transfer = sensor.normal_transfer(f, angle)
        assert spectrum.dtype == transfer.dtype and np.array_equal(spectrum, transfer)
        x, lsf = sensor.normal_lsf(angle)
        half = 4 * sensor.support_radius_m() / sensor.gsd_m
        grid = line_grid(sensor, angle, sensor.gsd_m, reach_px=half, step_px=1 / 400)
        full = grid.lsf_remainder(sensor.normal_transfer(grid.frequencies_cy_px, angle))
        assert np.array_equal(lsf, line_spread(grid.start_px, grid.step_px, full, grid.reference, x))
