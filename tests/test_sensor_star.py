"""The exact Siemens-star renderer (imgmtf.sensor.star) against a brute-force
quadrature of the star through Gaussian optics and a square pixel (the erf
differences of the Gaussian integrated over the pixel, separable), for the
sinusoidal star and the binary one."""
import math

import numpy as np
import pytest
from scipy.special import ndtr

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.sensor.stages import Detector, GaussianOptics
from imgmtf.sensor.star import SiemensStar, default_cycles, render_star

SENSOR = im.Sensor(stages=[GaussianOptics(0.45, 0.6), Detector(1.0, 1.0)])
STEP = 0.005


def quadrature(star, centre, pixel):
    """The pixel's value: the star times the pixel-integrated Gaussian, summed on a fine grid."""
    u = np.arange(-3.5, 3.5 + STEP / 2, STEP)                # 5 sigma of the widest blur
    kx = ndtr((u + 0.5) / 0.45) - ndtr((u - 0.5) / 0.45)
    ky = ndtr((u + 0.5) / 0.6) - ndtr((u - 0.5) / 0.6)
    x = pixel[0] - u[None, :] - centre[0]
    y = pixel[1] - u[:, None] - centre[1]
    wave = np.cos(star.cycles * (np.arctan2(y, x) - math.radians(star.phase_deg)))
    pattern = np.sign(wave) if star.profile == "binary" else wave
    mean, half = (star.high_dn + star.low_dn) / 2, (star.high_dn - star.low_dn) / 2
    return mean + half * float(np.sum(ky[:, None] * kx[None, :] * pattern)) * STEP * STEP


@pytest.mark.parametrize("profile, tolerance_dn", [("sinusoidal", 1e-3), ("binary", 0.05)])
def test_a_star_is_the_scene_through_the_sensor_exactly(profile, tolerance_dn):
    star = SiemensStar(cycles=24, profile=profile, centre_offset_px=(0.3, -0.2), phase_deg=5.0)
    chip = render_star(SENSOR, star, 64, bits=None)
    for dx, dy in ((6, 2), (15, -11)):                       # near Nyquist (r = 7.6 px) and beyond
        x, y = 32 + dx, 32 + dy
        assert abs(chip.image[y, x] - quadrature(star, chip.centre_px, (x, y))) < tolerance_dn


def test_the_truth_and_the_provenance_name_the_star():
    chip = render_star(SENSOR, SiemensStar(cycles=16, profile="binary"), 40, noise_std_dn=2.0, seed=1)
    assert chip.image.dtype == np.uint16 and chip.centre_px == (19.8, 19.3)
    provenance = chip.provenance()
    assert provenance["target"]["kind"] == "star" and provenance["target"]["profile"] == "binary"
    assert provenance["mtf_nyquist_along"] == pytest.approx(float(chip.true_mtf(0.5, 90.0)))
    assert chip.true_mtf50_cy_px(0.0) > chip.true_mtf50_cy_px(90.0)      # wider blur along


def test_bad_stars_and_chips_are_refused():
    with pytest.raises(ParameterError, match="cycles >= 4"):
        SiemensStar(cycles=3)
    with pytest.raises(ParameterError, match="profile must be one of"):
        SiemensStar(profile="square")
    with pytest.raises(ParameterError, match="at least 32 x 32"):
        render_star(SENSOR, SiemensStar(), 20)
    assert default_cycles(201) == 76 and default_cycles(201, "binary") == 46
