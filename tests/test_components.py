import numpy as np
from numpy.testing import assert_allclose

from imgmtf.sensor import components as c


def test_gaussian_ft_closed_form():
    f = np.array([0.0, 0.25, 0.5, 1.0])
    assert_allclose(c.gaussian_ft(f, 0, 0.39, 0.1), np.exp(-2 * np.pi**2 * 0.39**2 * f**2))
    assert_allclose(c.gaussian_ft(0, f, 0.39, 0.1), np.exp(-2 * np.pi**2 * 0.01 * f**2))


def test_pixel_ft_zero_at_inverse_width():
    assert_allclose(c.pixel_ft(1.0, 0.0, 1.0, 1.0), 0.0, atol=1e-15)
    assert_allclose(c.pixel_ft(0.5, 0.0, 1.0, 1.0), 2 / np.pi)
    assert_allclose(c.pixel_ft(0.0, 0.5, 1.0, 2.0), 0.0, atol=1e-15)


def test_smear_acts_along_track_only():
    assert_allclose(c.smear_ft(4.0, 0.25), 0.0, atol=1e-15)
    assert_allclose(c.smear_ft(0.0, 0.25), 1.0)


def test_butterworth_half_power_at_cutoff_and_absent_when_zero():
    assert_allclose(c.butterworth_ft(1.4, 0.0, 1.4), 0.5)
    assert_allclose(c.butterworth_ft(0.6, 0.8, 1.0), 0.5)      # radial: D = 1
    assert_allclose(c.butterworth_ft(np.ones(3), 0.0, 0.0), np.ones(3))
