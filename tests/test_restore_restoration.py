"""One image restored end to end (imgmtf.restore_image), on synthetic and real chips."""

import numpy as np
import pytest

import imgmtf as im
from imgmtf.sensor.stages import Detector, GaussianOptics

from conftest import real_scene


@pytest.fixture(scope="module")
def chip(tmp_path_factory):
    path = tmp_path_factory.mktemp("restoration") / "chip.tif"
    rendered = im.render(im.Sensor(), im.Target("edge", 6.0), 120, noise_std_dn=4.0, seed=3)
    im.write_geotiff(path, rendered.image, gsd_m=2.0)
    return path


# the paper's sensor scaled to the chip's 2 m pixel: the same sensor in pixels
SCALED = im.Sensor(2.0, optics_sigma_x_m=0.78, optics_sigma_y_m=0.78, detector_width_x_m=2.0, detector_width_y_m=2.0,
                   motion_m=0.5, electronics_cutoff_cy_m=0.7)


def test_noise_measured_or_given(chip, tmp_path):
    measured = im.restore_image(chip, SCALED, tmp_path / "a.tif", target_nyquist=0.35)
    assert measured.noise_source == "measured"
    assert measured.filter.noise_std_dn == pytest.approx(4.0, rel=0.1)
    assert measured.filter.signal_std_dn == pytest.approx(500.0, rel=0.05)     # a 1000 DN step, half and half
    given = im.restore_image(chip, SCALED, tmp_path / "b.tif", target_nyquist=0.35, noise_std_dn=4.0,
                             signal_std_dn=500.0)
    assert given.noise_source == "given" and given.filter.regulariser == pytest.approx(6.4e-5)
    assert given.to_dict()["axes"]["across"]["achieved_mtf_nyquist"] == pytest.approx(0.35, abs=0.005)
    assert not given.warnings


def test_a_pixel_unlike_the_sensors_is_warned_about(chip, tmp_path):
    # the chip's GeoTIFF says 2 m; a sensor fitted at 1 m would be applied at the image's pixel
    done = im.restore_image(chip, im.Sensor(1.0), tmp_path / "c.tif", target_nyquist=0.35)
    assert done.filter.gsd_m == 2.0 and "the image's pixel is 2 m, the sensor's 1 m" in done.warnings[0]


def test_baotou_a_model_that_does_not_fit_asks_an_absurd_filter(tmp_path):
    """The Baotou L0R chip (JorgeGIlG/MTF_Estimator, GPL-3.0, read in place) with the sensor
    `imgmtf.fit_sensor` gives for its four scan-accepted half-edges (Gaussian optics of
    sigma 1.063 and 1.035 px and the pixel; a misfit, reduced chi-square 4.1): docs/restore.md."""
    path = real_scene("baotou_l0r_checkerboard.tif", "JorgeGIlG/MTF_Estimator (GPL-3.0, read in place)")
    sensor = im.Sensor(1.0, [GaussianOptics(1.0633, 1.0346), Detector(1.0, 1.0)])
    # its noise would dominate the result: refused before anything is written, unless a noise budget is given
    with pytest.raises(im.ImgmtfError, match="multiplies the noise by 11 ") as refused:
        im.restore_image(path, sensor, tmp_path / "r.tif", target_nyquist=0.25)
    assert refused.value.reason == "noise-dominated" and not (tmp_path / "r.tif").exists()
    done = im.restore_image(path, sensor, tmp_path / "r.tif", target_nyquist=0.25, max_noise_gain=20.0)
    assert done.warnings[0].startswith("NOISE DOMINATES: the filter multiplies the noise by 11 ")
    assert done.filter.noise_std_dn == pytest.approx(29.4, rel=0.05) and not done.filter.limited
    assert 8 < done.filter.noise_gain < 15
    achieved = [a.achieved_mtf_nyquist for a in done.report.axes.values()]
    assert max(achieved) < 0.05 and done.file.clipped_fraction > 0.005
    limited = im.restore_image(path, sensor, tmp_path / "l.tif", target_nyquist=0.25, max_noise_gain=2.0)
    assert limited.filter.noise_gain == pytest.approx(2.0, abs=1e-4)
    assert max(a.achieved_mtf_nyquist for a in limited.report.axes.values()) < 0.005
    assert np.isfinite(im.read_raster(tmp_path / "l.tif").data).all()


def test_pure_noise_needs_the_signal_given(tmp_path):
    noise = np.random.default_rng(0).normal(1000.0, 10.0, (80, 80))
    im.write_geotiff(tmp_path / "noise.tif", np.rint(noise).astype(np.uint16))
    with pytest.raises(im.ImageContentError, match="no signal above its noise"):
        im.restore_image(tmp_path / "noise.tif", SCALED, tmp_path / "r.tif", target_nyquist=0.3)
    # (the file's 1 m pixel sees the 2 m sensor's blur doubled: a noise gain of 4.6, a budget given)
    done = im.restore_image(tmp_path / "noise.tif", SCALED, tmp_path / "r.tif", target_nyquist=0.3,
                            signal_std_dn=400.0, max_noise_gain=10.0)
    assert done.noise_source == "given and measured"
    assert done.filter.noise_std_dn == pytest.approx(10.0, rel=0.05)
