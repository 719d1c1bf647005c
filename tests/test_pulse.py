"""Pulse estimator against exact answers: bars whose every pixel is the
exact pulse response (edge response at d + W/2 minus at d - W/2)."""
import math
import re

import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError, TargetNotFoundError, UnsuitableTargetError
from imgmtf.estimate.pulse import check_width, measure_pulse, usable_band

from conftest import exact_edge_chip, exact_esf, gaussian_pixel_transfer, true_fwhm, true_mtf50


def exact_pulse_chip(transfer, angle_deg, width, shape=(100, 60), offset=0.0, low=200.0,
                     high=1200.0, noise_std=0.0, seed=0):
    rows, cols = shape
    a = math.radians(angle_deg)
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    d = (x - (cols - 1) / 2) * math.cos(a) + (y - (rows - 1) / 2) * math.sin(a) - offset
    fx, esf = exact_esf(transfer)
    resp = np.interp(d + width / 2, fx, esf) - np.interp(d - width / 2, fx, esf)
    img = low + (high - low) * resp
    if noise_std:
        img = img + np.random.default_rng(seed).normal(0, noise_std, img.shape)
    return np.clip(np.rint(img), 0, 65535).astype(np.uint16)


@pytest.mark.parametrize("width, sigma, angle", [(1.2, 0.5, 6.0), (1.6, 0.5, 6.0), (1.6, 0.35, -9.0),
                                                 (0.8, 0.45, 5.0)])
def test_noise_free_accuracy(width, sigma, angle):
    h = gaussian_pixel_transfer(sigma, angle)
    r = measure_pulse(exact_pulse_chip(h, angle, width, offset=0.23), width_px=width)
    assert abs(r.mtf_nyquist - h(0.5)) <= 0.005
    assert r.fwhm_px == pytest.approx(true_fwhm(h), rel=0.01)
    assert r.mtf50_cy_px == pytest.approx(true_mtf50(h), rel=0.005)
    assert r.normal_angle_deg == pytest.approx(angle, abs=0.03)
    assert r.usable_band_cy_px == pytest.approx(usable_band(width))


def test_width_is_estimated_from_the_spectrum_zero():
    h = gaussian_pixel_transfer(0.45, 6.0)
    r = measure_pulse(exact_pulse_chip(h, 6.0, 2.2))
    assert r.width_estimated and r.pulse_width_px == pytest.approx(2.2, rel=0.01)


def test_dark_bar_and_along_track_bar():
    h = gaussian_pixel_transfer(0.5, 84.0)
    r = measure_pulse(exact_pulse_chip(h, 84.0, 1.4, shape=(60, 100), low=1200, high=300), width_px=1.4)
    assert r.polarity == "dark" and r.orientation == "horizontal"
    assert abs(r.mtf_nyquist - h(0.5)) <= 0.005


def test_sinc_zeros_are_masked_and_warned():
    h = gaussian_pixel_transfer(0.5, 6.0)
    r = measure_pulse(exact_pulse_chip(h, 6.0, 4.0, shape=(100, 70)), width_px=4.0)
    # zeros of sinc(4 f) at 0.25, 0.5, 0.75 cy/px
    assert np.isnan(r.mtf_at([0.25, 0.5, 0.75])).all()
    assert np.isfinite(r.mtf_at([0.1, 0.375])).all()
    assert r.usable_band_cy_px < 0.25 and any("before Nyquist" in w for w in r.warnings)
    assert abs(r.mtf_at([0.375])[0] - h(0.375)) < 0.01


def test_generic_sensor_pulse(paper_sensor):
    chip = im.render(paper_sensor, im.Target("pulse", 6.0, 200, 1200, 0.1, 1.5), (100, 60))
    r = measure_pulse(chip.image, width_px=1.5, gsd_m=chip.gsd_m)
    assert abs(r.mtf_nyquist - chip.true_mtf(0.5)) <= 0.005
    assert r.fwhm_px == pytest.approx(chip.true_fwhm_px(), rel=0.01)


