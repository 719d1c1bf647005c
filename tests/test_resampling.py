import numpy as np
import pytest
from scipy.special import erf

from imgmtf.errors import ParameterError
from imgmtf.estimate.resampling import METHODS, resample_profile, sample_gap


def erf_edge(x, sigma=0.6):
    return 0.5 * (1 + erf(x / (sigma * np.sqrt(2))))


@pytest.fixture(scope="module")
def samples():
    d = np.random.default_rng(0).uniform(-12, 12, 6000)
    return d, erf_edge(d)


@pytest.mark.parametrize("method, tolerance", [("msg", 1e-4), ("spline", 1e-3), ("iso", None), ("sliding", None)])
def test_methods_reproduce_a_smooth_edge(samples, method, tolerance):
    d, v = samples
    r = resample_profile(d, v, method=method, half_range=11)
    assert np.allclose(np.diff(r.grid), r.step)
    assert r.grid[0] == pytest.approx(-r.grid[-1])
    if tolerance is None:
        # box-like methods: the result is the edge blurred by their own
        # kernel; a bin's mean over ~60 random positions scatters by ~0.006
        width = r.params.get("window_px", r.params.get("bin_px"))
        x = np.linspace(-width / 2, width / 2, 401)
        blurred = np.array([np.mean(erf_edge(g + x)) for g in r.grid])
        assert np.abs(r.values - blurred).max() < (2e-3 if method == "sliding" else 2e-2)
    else:
        assert np.nanmax(np.abs(r.values - erf_edge(r.grid))) < tolerance


def test_transfer_functions_closed_forms(samples):
    d, v = samples
    f = np.array([0.0, 0.25, 0.5, 1.0])
    sliding = resample_profile(d, v, method="sliding", half_range=10)
    w = sliding.params["window_px"]
    np.testing.assert_allclose(sliding.transfer(f), np.sinc(f * w), atol=1e-6)
    iso = resample_profile(d, v, method="iso", half_range=10)
    np.testing.assert_allclose(iso.transfer(f), np.sinc(f * 0.25))
    spline = resample_profile(d, v, method="spline", half_range=10)
    assert spline.transfer(np.array([2.0]))[0] == pytest.approx(0.5)
    msg = resample_profile(d, v, method="msg", half_range=10)
    assert msg.transfer(np.array([0.0]))[0] == pytest.approx(1.0)
    assert 0.99 < msg.transfer(np.array([0.5]))[0] < 1.0


def test_msg_preserves_quartics_exactly():
    d = np.random.default_rng(1).uniform(-5, 5, 3000)
    v = 0.3 * d**4 - d**3 + 2 * d + 1
    r = resample_profile(d, v, method="msg", half_range=4)
    assert np.abs(r.values - (0.3 * r.grid**4 - r.grid**3 + 2 * r.grid + 1)).max() < 1e-8


def test_window_widens_on_a_sample_lattice():
    d = np.arange(-2000, 2001) * 0.24 / 10
    d = np.round(d / 0.24) * 0.24                # samples only every 0.24 px
    assert sample_gap(d) == pytest.approx(0.24)
    r = resample_profile(d, erf_edge(d), method="msg", half_range=8)
    assert r.params["window_px"] >= 5.5 * 0.24 - 0.05
    assert np.isfinite(r.values).all()


def test_dispatcher_errors(samples):
    d, v = samples
    with pytest.raises(ParameterError, match="unknown method"):
        resample_profile(d, v, method="lanczos", half_range=5)
    with pytest.raises(ParameterError, match="takes no option"):
        resample_profile(d, v, method="iso", half_range=5, order=3)
    with pytest.raises(ParameterError, match="step"):
        resample_profile(d, v, method="msg", step=0, half_range=5)
    assert set(METHODS) == {"msg", "sliding", "spline", "iso"}


