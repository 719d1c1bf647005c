"""Linearised intervals: the row influences' standard error, the interval
it gives, and the width reading's pull on the samples (the adjoint the
intervals rest on) against finite differences."""
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy import stats

import imgmtf as im
from imgmtf.estimate.intervals.influence import influence_sd, influence_sds, linearised_interval


def test_the_stacked_standard_errors_are_each_rows_own():
    rng = np.random.default_rng(2)
    rows = np.repeat(np.arange(50), 20)
    influences = rng.normal(size=(3, rows.size))
    sds, n = influence_sds(influences, rows)
    assert n == 50
    for k in range(3):
        assert sds[k] == pytest.approx(influence_sd(influences[k], rows)[0], rel=1e-12)


def test_independent_rows_give_the_spread_of_their_sum():
    """Row influences of N(0, 1) each: the sum over n rows has sd sqrt(n)."""
    rng = np.random.default_rng(3)
    n = 400
    estimates = [influence_sd(rng.normal(size=n), np.arange(n))[0] for _ in range(200)]
    assert np.mean(estimates) == pytest.approx(math.sqrt(n), rel=0.05)
    assert math.isnan(influence_sd(np.ones(2), np.arange(2))[0])      # fewer than 3 rows: no error


def test_the_interval_is_students_t_times_the_error_widened_by_the_systematic_part():
    interval = linearised_interval(0.3, 0.01, 25, 0.95, systematic=0.0075)
    half = stats.t.ppf(0.975, 24) * 0.0125
    assert (interval.low, interval.high) == pytest.approx((0.3 - half, 0.3 + half), rel=1e-9)
    assert math.isnan(linearised_interval(0.3, 0.01, 2, 0.95).low)
    assert math.isnan(linearised_interval(math.nan, 0.01, 25, 0.95).high)


def test_a_read_widths_pull_on_the_samples_matches_finite_differences():
    """R(f), the bar's spectrum the width is read from, is linear in the
    samples (through the resampling and the background): changing one
    sample by 1 DN changes R by that sample's pull."""
    from imgmtf.estimate.pipeline import run
    from imgmtf.estimate.profile import INITIAL_SPAN_PX, resample_samples
    from imgmtf.estimate.pulse import PulseKind
    from imgmtf.estimate.settings import make_settings
    chip = im.render(im.Sensor(), im.Target("pulse", 6.0, 200, 1200, width_px=1.5), 60, noise_std_dn=2.0, seed=1)
    settings = make_settings(intervals="none")
    estimate = run(PulseKind(), chip.image, settings).estimate
    reading, read, samples = estimate.width, estimate.shape_profile, estimate.samples
    pull = reading.sample_pull(read.resampled.adjoint, read.resampled.grid.size, read.span)
    span_px = min(samples.reach_px, INITIAL_SPAN_PX)

    def spectrum(values):
        profile = resample_samples(replace(samples, values_dn=values), settings, span_px, "bar")
        assert profile.span == read.span
        background = 0.5 * sum(values[side].mean() for side in reading.background_sides)
        return reading.on_grid @ profile.values + reading.per_background * background

    base = spectrum(samples.values_dn)
    near = int(np.argmin(np.abs(samples.distance_px)))
    far = int(np.argmax(samples.distance_px))              # beyond the resampled profile
    assert reading.background_sides[1][far]
    for i in (near, far):
        changed = samples.values_dn.copy()
        changed[i] += 1.0
        np.testing.assert_allclose(spectrum(changed) - base, pull[:, i], rtol=1e-6, atol=1e-12)
    assert np.abs(pull[:, far]).max() > 0                  # it moves R through the background alone


def test_one_pass_through_the_resampling_serves_the_figures_and_a_read_width_alike():
    """A width read off the profile the LSF came from shares its pass
    backwards through the resampling; read off another (a profile widened
    after), it takes its own: the same intervals either way."""
    from imgmtf.estimate.intervals import intervals
    from imgmtf.estimate.pipeline import run
    from imgmtf.estimate.pulse import PulseKind
    from imgmtf.estimate.settings import make_settings
    from imgmtf.estimate.state import Profile
    chip = im.render(im.Sensor(), im.Target("pulse", 6.0, 200, 1200, width_px=1.5), 60, noise_std_dn=4.0, seed=3)
    estimate = run(PulseKind(), chip.image, make_settings(intervals="none")).estimate
    assert estimate.shape_profile.resampled is estimate.profile.resampled
    apart = replace(estimate, shape_profile=Profile(replace(estimate.shape_profile.resampled),
                                                    estimate.shape_profile.span))
    shared, separate = intervals(estimate), intervals(apart)
    assert shared == separate and shared.mtf_nyquist.width > 0


@pytest.mark.parametrize("target", ["edge", "bar"])
def test_the_figures_gradients_combined_on_the_grid_are_those_of_the_frequencies(target):
    """Each figure's gradient, |F(f)| / |F(0)| scaled to the MTF, taken as a
    real combination of the transform's rows before the passes backwards,
    is the one made of every frequency's complex gradient dF(f) / dv
    (each frequency's real and imaginary rows through the adjoints)."""
    from imgmtf.estimate.edge import EdgeKind
    from imgmtf.estimate.intervals.influence import _figure_combination, _sample_gradients, _transform_kernel
    from imgmtf.estimate.pipeline import run
    from imgmtf.estimate.pulse import PulseKind
    from imgmtf.estimate.settings import make_settings
    shape = im.Target("edge", 6.0) if target == "edge" else im.Target("pulse", 6.0, width_px=1.5)
    chip = im.render(im.Sensor(), shape, 60, noise_std_dn=2.0, seed=4)
    kind = EdgeKind() if target == "edge" else PulseKind(1.5)
    estimate = run(kind, chip.image, make_settings(intervals="none")).estimate
    freqs = np.array([0.0, 0.5, estimate.spectrum.mtf50_cy_px])
    kernel = _transform_kernel(estimate.lsf.x_px, freqs)
    transform, mtf_at = kernel @ estimate.lsf.combined, estimate.spectrum.mtf(freqs[1:])
    figures, _ = _sample_gradients(estimate, kernel, _figure_combination(transform, mtf_at), None)
    rows, _ = _sample_gradients(estimate, kernel, np.eye(2 * freqs.size - 1), None)
    n_f, f0 = freqs.size, transform[0].real
    for j in (1, 2):
        fj, gradient = transform[j], rows[j] + 1j * rows[n_f - 1 + j]
        ratio = abs(fj) / abs(f0)
        expected = np.real(np.conj(fj) * gradient) / (abs(fj) * abs(f0)) - ratio * rows[0] / f0
        expected *= mtf_at[j - 1] / ratio
        np.testing.assert_allclose(figures[j - 1], expected, rtol=1e-9, atol=1e-12 * np.abs(expected).max())
