"""Bootstrap intervals: the weighting is exact and the spectral figures
match closed forms."""
import math

import numpy as np
import pytest

from imgmtf.estimate.intervals.bootstrap import row_weights, spectral_figures
from imgmtf.estimate.resampling import resample_profile


def test_row_weights_resample_whole_rows():
    rows = np.repeat(np.arange(30), 7)
    weights = row_weights(rows, 50, np.random.default_rng(0))(np.ones(rows.size, bool))
    assert weights.shape == (50, rows.size)
    per_row = weights.reshape(50, 30, 7)
    assert (per_row == per_row[..., :1]).all()                # a row's samples share its count
    assert (per_row[..., 0].sum(axis=1) == 30).all()          # as many rows drawn as there are


@pytest.mark.parametrize("method", ["msg", "sliding", "spline", "iso"])
def test_integer_weights_equal_repeated_samples(method):
    rng = np.random.default_rng(1)
    d = rng.uniform(-6, 6, 1500)
    v = np.tanh(d) + rng.normal(0, 0.02, d.size)
    w = rng.integers(0, 3, d.size).astype(float)
    weighted = resample_profile(d, v, method=method, half_range=4, weights=np.stack([w, w]))
    repeated = resample_profile(np.repeat(d, w.astype(int)), np.repeat(v, w.astype(int)),
                                method=method, half_range=4)
    tol = 1e-9 if method != "spline" else 2e-3   # the spline's smoothing follows the sample count
    np.testing.assert_allclose(weighted.values[1], repeated.values, atol=tol, equal_nan=True)


def test_spectral_figures_of_a_gaussian_lsf_match_closed_forms():
    sigma, step = 0.6, 0.05
    x = np.arange(-6, 6 + step / 2, step)
    lsf = np.exp(-x**2 / (2 * sigma**2))
    nyquist, fifty = spectral_figures(np.stack([lsf, 2 * lsf]), step, lambda f: np.ones_like(f))
    np.testing.assert_allclose(nyquist, math.exp(-2 * math.pi**2 * sigma**2 * 0.25), atol=1e-9)
    np.testing.assert_allclose(fifty, math.sqrt(math.log(2) / 2) / (math.pi * sigma), rtol=2e-4)


def test_spectral_figures_of_a_profile_in_parts_equal_those_of_the_whole():
    step = 0.05
    x = np.arange(-6, 6 + step / 2, step)
    lsf = np.exp(-x**2 / (2 * 0.6**2)) + 0.01 / (1 + x**2)
    w = np.clip(2.5 - np.abs(x), 0, 1)                 # a window: 1 within 1.5 px, 0 beyond 2.5 px
    held = np.flatnonzero(w)
    shapes = (1 - w) * np.stack([x < 0, x >= 0]) / (1 + x**2)
    amplitudes = np.array([[0.01, 0.01], [0.02, 0.005]])
    whole = amplitudes @ shapes + w * lsf
    parts = spectral_figures(np.stack([lsf, lsf])[:, held] * w[held], step, lambda f: np.ones_like(f),
                             start=held[0], length=x.size, amplitudes=amplitudes, shapes=shapes)
    np.testing.assert_allclose(parts, spectral_figures(whole, step, lambda f: np.ones_like(f)), rtol=1e-12)
