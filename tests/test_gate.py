"""The quality gate: for every check, a chip that trips it and one that
passes; forced measurements carry every failed check as a warning."""
import math

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter
from scipy.special import erf

import imgmtf as im
from imgmtf.errors import ImgmtfError, MultipleTargetsError, TargetNotFoundError
from imgmtf.estimate import gate
from imgmtf.estimate.sides import side_checks

from conftest import exact_edge_chip, exact_esf, gaussian_pixel_transfer

H = gaussian_pixel_transfer(0.5, 6.0)


def edge(noise=5.0, seed=1, angle=6.0, shape=(100, 100), **kw):
    h = gaussian_pixel_transfer(0.5, angle)
    return exact_edge_chip(h, angle, shape=shape, noise_std=noise, seed=seed, offset=0.2, **kw)


def refused(image, reason, measure=im.measure_edge, **kw):
    with pytest.raises(ImgmtfError) as info:
        measure(image, **kw)
    assert info.value.reason == reason, str(info.value)
    assert "\n" not in str(info.value)
    return info.value


def test_a_clean_edge_passes_every_check():
    r = im.measure_edge(edge())
    assert all(c.passed for c in r.checks) and not r.warnings
    assert {c.reason for c in r.checks} >= {"fill", "not-straight", "too-short", "saturated", "non-uniform",
                                           "two-targets", "snr", "mtf-above-one"}


def test_fill_with_a_hard_boundary_is_refused_and_a_dark_plateau_is_not():
    chip = edge().astype(float)
    chip[:, :18] = 0
    refused(chip, "fill")
    # a 0 DN side blurred into the edge is a level (clipped or not), not fill
    dark = edge(noise=0.0, low=0, high=1000, dtype=np.float64)
    assert im.measure_edge(dark).mtf_nyquist == pytest.approx(H(0.5), abs=0.003)
    # a sentinel far outside the data: a type's limit, or a negative value among positive ones
    sentinel = edge().astype(float)
    sentinel[:20] = 65535
    assert not gate.fill_check(sentinel, np.uint16).passed
    sentinel[:20] = -9999
    assert not gate.fill_check(sentinel, np.float32).passed
    # a second, unblurred step to a level inside the data's range is not fill
    step = edge().astype(float) + np.where(np.arange(100) > 80, 300.0, 0.0)[None, :]
    assert gate.fill_check(step, np.uint16).passed
    # pixels of 0 DN scattered through noise (1 in 180 of uniform values) are no fill region,
    # but a one-pixel column of them is
    noise = np.random.default_rng(0).integers(0, 180, (100, 100)).astype(np.uint8)
    assert (noise == 0).mean() > gate.MIN_FILL_FRACTION and gate.fill_check(noise, np.uint8).passed
    column = edge().astype(float)
    column[:, 3] = 0
    assert not gate.fill_check(column, np.uint16).passed


def test_saturation_by_type_limit_by_given_range_and_by_a_clip_no_one_declared():
    refused(edge(noise=3.0, low=40, high=400, dtype=np.uint8), "saturated")
    ok = edge(noise=3.0)
    refused(ok, "saturated", saturation=(0, 1000))
    assert im.measure_edge(ok, saturation=(0, 4095)).mtf_nyquist > 0
    clipped = np.minimum(edge(noise=0.0).astype(float), 255.0)          # float, noise-free
    refused(clipped, "saturated")
    noisy_clip = np.minimum(edge(noise=5.0).astype(float), 700.0)       # a pile-up at 700
    refused(noisy_clip, "saturated")


def test_a_noise_free_bar_clipped_flat_is_refused_and_a_wide_bars_own_plateau_is_not():
    # a clip meets the top steeply; a 5 px bar reaches its own flat top through a shoulder
    for width, clip in ((1.5, 800.0), (5.0, 1100.0), (5.0, 1190.0)):
        bar = im.render(im.Sensor(), im.Target("pulse", 6.0, 200.0, 1200.0, 0.3, width), (100, 80)).image
        refused(np.minimum(bar.astype(float), clip), "saturated", measure=im.measure_pulse, width_px=width)
    wide = im.render(im.Sensor(), im.Target("pulse", 6.0, 200.0, 1200.0, 0.3, 5.0), (100, 80))
    result = im.measure_pulse(wide.image, width_px=5.0)
    assert abs(result.mtf_nyquist - float(wide.true_mtf(0.5))) < 0.002


