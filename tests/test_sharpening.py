"""Sharpened products measured, with their peak said; a rise above 1 no
sharpening kernel explains refused.  Truth: the Gaussian + pixel transfer
times the kernel's own transfer along the edge's normal, exact."""
import dataclasses
import math

import numpy as np
import pytest
from scipy.ndimage import convolve

import imgmtf as im
from imgmtf.errors import ImgmtfError
from imgmtf.estimate.sharpening import mtf_peak

from conftest import exact_edge_chip, gaussian_pixel_transfer, true_mtf50

ANGLE = 6.0


def unsharp_kernel(size, amount, sigma):
    """(1 + amount) delta - amount Gaussian, size x size on the pixel grid."""
    r = size // 2
    y, x = np.mgrid[-r:r + 1, -r:r + 1]
    blur = np.exp(-(x ** 2 + y ** 2) / (2 * sigma ** 2))
    kernel = -amount * blur / blur.sum()
    kernel[r, r] += 1 + amount
    return kernel


def laplacian_kernel(a):
    kernel = np.zeros((3, 3))
    kernel[1, 1] = 1 + 4 * a
    kernel[0, 1] = kernel[2, 1] = kernel[1, 0] = kernel[1, 2] = -a
    return kernel


def sharpened_edge(sigma, kernel, noise, seed=1, shape=(100, 100)):
    """The chip, and its exact MTF: |H(f)| times the kernel's transfer along
    the normal, sum k[m, n] cos(2 pi f (m cos a + n sin a))."""
    h = gaussian_pixel_transfer(sigma, ANGLE)
    r = kernel.shape[0] // 2
    pad = exact_edge_chip(h, ANGLE, shape=(shape[0] + 2 * r, shape[1] + 2 * r), offset=0.2, dtype=np.float64)
    chip = convolve(pad, kernel, mode="nearest")[r:-r, r:-r]
    chip = chip + np.random.default_rng(seed).normal(0, noise, chip.shape)
    a = math.radians(ANGLE)
    m, n = np.mgrid[-r:r + 1, -r:r + 1]
    where = (n * math.cos(a) + m * math.sin(a)).ravel()

    def truth(f):
        f = np.atleast_1d(np.asarray(f, float))
        k = np.cos(2 * np.pi * f[:, None] * where[None, :]) @ kernel.ravel()
        return np.abs(h(f) * k)
    return chip, truth


@pytest.mark.parametrize("sigma, kernel, noise", [
    (0.6, unsharp_kernel(5, 1.3, 1.0), 0.0),         # 5 x 5, true peak 1.20
    (0.6, unsharp_kernel(5, 1.3, 1.0), 10.0),        # ... at SNR 100
    (0.5, laplacian_kernel(0.3), 10.0),              # 3 x 3, true peak 1.11
    (0.5, unsharp_kernel(5, 1.0, 1.0), 0.0),         # 5 x 5, true peak 1.18
    (0.4, unsharp_kernel(3, 1.0, 10.0), 0.0),        # 3 x 3 box, true peak 1.23 on a sharp edge: its rows'
                                                     # locations swing 0.3 px with their phase, and are straight
    (0.4, unsharp_kernel(5, 0.8, 1.0), 0.0),         # 5 x 5, true peak 1.18 on a sharp edge: the rows' Fermi
])                                                   # fits collapse to steps (their width is held)
def test_a_sharpened_product_is_measured_with_its_peak_and_a_note(sigma, kernel, noise):
    chip, truth = sharpened_edge(sigma, kernel, noise)
    f = np.arange(0, 1, 0.001)
    true_peak = float(truth(f).max())
    assert 1.05 < true_peak < 1.25
    r = im.measure_edge(chip)
    assert not any(c.failed for c in r.checks) and r.sharpened
    assert abs(r.mtf_nyquist - float(truth(0.5)[0])) < 0.01
    assert abs(r.mtf50_cy_px / true_mtf50(truth) - 1) < 0.01
    assert abs(r.mtf_peak - true_peak) < 0.01 and abs(r.mtf_peak_cy_px - f[np.argmax(truth(f))]) < 0.03
    assert any(w.startswith("sharpened: the MTF rises to") for w in r.warnings)
    out = r.to_dict()
    assert out["sharpened"] and out["mtf_peak"] > 1
    from imgmtf.plot.measurement import measurement_verdict  # the figure's header says so too
    assert measurement_verdict(r)[0].startswith(f"SHARPENED: the MTF rises to {r.mtf_peak:.3f}")
    explained = [c for c in out["checks"] if c.get("explained_by") == "sharpening"]
    assert explained and explained[0]["outcome"] == "passed"