def test_penalised_spline_is_scipys_smoothing_spline_and_meets_its_limits():
    """The O(n) smoothing spline is SciPy's make_smoothing_spline (the same
    minimiser), interpolates as the natural cubic spline when lam -> 0 and
    becomes the weighted least-squares line when lam -> infinity."""
    from scipy.interpolate import CubicSpline, make_smoothing_spline

    from imgmtf.estimate.resampling import penalised_spline
    rng = np.random.default_rng(2)
    x = -8.0 + 0.04 * np.arange(400) + rng.uniform(0, 0.02, 400)      # gaps of 0.02 to 0.06
    y = np.tanh(x) + rng.normal(0, 0.02, x.size)
    w = rng.uniform(0.5, 3.0, x.size)
    at = np.linspace(x[0], x[-1], 1001)
    for lam in (1e-4, 0.1, 10.0):
        expected = make_smoothing_spline(x, y, w=w, lam=lam)(at)
        np.testing.assert_allclose(penalised_spline(x, y, w, lam, at), expected, rtol=0, atol=1e-9)
    natural = CubicSpline(x, y, bc_type="natural")(at)
    np.testing.assert_allclose(penalised_spline(x, y, w, 1e-12, at), natural, rtol=0, atol=1e-6)
    slope, intercept = np.polyfit(x, y, 1, w=np.sqrt(w))
    np.testing.assert_allclose(penalised_spline(x, y, w, 1e12, at), slope * at + intercept, rtol=0, atol=1e-6)


def test_penalised_spline_refuses_knots_too_close_and_the_resampler_merges_them():
    from imgmtf.errors import ImageContentError
    from imgmtf.estimate.resampling import penalised_spline
    rng = np.random.default_rng(0)
    x = np.sort(rng.uniform(-20, 20, 20000))
    y = np.tanh(x) + rng.normal(0, 0.01, x.size)
    x, y = np.insert(x, 10001, x[10000] + 1e-12), np.insert(y, 10001, y[10000])     # two knots 1e-12 apart
    lam = x.size / 40 / (4 * np.pi) ** 4                # the resampler's weight for a 2 cy/px cut-off
    with pytest.raises(ImageContentError, match="singular"):
        penalised_spline(x, y, np.ones(x.size), lam, np.linspace(-19, 19, 5))
    # the resampler takes samples within 1e-7 px as one knot
    r = resample_profile(x, y, method="spline", half_range=10)
    assert np.nanmax(np.abs(r.values - np.tanh(r.grid))) < 0.01


@pytest.mark.parametrize("half_bins", [10, 30])        # 21 taps: row by row; 61: OpenCV's DFTs, every moment
@pytest.mark.parametrize("adjoint", [False, True])
def test_shifted_powers_are_every_moment_correlated_with_every_power(half_bins, adjoint):
    from imgmtf.estimate._correlation import correlate1d
    from imgmtf.estimate._window_sums import _binomial_shifts, _shifted_powers, _shifted_powers_by_power
    rng = np.random.default_rng(half_bins)
    moments = rng.normal(size=(4, 9, 200)) * 10.0 ** rng.integers(-2, 4, size=(9, 1))
    offsets = np.arange(-half_bins, half_bins + 1) / (half_bins + 0.5)
    binomials = _binomial_shifts(9, adjoint)
    every = np.stack([correlate1d(moments, offsets ** p) for p in range(9)], axis=-3).reshape(4, 81, 200)
    expected = binomials @ every
    # correlated power by power (stacks of weightings): the same sums in the same order
    np.testing.assert_array_equal(_shifted_powers_by_power(moments, offsets, binomials), expected)
    # one weighting's moments: one product with the folded kernel, the same sums in another order
    for one, sums in zip(moments, expected):
        scale = np.abs(one).max()
        np.testing.assert_allclose(_shifted_powers(one, offsets, binomials) / scale, sums / scale,
                                   rtol=0, atol=1e-13 * (half_bins + 1))
    np.testing.assert_array_equal(_shifted_powers(moments, offsets, binomials), expected)    # a stack