def test_a_bent_edge_and_scattered_rows_are_not_straight():
    y, x = np.mgrid[0:100, 0:100].astype(float)
    r = np.hypot(x - 200, y - 50)
    bent = 200 + 1000 * 0.5 * (1 + erf((150 - r) / (0.6 * math.sqrt(2))))
    refused(bent + np.random.default_rng(0).normal(0, 5, bent.shape), "not-straight")
    wobbly = np.array([np.interp(np.arange(100.0), np.arange(100.0) + 3 * math.sin(i / 3.0),
                                 row) for i, row in enumerate(edge(noise=2.0).astype(float))])
    refused(wobbly, "not-straight")


def test_two_parallel_edges_and_two_bars():
    h = H
    first = exact_edge_chip(h, 6.0, offset=-7.5, low=200, high=700)
    second = exact_edge_chip(h, 6.0, offset=7.5, low=0, high=500)
    with pytest.raises(MultipleTargetsError) as info:
        im.measure_edge(first.astype(float) + second)
    assert info.value.reason == "two-targets"
    bars = (im.render(im.Sensor(), im.Target("pulse", 6.0, 200, 1200, -8.5, 1.5), 100).image.astype(float)
            + im.render(im.Sensor(), im.Target("pulse", 6.0, 200, 1200, 8.5, 1.5), 100).image - 200)
    refused(bars, "two-targets", measure=im.measure_pulse, width_px=1.5)


def test_a_level_that_drifts_or_carries_texture_is_non_uniform():
    chip = edge().astype(float)
    x = np.arange(100.0)
    refused(chip + np.where(x > 55, 4.0 * (x - 55), 0.0)[None, :], "non-uniform")
    texture = 150 * gaussian_filter(np.random.default_rng(3).normal(size=chip.shape), 2.0) / 0.14
    refused(chip + np.where(x > 56, 1.0, 0.0)[None, :] * texture, "non-uniform")


def test_too_few_rows_and_too_little_snr():
    refused(edge(shape=(16, 100)), "too-short")
    refused(edge(noise=150.0, seed=4, dtype=np.float64), "snr")
    warned = im.measure_edge(edge(noise=50.0, seed=4))          # SNR 20: measured, with a warning
    assert warned.snr == pytest.approx(20, rel=0.25) and any("SNR" in w for w in warned.warnings)


def test_a_sharpened_edge_reads_above_one_and_is_refused():
    chip = edge(noise=1.0).astype(float)
    sharpened = chip + 2.5 * (chip - gaussian_filter(chip, 2.0))
    refused(sharpened, "mtf-above-one")


def test_edge_and_bar_are_one_classification():
    bar = im.render(im.Sensor(), im.Target("pulse", 6.0, 200, 1200, 0.1, 2.0), 100).image
    refused(bar, "not-an-edge")
    # cropped close, a noisy bar defeats every row's step fit: still a bar
    bar = im.render(im.Sensor(), im.Target("pulse", -5.0, 200, 1200, 0.1, 3.0), 122).image
    noisy = bar + np.random.default_rng(1).normal(0.0, 6.0, bar.shape)
    centre = int(np.argmax(bar[61]))
    refused(noisy[:, centre - 19:centre + 19], "not-an-edge")
    # a thin bar near the rows leaves the step fits' phases too sparse: the reason is still the bar
    for angle, width in ((84.0, 1.5), (6.0, 3.0)):
        bar = im.render(im.Sensor(), im.Target("pulse", angle, 200, 1200, 0.2, width), 100, noise_std_dn=2.0,
                        seed=3).image
        refused(bar, "not-an-edge")
    refused(edge(), "not-a-bar", measure=im.measure_pulse)
    grid = np.linspace(-10, 10, 401)
    assert gate.classify_profile(0.5 * (1 + erf(grid))) == "edge"
    assert gate.classify_profile(np.exp(-grid ** 2)) == "bar"