def test_an_unsharpened_edge_peaks_at_one_and_is_not_called_sharpened():
    chip, _ = sharpened_edge(0.5, laplacian_kernel(0.0), 5.0)
    r = im.measure_edge(chip)
    assert not r.sharpened and r.mtf_peak == pytest.approx(1.0, abs=0.01)


def _refused_above_one(chip):
    with pytest.raises(ImgmtfError) as info:
        im.measure_edge(chip)
    assert info.value.reason == "mtf-above-one", str(info.value)
    return str(info.value)


def test_a_rise_no_kernel_explains_stays_refused():
    plain = exact_edge_chip(gaussian_pixel_transfer(0.5, ANGLE), ANGLE, offset=0.2, noise_std=1.0, dtype=np.float64)
    y, x = np.mgrid[0:100, 0:100].astype(float)
    a = math.radians(ANGLE)
    d = (x - 49.5) * math.cos(a) + (y - 49.5) * math.sin(a) - 0.2
    # a dark halo on the dark side only: the LSF dips on one side
    assert "one-sided halo" in _refused_above_one(plain - 150 * np.exp(-0.5 * ((d + 1.5) / 0.7) ** 2))
    # sharpened in the top 70 rows only: not one kernel along the edge
    sharpened, _ = sharpened_edge(0.5, unsharp_kernel(5, 1.0, 1.0), 3.0)
    plain3 = exact_edge_chip(gaussian_pixel_transfer(0.5, ANGLE), ANGLE, offset=0.2, noise_std=3.0, dtype=np.float64)
    assert "not one kernel along it" in _refused_above_one(np.where(y < 70, sharpened, plain3))
    # far more than MTF compensation gives
    chip, _ = sharpened_edge(0.6, unsharp_kernel(3, 3.0, 10.0), 1.0)
    assert "more than the 1.5" in _refused_above_one(chip)


def test_the_peak_is_read_up_to_the_limit():
    peak = mtf_peak(lambda f: 1 + 0.2 * np.sin(np.pi * np.asarray(f) / 0.5) * (np.asarray(f) < 0.5), 0.8)
    assert (round(peak.mtf, 3), round(peak.cy_px, 3)) == (1.2, 0.25)
    assert mtf_peak(lambda f: np.exp(-np.asarray(f)), 0.3).cy_px == 0.0


def test_a_consistency_along_the_target_that_cannot_be_compared_is_no_evidence():
    from imgmtf.estimate.evidence import Evidence
    from imgmtf.estimate.sharpening import _lobe_change
    d = np.linspace(-6, 6, 400)
    esf = np.where(d < 0, 200.0, 1200.0) + 50 * np.sign(d) * np.exp(-0.5 * (np.abs(d) - 1) ** 2)
    ev = Evidence(d, esf, np.repeat(np.arange(2), 200), 0.0, 1.0, 2.0, 200.0, 1200.0, 1.0, 1.0, 1, "edge", "edge",
                  ("dark", "bright"), None)
    assert "could not be compared" in _lobe_change(ev)                         # two rows: no halves
    assert _lobe_change(dataclasses.replace(ev, rows=np.tile(np.arange(8), 50))) is None      # alike halves
