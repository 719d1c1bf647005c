"""The shared pipeline: long-tailed blurs against their closed forms, the
settings' validation, and the linearised intervals."""
import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.estimate.geometry import direction_label
from imgmtf.estimate.settings import make_settings

from conftest import (
    defocus_transfer,
    diffraction_transfer,
    exact_edge_chip,
    gaussian_pixel_transfer,
    olpf_transfer,
    product,
    true_fwhm,
    true_mtf50,
)


def pixel(angle):
    a = math.radians(angle)
    return lambda f: np.sinc(f * math.cos(a)) * np.sinc(f * math.sin(a))


LONG_TAILED = {
    "diffraction f/8": lambda a: product(diffraction_transfer(4.73 / (0.55 * 8)), pixel(a)),
    "diffraction f/22": lambda a: product(diffraction_transfer(4.73 / (0.55 * 22)), pixel(a)),
    "diffraction + Gaussian": lambda a: product(diffraction_transfer(4.73 / (0.55 * 11)),
                                                gaussian_pixel_transfer(0.4, a)),
    "defocus r 1.5": lambda a: product(defocus_transfer(1.5), gaussian_pixel_transfer(0.3, a)),
    "OLPF": lambda a: product(olpf_transfer(0.75, a), diffraction_transfer(4.73 / (0.55 * 5.6)), pixel(a)),
}


@pytest.mark.parametrize("name", list(LONG_TAILED))
def test_long_tailed_blurs_keep_their_tails(name):
    angle = 5.0
    h = LONG_TAILED[name](angle)
    r = im.measure_edge(exact_edge_chip(h, angle, shape=(100, 200), offset=0.3))
    assert abs(r.mtf_nyquist - abs(h(0.5))) <= 0.002      # a defocus disk's transfer turns negative
    assert r.mtf50_cy_px == pytest.approx(true_mtf50(h), rel=0.003)
    assert r.fwhm_px == pytest.approx(true_fwhm(h), rel=0.005)


def test_a_short_window_without_the_tail_model_would_read_high():
    """What the tails are worth: cut at the core, diffraction reads MTF50 3 % high."""
    angle = 5.0
    h = LONG_TAILED["diffraction f/8"](angle)
    chip = exact_edge_chip(h, angle, shape=(100, 200), offset=0.3)
    kept = im.measure_edge(chip)
    assert kept.tail_fraction > 0.01
    profile = kept.lsf
    assert profile.sum() > 0
    assert true_mtf50(h) * 1.02 < _truncated_mtf50(kept)


def _truncated_mtf50(result):
    """MTF50 of the result's own LSF cut to its core and renormalised."""
    x, lsf = result.lsf_x_px, result.lsf
    core = np.abs(x - x[np.argmax(lsf)]) <= result.lsf_half_width_px
    f = np.linspace(0, 1, 2001)
    spectrum = np.abs(np.exp(-2j * np.pi * f[:, None] * x[None, core]) @ lsf[core])
    mtf = spectrum / spectrum[0]
    i = np.nonzero(mtf < 0.5)[0][0]
    return f[i]


def test_settings_are_validated_by_name():
    for bad, words in [(dict(step_px=1e-7), "step_px"), (dict(step_px=5), "step_px"),
                       (dict(lsf_half_width_px=-1), "lsf_half_width_px"),
                       (dict(lsf_window_factor=1e-9), "lsf_window_factor"),
                       (dict(bootstrap=5), "replicates"), (dict(bootstrap=10 ** 6), "replicates"),
                       (dict(colour="red"), "unknown option"), (dict(method="lanczos"), "unknown method"),
                       (dict(method_options={"window_px": 0}), "window_px"),
                       (dict(frequencies_cy_px=[0.1, np.nan]), "frequencies"), (dict(force="yes"), "force")]:
        with pytest.raises(ParameterError, match=words):
            make_settings(**bad)
    assert make_settings(bootstrap=200).intervals.replicates == 200
    assert make_settings(bootstrap=0).intervals.method == "none"
    assert make_settings(step_px=np.float32(0.05)).step_px == pytest.approx(0.05)
    chip = exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0)
    for gsd in (-1, float("nan"), "abc"):
        with pytest.raises(ParameterError, match="gsd_m"):
            im.measure_edge(chip, gsd_m=gsd)
    for saturation in ("x", (5, 1), (0, float("inf"))):
        with pytest.raises(ParameterError, match="saturation"):
            im.measure_edge(chip, saturation=saturation)
    assert im.measure_edge(chip, gsd_m=np.int64(2)).mtf50_cy_m == pytest.approx(
        im.measure_edge(chip).mtf50_cy_px / 2)