def test_no_target_in_noise():
    with pytest.raises(TargetNotFoundError):
        im.measure_edge(np.random.default_rng(0).normal(500, 20, (80, 80)))


def test_force_measures_anyway_with_every_failed_check_as_a_warning():
    chip = edge().astype(float)
    x = np.arange(100.0)
    chip += np.where(x > 55, 4.0 * (x - 55), 0.0)[None, :]
    chip[:12, :] = 0
    error = refused(chip, "fill")
    assert "non-uniform" in str(error).split("also failed:")[1] and "fill" not in str(error).split("also failed:")[1]
    r = im.measure_edge(chip, force=True)
    assert {w.split(":")[0] for w in r.warnings} >= {"fill", "non-uniform"}
    assert r.to_dict()["checks"]
    # and its figure says so first, in red: it looks like no other
    from imgmtf.plot import plot_measurement
    header = plot_measurement(r, title="chip.tif")._suptitle
    assert header.get_text().splitlines()[1].startswith("FORCED past") and header.get_color() == "C3"


def test_direction_is_labelled_only_near_the_track():
    assert im.measure_edge(edge(angle=6.0)).direction == "across-track"
    assert im.measure_edge(edge(angle=84.0)).direction == "along-track"
    oblique = im.measure_edge(edge(angle=30.0))
    assert oblique.direction == "oblique" and oblique.tilt_deg == pytest.approx(30.0, abs=0.05)
    # the same edge in a scene whose track runs 30 deg clockwise from the image's up
    assert im.measure_edge(edge(angle=30.0), track_azimuth_deg=30.0).direction == "across-track"
    unknown = im.measure_edge(edge(), track_azimuth_deg=None)
    assert unknown.direction == "unknown" and any("map-projected" in w for w in unknown.warnings)


def _normal_distance(shape=(100, 100), angle=6.0, offset=0.2):
    rows, cols = shape
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    a = math.radians(angle)
    return (x - (cols - 1) / 2) * math.cos(a) + (y - (rows - 1) / 2) * math.sin(a) - offset


def test_a_side_that_curves_or_never_settles_is_non_uniform_and_a_lens_tail_is_not():
    from conftest import diffraction_transfer, product
    chip = edge(noise=3.0, dtype=np.float64)
    d = _normal_distance()
    bright = np.clip(d / 50.0, 0.0, None)
    # an illumination fall-off growing as the square of the distance: 10 % of the contrast over the side
    error = refused(chip + 1000 * 0.1 * bright ** 2, "non-uniform")
    assert "departs from a settled level" in str(error)
    # a level still rising towards its plateau 15 px out (20 % of the contrast to come): never settles
    error = refused(chip + 1000 * 0.2 * (1 - np.exp(-d.clip(0) / 15)), "non-uniform")
    assert "has not settled" in str(error)
    # half as much curvature: measured, with the departure said
    mild = im.measure_edge(chip + 1000 * 0.05 * bright ** 2)
    assert any("departs from a settled level" in w for w in mild.warnings)
    # diffraction's long tails (f/16) and a Gaussian's none are a settled level: no word
    for h in (product(diffraction_transfer(8.6 / 16), gaussian_pixel_transfer(0.0, 6.0)), H):
        r = im.measure_edge(exact_edge_chip(h, 6.0, shape=(100, 200), offset=0.2, noise_std=1.0))
        assert not r.warnings and all(c.passed for c in r.checks)
        assert abs(r.mtf_nyquist - float(h(0.5))) < 0.01


