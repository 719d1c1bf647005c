"""Edge estimator against exact answers: chips whose every pixel is the
analytic edge response (conftest.exact_edge_chip, no renderer involved)."""
import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import (
    ImageContentError,
    MultipleTargetsError,
    ParameterError,
    TargetNotFoundError,
    UnsuitableTargetError,
)
from imgmtf.estimate.edge import EdgeEstimator, measure_edge, window_factor

from conftest import exact_edge_chip, gaussian_pixel_transfer, true_fwhm, true_mtf50


@pytest.mark.parametrize("sigma, angle", [(0.35, 4.0), (0.5, -7.0), (0.7, 10.0), (0.5, 33.0)])
def test_noise_free_accuracy(sigma, angle):
    h = gaussian_pixel_transfer(sigma, angle)
    chip = exact_edge_chip(h, angle, offset=0.27)
    r = measure_edge(chip)
    assert abs(r.mtf_nyquist - h(0.5)) <= 0.003
    assert r.mtf50_cy_px == pytest.approx(true_mtf50(h), rel=0.005)
    assert r.fwhm_px == pytest.approx(true_fwhm(h), rel=0.005)
    assert r.normal_angle_deg == pytest.approx(angle, abs=0.02)
    f = r.frequencies_cy_px
    assert np.nanmax(np.abs(r.mtf[f <= 1.0] - h(f[f <= 1.0]))) < 0.004
    assert r.mtf[0] == pytest.approx(1.0)


def test_along_track_edge_is_measured_transposed():
    angle = 84.0
    h = gaussian_pixel_transfer(0.45, angle)
    r = measure_edge(exact_edge_chip(h, angle))
    assert r.orientation == "horizontal" and r.direction == "along-track"
    assert r.normal_angle_deg == pytest.approx(angle, abs=0.02)
    assert abs(r.mtf_nyquist - h(0.5)) <= 0.003


def test_polarity_does_not_change_the_mtf():
    h = gaussian_pixel_transfer(0.5, 6.0)
    rising = measure_edge(exact_edge_chip(h, 6.0, low=200, high=1200))
    falling = measure_edge(exact_edge_chip(h, 6.0, low=1200, high=200))
    assert rising.polarity == "rising" and falling.polarity == "falling"
    assert falling.mtf_nyquist == pytest.approx(rising.mtf_nyquist, abs=5e-4)
    assert falling.esf[0] < 0.05 and falling.esf[-1] > 0.95     # normalised to rise


def test_generic_sensor_chip_matches_its_true_mtf(paper_sensor):
    chip = im.render(paper_sensor, im.Target("edge", 6.0, 200, 1200, 0.31), 100)
    r = measure_edge(chip.image, gsd_m=chip.gsd_m)
    assert abs(r.mtf_nyquist - chip.true_mtf(0.5)) <= 0.003
    assert r.fwhm_px == pytest.approx(chip.true_fwhm_px(), rel=0.005)
    assert r.mtf50_cy_m == pytest.approx(r.mtf50_cy_px / 1.0)
    assert r.fwhm_m == pytest.approx(r.fwhm_px)


@pytest.mark.parametrize("method, tolerance", [("msg", 0.003), ("sliding", 0.003), ("spline", 0.003),
                                               ("iso", 0.01)])
def test_every_method_is_accurate_once_corrected(method, tolerance):
    """iso keeps the scatter of 1/4-px bin means taken at random sample
    positions (~25 per bin here), which no correction removes."""
    h = gaussian_pixel_transfer(0.5, 6.0)
    r = measure_edge(exact_edge_chip(h, 6.0), method=method)
    assert abs(r.mtf_nyquist - h(0.5)) <= tolerance
    assert r.method == method and r.params["method"] == method


def test_uncorrected_sliding_window_reads_low_by_its_box():
    h = gaussian_pixel_transfer(0.5, 6.0)
    chip = exact_edge_chip(h, 6.0)
    raw = measure_edge(chip, method="sliding", correct=False)
    width = raw.params["window_px"]
    expected = h(0.5) * np.sinc(0.5 * width) * np.sinc(2 * 0.5 * 0.05)
    assert raw.mtf_nyquist == pytest.approx(expected, abs=0.003)


def test_noise_gives_a_finite_snr_and_a_warning_below_threshold():
    h = gaussian_pixel_transfer(0.5, 6.0)
    r = measure_edge(exact_edge_chip(h, 6.0, noise_std=25.0, seed=4))
    assert r.snr == pytest.approx(40.0, rel=0.15)
    assert any("SNR" in w for w in r.warnings)
    assert abs(r.mtf_nyquist - h(0.5)) < 0.05


def test_window_factor_adapts_to_snr():
    assert window_factor(float("inf")) == window_factor(1e4) == 1.35
    assert window_factor(20.0) == 0.9
    assert 0.9 < window_factor(50.0) < 1.35


def test_roi_selects_one_edge_of_two():
    h = gaussian_pixel_transfer(0.5, 6.0)
    left = exact_edge_chip(h, 6.0, shape=(80, 60))
    right = exact_edge_chip(h, 6.0, shape=(80, 60), low=1200, high=200)
    both = np.hstack([left, right])
    with pytest.raises(MultipleTargetsError):
        measure_edge(both)
    r = measure_edge(both, roi=(60, 0, 60, 80))
    assert r.polarity == "falling" and r.roi == (60, 0, 60, 80)


