"""sensor/lines.py: the line response's grid, its batched inverse FFT and
the Hermite interpolation, against closed forms."""
import math

import numpy as np
import pytest
from scipy.special import ndtr

import imgmtf as im
from imgmtf.sensor import stages as st
from imgmtf.sensor.lines import PROBE_CY_PX, LineGrid, hermite, hermite_placement, line_grid, reference_transfer


def test_hermite_is_exact_for_cubics_and_zero_beyond_the_grid():
    x = np.arange(-3.0, 3.01, 0.5)
    values, slopes = x**3 - 2 * x, 3 * x**2 - 2
    d = np.array([-2.9, -0.26, 0.0, 1.13, 2.99, 3.2, -3.1])
    inside = np.abs(d) <= 3
    out = hermite(-3.0, 0.5, np.stack([values, 2 * values]), np.stack([slopes, 2 * slopes]), d)
    assert out.shape == (2, d.size)
    np.testing.assert_allclose(out[0, inside], d[inside] ** 3 - 2 * d[inside], atol=1e-12)
    np.testing.assert_allclose(out[1], 2 * out[0], atol=1e-12)
    assert not out[:, ~inside].any()


def test_hermites_second_derivative_is_the_cubics():
    """Exact for a cubic (6x - 2 here); linear between grid samples; the
    values the same as without it, bit for bit."""
    x = np.arange(-3.0, 3.01, 0.5)
    d = np.array([-2.9, -0.26, 0.0, 1.13, 2.99])
    values, out = hermite(-3.0, 0.5, x**3 - x**2, 3 * x**2 - 2 * x, d, curvature=True)
    np.testing.assert_allclose(out, 6 * d - 2, atol=1e-12)
    assert np.array_equal(values, hermite(-3.0, 0.5, x**3 - x**2, 3 * x**2 - 2 * x, d))


@pytest.mark.parametrize("sensor, gaussian_px", [(im.Sensor(1.0, [st.GaussianOptics(0.6, 0.6)]), 0.6),
                                                 (im.Sensor(), None),
                                                 (im.Sensor(1.0, [st.Diffraction(8.0), st.Detector()]), None)],
                         ids=["gaussian", "paper", "airy"])
def test_esf_with_curvature_gives_the_second_derivative_of_the_esf(sensor, gaussian_px):
    """Of the interpolant esf() evaluates: against its central second
    difference (h = 2e-4 px: exact for the cubic within a grid interval,
    so the few points within h of a grid sample are left out, and 5e-6 off
    for the sharpest reference, a Cauchy LSF 0.18 px wide); for a
    Gaussian, the closed form -x / s^3 phi(x / s) too."""
    response = sensor.line_response(5.0, reach_px=20.0)
    d = np.random.default_rng(3).uniform(-6, 6, 2000)
    h = 2e-4
    knot = (d - response.start_px) / response.step_px
    away = np.abs(knot - np.round(knot)) * response.step_px > 1.5 * h
    second = (response.esf(d + h) - 2 * response.esf(d) + response.esf(d - h)) / h**2
    _, curvature = response.esf_with_curvature(d)
    np.testing.assert_allclose(curvature[away], second[away], atol=2e-5)
    if gaussian_px is not None:
        s = gaussian_px
        exact = -d / s**3 * np.exp(-0.5 * (d / s) ** 2) / math.sqrt(2 * math.pi)
        np.testing.assert_allclose(curvature, exact, atol=1e-6)


def test_remainders_of_a_gaussian_give_its_closed_form_esf_and_lsf():
    """A Gaussian transfer of width s against a reference of another width:
    the remainders plus the reference's closed form are Phi(x/s) and the
    normal density, every row of a batch alike."""
    grid = LineGrid(1 / 64, 4096, ("gaussian", 0.8))
    f = grid.frequencies_cy_px
    widths = np.array([0.5, 0.7, 1.1])
    spectra = np.exp(-2 * np.pi**2 * widths[:, None] ** 2 * f**2) - reference_transfer(grid.reference, f)
    esf, lsf = grid.remainders(spectra)
    x = grid.start_px + grid.step_px * np.arange(grid.size)
    for row, s in enumerate(widths):
        np.testing.assert_allclose(esf[row] + ndtr(x / 0.8), ndtr(x / s), atol=1e-9)
        density = np.exp(-0.5 * (x / s) ** 2) / (s * math.sqrt(2 * math.pi))
        np.testing.assert_allclose(lsf[row] + np.exp(-0.5 * (x / 0.8) ** 2) / (0.8 * math.sqrt(2 * math.pi)),
                                   density, atol=1e-9)


def test_line_grid_covers_the_support_and_reach_and_takes_the_tail():
    gaussian = im.Sensor(1.0, [st.GaussianOptics(0.5, 0.5)])
    grid = line_grid(gaussian, 0.0, 1.0)
    assert grid.reference == ("gaussian", pytest.approx(0.5, rel=1e-3))
    assert grid.size * grid.step_px / 2 >= gaussian.support_radius_m() + 8 * 0.5 + 4
    assert grid.size & (grid.size - 1) == 0
    far = line_grid(gaussian, 0.0, 1.0, reach_px=100.0)
    assert far.size * far.step_px / 2 >= 100 + gaussian.support_radius_m()
    airy = im.Sensor(1.0, [st.Diffraction(16.0)])
    assert line_grid(airy, 0.0, 1.0).reference == ("cauchy", airy.tail_length_m())