def test_blur_that_changes_along_the_target_is_refused_or_said():
    def halves(sigma_top, sigma_bottom, noise=3.0):
        top = exact_edge_chip(gaussian_pixel_transfer(sigma_top, 6.0), 6.0, offset=0.2, noise_std=noise,
                              dtype=np.float64)
        bottom = exact_edge_chip(gaussian_pixel_transfer(sigma_bottom, 6.0), 6.0, offset=0.2, noise_std=noise,
                                 seed=2, dtype=np.float64)
        return np.vstack([top[:50], bottom[50:]])
    error = refused(halves(0.5, 0.9), "varying-blur")
    assert "rows 0-" in str(error) and "-99" in str(error)
    slight = im.measure_edge(halves(0.5, 0.55, noise=1.0))
    assert any("blur changes a little" in w for w in slight.warnings)
    assert not any("blur" in w for w in im.measure_edge(halves(0.5, 0.5)).warnings)
    # a bar whose lower half is blurred more
    sharp, soft = (im.render(im.Sensor(optics_sigma_x_m=s, optics_sigma_y_m=s, motion_m=0.0,
                                       electronics_cutoff_cy_m=0.0),
                             im.Target("pulse", 6.0, 200.0, 1200.0, 0.3, 3.0), (100, 80), noise_std_dn=2.0,
                             seed=k).image for k, s in ((1, 0.4), (2, 0.8)))
    refused(np.vstack([sharp[:50], soft[50:]]).astype(float), "varying-blur", measure=im.measure_pulse,
            width_px=3.0)
    assert im.measure_pulse(sharp, width_px=3.0).mtf_nyquist > 0


def test_a_flat_white_level_approached_smoothly_is_no_clip_and_a_clip_still_is():
    """MTF Mapper's generator writes its white as one exact value (63897 DN,
    22 % of the samples), with a wobble of its last digits below it (never
    above, in steps of about 17 DN); its chips were refused as clipped.  A
    Gaussian + pixel edge with that white stands in for them here."""
    from conftest import true_mtf50
    h = gaussian_pixel_transfer(0.45, 5.0)
    white = 63897.0
    exact = exact_edge_chip(h, 5.0, low=1638.0, high=white, offset=0.2, dtype=np.float64)
    wobble = 17.0 * np.floor(np.abs(np.random.default_rng(5).normal(0.0, 1.9, exact.shape)))
    wobbly = np.rint(exact) - wobble
    assert (wobbly == white).mean() > 0.15
    for chip in (wobbly, exact):
        r = im.measure_edge(np.rint(chip).astype(np.uint16))
        assert r.mtf50_cy_px == pytest.approx(true_mtf50(h), rel=0.01)
    # the same white cut 5 % of the contrast lower is a clip, with the wobble and without
    cut = white - 0.05 * (white - 1638.0)
    refused(np.rint(np.minimum(wobbly, cut)).astype(np.uint16), "saturated")
    refused(np.rint(np.minimum(exact, cut)).astype(np.uint16), "saturated")


def test_noise_free_bars_up_to_10_px_wide_are_measured_and_clipped_ones_are_not():
    for width in (8.0, 10.0):
        chip = im.render(im.Sensor(), im.Target("pulse", 6.0, 200.0, 1200.0, 0.3, width), (100, 80))
        result = im.measure_pulse(chip.image, width_px=width)
        f = np.array([0.5, 1.5]) / width           # between the sinc's zeros at multiples of 1 / width
        assert np.allclose(result.mtf_function(f), chip.true_mtf(f), atol=0.003)
        for clip in (1100.0, 1190.0):
            refused(np.minimum(chip.image.astype(float), clip), "saturated", measure=im.measure_pulse,
                    width_px=width)