def test_noisy_pulse_has_snr_by_the_pulse_definition():
    h = gaussian_pixel_transfer(0.5, 6.0)
    r = measure_pulse(exact_pulse_chip(h, 6.0, 1.6, noise_std=10.0, seed=3), width_px=1.6)
    peak = 1000 * (np.interp(0.8, *exact_esf(h)) - np.interp(-0.8, *exact_esf(h)))
    assert r.snr == pytest.approx(peak / 10.0, rel=0.15)
    assert abs(r.mtf_nyquist - h(0.5)) < 0.06


def test_bad_widths():
    with pytest.raises(ParameterError, match="> 0"):
        check_width(-1.0)
    with pytest.raises(ParameterError, match="below 0.1 cy/px"):
        check_width(12.0)
    h = gaussian_pixel_transfer(0.5, 6.0)
    with pytest.raises(ParameterError):
        measure_pulse(exact_pulse_chip(h, 6.0, 1.6), width_px=0.0)


def test_bar_too_wide_for_the_chip():
    h = gaussian_pixel_transfer(0.5, 6.0)
    chip = exact_pulse_chip(h, 6.0, 9.0, shape=(100, 24))
    with pytest.raises(UnsuitableTargetError, match="too wide|too narrow"):
        measure_pulse(chip, width_px=9.0)


def test_no_bar_and_an_edge_are_refused():
    with pytest.raises(TargetNotFoundError):
        measure_pulse(np.random.default_rng(0).normal(300, 5, (60, 60)))
    h = gaussian_pixel_transfer(0.5, 6.0)
    with pytest.raises(UnsuitableTargetError, match="step"):
        measure_pulse(exact_edge_chip(h, 6.0), width_px=1.5)


def test_narrow_bar_width_cannot_be_estimated():
    h = gaussian_pixel_transfer(0.7, 6.0)
    with pytest.raises(UnsuitableTargetError, match="give its width") as info:
        measure_pulse(exact_pulse_chip(h, 6.0, 0.5))
    assert info.value.reason == "bar-width"          # the CLI answers it with --pulse-width


def test_a_sub_pixel_bar_without_its_width_is_refused_saying_how_far_its_width_moves_the_mtf():
    # a 0.6 px bridge, sigma 0.39 px + pixel, noise 1 % of its contrast: noise made a zero at 0.87 cy/px,
    # once read as a 1.15 px bar and MTF at Nyquist 0.45 against 0.30, its interval missing the truth
    h = gaussian_pixel_transfer(0.39, 6.0)
    chip = exact_pulse_chip(h, 6.0, 0.6, noise_std=10.0, seed=1)
    with pytest.raises(UnsuitableTargetError, match="cannot be told from the noise") as info:
        measure_pulse(chip)
    assert info.value.reason == "bar-width"
    widest, line, top = (float(v) for v in re.search(r"up to ([\d.]+) px wide.* about ([\d.]+) \(a line\) to "
                                                      r"([\d.]+)", str(info.value)).groups())
    assert widest >= 0.6 and line <= h(0.5) <= top
    given = measure_pulse(chip, width_px=0.6)          # the width given, the same chip is measured
    assert abs(given.mtf_nyquist - h(0.5)) < 0.01 and h(0.5) in given.mtf_nyquist_ci


def test_a_read_width_carries_its_uncertainty_into_the_interval_and_says_so():
    chip = im.render(im.Sensor(), im.Target("pulse", 6.0, 200.0, 1200.0, 0.2, 1.5), 100, noise_std_dn=2.0,
                     seed=1)
    given, read = measure_pulse(chip.image, width_px=1.5), measure_pulse(chip.image)
    # at Nyquist a 1.5 px bar's MTF moves 2.2 % per 0.01 px of width: that uncertainty dominates
    assert read.mtf_nyquist_ci.width > 2.0 * given.mtf_nyquist_ci.width
    assert float(chip.true_mtf(0.5)) in read.mtf_nyquist_ci
    assert any("read off its profile" in w and "give the width" in w for w in read.warnings)
    assert not any("read off its profile" in w for w in given.warnings)
    boot = measure_pulse(chip.image, bootstrap=50)
    assert any("bootstrap holds the bar's width" in w for w in boot.warnings)


