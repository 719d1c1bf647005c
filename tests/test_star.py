"""Siemens stars measured (imgmtf.estimate.star) against the exact truth of
the renderer: ISO 12233's sinusoidal star through an anisotropic Gaussian
(0.45 px across, 0.6 px along) and a square pixel, noise-free and at SNR 100
(the star's range over the noise), read across and along track within 3 %
at MTF50 and 0.03 at Nyquist; a binary star through its wedges' levels;
the centre, cycles and profile found; what is no star refused."""
import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError, UnsuitableTargetError
from imgmtf.estimate.star import measure_star
from imgmtf.sensor.stages import Detector, GaussianOptics
from imgmtf.sensor.star import SiemensStar, render_star

SENSOR = im.Sensor(stages=[GaussianOptics(0.45, 0.6), Detector(1.0, 1.0)])


@pytest.fixture(scope="module")
def sinusoidal():
    return render_star(SENSOR, SiemensStar(cycles=76, centre_offset_px=(0.3, -0.2)), 201, bits=None)


def check_across_and_along(result, chip):
    for name, angle in (("across-track", 0.0), ("along-track", 90.0)):
        d = result.direction(name)
        assert d.angle_deg == angle
        assert abs(d.mtf_nyquist - float(chip.true_mtf(0.5, angle))) < 0.03
        assert d.mtf50_cy_px == pytest.approx(chip.true_mtf50_cy_px(angle), rel=0.03)


def test_a_sinusoidal_star_noise_free_gives_the_mtf_in_every_direction(sinusoidal):
    result = measure_star(sinusoidal.image)
    check_across_and_along(result, sinusoidal)
    assert len(result.directions) == 8 and result.profile == "sinusoidal" and result.cycles == 76
    assert result.centre_px == pytest.approx(sinusoidal.centre_px, abs=0.01)
    assert result.contrast == pytest.approx(500.0 / 700.0, rel=1e-3) and result.contrast_method == "extrapolated"
    for d in result.directions:                 # every direction, its truth within its interval's reach
        assert abs(d.mtf_nyquist - float(sinusoidal.true_mtf(0.5, d.angle_deg))) < 0.01
    assert result.nyquist_radius_px == pytest.approx(76 / np.pi)
    assert result.inner_radius_px < result.unresolved_radius_px < result.nyquist_radius_px


def test_a_sinusoidal_star_at_snr_100_within_tolerance_and_its_intervals(sinusoidal):
    rng = np.random.default_rng(7)
    noisy = np.rint(sinusoidal.image + rng.normal(0.0, 10.0, sinusoidal.image.shape))   # 1000 DN range / 100
    result = measure_star(noisy)
    check_across_and_along(result, sinusoidal)
    assert result.snr == pytest.approx(100.0, rel=0.05)
    covered = [float(sinusoidal.true_mtf(0.5, d.angle_deg)) in d.mtf_nyquist_ci for d in result.directions]
    assert sum(covered) >= 6
    summaries = result.summaries(curves=False)
    assert [row["direction_deg"] for row in summaries] == [0.0, 22.5, 45.0, 67.5, 90.0, 112.5, 135.0, 157.5]
    assert summaries[0]["direction"] == "across-track" and summaries[2]["direction"] == "45deg"


def test_a_binary_star_uses_its_wedges_levels_and_the_square_waves_4_over_pi():
    chip = render_star(SENSOR, SiemensStar(cycles=46, profile="binary"), 161, noise_std_dn=10.0, seed=3)
    result = measure_star(chip.image, track_azimuth_deg=None)
    assert result.profile == "binary" and result.contrast_method == "levels"
    assert result.contrast == pytest.approx(4 / np.pi * 1000 / 1400, rel=0.01)
    assert [d.direction for d in result.directions][::4] == ["image-x", "image-y"]
    x, y = result.directions[0], result.directions[4]
    assert abs(x.mtf_nyquist - float(chip.true_mtf(0.5, 0.0))) < 0.03
    assert y.mtf50_cy_px == pytest.approx(chip.true_mtf50_cy_px(90.0), rel=0.03)


def test_an_edge_is_no_star():
    chip = im.render(SENSOR, im.Target("edge", 6.0), 64, seed=1, noise_std_dn=2.0)
    with pytest.raises(UnsuitableTargetError, match="no Siemens star") as info:
        measure_star(chip.image)
    assert info.value.reason == "not-a-star"


def test_bad_settings_are_refused(sinusoidal):
    with pytest.raises(ParameterError, match="n_directions"):
        measure_star(sinusoidal.image, n_directions=3)
    with pytest.raises(ParameterError, match="profile"):
        measure_star(sinusoidal.image, profile="square")
