import numpy as np
import pytest
from scipy.special import erf

from imgmtf.estimate.spectrum import (
    central_difference,
    corrected_mtf,
    edge_divisor,
    flat_top_window,
    mtf50,
    mtf_area,
    relative_edge_response,
    restore_lsf,
    rise_distance,
)
from imgmtf.metrics import first_crossing, fwhm


def gaussian_edge(sigma=0.6, step=0.05, half=15.0):
    x = np.arange(-half, half + step / 2, step)
    return x, 0.5 * (1 + erf(x / (sigma * np.sqrt(2))))


def test_corrected_mtf_of_gaussian_edge_is_exact():
    sigma = 0.6
    x, esf = gaussian_edge(sigma)
    _, lsf = central_difference(x, esf)
    mtf = corrected_mtf(lsf, 0.05, edge_divisor(0.05, None))
    f = np.array([0.1, 0.25, 0.5, 0.8])
    np.testing.assert_allclose(mtf(f), np.exp(-2 * np.pi**2 * sigma**2 * f**2), atol=2e-6)


def test_the_corrected_mtf_is_a_value_that_travels_between_processes():
    """A result holding it is pickled to and from a scan's workers: the
    same MTF after the round trip, even, NaN beyond the table."""
    import pickle
    x, esf = gaussian_edge(0.6)
    _, lsf = central_difference(x, esf)
    mtf = corrected_mtf(lsf, 0.05, edge_divisor(0.05, None))
    f = np.array([-0.5, 0.0, 0.25, 0.5, 100.0])
    there = pickle.loads(pickle.dumps(mtf))
    np.testing.assert_array_equal(there(f), mtf(f))
    assert mtf(-0.5) == mtf(0.5) and mtf(0.0) == pytest.approx(1.0) and np.isnan(mtf(100.0)[0])


def test_uncorrected_central_difference_reads_low_by_its_sinc():
    x, esf = gaussian_edge(0.6, step=0.25)
    _, lsf = central_difference(x, esf)
    corrected = corrected_mtf(lsf, 0.25, edge_divisor(0.25, None))(np.array([0.5]))[0]
    raw = corrected * np.sinc(2 * 0.5 * 0.25)
    assert corrected == pytest.approx(np.exp(-2 * np.pi**2 * 0.36 * 0.25), abs=1e-4)
    assert raw < corrected


def test_mtf50_and_area_of_gaussian():
    sigma = 0.6
    x, esf = gaussian_edge(sigma)
    mtf = corrected_mtf(central_difference(x, esf)[1], 0.05, edge_divisor(0.05, None))
    assert mtf50(mtf) == pytest.approx(np.sqrt(np.log(2) / (2 * np.pi**2 * sigma**2)), abs=1e-5)
    f = np.linspace(0, 0.5, 2001)
    assert mtf_area(mtf) == pytest.approx(np.trapezoid(np.exp(-2 * np.pi**2 * sigma**2 * f**2), f), abs=1e-5)


def test_rise_rer_and_fwhm_of_gaussian():
    sigma = 0.6
    x, esf = gaussian_edge(sigma)
    assert rise_distance(x, esf, 0.0) == pytest.approx(2 * 1.2815516 * sigma, abs=2e-3)
    assert relative_edge_response(x, esf, 0.0) == pytest.approx(erf(0.5 / (sigma * np.sqrt(2))), abs=1e-6)
    xl, lsf = central_difference(x, esf)
    # the central difference widens the LSF by ~0.1 %; deconvolution undoes it
    assert fwhm(xl, lsf) == pytest.approx(2.3548200 * sigma, rel=2e-3)
    xr, restored = restore_lsf(lsf, xl, edge_divisor(0.05, None))
    assert fwhm(xr, restored) == pytest.approx(2.3548200 * sigma, rel=2e-4)
    assert xr[np.argmax(restored)] == pytest.approx(0.0, abs=0.03)
    # a coarse 1/4-px LSF is interpolated onto a 0.05 px grid
    xc, esfc = gaussian_edge(sigma, step=0.25)
    xl, lsf = central_difference(xc, esfc)
    xr, restored = restore_lsf(lsf, xl, edge_divisor(0.25, None))
    assert xr[1] - xr[0] == pytest.approx(0.05)
    assert fwhm(xr, restored) == pytest.approx(2.3548200 * sigma, rel=1e-3)


def test_flat_top_window_shape():
    x = np.linspace(-5, 5, 1001)
    w = flat_top_window(x, 0.5, 2.0, 1.0)
    assert w[np.abs(x - 0.5) <= 2.0].min() == 1.0
    assert w[np.abs(x - 0.5) >= 3.0].max() == 0.0
    assert w[np.argmin(np.abs(x - 3.0))] == pytest.approx(0.5)