def test_fieller_spread_of_a_read_width_matches_its_closed_form():
    from imgmtf.estimate.intervals.width import WidthReading
    f0, slope, sd, t = 0.6, -0.25, 0.004, 2.0
    freqs = np.concatenate([[f0], np.arange(0.3, 0.96, 0.02)])
    reading = WidthReading(1 / f0, freqs, np.zeros((freqs.size, 3)), np.zeros(freqs.size),
                           slope * (freqs - f0), slope, lambda f: f)
    a = t * sd / abs(slope)                    # |R(f)| <= t sd for |f - f0| <= a
    expected = 0.5 * (1 / (f0 - a) - 1 / (f0 + a))
    assert reading.spread_px(np.full(freqs.size - 1, sd), t) == pytest.approx(expected, rel=1e-9)
    # a spectrum that never leaves its noise below f0: no width is read at all
    assert reading.spread_px(np.full(freqs.size - 1, 1.0), t) == math.inf
    assert reading.width_change(slope * f0 * f0) == pytest.approx(1.0)


def test_bar_reach_is_where_the_mean_profile_fades_plus_a_margin():
    from imgmtf.estimate.pulse import REACH_MARGIN_PX, bar_reach_px
    offsets = np.arange(-12.0, 12.5, 0.5)[None, :] + np.zeros((3, 1))
    rect = np.where(np.abs(offsets) <= 2.0, 100.0, 0.0)               # the profile ends at 2 px
    assert bar_reach_px(offsets, rect) == 2 + REACH_MARGIN_PX
    gauss = np.exp(-0.5 * (offsets / 1.5) ** 2)                       # 5 % at 1.5 sqrt(2 ln 20) = 3.67 px
    assert bar_reach_px(offsets, gauss) == math.ceil(3.5) + REACH_MARGIN_PX


def test_row_centres_of_a_noisy_bar_are_centroids_over_its_own_reach():
    # at SNR 25 a centroid over a 25 px window scatters by about 1 px a row;
    # over the bar's reach (about 9 px) by about 0.2 px, what location_sd_px expects
    from imgmtf.estimate.detection import robust_noise
    from imgmtf.estimate.geometry import vertical_frame
    from imgmtf.estimate.pulse import PulseKind, locate_pulse
    scatter, expected = [], []
    for seed in range(4):
        chip = im.render(im.Sensor(), im.Target("pulse", 6.0, 200.0, 1200.0, 0.2, 1.5), (100, 60),
                         noise_std_dn=40.0, seed=seed).image.astype(float)
        line, _ = PulseKind(1.5).seed(chip, robust_noise(chip))
        geometry = locate_pulse(*vertical_frame(chip, line))
        resid = geometry.locations - (geometry.slope * geometry.rows + geometry.intercept)
        scatter.append(float(np.std(resid[geometry.kept])))
        expected.append(geometry.location_sd_px)
    assert max(scatter) < 0.35
    assert np.mean(scatter) == pytest.approx(np.mean(expected), rel=0.3)


def test_the_figures_read_the_pulse_response_between_background_and_peak():
    h = gaussian_pixel_transfer(0.5, 6.0)
    r = measure_pulse(exact_pulse_chip(h, 6.0, 1.6), width_px=1.6)
    x, profile, (background, peak) = r.normalised_profile()
    assert r.width_px == 1.6 and x is r.prf_x_px
    assert background == pytest.approx(200.0, abs=0.5) and 200.0 < peak < 1200.0
    assert profile.max() == pytest.approx(1.0, abs=0.01)
    x_lsf, lsf, fwhm = r.lsf_like()
    assert x_lsf is r.prf_x_px and lsf is r.prf and fwhm == r.prf_fwhm_px
