"""The LSF window and the tails beyond it: the noise that sizes it, its
core and taper, and the tail model blended in, against exact answers."""
import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.estimate.edge import EdgeKind
from imgmtf.estimate.kind import Shape
from imgmtf.estimate.pipeline import run
from imgmtf.estimate.profile import resample_samples
from imgmtf.estimate.settings import make_settings
from imgmtf.estimate.state import Samples, Window
from imgmtf.estimate.window import TAPER_FACTOR, blend_tails, choose_window, measure_noise

from conftest import exact_edge_chip, gaussian_pixel_transfer


def measured(noise_std=0.0, seed=0, **options):
    chip = exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0, noise_std=noise_std, seed=seed,
                           dtype=np.float64)
    return run(EdgeKind(), chip, make_settings(intervals="none", **options))


def test_the_noise_is_the_sides_scatter():
    m = measured(noise_std=10.0, seed=1)
    assert m.noise.noise_dn == pytest.approx(10.0, rel=0.05)
    assert m.noise.snr == m.noise.contrast_dn / m.noise.noise_dn
    assert measured().noise.contrast_dn == pytest.approx(1000.0, rel=1e-9)


def test_a_noise_free_quantised_profile_rests_on_the_quantisation_floor():
    m = measured()
    assert measure_noise(EdgeKind(), m.estimate.samples, m.shape, 1.0).noise_dn == pytest.approx(1 / math.sqrt(12))


def test_a_given_half_width_or_factor_sets_the_core():
    m = measured(noise_std=2.0)
    e = m.estimate
    fixed = choose_window(EdgeKind(), e.samples, m.shape, m.noise, make_settings(lsf_half_width_px=2.5), 0.0)
    assert (fixed.core_px, fixed.taper_px, fixed.cut) == (2.5, 2.5 * TAPER_FACTOR, False)
    narrow = choose_window(EdgeKind(), e.samples, m.shape, m.noise, make_settings(lsf_half_width_px=1.0), 0.0)
    assert narrow.cut                                         # narrower than the 10-90 % rise
    scaled = choose_window(EdgeKind(), e.samples, m.shape, m.noise, make_settings(lsf_window_factor=2.0), 0.0)
    assert scaled.core_px == pytest.approx(2.0 * m.shape.scale_px) and not scaled.cut
    clean = choose_window(EdgeKind(), e.samples, m.shape, m.noise, make_settings(), 0.0)
    assert clean == e.window and clean.narrowed == 0.0        # SNR 500: the clean window


def test_the_tail_model_recovers_a_known_tail():
    """An ESF whose sides are level + A / |s| beyond 1 px (a ramp between):
    each side's fit gives the LSF tail a / s^2 with a = A exactly; inside
    the window's core the profile is kept as measured, beyond its taper the
    model alone."""
    amplitude = 0.1
    rng = np.random.default_rng(0)
    d = rng.uniform(-20, 20, 40000)
    s = np.abs(d)
    esf = np.where(d > 1, 1 - amplitude / np.maximum(s, 1), np.where(d < -1, amplitude / np.maximum(s, 1),
                   amplitude + (1 - 2 * amplitude) * (d + 1) / 2))
    samples = Samples(d, esf, esf, np.arange(d.size) % 100, 20.0)
    profile = resample_samples(samples, make_settings(), 16.0, "edge")
    window = Window(3.0, 3.0, 0.0, False)
    lsf = blend_tails(EdgeKind(), samples, profile, Shape(0.0, 1.6, 0.0, 1.0, 3.0), window)
    assert lsf.amplitudes == pytest.approx((amplitude, amplitude), rel=1e-9)
    assert lsf.tail_starts_px == (3.0, 3.0)
    core = np.abs(lsf.x_px) <= window.core_px
    np.testing.assert_array_equal(lsf.combined[core], lsf.measured[core])
    beyond = np.abs(lsf.x_px) >= window.core_px + window.taper_px
    np.testing.assert_allclose(lsf.combined[beyond], amplitude * lsf.tail_shape[beyond], rtol=1e-12)
    # the model's share: 2 a (1 / 3 - 1 / 19.4) beyond the core's end, under the taper
    assert 0.02 < lsf.tail_share < 2 * amplitude * (1 / 3 - 1 / 19.4) + 1e-3


def test_a_side_without_samples_is_refused():
    m = measured()
    e = m.estimate
    lonely = Samples(e.samples.distance_px[e.samples.distance_px < 5], e.samples.values_dn[e.samples.distance_px < 5],
                     e.samples.raw_dn[e.samples.distance_px < 5], e.samples.rows[e.samples.distance_px < 5],
                     e.samples.half_range_px)
    with pytest.raises(im.ImgmtfError, match="too few samples"):
        blend_tails(EdgeKind(), lonely, e.profile, m.shape, Window(10.0, 10.0, 0.0, False))


def test_the_reach_s_fit_is_the_side_s_own_fit_from_there_to_the_bit():
    from types import SimpleNamespace

    from imgmtf.estimate.tails import fit_side, reach_and_fit, tail_integral
    rng = np.random.default_rng(2)
    s = rng.uniform(-12.0, 12.0, 3000)
    v = np.where(s < 0, 100.0, 900.0) + 40.0 * np.sign(s) / np.maximum(s * s, 0.25) + rng.normal(0, 2.0, s.size)
    kind = SimpleNamespace(tail_power=2, lsf_tail_amplitudes=lambda: (np.array([0.0, 2.0]), np.array([0.0, -2.0])))
    for side in (-1, 1):
        reach, fit = reach_and_fit(s, v, side, 1.0, 2, 0.5)
        assert reach in 1.0 + 0.5 * np.arange(13) and fit is not None       # from the start, in steps
        own = fit_side(s, v, (np.sign(s) == side) & (np.abs(s) >= reach), 2)
        assert fit.coef.tobytes() == own.coef.tobytes() and fit.sd == own.sd
        assert fit.operator.tobytes() == own.operator.tobytes()
        assert tail_integral(s, v, side, reach, 12.0, kind, fit) == tail_integral(s, v, side, reach, 12.0, kind)