def test_saturated_side_is_refused():
    h = gaussian_pixel_transfer(0.5, 6.0)
    chip = exact_edge_chip(h, 6.0, low=30, high=400).astype(float)
    chip = np.clip(chip, 0, 255).astype(np.uint8)
    with pytest.raises(UnsuitableTargetError, match="saturated"):
        measure_edge(chip)


@pytest.mark.parametrize("angle, message", [(0.3, "too close for sub-pixel"),
                                            (44.7, "too close to 45"),
                                            (26.5651, "gap")])
def test_unsuitable_angles_are_refused(angle, message):
    h = gaussian_pixel_transfer(0.5, angle)
    with pytest.raises(UnsuitableTargetError, match=message):
        measure_edge(exact_edge_chip(h, angle))


def test_bad_images():
    h = gaussian_pixel_transfer(0.5, 6.0)
    chip = exact_edge_chip(h, 6.0).astype(float)
    with pytest.raises(ImageContentError, match="flat"):
        measure_edge(np.full((50, 50), 3.0))
    with pytest.raises(ImageContentError, match="at least 16 x 16"):
        measure_edge(chip[:10, :40])
    infinite = chip.copy()
    infinite[5, 5] = np.inf
    with pytest.raises(ImageContentError, match="infinite"):
        measure_edge(infinite)
    with pytest.raises(ImageContentError, match="every pixel is NaN"):
        measure_edge(np.full((40, 40), np.nan))
    with pytest.raises(ImageContentError, match="2-D"):
        measure_edge(np.zeros((3, 20, 20)))
    with pytest.raises(TargetNotFoundError):
        measure_edge(np.random.default_rng(0).normal(100, 5, (60, 60)))
    with pytest.raises(ParameterError, match="not inside"):
        measure_edge(chip, roi=(90, 0, 30, 30))
    with pytest.raises(UnsuitableTargetError, match="border"):
        measure_edge(chip, roi=(0, 0, 52, 100))


def test_estimator_is_reusable_and_result_serialises():
    import json
    est = EdgeEstimator("msg", frequencies_cy_px=np.linspace(0, 0.5, 6))
    h = gaussian_pixel_transfer(0.5, 6.0)
    a = est(exact_edge_chip(h, 6.0, offset=0.1))
    b = est(exact_edge_chip(h, 6.0, offset=0.4))
    assert a.mtf.shape == (6,) and abs(a.mtf_nyquist - b.mtf_nyquist) < 1e-3
    d = json.loads(json.dumps(a.to_dict()))
    for key in ("normal_angle_deg", "orientation", "snr", "mtf_nyquist", "mtf50_cy_px", "fwhm_px", "rer",
                "mtfa", "gsd_m", "frequencies_cy_px", "mtf", "warnings", "params"):
        assert key in d
    assert a.mtf_at([0.5])[0] == pytest.approx(a.mtf_nyquist)
    assert a.mtf_at([-0.5])[0] == a.mtf_at([0.5])[0]         # an MTF is even in f
    assert np.isnan(a.mtf_at([4.5])[0])                        # beyond the transform's reach


def test_a_path_or_a_fractional_roi_is_refused_with_the_way_out():
    from imgmtf.errors import ParameterError
    with pytest.raises(ParameterError, match="read_raster"):
        measure_edge("data/edge.tif")
    chip = exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0)
    with pytest.raises(ParameterError, match="ROI must be four integers"):
        measure_edge(chip, roi=(20, 0, 60.5, 100))
    assert measure_edge(chip, roi=(20.0, 0, 60, 100)).roi[2] == 60    # whole numbers as floats are fine


def test_noisy_fwhm_and_noise_limit():
    h = gaussian_pixel_transfer(0.5, 6.0)
    r = measure_edge(exact_edge_chip(h, 6.0, noise_std=10.0, seed=9))      # SNR 100
    assert r.fwhm_px == pytest.approx(true_fwhm(h), rel=0.04)
    assert 0.5 < r.noise_limit_cy_px < 1.5
    clean = measure_edge(exact_edge_chip(h, 6.0))
    assert clean.noise_limit_cy_px > r.noise_limit_cy_px


def test_confident_snr_scales_with_rows():
    from imgmtf.estimate.edge import CONFIDENT_SNR_40_ROWS, confident_snr
    assert confident_snr(40) == CONFIDENT_SNR_40_ROWS
    assert confident_snr(160) == pytest.approx(CONFIDENT_SNR_40_ROWS / 2)
    h = gaussian_pixel_transfer(0.5, 6.0)
    quiet = measure_edge(exact_edge_chip(h, 6.0, noise_std=9.0, seed=2))     # SNR ~110, 100 rows
    assert quiet.snr > confident_snr(quiet.rows_used) and not quiet.warnings


def test_the_figures_read_the_esf_between_its_levels_and_the_lsf():
    h = gaussian_pixel_transfer(0.5, 6.0)
    r = measure_edge(exact_edge_chip(h, 6.0, low=1200, high=200))
    x, esf, levels = r.normalised_profile()
    assert r.width_px == 0.0 and x is r.esf_x_px
    assert levels == pytest.approx((1200.0, 200.0), abs=0.5)
    assert esf[0] == pytest.approx(0.0, abs=0.01) and esf[-1] == pytest.approx(1.0, abs=0.01)
    x_lsf, lsf, fwhm = r.lsf_like()
    assert x_lsf is r.lsf_x_px and lsf is r.lsf and fwhm == r.fwhm_px
