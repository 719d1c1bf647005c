"""estimate/fit: the edges' samples binned along the normal (data.bin_profile),
the model of a bin (model.bin_esf) and what the fit reports from bins, against
the samples themselves."""
import dataclasses
import math
import types

import numpy as np
import pytest
from scipy.special import chdtrc

import imgmtf as im
from imgmtf.estimate.fit import fit_edges
from imgmtf.estimate.fit.data import FIT_BIN_PX, EdgeData, bin_profile, edge_data, sorted_bins
from imgmtf.estimate.fit.model import Model, bin_esf, initial_stages
from imgmtf.estimate.fit.report import misfit_test, residual_means
from imgmtf.sensor import stages as st

SENSORS = {"gaussian 0.3 px + pixel": im.Sensor(1.0, [st.GaussianOptics(0.3, 0.3), st.Detector()]),
           "paper": im.Sensor(),
           "f/8 + pixel": im.Sensor(1.0, [st.Diffraction(8.0), st.Detector()])}


def slanted(rows: int, cols: int = 60, angle_deg: float = 5.0, offset: float = 0.3) -> np.ndarray:
    """The samples' distances from an edge tilted ``angle_deg`` from the
    columns through a rows x cols chip, px, ascending."""
    r, c = np.mgrid[0:rows, 0:cols].astype(float)
    t = math.radians(angle_deg)
    return np.sort(((c - cols / 2 + offset) * math.cos(t) - (r - rows / 2) * math.sin(t)).ravel())


def per_bin(x, values, width):
    """Each bin's samples by a direct loop: the reference."""
    keys = np.floor(x / width)
    return [(values[keys == k], x[keys == k]) for k in np.unique(keys)]


def test_bins_hold_their_samples_count_mean_and_variance():
    rng = np.random.default_rng(1)
    x = np.concatenate([rng.uniform(-20, 20, 3000), [0.0, 0.25, -0.25]])     # on bin boundaries too
    y = rng.normal(500, 40, x.size)
    shuffled = rng.permutation(x.size)
    bins = bin_profile(x[shuffled], y[shuffled], 0.25)
    expected = per_bin(x, y, 0.25)
    assert bins.x.size == len(expected) and bins.count.sum() == x.size and (bins.count > 0).all()
    assert (np.diff(bins.x) > 0).all()
    np.testing.assert_array_equal(bins.count, [v.size for v, _ in expected])
    np.testing.assert_allclose(bins.x, [d.mean() for _, d in expected], rtol=0, atol=1e-13)
    np.testing.assert_allclose(bins.y, [v.mean() for v, _ in expected], rtol=1e-13)
    np.testing.assert_allclose(bins.m2, [d.var() for _, d in expected], rtol=0, atol=1e-15)
    assert bin_profile(np.zeros(0), np.zeros(0)).x.size == 0


def test_sorted_samples_bin_as_sorted_again():
    """sorted_bins (edge_data's samples, sorted before) gives bin_profile's
    bins bit for bit, tied distances' values kept in their order."""
    rng = np.random.default_rng(2)
    x = np.sort(np.concatenate([rng.uniform(-5, 5, 400), np.full(5, 0.5), [-0.25, 0.25]]), kind="stable")
    y = rng.normal(500, 40, x.size)
    for mine, theirs in zip(dataclasses.astuple(sorted_bins(x, y, 0.25)), dataclasses.astuple(bin_profile(x, y, 0.25))):
        assert mine.tobytes() == theirs.tobytes()


@pytest.mark.parametrize("name", SENSORS)
@pytest.mark.parametrize("rows", [100, 300])
def test_a_bins_model_is_its_samples_mean_model_far_below_the_noise(name, rows):
    """ESF(x̄) + ESF''(x̄) m2 / 2 against the mean of the ESF over each bin's
    samples, noise-free, for a step of 1: within 1.5e-6 (measured: 1.2-3.3e-7,
    1.2e-6 near f/8's sharp core), and 0.01 RMS of a bin mean's noise at the
    noise floor of noise-free floats (1e-5 / sqrt(n); measured 0.002-0.007):
    a 1e-4 change of the chi-square at most.  Without the m2 term it is
    0.9-1.9 times that noise, over 100 times more."""
    sensor = SENSORS[name]
    x, x0 = slanted(rows), 0.137
    response = sensor.line_response(5.0, reach_px=40.0)
    bins = bin_profile(x, response.esf(x - x0))
    error = bins.y - bin_esf(response, bins, x0)
    in_noise = np.sqrt(np.mean(bins.count * error**2)) / 1e-5
    assert np.abs(error).max() < 1.5e-6 and in_noise < 0.01
    plain = bins.y - response.esf(bins.x - x0)
    assert np.sqrt(np.mean(bins.count * plain**2)) / 1e-5 > 100 * in_noise