def test_nan_holes_and_hot_pixels_are_left_out_and_counted():
    chip = edge(noise=3.0, dtype=np.float64)
    y, x = np.mgrid[0:100, 0:100]
    holes = chip.copy()
    for cy, cx, radius in ((20, 30, 6), (60, 70, 8), (80, 45, 4)):       # cloud-like NaN blobs on both sides
        holes[(y - cy) ** 2 + (x - cx) ** 2 < radius ** 2] = np.nan
    clean = im.measure_edge(chip)
    r = im.measure_edge(holes)
    assert r.params["nodata_px"] == int(np.isnan(holes).sum())
    assert any(f"{r.params['nodata_px']} NaN or nodata" in w for w in r.warnings)
    assert abs(r.mtf_nyquist - clean.mtf_nyquist) < 0.01 and abs(r.mtf_nyquist - H(0.5)) < 0.015
    # a mask leaves pixels out without a word; NaN among them is not counted again
    masked = im.measure_edge(holes, mask=~np.isnan(holes))
    assert "nodata_px" not in masked.params and masked.mtf_nyquist == r.mtf_nyquist
    hot = chip.copy()
    rng = np.random.default_rng(3)
    # hot and dead pixels on the levels (within a few px of the edge a dead pixel hides in the step)
    columns = rng.choice(np.r_[5:40, 62:95], 12, replace=False)
    hot[rng.choice(100, 12, replace=False), columns] = np.where(np.arange(12) % 2, 4000.0, 0.0)
    r = im.measure_edge(hot)
    assert r.params["outlier_px"] == 12 and any("12 isolated" in w for w in r.warnings)
    assert abs(r.mtf_nyquist - clean.mtf_nyquist) < 0.01
    # no pixel of a clean edge or a thin noise-free bar, at any angle, is an outlier
    from imgmtf.estimate.outliers import isolated_outliers
    for angle in np.arange(2.0, 44.0, 3.7):
        bar = im.render(im.Sensor(), im.Target("pulse", angle, 200, 1200, 0.3, 0.5), 100).image.astype(float)
        assert not isolated_outliers(bar, 0.0).any()
        assert not isolated_outliers(edge(noise=0.0, angle=angle, dtype=np.float64), 0.0).any()


def test_a_road_beside_an_edge_and_a_shadow_beside_a_bar_are_second_targets():
    d = _normal_distance()
    road = edge(noise=3.0, dtype=np.float64) + 600.0 * ((d < -10) & (d > -16))     # a bright band on the dark side
    refused(road, "two-targets")
    bar = im.render(im.Sensor(), im.Target("pulse", 6.0, 200.0, 1200.0, 0.3, 2.0), (100, 80), noise_std_dn=3.0,
                    seed=5).image.astype(float)
    d = _normal_distance((100, 80), offset=0.3)
    refused(bar - 300.0 * ((d > 7) & (d < 11)), "two-targets", measure=im.measure_pulse, width_px=2.0)
    assert gate.mixed_profile(np.r_[np.full(10, 200.0), np.full(5, 800.0), np.full(10, 200.0), np.full(10, 1200.0)])
    assert not gate.mixed_profile(np.r_[np.full(10, 200.0), np.linspace(200, 1200, 5), np.full(10, 1200.0)])


def test_a_side_whose_plateau_never_arrives_is_refused_not_passed_unchecked():
    # the bright side keeps rising as a curve beyond the edge, 200 + (1000 + 12 d^1.5) DN: read as
    # blur the edge measured 0.04 at Nyquist (truth 0.19) with no side left to check and no word
    d = _normal_distance()
    fx, esf = exact_esf(H)
    chip = 200 + (1000 + 12 * np.clip(d, 0, None) ** 1.5) * np.interp(d, fx, esf)
    error = refused(chip + np.random.default_rng(3).normal(0, 3, chip.shape), "non-uniform")
    assert "holds no plateau within the chip" in str(error)


def test_every_check_is_listed_with_its_outcome_and_one_that_cannot_run_says_why():
    # 30 rows: too few for the 8-row block grid; measured, the check listed as not run
    r = im.measure_edge(edge(shape=(30, 100)))
    outcomes = {(c.reason, c.outcome) for c in r.checks}
    assert ("compression", "not-run") in outcomes and all(not c.failed for c in r.checks)
    listed = r.to_dict()["checks"]
    assert len(listed) == len(r.checks) and {c["outcome"] for c in listed} == {"passed", "not-run"}
    not_run = next(c for c in listed if c["outcome"] == "not-run")
    assert not not_run["passed"] and not_run["message"].startswith("not run: ")
    # a check that did not run is no pass, and no refusal either
    check = gate.not_run("varying-blur", "too few rows")
    assert (check.passed, check.failed, check.outcome) == (False, False, "not-run")
    assert gate.enforce([check], force=False) == ()