def test_intervals_switch_off_and_the_bootstrap_agrees_with_the_linearised_one():
    chip = exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0, noise_std=10.0, seed=3)
    none = im.measure_edge(chip, bootstrap=0)
    assert math.isnan(none.mtf_nyquist_ci.low)
    linear = im.measure_edge(chip)
    boot = im.measure_edge(chip, bootstrap=200)
    assert boot.mtf_nyquist == linear.mtf_nyquist
    assert boot.mtf_nyquist_ci.width == pytest.approx(linear.mtf_nyquist_ci.width, rel=0.35)
    assert boot.mtf50_ci_cy_px.width == pytest.approx(linear.mtf50_ci_cy_px.width, rel=0.35)


def test_linearised_standard_error_matches_the_spread_of_repeated_chips():
    """40 chips of one edge under fresh noise: the spread of their MTF at
    Nyquist against the mean standard error the intervals imply."""
    h = gaussian_pixel_transfer(0.5, 6.0)
    estimates, widths = [], []
    for seed in range(40):
        r = im.measure_edge(exact_edge_chip(h, 6.0, shape=(60, 60), noise_std=20.0, seed=seed))
        estimates.append(r.mtf_nyquist)
        widths.append(r.mtf_nyquist_ci.width)
    from scipy.special import stdtrit
    implied = np.mean(widths) / (2 * stdtrit(59, 0.975))
    assert np.std(estimates) == pytest.approx(implied, rel=0.3)


@pytest.mark.parametrize("normal, track, label", [(5.0, 0.0, "across-track"), (-8.0, 0.0, "across-track"),
                                                  (84.0, 0.0, "along-track"), (-89.0, 0.0, "along-track"),
                                                  (30.0, 0.0, "oblique"), (30.0, 30.0, "across-track"),
                                                  (0.0, None, "unknown")])
def test_direction_label(normal, track, label):
    assert direction_label(normal, track) == label


def test_a_mask_leaves_the_fill_around_a_tilted_target_out():
    """A 16.8 deg edge cut out of a 0 fill (as a calibration chip is): refused
    whole, measured true inside a tilted mask that stops short of the fill."""
    angle = 16.8
    h = gaussian_pixel_transfer(0.5, angle)
    chip = exact_edge_chip(h, angle, offset=0.2, noise_std=5.0, seed=2).astype(float)
    y, x = np.mgrid[0:100, 0:100].astype(float)
    a = math.radians(angle)
    across = (x - 49.5) * math.cos(a) + (y - 49.5) * math.sin(a)
    along = -(x - 49.5) * math.sin(a) + (y - 49.5) * math.cos(a)
    chip[(np.abs(across) >= 30) | (np.abs(along) >= 25)] = 0
    with pytest.raises(im.ImgmtfError, match="fill"):
        im.measure_edge(chip.astype(np.uint16))
    r = im.measure_edge(chip.astype(np.uint16), mask=(np.abs(across) < 28) & (np.abs(along) < 23))
    assert abs(r.mtf_nyquist - h(0.5)) < 0.02 and r.normal_angle_deg == pytest.approx(angle, abs=0.1)
    with pytest.raises(ParameterError, match="mask"):
        im.measure_edge(chip, mask=np.ones((3, 3), bool))


# -- the stages ----------------------------------------------------------------
def _stages_of(chip_image, kind=None, **options):
    from imgmtf.estimate.edge import EdgeKind
    from imgmtf.estimate.pipeline import run
    return run(kind or EdgeKind(), chip_image, make_settings(intervals="none", **options))