@pytest.fixture(scope="module")
def exact_edge():
    """A noisy edge whose model is exact: the samples of a slanted edge,
    valued by the paper's sensor's ESF, levels 200 and 1200 DN, offset
    0.137 px, noise 5 DN; and the model at its truth (the fit's own line
    response)."""
    from imgmtf.estimate.fit.responses import EdgeResponses
    sensor = im.Sensor()
    x = slanted(100)
    levels, x0, noise = (200.0, 1200.0), 0.137, 5.0
    response = EdgeResponses(5.0, 1.0, float(np.abs(x).max()) + 2.0).response(sensor)
    model_values = levels[0] + (levels[1] - levels[0]) * response.esf(x - x0)
    y = model_values + np.random.default_rng(7).normal(0, noise, x.size)
    data = EdgeData("exact", x, y, bin_profile(x, y), 5.0, 1.0, True, noise, levels, None)
    model = Model(1.0, initial_stages([s.name for s in sensor.stages], sensor, 1.0), [data])
    z = model.initial_vector()
    z[-3:] = (*levels, x0)           # the edge's levels and offset: its truth
    return data, model, z, model_values


def test_the_bins_chi_square_is_the_samples_less_their_scatter_within_bins(exact_edge):
    """sum_b n (ȳ - m̄)^2 = sum_i (y - m)^2 - sum_b sum_i ((y - ȳ) - (m - m̄))^2
    exactly with each bin's mean model m̄; the bins' model (bin_esf) gives
    the same to 1e-6 (it is within 3e-7 of the step, 3e-4 DN, of m̄).  Of
    noise, the scatter holds (samples - bins)
    variances and the bins' chi-square the rest: it reads 1 per degree of
    freedom over bins - parameters."""
    data, model, z, m = exact_edge
    keys = np.floor(data.x / FIT_BIN_PX)
    _, index = np.unique(keys, return_inverse=True)
    mean_model = np.bincount(index, weights=m) / data.bins.count
    residual = (data.y - m) / data.noise
    within = residual - (data.bins.y - mean_model)[index] / data.noise
    samples = float(np.sum(residual**2))
    scatter = float(np.sum(within**2))
    exact_bins = float(np.sum(data.bins.count * ((data.bins.y - mean_model) / data.noise) ** 2))
    assert exact_bins == pytest.approx(samples - scatter, rel=1e-12)
    assert model.chi_square(z) == pytest.approx(samples - scatter, rel=1e-6)
    assert model.sample_chi_squares(z)[0] == pytest.approx(samples, rel=1e-9)
    bins, n = data.bins.x.size, data.x.size
    assert abs(scatter - (n - bins)) < 5 * math.sqrt(2 * (n - bins))
    assert abs(model.chi_square(z) - bins) < 5 * math.sqrt(2 * bins)
    assert model.dof == n - model.n_free - 3 and model.rows == bins


def test_residual_means_of_the_bins_are_the_samples_at_zero_offset(exact_edge):
    """Residual means over 0.25 px from the fit's bins, each by its count,
    are the samples' own means when the bins nest in them (zero offset):
    what the residual panel draws."""
    data, _, _, m = exact_edge
    residual = data.y - m
    binned = bin_profile(data.x, residual)
    centres, means, counts = residual_means(binned.x, binned.y, binned.count, 3.0)
    near = np.abs(data.x) <= 3.0
    direct = [(v.mean(), v.size) for v, _ in per_bin(data.x[near], residual[near], 0.25)]
    np.testing.assert_allclose(means, [mean for mean, _ in direct], rtol=1e-12)
    np.testing.assert_array_equal(counts, [size for _, size in direct])
    np.testing.assert_allclose(centres, np.arange(-3.0, 3.0, 0.25) + 0.125)


@pytest.mark.parametrize("bump_dn", [0.0, 6.0], ids=["exact", "bump"])
def test_the_reported_misfit_test_is_the_samples_at_an_offset(exact_edge, bump_dn):
    """The report's misfit p-value and size are those of the samples'
    residuals against the model, binned 0.25 px from the fitted edge at
    0.137 px (the samples' own statistic, to 1e-9), with or without a
    structure of 0.6 % of the step.  The fit's 1/32 px bins, formed on the
    distances before the offset, straddle those bins: their means binned
    so give another p-value (0.633 against the samples' 0.368 here, exact
    model), which the report gave before."""
    from imgmtf.estimate.fit.covariance import parameter_covariance
    from imgmtf.estimate.fit.report import fit_report
    data, model, z, m = exact_edge
    x0 = z[model.n_free + 2]
    assert x0 == 0.137
    y = data.y + bump_dn * np.exp(-0.5 * ((data.x - x0) / 0.5) ** 2)
    # what the report reads of the edge's non-parametric measurement, which this edge has not
    measured = types.SimpleNamespace(rows_used=100, snr=200.0, frequencies_cy_px=np.array([0.0, 1.0]),
                                     mtf=np.array([1.0, 0.0]))
    model = Model(1.0, model.stages, [dataclasses.replace(data, y=y, bins=bin_profile(data.x, y),
                                                          measurement=measured)])
    response = model.responses(z[: model.n_free])[0]
    on_samples = misfit_test(data.x - x0, y - m, data.noise, 1000.0, response)
    covariance = parameter_covariance(model.jacobian(z), 1.0)
    edge = fit_report(model, z, covariance, {}, 0.95).edges[0]
    assert (edge.misfit_p, edge.misfit_fraction) == pytest.approx(on_samples, rel=1e-9)
    # the fit's bins' residual means, 0.25 px binned from the fitted edge: not the samples'
    grid = np.arange(-50.0, 50.0, 0.25 / 4)
    reach = max(3.0, float(np.abs(grid[(response.esf(grid) > 1e-3) & (response.esf(grid) < 1 - 1e-3)]).max()))
    _, means, count = residual_means(edge.samples_x_px - x0, edge.residuals_dn, edge.bin_counts, reach)
    on_bins = float(chdtrc(count.size, np.sum(count * means**2) / data.noise**2))
    if bump_dn:
        assert on_samples[0] < 1e-6 and on_samples[1] > 1e-3
    else:
        assert abs(on_bins - on_samples[0]) > 0.2          # measured 0.633 against 0.368


