"""The point-target stack (imgmtf.estimate.mtf2d.points) against the exact
renderer's truth: quarter-pixel arrays of bright points and of dark 1 px
squares, a lone point, noise; and the refusals of what is not a usable
point.  Coverage over many noisy rows: bench/points_accuracy.py."""
import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError, TargetNotFoundError, UnsuitableTargetError
from imgmtf.estimate.mtf2d import measure_points
from imgmtf.sensor.points import PointArray, quarter_pixel_offsets, render_points
from imgmtf.sensor.stages import Detector, GaussianOptics

SENSOR = im.Sensor(stages=[GaussianOptics(0.45, 0.55), Detector(1.0, 1.0)])
ARRAY = PointArray(4, 4, spacing_px=12.0)


def errors(result, chip):
    return {d.direction: d.mtf_nyquist - float(chip.true_mtf(0.5, d.direction)) for d in result.directions}


def test_bright_quarter_pixel_points_give_the_truth_noise_free():
    chip = render_points(SENSOR, ARRAY, 64, bits=None)
    result = measure_points(chip.image, intervals="none")
    assert len(result.used) == 16 and not result.refused and result.polarity == "bright"
    assert all(abs(e) < 0.01 for e in errors(result, chip).values()), errors(result, chip)
    assert result.alias_weight < 1e-6                  # the quarter pixels tile the pixel evenly
    across, along = result.directions
    assert across.direction == "across-track" and along.direction == "along-track"
    assert across.mtf50_cy_px == pytest.approx(chip.true_mtf50_cy_px("across"), abs=0.005)
    assert along.mtf50_cy_px == pytest.approx(chip.true_mtf50_cy_px("along"), abs=0.005)
    assert across.fwhm_px < along.fwhm_px              # the PSF is wider along track
    assert result.psf.shape[0] == result.psf.shape[1]
    assert result.psf.sum() * result.psf_step_px ** 2 == pytest.approx(1.0, abs=1e-6)
    centre = len(result.frequencies2d_cy_px) // 2
    assert result.mtf2d[centre, centre] == pytest.approx(1.0)
    # the 2-D MTF off the axes: the Gaussian's ellipse times the pixel's sinc, exactly
    f = result.frequencies2d_cy_px
    truth = np.abs(SENSOR.transfer(f[None, :], f[:, None]))
    band = (np.abs(f[None, :]) <= 0.6) & (np.abs(f[:, None]) <= 0.6)
    assert np.abs(result.mtf2d - truth)[band].max() < 0.005


def test_bright_points_at_snr_100_with_intervals():
    clean = render_points(SENSOR, ARRAY, 64, bits=None)
    peak = float(clean.image.max() - ARRAY.low_dn)
    chip = render_points(SENSOR, ARRAY, 64, bits=None, noise_std_dn=peak / 100.0, seed=11)
    result = measure_points(chip.image, intervals=im.Intervals("bootstrap", replicates=100))
    assert all(abs(e) < 0.02 for e in errors(result, chip).values()), errors(result, chip)
    for section in result.directions:
        assert section.mtf_nyquist_ci.low < section.mtf_nyquist < section.mtf_nyquist_ci.high
        assert section.mtf_nyquist_ci.width < 0.08


def test_dark_one_pixel_squares_with_their_size_divided_out():
    array = PointArray(4, 4, spacing_px=12.0, size_px=1.0, low_dn=1000.0, high_dn=100.0)
    chip = render_points(SENSOR, array, 64, bits=None)
    result = measure_points(chip.image, point_size_px=1.0, intervals="none")
    assert result.polarity == "dark" and len(result.used) == 16
    assert all(abs(e) < 0.01 for e in errors(result, chip).values()), errors(result, chip)
    # without the size, the square's sinc (0.637 at Nyquist) stays in
    plain = measure_points(chip.image, intervals="none")
    assert plain.directions[0].mtf_nyquist == pytest.approx(0.637 * result.directions[0].mtf_nyquist, rel=0.02)


