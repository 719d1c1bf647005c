"""correlate1d against SciPy's, which OpenCV stands in for on the hot path."""
import numpy as np
import pytest
from scipy import ndimage

from imgmtf.errors import ParameterError
from imgmtf.estimate._correlation import ROW_BY_ROW_TAPS, correlate1d


@pytest.mark.parametrize("shape, axis, taps", [((50,), -1, 3), ((7, 40), -1, 21), ((40, 30), 0, 17),
                                               ((3, 5, 60), 1, 5), ((6, 4), 1, 9)])
def test_matches_scipy(shape, axis, taps):
    rng = np.random.default_rng(taps)
    values, weights = rng.normal(size=shape), rng.normal(size=taps)
    expected = ndimage.correlate1d(values, weights, axis=axis, mode="constant")
    np.testing.assert_allclose(correlate1d(values, weights, axis), expected, rtol=0, atol=1e-12)


def test_an_empty_axis_gives_an_empty_result():
    assert correlate1d(np.zeros((3, 0)), [1.0, 2.0, 1.0]).shape == (3, 0)


def test_a_centred_impulse_gives_the_kernel_reversed_about_its_centre():
    out = correlate1d(np.eye(1, 9, 4)[0], [1.0, 2.0, 3.0, 4.0, 5.0])
    np.testing.assert_array_equal(out, [0, 0, 5, 4, 3, 2, 1, 0, 0])


@pytest.mark.parametrize("weights", [[1.0, 1.0], [], [[1.0]]])
def test_bad_kernel(weights):
    with pytest.raises(ParameterError):
        correlate1d(np.ones(5), weights)


def test_below_row_by_row_taps_each_row_is_correlated_on_its_own():
    # what _shifted_powers relies on to correlate only some of its moments: a row's result is the
    # same, to the bit, whatever rows are correlated beside it (from ROW_BY_ROW_TAPS on it is not)
    rng = np.random.default_rng(5)
    values = rng.normal(size=(30, 9, 300)) * 10.0 ** rng.integers(-3, 5, size=(9, 1))
    for taps in (3, 21, ROW_BY_ROW_TAPS - 1):
        weights = rng.normal(size=taps)
        np.testing.assert_array_equal(correlate1d(values[:, 2:5], weights), correlate1d(values, weights)[:, 2:5])
