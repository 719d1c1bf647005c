"""The local polynomial fitted for many profiles at once: each the same, to the bit, as alone."""
import numpy as np
import pytest

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


@pytest.mark.parametrize("weighted", [False, True])
@pytest.mark.parametrize("by_power", [False, True])
def test_the_adjoint_is_the_transpose_of_the_fits_linear_map(monkeypatch, weighted, by_power):
    """S^T h (the intervals' pass backwards) against the dense map S, each
    column a unit sample's fit: a few rows of grid weights by one folded
    product, a stack beyond ``SHIFTED_ELEMENTS`` power by power."""
    import imgmtf.estimate.local_polynomial as lp
    if by_power:
        monkeypatch.setattr(lp, "SHIFTED_ELEMENTS", 0)
    rng = np.random.default_rng(5)
    # no window about 2.7 px holds a fit; the last sample, beyond the grid, has no weight
    d = np.concatenate([rng.uniform(-1.9, 1.9, 120), rng.uniform(3.3, 4.2, 30), [9.0]])
    w = rng.uniform(0.5, 2.0, d.size) if weighted else None
    fitted = local_polynomial_many([LocalFit(d, np.tanh(d), 0.05, 4.0, weights=w)])[0]
    units = local_polynomial_many([LocalFit(d, e, 0.05, 4.0, weights=w) for e in np.eye(d.size)])
    dense = np.stack([u.values for u in units], axis=1)                 # (grid, samples), NaN off valid windows
    assert np.isnan(dense).any() and np.isfinite(dense).any()
    h = rng.normal(size=(3, fitted.grid.size))
    expected = np.nan_to_num(dense).T @ h.T
    np.testing.assert_allclose(fitted.adjoint(h), expected.T, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fitted.adjoint(h[0]), expected[:, 0], rtol=1e-9, atol=1e-12)
    assert fitted.adjoint(h)[:, -1].tolist() == [0.0, 0.0, 0.0]


def test_the_features_powers_are_numpys_vander_to_the_bit():
    from imgmtf.estimate.local_polynomial import _features
    rng = np.random.default_rng(7)
    u, v = rng.uniform(-1.0, 1.0, 257), rng.normal(size=257)
    for order in range(5):
        powers = np.vander(u, 2 * order + 1, increasing=True).T
        expected = np.concatenate([powers, powers[: order + 1] * v])
        assert _features(u, v, order).tobytes() == expected.tobytes()