def test_first_crossing():
    f = np.linspace(0, 1, 11)
    assert first_crossing(f, 1 - f, 0.55) == pytest.approx(0.45)
    assert np.isnan(first_crossing(f, np.ones(11), 0.5))


def test_one_curves_first_crossing_is_its_rows_in_a_stack():
    """A single curve's crossing (read off its two samples) is the one the
    stacked path gives its row, bit for bit: crossings inside, at the last
    sample, never (NaN), below from the start (NaN), a sample exactly at
    the level (not below) and a NaN sample (never below)."""
    import math
    rng = np.random.default_rng(3)
    x = np.sort(rng.random(12)) * 3.0
    curves = np.vstack([np.cumsum(-rng.random((40, 12)), axis=1) + rng.random((40, 1)) * 6.0,
                        np.linspace(1.0, 0.2, 12), np.ones(12), np.full(12, 0.1),
                        np.r_[1.0, 0.5, 0.4, np.zeros(9)], np.r_[1.0, np.nan, 0.3, np.zeros(9)]])
    stacked = first_crossing(x, curves, 0.5)
    assert np.isnan(stacked).sum() >= 3 and np.isfinite(stacked).sum() >= 30
    for row, expected in zip(curves, stacked):
        got = first_crossing(x, row, 0.5)
        assert type(got) is float and (got == expected or (math.isnan(got) and math.isnan(expected)))
    # at the level is not below: the crossing is that sample; a NaN before the first sample below spoils it
    assert first_crossing(x, curves[-2], 0.5) == x[1] and math.isnan(first_crossing(x, curves[-1], 0.5))


def test_noise_limited_frequency_closed_form():
    from scipy.optimize import brentq

    from imgmtf.estimate.spectrum import noise_limited_frequency, white_noise_mtf_sd

    def mtf(f):
        return np.exp(-4.0 * np.asarray(f))
    k = 3 * 2 * np.pi / 100 * np.sqrt(4.0 / 200.0)
    exact = brentq(lambda f: np.exp(-4 * f) - k * f, 0.01, 3.0)
    edge_noise = white_noise_mtf_sd(100.0, 4.0, 100.0, lambda f: 2 * np.pi * f)
    got = noise_limited_frequency(mtf, edge_noise)
    assert exact <= got < exact + 0.02
    assert noise_limited_frequency(mtf, white_noise_mtf_sd(float("inf"), 4.0, 100.0, lambda f: f)) == float("inf")
    # masked frequencies (NaN) are skipped, not taken for noise
    masked = noise_limited_frequency(lambda f: np.where((f > 0.5) & (f < 0.7), np.nan, mtf(f)), edge_noise)
    assert masked == got


def test_many_spectra_are_each_the_same_to_the_bit_as_alone():
    """Profiles of one step and length share an FFT (in blocks of a few
    rows); each row is the profile's transform alone."""
    from imgmtf.estimate.spectrum import _rows_at_once, spectrum, spectrum_many
    rng = np.random.default_rng(6)
    requests = [(rng.normal(size=rng.integers(50, 400)), 0.05) for _ in range(_rows_at_once(20000) + 3)]
    requests += [(rng.normal(size=300), 0.1), (rng.normal(size=600), 2.0)]     # a coarser step; longer than padded
    together = spectrum_many(requests)
    for (profile, step), (f, modulus) in zip(requests, together):
        alone_f, alone_modulus = spectrum(profile, step)
        np.testing.assert_array_equal(f, alone_f)
        np.testing.assert_array_equal(modulus, alone_modulus)


def test_many_restorations_are_each_the_same_to_the_bit_as_alone():
    """LSFs restored together (their transforms as rows of one FFT per
    length) are each the one restored alone; a profile that cannot be
    restored gets its exception in its place."""
    from imgmtf.estimate.spectrum import RestoreRequest, restore_lsf_many
    rng = np.random.default_rng(7)
    x = np.arange(-150, 151) * 0.05
    requests = [RestoreRequest(np.exp(-(x / (0.4 + 0.1 * k)) ** 2) * (np.abs(x) < 3 + k % 3), x,
                               lambda f: np.sinc(0.1 * f), 0.8 + 0.3 * k) for k in range(20)]
    requests.append(RestoreRequest(np.zeros(x.size), x, lambda f: np.ones_like(f)))
    requests.append(RestoreRequest(rng.normal(size=x.size), x, lambda f: np.sinc(f), out_step=0.02))
    together = restore_lsf_many(requests)
    assert isinstance(together[-2], IndexError)
    for request, (x_out, lsf) in zip(requests[:-2] + requests[-1:], together[:-2] + together[-1:]):
        (x_alone, lsf_alone), = restore_lsf_many([request])
        np.testing.assert_array_equal(x_out, x_alone)
        np.testing.assert_array_equal(lsf, lsf_alone)
