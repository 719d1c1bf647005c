"""De-quantising a noise-free staircase: the ESF rebuilt through its level
crossings, against the exact edge response."""
import numpy as np
import pytest
from scipy.special import ndtr

import imgmtf as im
from imgmtf.estimate.quantisation import dequantise

from conftest import exact_edge_chip, gaussian_pixel_transfer


def test_the_staircase_of_a_gaussian_edge_is_rebuilt():
    d = np.random.default_rng(0).uniform(-6, 6, 5000)
    exact = 100 + 12 * ndtr(d / 0.6)
    rebuilt = dequantise(d, np.round(exact), 1.0)
    assert np.abs(rebuilt - exact).max() < 0.05            # 0.4 % of the 12 DN step
    assert np.abs(np.round(exact) - exact).max() > 0.45     # the staircase itself is off by half a step


def test_nothing_to_undo_with_noise_unquantised_values_or_many_levels():
    d = np.random.default_rng(1).uniform(-6, 6, 5000)
    exact = 100 + 12 * ndtr(d / 0.6)
    noisy = np.round(exact + np.random.default_rng(2).normal(0, 1.0, d.size))
    assert dequantise(d, noisy, 1.0) is None
    assert dequantise(d, exact, 0.0) is None
    assert dequantise(d, np.round(100 + 5000 * ndtr(d / 0.6)), 1.0) is None


@pytest.mark.parametrize("step, angle", [(12, 5.0), (18, 8.0), (30, 11.0)])
def test_low_contrast_8_bit_edges_read_true(step, angle):
    h = gaussian_pixel_transfer(0.5, angle)
    chip = exact_edge_chip(h, angle, offset=0.3, low=100, high=100 + step, dtype=np.uint8)
    r = im.measure_edge(chip)
    assert abs(r.mtf_nyquist - h(0.5)) <= 0.012
    assert np.isfinite(r.snr) and r.snr == pytest.approx(step * np.sqrt(12), rel=0.01)
    assert r.params["dequantised"]


def test_a_rebuilt_staircase_still_has_an_honest_interval():
    h = gaussian_pixel_transfer(0.5, 7.0)
    r = im.measure_edge(exact_edge_chip(h, 7.0, offset=0.1, low=100, high=118, dtype=np.uint8))
    assert r.params["dequantised"] and h(0.5) in r.mtf_nyquist_ci
    assert r.mtf_nyquist_ci.width > 0.015            # the rebuild's own error, not noise, sets it


def test_each_crossing_is_the_split_with_fewest_samples_on_the_wrong_side():
    from imgmtf.estimate.quantisation import _crossings
    rng = np.random.default_rng(4)
    for _ in range(100):
        n = int(rng.integers(5, 300))
        d = np.sort(rng.uniform(-5, 5, n))
        u = np.round(10 * (1 + np.tanh(d / rng.uniform(0.3, 2))) + rng.normal(0, rng.choice([0.0, 0.3, 2.0]), n))
        thresholds = np.arange(u.min(), u.max()) + 0.5
        # every split tried: above it on its left, at or below it on its right; the first of equals
        above = u[None, :] > thresholds[:, None]
        above_left = np.cumsum(above, axis=1)
        below_right = (n - np.arange(1, n + 1))[None, :] - (above_left[:, -1:] - above_left)
        np.testing.assert_array_equal(_crossings(u, thresholds), np.argmin(above_left + below_right, axis=1))


def test_a_noise_free_8_bit_edge_is_rebuilt_without_scipy(tmp_path):
    import subprocess
    import sys
    h = gaussian_pixel_transfer(0.5, 6.0)
    np.save(tmp_path / "chip.npy", exact_edge_chip(h, 6.0, offset=0.2, low=30, high=210, dtype=np.uint8))
    code = ("import sys, numpy as np, imgmtf as im; "
            f"r = im.measure_edge(np.load({str(tmp_path / 'chip.npy')!r})); "
            "print(r.params['dequantised'], [m for m in ('scipy', 'skimage') if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["True", "[]"]
