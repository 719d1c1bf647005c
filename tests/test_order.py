"""The order statistics (imgmtf.estimate._order) give NumPy's floats to the bit."""
import warnings

import numpy as np
import pytest

from imgmtf.estimate._order import median, percentile, quantile


def _samples():
    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 4, 7, 10, 31, 120):
        yield rng.normal(size=n) * 10.0 ** rng.uniform(-3, 3)
        yield np.round(rng.normal(size=n) * 3)                      # ties
        yield rng.integers(-3, 3, n)                                # integers
        yield np.where(rng.random(n) < 0.5, -0.0, 0.0)              # signed zeros


@pytest.mark.parametrize("q", [0.25, [0.01, 0.99], [0.5, 0.8], [0.0, 1.0]])
def test_quantile_and_median_are_numpys(q):
    for values in _samples():
        assert np.asarray(quantile(values, q)).tobytes() == np.asarray(np.quantile(values, q)).tobytes()
        assert np.asarray(median(values)).tobytes() == np.asarray(np.median(values)).tobytes()
    pct = np.asarray(q) * 100
    values = np.random.default_rng(4).normal(size=(5, 9))
    assert np.asarray(percentile(values, pct)).tobytes() == np.asarray(np.percentile(values, pct)).tobytes()


def test_nan_and_empty_as_numpy():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        assert np.isnan(median([1.0, np.nan, 2.0])) and np.isnan(median([]))
        assert np.isnan(quantile([1.0, np.nan, 2.0], [0.1, 0.9])).all()


def test_distinct_is_numpys_unique():
    from imgmtf.estimate._order import distinct
    rng = np.random.default_rng(6)
    for values in (rng.integers(0, 40, 300), rng.integers(-7, 7, 9).astype(np.int32), np.array([5]),
                   rng.integers(0, 10**9, 20), rng.normal(size=12)):
        ids, inverse = distinct(values, return_inverse=True)
        want, want_inverse = np.unique(values, return_inverse=True)
        assert ids.dtype == want.dtype and ids.tobytes() == want.tobytes()
        assert inverse.dtype == want_inverse.dtype and inverse.tobytes() == want_inverse.tobytes()
        assert distinct(values).tobytes() == want.tobytes()