def test_a_grid_response_is_the_sensors_line_response():
    sensor = im.Sensor()
    grid = line_grid(sensor, 6.0, 1.0, reach_px=10.0)
    mine = grid.response(sensor.normal_transfer(grid.frequencies_cy_px, 6.0))
    theirs = sensor.line_response(6.0, reach_px=10.0)
    d = np.linspace(-12, 12, 97)
    assert np.array_equal(mine.esf(d), theirs.esf(d)) and np.array_equal(mine.lsf(d), theirs.lsf(d))


def shifted_remainders(grid, spectra):
    """The remainders as the inverse FFTs, shifted and divided after (what
    :meth:`LineGrid.remainders` computed before it folded both into the
    spectra)."""
    f = grid.frequencies_cy_px
    lsf = np.fft.fftshift(np.fft.irfft(spectra, grid.size), axes=-1) / grid.step_px
    integral = np.zeros(spectra.shape, complex)
    integral[..., 1:] = spectra[..., 1:] / (2j * np.pi * f[1:])
    esf = np.fft.fftshift(np.fft.irfft(integral, grid.size), axes=-1) / grid.step_px
    return esf - esf[..., :1], lsf


def test_long_grids_factors_are_made_afresh_and_the_same_as_kept_ones(monkeypatch):
    """Up to CACHED_LINE_SAMPLES a grid's factors are kept (the same arrays
    again); beyond, made each time and not kept; either way the same values,
    bit for bit (one size through both paths), and the same remainders."""
    from imgmtf.sensor import lines
    step, size = 1 / 64, lines.CACHED_LINE_SAMPLES
    kept = lines._inverse_factors(step, size)
    assert all(a is b for a, b in zip(kept, lines._inverse_factors(step, size)))
    monkeypatch.setattr(lines, "CACHED_LINE_SAMPLES", size // 2)
    held = lines._cached_inverse_factors.cache_info().currsize
    afresh = lines._inverse_factors(step, size)
    assert lines._cached_inverse_factors.cache_info().currsize == held
    assert not any(a is b for a, b in zip(kept, afresh))
    assert all(np.array_equal(a, b) and a.dtype == b.dtype and not b.flags.writeable for a, b in zip(kept, afresh))
    grid = LineGrid(step, size, ("gaussian", 1.0))
    spectra = np.exp(-2 * np.pi**2 * 0.5**2 * grid.frequencies_cy_px**2) - reference_transfer(
        grid.reference, grid.frequencies_cy_px)
    uncached = grid.remainders(spectra)
    monkeypatch.setattr(lines, "CACHED_LINE_SAMPLES", size)
    assert all(np.array_equal(a, b) for a, b in zip(uncached, grid.remainders(spectra)))


@pytest.mark.parametrize("step, size", [(1 / 64, 2048), (0.0123, 4096), (0.25, 9)], ids=["even", "cauchy-step", "odd"])
def test_remainders_are_the_shifted_inverse_transforms(step, size):
    """The shift as a phase factor and the scale folded into the spectra:
    the same remainders as shifting and scaling the inverse FFTs' output,
    to rounding."""
    grid = LineGrid(step, size, ("gaussian", 1.0))
    f = grid.frequencies_cy_px
    spectra = np.stack([np.exp(-2 * np.pi**2 * w**2 * f**2) * np.sinc(f * w) for w in (0.4, 0.9)])
    spectra -= reference_transfer(grid.reference, f)
    esf, lsf = grid.remainders(spectra)
    expected_esf, expected_lsf = shifted_remainders(grid, spectra)
    assert esf.shape == lsf.shape == (2, size)
    np.testing.assert_allclose(lsf, expected_lsf, rtol=0, atol=1e-12 * np.abs(expected_lsf).max())
    np.testing.assert_allclose(esf, expected_esf, rtol=0, atol=1e-12)
    one, _ = grid.remainders(spectra[1])
    np.testing.assert_allclose(one, esf[1], rtol=0, atol=1e-15)


def test_a_grid_given_the_transfer_at_the_probe_is_the_one_it_computes():
    """line_grid reads the sensor's transfer at PROBE_CY_PX for its
    Gaussian reference: given it, the same grid; a Cauchy grid does not
    read it."""
    def described(grid):
        return grid.step_px, grid.size, grid.reference
    sensor = im.Sensor()
    probe = float(sensor.normal_transfer(PROBE_CY_PX, 6.0, 1.0))
    assert described(line_grid(sensor, 6.0, 1.0, transfer_at_probe=probe)) == described(line_grid(sensor, 6.0, 1.0))
    wider = line_grid(sensor, 6.0, 1.0, transfer_at_probe=1 - 2 * math.pi**2 * 2.0**2 * PROBE_CY_PX**2)
    assert wider.reference == ("gaussian", pytest.approx(2.0, rel=1e-9))
    airy = im.Sensor(1.0, [st.Diffraction(8.0)])
    assert described(line_grid(airy, 6.0, 1.0, transfer_at_probe=0.0)) == described(line_grid(airy, 6.0, 1.0))


@pytest.mark.parametrize("sensor", [im.Sensor(), im.Sensor(1.0, [st.Diffraction(8.0), st.Detector()])],
                         ids=["gaussian", "cauchy"])
def test_esf_with_curvature_is_esf_bit_for_bit(sensor):
    """The distances placed on the grid once: the same values as esf(),
    within the grid and beyond it (zero remainder there), and the same
    curvature at the same distances however they are shaped."""
    response = sensor.line_response(5.0, reach_px=4.0)
    d = np.random.default_rng(5).uniform(-40, 40, (30, 20))
    esf, curvature = response.esf_with_curvature(d)
    assert esf.shape == curvature.shape == d.shape
    assert np.array_equal(esf, response.esf(d))
    assert np.array_equal(curvature.ravel(), response.esf_with_curvature(d.ravel())[1])
    near = np.linspace(-2, 2, 7)                       # all within the grid
    assert response.esf_with_curvature(near)[0].tolist() == response.esf(near).tolist()


def test_hermite_within_the_grid_and_beyond_alike():
    """Every distance within the grid (nothing to place back) or some
    beyond: the same values where both have them, rows and shapes kept."""
    x = np.arange(-3.0, 3.01, 0.5)
    values, slopes = np.stack([x**3, x**2]), np.stack([3 * x**2, 2 * x])
    d = np.array([[-2.9, 0.3], [1.1, 2.99]])
    within = hermite(-3.0, 0.5, values, slopes, d, curvature=True)
    beyond = hermite(-3.0, 0.5, values, slopes, np.append(d, 7.0), curvature=True)
    for a, b in zip(within, beyond):
        assert a.shape == (2, 2, 2) and b.shape == (2, 5)
        assert np.array_equal(a.reshape(2, 4), b[:, :4]) and not b[:, 4].any()
    np.testing.assert_allclose(within[0][0], d**3, atol=1e-12)
    np.testing.assert_allclose(within[1][0], 6 * d, atol=1e-12)


def test_hermite_placement_interpolates_as_the_explicit_sum():
    """The in-place gathers and sums give the four-term Hermite sum bit for
    bit: one function or rows of them, with the curvature, some distances
    beyond the grid."""
    rng = np.random.default_rng(3)
    values, slopes = rng.normal(size=(3, 40)), rng.normal(size=(3, 40))
    d = rng.uniform(-1.0, 6.0, 25)
    placement = hermite_placement(-0.5, 0.125, 40, d, curvature=True)
    k, inside = placement.index, placement.inside
    for rows in (values[0], values):
        v, s = (rows, slopes[0]) if rows.ndim == 1 else (rows, slopes)
        got = placement.interpolate(v, s, curvature=True)
        for w, out in zip(placement.weights, got):
            expected = np.zeros(v.shape[:-1] + d.shape)
            expected[..., inside] = (w[0] * v[..., k] + w[1] * s[..., k] + w[2] * v[..., k + 1]
                                     + w[3] * s[..., k + 1])
            assert np.array_equal(out, expected)


@pytest.mark.parametrize("size", [4096, 4095], ids=["even", "odd"])
def test_the_lsf_remainder_alone_is_the_responses_bit_for_bit(size):
    """What a FWHM reads (LineGrid.lsf_remainder, half the inverse FFTs)
    is the full response's LSF remainder, for a real and a one-sided
    (complex) transfer; Sensor.normal_lsf is the line response's LSF."""
    grid = LineGrid(0.01, size, ("gaussian", 0.6))
    for sensor in (im.Sensor(1.0, [st.GaussianOptics(0.4, 0.5), st.Detector(1.0, 0.9)]),
                   im.Sensor(1.0, [st.GaussianOptics(0.4, 0.5), st.Lag(0.8, 0.3)])):
        transfer = sensor.normal_transfer(grid.frequencies_cy_px, 20.0)
        assert np.array_equal(grid.lsf_remainder(transfer), grid.response(transfer).lsf_remainder)
        x, lsf = sensor.normal_lsf(20.0)
        half = 4 * sensor.support_radius_m()
        assert np.array_equal(lsf, sensor.line_response(20.0, reach_px=half, step_px=1 / 400).lsf(x))


def test_underflowing_exp_is_exp_bit_for_bit():
    from imgmtf.sensor.lines import underflowing_exp
    x = np.concatenate([-np.linspace(700.0, 760.0, 6001), [0.0, -0.5, -np.inf, np.nan, 3.0]])
    assert np.array_equal(underflowing_exp(x), np.exp(x), equal_nan=True)
    assert underflowing_exp(-2.0) == np.exp(-2.0) and np.ndim(underflowing_exp(-2.0)) == 0