def test_block_jumps_are_told_from_the_locators_bias_with_the_phase():
    """Row locations about their line: a sharp edge's locator bias with the
    sub-pixel phase, 0.2 px jumping where the phase wraps (every 24 rows at
    2.39 deg: always at one phase of an 8-row grid), is no codec (it was
    refused as one); 8-row jumps of 0.1 px beside it are.  At 14.04 deg the
    phase repeats every 4 rows and could stand in for the blocks, so the
    jumps are judged as they are."""
    from types import SimpleNamespace

    from imgmtf.estimate.blocks import block_boundaries
    from imgmtf.estimate.geometry import TargetGeometry
    rows = np.arange(100)
    noise = np.random.default_rng(1).normal(0, 0.01, 100)

    def compression(slope, offsets, bias=0.2):
        line = slope * rows + 40.3
        located = line + bias * (np.mod(line, 1.0) - 0.5) + offsets + noise
        geometry = TargetGeometry(slope, 40.3, rows, located, np.ones(100, bool), False)
        (check,), _ = block_boundaries(SimpleNamespace(geometry=geometry, name="edge"))
        return check
    blocks = 0.1 * (rows // 8)
    assert compression(1 / 24, 0.0).passed
    assert compression(1 / 24, blocks).failed
    assert compression(0.25, blocks, bias=0.0).failed


def test_checks_with_nothing_to_judge_are_not_run_rather_than_passed():
    # an MTF that is nowhere finite is not below 1
    check = gate.mtf_excess_check(lambda f: np.full(np.shape(f), np.nan), lambda f: np.zeros(np.shape(f)), 0.5)
    assert check.outcome == "not-run" and not check.failed
    # 30 samples each side spread 1 per 0.2 px over 6 px: no 1-px band holds 10, no second feature looked for
    d = np.r_[-np.arange(3.0, 9.0, 0.2), np.arange(3.0, 9.0, 0.2)]
    values = np.where(d < 0, 200.0, 1200.0)
    checks = side_checks(d, values, np.arange(d.size, dtype=float), 0.0, 2.0, 1000.0, 1.0, 1)
    second = [c for c in checks if c.reason == "two-targets"]
    assert len(second) == 2 and all(c.outcome == "not-run" for c in second)
    assert all(c.outcome == "passed" for c in checks if c.reason == "non-uniform")


def test_closed_form_line_matches_numpy():
    # the rows' line (geometry) in closed form: NumPy's to rounding
    from imgmtf.estimate.geometry import _straight_line
    rng = np.random.default_rng(3)
    rows = np.arange(7.0, 93.0)
    locations = 0.17 * rows + 41.3 + rng.normal(0.0, 0.2, rows.size)
    np.testing.assert_allclose(_straight_line(rows, locations), np.polyfit(rows, locations, 1), rtol=1e-12)


def test_every_message_of_a_noise_free_chip_stands_under_rounding(monkeypatch):
    # trends, band means and tail shares of a flat side are rounding: which is larger, their sign and
    # where they peak must not move with a change of the arithmetic before them (here the rows' line
    # by np.polyfit instead of in closed form: the same line to about 1e-16)
    from imgmtf.estimate import geometry
    chips = [im.render(im.Sensor(), im.Target("edge", angle, 100.0, 1100.0), 60).image for angle in (5.0, 7.0)]

    def messages():
        return [c.message for chip in chips for c in im.measure_edge(chip).checks]
    plain = messages()
    monkeypatch.setattr(geometry, "_straight_line", lambda y, x: tuple(float(v) for v in np.polyfit(y, x, 1)))
    assert messages() == plain


def test_many_targets_lines_are_checked_as_each_alone(mixed_evidence):
    calls = [(ev.geometry, 0.05, ev.name) for ev in mixed_evidence]
    together = gate.line_checks_many(calls)
    assert together == [gate.line_checks(*call) for call in calls]
    assert len({str(checks) for checks in together}) == len(together)


def test_many_chips_block_jumps_are_judged_as_each_alone(mixed_evidence):
    from imgmtf.estimate.blocks import block_boundaries, block_boundaries_many
    together = block_boundaries_many(mixed_evidence)
    assert together == [block_boundaries(ev) for ev in mixed_evidence]
    assert len({str(outcome) for outcome in together}) == len(together)