def test_a_fits_edges_report_its_bins_and_the_samples_chi_square():
    """EdgeFit's samples_x_px, residuals_dn and bin_counts are per bin and
    hold every sample; the reduced chi-squares are the samples' (their
    residuals against the fitted model over samples - parameters), as
    without bins."""
    sensor = im.Sensor(1.0, [st.GaussianOptics(0.45, 0.35), st.Detector()])
    renderer = im.Renderer(sensor, 80)
    edges = [im.measure_edge(renderer(im.Target("edge", a, 200.0, 1200.0, 0.2), noise_std_dn=8.0, seed=k).image)
             for k, a in enumerate((5.0, -84.0))]
    fit = fit_edges(edges, stages="optics,detector", hold="detector")
    free = sum(p.status == "fitted" for p in fit.parameters)
    chi, samples = [], 0
    for e, edge in zip(fit.edges, edges):
        x = np.asarray(edge.samples_x_px, float)
        data = edge_data(edge, 0, None)
        assert e.bin_counts.sum() == x.size and e.samples_x_px.size == e.residuals_dn.size == e.bin_counts.size
        np.testing.assert_array_equal(e.samples_x_px, data.bins.x)
        esf = fit.sensor.line_response(e.normal_angle_deg, reach_px=float(np.abs(x).max()) + 2).esf(x - e.offset_px)
        lo, hi = e.levels_dn
        chi.append(float(np.sum(((np.asarray(edge.samples_dn, float) - lo - (hi - lo) * esf) / e.noise_dn) ** 2)))
        assert e.reduced_chi_square == pytest.approx(chi[-1] / (x.size - 3 - free / 2), rel=1e-6)
        samples += x.size
    assert fit.reduced_chi_square == pytest.approx(sum(chi) / (samples - free - 6), rel=1e-6)
    assert 0.9 < fit.reduced_chi_square < 1.1


def test_the_residual_panel_draws_the_bins_means_over_their_samples():
    from imgmtf.plot import plot_fit_residuals
    chip = im.render(im.Sensor(), im.Target("edge", 6.0, 200.0, 1200.0), 60, noise_std_dn=8.0, seed=2)
    fit = im.fit_sensor([chip.image])
    edge = fit.edges[0]
    line = plot_fit_residuals(fit).axes[0].lines[0]
    centres, means, _ = residual_means(edge.samples_x_px - edge.offset_px, edge.residuals_dn, edge.bin_counts, 6.0)
    np.testing.assert_allclose(line.get_xdata(), centres)
    np.testing.assert_allclose(line.get_ydata(), means * 100 / abs(edge.step_dn))


def test_a_misfit_test_without_a_bin_is_not_run_and_no_pass():
    """Samples all beyond the transition (no 0.25 px bin within reach holds
    3): the test cannot run, says so with NaN, and a record of such a fit
    says it could not be tested rather than that it fits."""
    from imgmtf.estimate.fit.record import FitRecord
    response = types.SimpleNamespace(esf=lambda x: (np.asarray(x) > 0).astype(float))
    p, size = misfit_test(np.array([-9.0, -8.0, 8.0, 9.0]), np.zeros(4), 1.0, 1000.0, response)
    assert math.isnan(p) and math.isnan(size)
    untested = types.SimpleNamespace(misfit_p=math.nan, misfit_fraction=math.nan, source="a", misfit_tested=False)
    fit = types.SimpleNamespace(misfit=False, reduced_chi_square=1.0, edges=[untested],
                                sensor=types.SimpleNamespace(stages=[]))
    record = FitRecord.of(fit)
    assert math.isnan(record.misfit_p) and "could not be tested on" in record.summary()
    tested = types.SimpleNamespace(misfit_p=0.4, misfit_fraction=0.001, source="b", misfit_tested=True)
    for edges in ([untested, tested], [tested, untested]):       # the tested edge's p, in either order
        assert FitRecord.of(types.SimpleNamespace(**{**vars(fit), "edges": edges})).misfit_p == 0.4
