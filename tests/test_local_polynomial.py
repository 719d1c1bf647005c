"""The local polynomial fitted for many profiles at once: each the same, to the bit, as alone."""
import numpy as np

from imgmtf.estimate._window_sums import _binomial_shifts, _shifted_powers, window_sums_each
from imgmtf.estimate.local_polynomial import LocalFit, local_polynomial_many


def test_many_profiles_fit_as_each_alone():
    rng = np.random.default_rng(3)
    fits = []
    for k in range(5):
        d = rng.uniform(-6.0, 6.0, 800 + 300 * k)
        v = 100.0 * np.tanh(d / (0.5 + 0.3 * k)) + rng.normal(0.0, 1.0, d.size)
        fits.append(LocalFit(d, v, 0.05, 3.0 + k, order=1 if k == 2 else 4,
                             weights=rng.uniform(0.5, 2.0, d.size) if k == 3 else None))
    sparse = np.repeat(np.arange(-6.0, 6.0, 0.5), 4)          # a wide window (50 taps and more): fitted alone
    fits.append(LocalFit(sparse, np.tanh(sparse), 0.05, 3.0))
    fits.append(LocalFit(fits[0].distance, fits[0].values, 0.05, 3.0, order=9))     # refused in its place
    together = local_polynomial_many(fits)
    assert isinstance(together[-1], Exception)
    h = rng.normal(size=(2, together[0].grid.size))
    for fit, many in zip(fits[:-1], together[:-1]):
        alone = local_polynomial_many([fit])[0]
        np.testing.assert_array_equal(many.values, alone.values)
        np.testing.assert_array_equal(many.leverage, alone.leverage)
    np.testing.assert_array_equal(together[0].adjoint(h), local_polynomial_many([fits[0]])[0].adjoint(h))


def test_window_sums_each_are_the_shifted_powers():
    rng = np.random.default_rng(4)
    moments = rng.normal(size=(9, 200))
    offsets = np.arange(-10, 11) / 10.5
    binomials = _binomial_shifts(9, False)
    np.testing.assert_allclose(window_sums_each(moments, offsets, binomials),
                               _shifted_powers(moments, offsets, binomials), rtol=1e-12, atol=1e-9)