def test_a_single_isolated_point_leans_on_its_model_and_says_so():
    chip = render_points(SENSOR, PointArray(1, 1, offsets_px=((0.3, 0.15),)), 32, bits=None)
    result = measure_points(chip.image, intervals="none")
    assert len(result.used) == 1 and result.alias_weight == pytest.approx(1.0)
    assert all(abs(e) < 0.01 for e in errors(result, chip).values()), errors(result, chip)
    assert any("aliases" in w for w in result.warnings)


def test_the_papers_sensor_through_the_stack():
    chip = render_points(im.Sensor(), ARRAY, 64, bits=None)
    result = measure_points(chip.image, intervals="none")
    assert all(abs(e) < 0.01 for e in errors(result, chip).values()), errors(result, chip)


def test_summaries_are_one_record_per_direction():
    chip = render_points(SENSOR, ARRAY, 64, bits=16)
    rows = measure_points(chip.image, intervals="none", gsd_m=2.0).summaries(curves=True)
    assert [r["direction"] for r in rows] == ["across-track", "along-track"]
    assert all(r["target"] == "points" and r["points_used"] == 16 and r["gsd_m"] == 2.0 for r in rows)
    assert rows[0]["mtf"][0] == 1.0 and len(rows[0]["frequencies_cy_px"]) == 101


def test_targets_at_the_edge_blended_or_clipped_are_refused_with_reasons():
    chip = render_points(SENSOR, PointArray(2, 2, spacing_px=12.0), 40, bits=None)
    image = chip.image.copy()
    image[1:4, 1:4] += 500.0                     # a target touching the chip's corner
    image[24:27, 19:22] += 400.0                 # a second target 7 px from the bottom-left point
    image[13:17, 13:17] = 2000.0                 # one point clipped
    result = measure_points(image, intervals="none", saturation=(0.0, 2000.0))
    reasons = {s.status for s in result.refused}
    assert reasons == {"edge", "clipped", "blended"}
    assert len(result.used) == 1
    assert all(s.message for s in result.refused)


def test_an_edge_is_no_point():
    chip = im.render(SENSOR, im.Target("edge", 6.0, 200.0, 1200.0), 60, noise_std_dn=2.0, seed=1)
    with pytest.raises(UnsuitableTargetError, match="an edge or a bar, not point targets") as info:
        measure_points(chip.image, intervals="none")
    assert info.value.reason == "not-points"


def test_a_flat_chip_has_no_target():
    with pytest.raises(TargetNotFoundError, match="no compact target"):
        measure_points(np.random.default_rng(0).normal(100.0, 1.0, (40, 40)), intervals="none")


@pytest.mark.parametrize("settings", [dict(point_size_px=-1.0), dict(polarity="grey"), dict(stamp_radius_px=1)])
def test_bad_settings_are_refused(settings):
    with pytest.raises(ParameterError):
        measure_points(np.zeros((20, 20)), **settings)