def test_the_stages_rerun_from_the_records_give_the_records():
    """Each named stage, given the records before it, gives the record the
    run kept: the stages are the run."""
    from dataclasses import replace

    from imgmtf.estimate.chip import prepare_chip
    from imgmtf.estimate.edge import EdgeKind
    from imgmtf.estimate.pipeline import locate_target
    from imgmtf.estimate.profile import read_profile, rebuild_staircase, widen_profile
    chip = exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0, noise_std=3.0, seed=2)
    settings = make_settings(intervals="none")
    m = _stages_of(chip)
    kind = EdgeKind()
    prepared = prepare_chip(chip, settings)
    np.testing.assert_array_equal(prepared.pixels, m.chip.pixels)
    located = locate_target(kind, prepared)
    assert located.rows_used == m.located.rows_used == 100 and located.rows_total == 100
    assert located.geometry.slope == m.located.geometry.slope
    samples = rebuild_staircase(kind, located.samples, prepared.quantum_dn)
    assert samples is located.samples                         # noisy: no staircase to rebuild
    profile, shape = read_profile(kind, samples, settings)
    assert shape.centre == m.shape.centre and profile.span == m.estimate.shape_profile.span
    assert widen_profile(profile, samples, shape, m.estimate.window, settings, "edge") is profile
    wide = replace(m.estimate.window, core_px=20.0)
    assert widen_profile(profile, samples, shape, wide, settings, "edge").grid[-1] > profile.grid[-1]


def test_a_noise_free_quantised_edge_has_its_staircase_rebuilt():
    from imgmtf.estimate.edge import EdgeKind
    from imgmtf.estimate.profile import rebuild_staircase
    chip = exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0, low=30, high=60, dtype=np.uint8)
    m = _stages_of(chip)
    assert m.estimate.samples.dequantised and m.params["dequantised"]
    rebuilt = rebuild_staircase(EdgeKind(), m.located.samples, 1.0)
    assert rebuilt.dequantised and not np.array_equal(rebuilt.values_dn, rebuilt.raw_dn)
    np.testing.assert_array_equal(rebuilt.raw_dn, m.located.samples.raw_dn)


def test_the_transform_divides_out_the_central_difference_and_nothing_else_uncorrected():
    """A Gaussian LSF laid on the lattice in place of the measured one:
    the uncorrected MTF times the central difference's transfer is the
    Gaussian's exp(-2 pi^2 sigma^2 f^2)."""
    from dataclasses import replace

    from imgmtf.estimate.edge import EdgeKind
    from imgmtf.estimate.spectrum import edge_divisor
    from imgmtf.estimate.transform import transform
    m = _stages_of(exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0))
    e, sigma = m.estimate, 0.6
    lsf = replace(e.lsf, combined=np.exp(-e.lsf.x_px ** 2 / (2 * sigma ** 2)))
    spectrum = transform(EdgeKind(), e.samples, e.profile, m.shape, m.noise, e.window, lsf,
                         make_settings(correct=False))
    f = np.array([0.1, 0.25, 0.5])
    expected = np.exp(-2 * np.pi ** 2 * sigma ** 2 * f ** 2)
    np.testing.assert_allclose(spectrum.mtf(f) * np.abs(edge_divisor(lsf.step_px, None)(f)), expected, atol=2e-4)
    assert spectrum.fwhm_px == pytest.approx(2 * math.sqrt(2 * math.log(2)) * sigma, rel=2e-3)


def test_the_gate_stage_passes_a_clean_chip_and_warns_of_a_noisy_one():
    from imgmtf.estimate.edge import EdgeKind
    from imgmtf.estimate.judge import judge
    m = _stages_of(exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0, noise_std=3.0, seed=1))
    e = m.estimate
    checks, warnings = judge(EdgeKind(), m.chip, m.located, e.samples, m.shape, m.noise, e.window, e.spectrum,
                             make_settings())
    assert all(check.passed for check in checks) and warnings == []
    low = _stages_of(exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0, noise_std=60.0, seed=1))
    e = low.estimate
    checks, warnings = judge(EdgeKind(), low.chip, low.located, e.samples, low.shape, low.noise, e.window,
                             e.spectrum, make_settings())
    assert [w for w in warnings if w.startswith(f"SNR {low.noise.snr:.0f} is below 79")]    # 125 sqrt(40 / 100)


def test_the_measurement_fills_every_field_a_result_has_but_the_kinds_own():
    from dataclasses import fields

    from imgmtf.estimate.results import MTFResult
    m = _stages_of(exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0))
    assert set(m.result_fields()) == {f.name for f in fields(MTFResult)} - {"method", "params", "polarity",
                                                                              "warnings"}
