import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.sensor import stages as st

from conftest import exact_esf

GAUSSIAN_ONLY = [im.Sensor(optics_sigma_x_m=s, optics_sigma_y_m=s, detector_width_x_m=0.0,
                           detector_width_y_m=0.0, motion_m=0.0, electronics_cutoff_cy_m=0.0)
                 for s in (0.35, 0.7)]
# long-tailed and ringing blurs: f/8 and f/22 diffraction (5 um pixels), a
# defocus disk of 1.5 px, a 4-spot OLPF of 0.7 px, each with the pixel aperture
LONG_TAILED = [im.Sensor(1.0, [st.Diffraction(8.0), st.Detector()]),
               im.Sensor(1.0, [st.Diffraction(22.0), st.OLPF(0.7), st.Detector()]),
               im.Sensor(1.0, [st.Defocus(1.5), st.Detector()]),
               im.Sensor(1.0, [st.OLPF(0.7), st.GaussianOptics(0.3, 0.3), st.Detector()])]


def exact_chip(sensor, target, shape):
    """Exact edge response at each pixel centre, computed independently:
    H(f) = T(f cos a, f sin a) by inverse FFT on a fine grid (+-8192 px,
    so that even the 1/x tail of diffraction is complete)."""
    x, esf = exact_esf(lambda f: sensor.normal_transfer(f, target.angle_deg), dx=1 / 64, n=1 << 20)
    rows, cols = shape
    yy, xx = np.mgrid[0:rows, 0:cols].astype(float)
    d = target.signed_distance(xx, yy, ((cols - 1) / 2, (rows - 1) / 2))
    return target.low_dn + (target.high_dn - target.low_dn) * np.interp(d, x, esf)


@pytest.mark.parametrize("sensor", [im.Sensor(), *GAUSSIAN_ONLY])
@pytest.mark.parametrize("angle", [6.0, 84.0, -23.0])
def test_noise_free_edge_equals_exact_edge_response(sensor, angle):
    target = im.Target("edge", angle, 200.0, 1200.0, 0.37)
    chip = im.render(sensor, target, (48, 40))
    error = np.abs(chip.image.astype(float) - exact_chip(sensor, target, (48, 40)))
    assert error.max() <= 1.0          # a 1000 DN step, 16-bit: rounding only
    assert error.mean() < 0.3


@pytest.mark.parametrize("sensor", LONG_TAILED)
def test_long_tailed_blur_renders_exactly(sensor):
    target = im.Target("edge", 7.0, 200.0, 20200.0, -0.21)
    chip = im.render(sensor, target, (40, 64))
    error = np.abs(chip.image.astype(float) - exact_chip(sensor, target, (40, 64)))
    assert error.max() <= 1.0          # of a 20000 DN step: 5e-5, rounding and the reference's own grid


def test_pulse_is_difference_of_two_edges():
    sensor = im.Sensor()
    r = im.Renderer(sensor, 40, bits=16)
    pulse = r(im.Target("pulse", 6.0, 100.0, 1100.0, 0.0, 3.0)).image.astype(float)
    up = exact_chip(sensor, im.Target("edge", 6.0, 0.0, 1000.0, -1.5), (40, 40))
    down = exact_chip(sensor, im.Target("edge", 6.0, 0.0, 1000.0, 1.5), (40, 40))
    assert np.abs(pulse - (100.0 + up - down)).max() <= 1.0


def test_borders_create_no_false_edge():
    flat = im.render(im.Sensor(), im.Target("edge", 6.0, 500.0, 500.0), 30).image
    assert np.all(flat == 500)


def test_quantisation_and_clipping():
    chip = im.render(im.Sensor(), im.Target("edge", 6.0, 10.0, 300.0), 30, bits=8)
    assert chip.image.dtype == np.uint8 and chip.image.max() == 255
    assert 0.2 < chip.clipped_fraction < 0.8


def test_seeded_noise_is_reproducible_and_has_the_set_std():
    t = im.Target("edge", 6.0, 1000.0, 1000.0)
    a = im.render(im.Sensor(), t, 60, noise_std_dn=12.0, seed=5).image.astype(float)
    b = im.render(im.Sensor(), t, 60, noise_std_dn=12.0, seed=5).image.astype(float)
    assert np.array_equal(a, b)
    assert a.std() == pytest.approx(12.0, rel=0.05)


def test_ground_noise_is_blurred_by_the_psf():
    t = im.Target("edge", 6.0, 1000.0, 1000.0)
    chip = im.render(im.Sensor(), t, 80, ground_noise=im.GroundNoise(), seed=2)
    # 2000 DN^2 on the ground, reduced by the PSF: nonzero but far smaller
    assert 10.0 < chip.image.astype(float).var() < 2000.0


def test_other_gsd_scales_the_true_mtf():
    s = im.Sensor()
    chip = im.render(s, im.Target("edge", 6.0), 30, gsd_m=2.0)
    assert chip.true_mtf(0.5) == pytest.approx(abs(s.normal_transfer(0.25, 6.0)), rel=1e-12)


@pytest.mark.parametrize("kwargs", [dict(shape=1), dict(bits=12), dict(gsd_m=-1.0), dict(shape=20.0),
                                    dict(gsd_m="2"), dict(sensor=None)])
def test_invalid_render_settings(kwargs):
    with pytest.raises(ParameterError):
        im.Renderer(**{"sensor": im.Sensor(), **kwargs})


@pytest.mark.parametrize("target, kwargs, message", [
    (None, {}, "target must be an imgmtf.Target"),
    ("edge", {}, "target must be an imgmtf.Target"),
    (im.Target(), dict(seed=-1), "seed must be an integer >= 0"),
    (im.Target(), dict(seed=1.5), "seed must be an integer >= 0"),
    (im.Target(), dict(ground_noise=3), "ground_noise must be an imgmtf.GroundNoise"),
])
def test_a_call_of_the_wrong_kind_is_refused_by_name(target, kwargs, message):
    with pytest.raises(ParameterError, match=message):
        im.Renderer(im.Sensor(), 20)(target, **kwargs)


def test_a_target_outside_the_chip_is_refused_before_any_work():
    with pytest.raises(ParameterError, match="offset of 1e\\+09 px puts the edge outside the 50 x 50 px chip"):
        im.render(im.Sensor(), im.Target("edge", 6.0, offset_px=1e9), 50)