def test_wings_the_gaussian_model_lacks_are_measured_not_eased_away():
    # 16 points whose PSF is a pixel Gaussian plus 10 % of their light in wings (sigma 1.5 px)
    from imgmtf.estimate.mtf2d.sources import pixel_gaussian
    n = np.arange(-6, 7.0)
    image = np.full((72, 72), 100.0)
    for k, (dx, dy) in enumerate(quarter_pixel_offsets()):
        y, x = 12 + 16 * (k // 4), 12 + 16 * (k % 4)
        image[y - 6: y + 7, x - 6: x + 7] += (pixel_gaussian((900.0, dx, dy, 0.5, 0.5, 0.0), n)
                                              + pixel_gaussian((100.0, dx, dy, 1.5, 1.5, 0.0), n))
    result = measure_points(np.random.default_rng(0).normal(image, 0.5), intervals="none")
    assert any("of their light beyond" in w for w in result.warnings)
    truth = 0.9 * np.exp(-2 * np.pi ** 2 * 0.25 * 0.25) + 0.1 * np.exp(-2 * np.pi ** 2 * 2.25 * 0.25)
    assert abs(result.directions[0].mtf_nyquist - truth * 2 / np.pi) < 0.005


def test_a_lack_of_tail_light_is_not_called_a_halo():
    from imgmtf.estimate.mtf2d.stack import tail_note
    lack, halo = tail_note(-0.043, 2.2), tail_note(0.043, 2.2)
    assert "4.3 % less" in lack and "halo" not in lack and "-" not in lack.split(":")[0]
    assert "4.3 % more" in halo and "halo" in halo


def test_asking_a_textured_chip_for_points_loads_no_optimizer():
    # a scan asks every edge refused for texture whether it holds points instead: finding none, it
    # must not pay for loading SciPy's optimizer (a fifth of a second), which only a stamp's fit needs
    import subprocess
    import sys
    code = ("import sys, numpy as np; from imgmtf.estimate.mtf2d.sources import points_seen; "
            "print(points_seen(np.random.default_rng(0).normal(100.0, 2.0, (40, 40))), "
            "'scipy.optimize' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["None", "False"]


def test_the_cheap_look_for_points_never_misses_a_used_one():
    # points_seen skips find_sources' judging where no peak passes its cheap checks (faint, off the
    # chip, blended): then none may be used, on textured edges and on chips of a few points alike
    from imgmtf.estimate.mtf2d.sources import _may_hold_points, find_sources, pixel_gaussian, points_seen
    rng = np.random.default_rng(3)
    n = np.arange(-3, 4.0)
    chips = [im.render(SENSOR, im.Target("edge", 6.0, 200.0, 1200.0), 40, noise_std_dn=2.0, seed=k).image
             + rng.normal(0, 40, (40, 40)) for k in range(4)]
    for _ in range(12):
        chip = rng.normal(100.0, 2.0, (36, 44))
        for _ in range(rng.integers(0, 4)):
            y, x = rng.integers(0, 30), rng.integers(0, 38)
            chip[y:y + 7, x:x + 7] += pixel_gaussian((rng.uniform(30, 900), 0.2, -0.3, 0.7, 0.6, 0.0), n)
        chips.append(chip)
    may = [_may_hold_points(chip, 10.0, 4) for chip in chips]
    used = [bool(find_sources(chip, min_snr=10.0).used) for chip in chips]
    assert all(m for m, u in zip(may, used) if u)
    assert any(used) and not all(may)           # both kinds of chip are here
    assert all(points_seen(chip) is None for chip, u in zip(chips, used) if not u)


def test_each_peaks_nearest_blending_neighbour_whatever_the_blocks(monkeypatch):
    # the distance to the nearest neighbour that could blend (not faint, at least a tenth of the peak's
    # height), found a block of peaks at a time: the same as peak by peak, whatever the block
    from imgmtf.estimate.mtf2d import sources
    rng = np.random.default_rng(5)
    n = np.arange(-3, 4.0)
    chip = rng.normal(100.0, 2.0, (60, 60))
    for y, x, flux in [(5, 5, 900.0), (5, 12, 60.0), (30, 30, 400.0), (33, 35, 30.0), (50, 8, 900.0)]:
        chip[y:y + 7, x:x + 7] += pixel_gaussian_stamp(flux, n)
    peaks = sources._peaks(chip, chip, "bright")
    assert len(peaks.ix) >= 5
    seen = []
    for min_snr in (10.0, 200.0):                  # neighbours of some weight, then all faint
        faint = peaks.faint(min_snr)
        expected = [min((np.hypot(peaks.ix[j] - peaks.ix[k], peaks.iy[j] - peaks.iy[k])
                         for j in range(len(peaks.ix))
                         if j != k and not faint[j] and peaks.heights[j] >= 0.1 * peaks.heights[k]), default=np.inf)
                    for k in range(len(peaks.ix))]
        whole = peaks.nearest(faint)
        with monkeypatch.context() as patch:
            patch.setattr(sources, "NEAREST_BLOCK", 2)
            assert np.array_equal(whole, expected) and np.array_equal(peaks.nearest(faint), expected)
            assert np.array_equal(peaks.nearest(faint, np.array([3, 0])), [expected[3], expected[0]])
        seen += expected
    assert np.isinf(seen).any() and np.isfinite(seen).any()


def pixel_gaussian_stamp(flux, n):
    from imgmtf.estimate.mtf2d.sources import pixel_gaussian
    return pixel_gaussian((flux, 0.2, -0.3, 0.7, 0.6, 0.0), n)
