"""The curves of the staircase rebuild against SciPy's, which they stand in
for: the monotone cubic is PchipInterpolator's to rounding, the smoothing
spline make_smoothing_spline's where the cross-validation has one minimum."""
import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator, make_smoothing_spline

from imgmtf.estimate.splines import monotone_cubic, smoothing_spline


@pytest.mark.parametrize("seed", range(4))
def test_monotone_cubic_is_pchip(seed):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.uniform(0.05, 1.0, 25))
    y = np.cumsum(rng.choice([0.0, 1.0], 25) * rng.uniform(0, 1, 25)) * rng.choice([-1, 1])
    y[10:13] = y[12]                       # a flat stretch, where the slopes must be 0
    at = np.linspace(x[0], x[-1], 1001)
    expected, curve = PchipInterpolator(x, y), monotone_cubic(x, y)
    np.testing.assert_allclose(curve(at), expected(at), rtol=0, atol=1e-12)
    np.testing.assert_allclose(curve.slope, expected.derivative()(x), rtol=0, atol=1e-12)


@pytest.mark.parametrize("n", [41, 120, 250])
def test_smoothing_spline_is_scipys(n):
    rng = np.random.default_rng(n)
    x = np.sort(rng.uniform(-2.5, 2.5, n))
    y = 0.6 * x + 0.05 * np.tanh(2 * x) + rng.normal(0, 0.02, n)
    at = np.linspace(x[0], x[-1], 1001)
    expected, curve = make_smoothing_spline(x, y), smoothing_spline(x, y)
    np.testing.assert_allclose(curve(at), expected(at), rtol=0, atol=0.002)      # a tenth of the noise
    np.testing.assert_allclose(curve.slope[[0, -1]], expected.derivative()(x[[0, -1]]), rtol=0, atol=0.01)


def test_weights_count_as_repeated_points():
    rng = np.random.default_rng(9)
    x = np.linspace(0.0, 3.0, 30)
    y = np.sin(x) + rng.normal(0, 0.05, 30)
    weighted = smoothing_spline(x, y, np.full(30, 4.0))
    assert np.allclose(weighted(x), smoothing_spline(x, y)(x))     # the same weight everywhere changes nothing
    straight = smoothing_spline(x, 2.0 * x + 1.0)
    np.testing.assert_allclose(straight(x), 2.0 * x + 1.0, atol=1e-9)   # a line is its own smoothing
