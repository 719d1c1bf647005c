"""estimate/fit: how the model's Jacobian is stored changes no fitted value."""
import math
from statistics import NormalDist

import numpy as np
import pytest

import imgmtf as im
from imgmtf.estimate.fit import bands as fit_bands
from imgmtf.estimate.fit import model as fit_model
from imgmtf.estimate.fit.data import edge_data
from imgmtf.estimate.fit.model import Model, initial_stages


def _edges():
    sensor = im.Sensor(1.0, [im.sensor.stages.GaussianOptics(0.5, 0.4), im.sensor.stages.Detector(1.0, 1.0)])
    chips = [im.render(sensor, im.Target("edge", angle), 60, noise_std_dn=40.0, seed=k).image
             for k, angle in enumerate((5.0, 83.0, -7.0, -84.0))]
    return [im.measure_edge(chip) for chip in chips]


@pytest.fixture(scope="module")
def edges():
    return _edges()


def test_the_sparse_jacobian_holds_exactly_the_dense_ones_entries(edges, monkeypatch):
    data = [edge_data(e, k, None) for k, e in enumerate(edges)]
    model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0), data)
    z = model.initial_vector()
    dense = model.jacobian(z)
    monkeypatch.setattr(fit_model, "DENSE_EDGES", 0)
    sparse = model.jacobian(z)
    assert sparse.shape == dense.shape and sparse.nnz == dense.shape[0] * (model.n_free + 3)
    np.testing.assert_array_equal(sparse.toarray(), dense)


def test_edge_model_mtfs_are_each_edges_own(edges):
    """The report's edges' model MTFs at Nyquist (with their bands) and
    MTF50s, computed for all edges in arrays (in chunks), are what
    model_mtf_band and first_crossing give edge by edge, bit for bit."""
    from imgmtf.estimate.fit.report import edge_model_mtfs
    from imgmtf.metrics import first_crossing
    data = [edge_data(e, k, None) for k, e in enumerate(edges)]
    model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0), data)
    u = model.initial_vector()[: model.n_free]
    covariance = np.diag(np.linspace(1e-4, 4e-4, model.n_free)) + 5e-5
    sensors = fit_bands.band_sensors(model, u)
    bands, mtf50 = edge_model_mtfs(model, u, covariance, sensors, 0.9, chunk=3)
    f = np.linspace(0.0, 2.0, 4001)
    for e, d in enumerate(data):
        own = fit_bands.model_mtf_band(model, u, covariance, np.array(0.5), d.normal_angle_deg, d.gsd_m, 0.9,
                                       sensors)
        assert [float(v) for v in own] == bands[:, e].tolist()
        assert bands[1, e] < bands[0, e] < bands[2, e]
        assert mtf50[e] == first_crossing(f, np.abs(sensors[0].normal_transfer(f, d.normal_angle_deg, d.gsd_m)), 0.5)
        # the band's stepped sensors' shared stages computed once: each sensor's own transfer, bit for bit
        value = np.abs(sensors[0].normal_transfer(0.5, d.normal_angle_deg, d.gsd_m))
        grads = [(np.abs(s.normal_transfer(0.5, d.normal_angle_deg, d.gsd_m)) - value) / h for h, s in sensors[1]]
        se = math.sqrt(max(float(np.einsum("i,ij,j->", grads, covariance, grads)), 0.0))
        assert own[0] == value and abs(own[2] - own[1] - 2 * NormalDist().inv_cdf(0.95) * se) < 1e-15


@pytest.mark.parametrize("first", [101, 766])
def test_mtf50s_read_on_the_grids_first_part_are_the_whole_grids(edges, monkeypatch, first):
    """The report's MTF50s (edges' and directions', with their intervals)
    and Nyquist bands, read on the MTF50 grid's first frequencies and on
    the whole grid where a curve has not crossed 0.5 there (to 0.05 cy/px:
    none has, every curve made again; to 0.3825 cy/px: the lower bounds), are the whole
    grid's first crossings and the band at 0.5 cy/px, bit for bit."""
    from imgmtf.estimate.fit import report
    from imgmtf.metrics import first_crossing
    data = [edge_data(e, k, None) for k, e in enumerate(edges)]
    model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0), data)
    u = model.initial_vector()[: model.n_free]
    covariance = np.diag(np.linspace(1e-4, 4e-4, model.n_free)) + 5e-5
    sensors = fit_bands.band_sensors(model, u)
    f = np.linspace(0.0, 2.0, 4001)
    whole = [[first_crossing(f, c, 0.5) for c in fit_bands.model_mtf_band(model, u, covariance, f, a, 1.0, 0.9,
                                                                          sensors)] for a in (0.0, 90.0)]
    nyquist = [fit_bands.model_mtf_band(model, u, covariance, np.array(0.5), a, 1.0, 0.9, sensors) for a in (0.0, 90.0)]
    edge_bands, edge_mtf50 = report.edge_model_mtfs(model, u, covariance, sensors, 0.9, chunk=3)
    monkeypatch.setattr(fit_bands, "MTF50_FIRST", first)
    monkeypatch.setattr(report, "MTF50_FIRST", first)
    crossed = [bool(v <= f[first - 1]) for row in whole for v in row]
    assert not any(crossed) if first == 101 else any(crossed) and not all(crossed)
    for a, own, at_nyquist in zip((0.0, 90.0), whole, nyquist):
        band, mtf50, (low, high) = fit_bands.model_nyquist_mtf50_bands(model, u, covariance, a, 1.0, 0.9, sensors)
        assert [mtf50, low, high] == own and [float(v) for v in band] == [float(v) for v in at_nyquist]
    bands, mtf50 = report.edge_model_mtfs(model, u, covariance, sensors, 0.9, chunk=3)
    assert np.array_equal(bands, edge_bands) and np.array_equal(mtf50, edge_mtf50)


def test_edges_grouped_by_angle_fit_as_each_edge_alone(edges, monkeypatch):
    """Edges whose responses are interpolated in angle (:mod:`.angles`,
    here groups of two) give the residuals, Jacobian and optimum of each
    edge's own response, far below their printed digits."""
    from imgmtf.estimate.fit import angles
    data = [edge_data(e, k, None) for k, e in enumerate(edges)]
    own = Model(1.0, initial_stages(["optics", "detector"], None, 1.0), data)
    monkeypatch.setattr(angles, "MIN_EDGES", 2)
    monkeypatch.setattr(fit_model, "DENSE_EDGES", 0)          # the sparse Jacobian, as a scene's
    grouped = Model(1.0, initial_stages(["optics", "detector"], None, 1.0), data)
    assert sorted(i for members, _ in grouped.groups for i in members) == [0, 1, 2, 3] and not grouped.own
    z = own.initial_vector()
    np.testing.assert_allclose(grouped.residuals(z), own.residuals(z), rtol=0, atol=1e-7)
    np.testing.assert_allclose(grouped.jacobian(z).toarray(), own.jacobian(z).toarray(), rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(grouped.solve(z)[0], own.solve(z)[0], rtol=1e-7, atol=1e-7)


def test_changes_written_in_place_are_each_edges_and_groups_own(edges, monkeypatch):
    """The Jacobian's changes, each edge's inverse FFT written into its
    place among the grids side by side and the groups' combined there, are
    what an edge's own changes and its group's combination give, bit for
    bit (a group of two and an edge of its own)."""
    from imgmtf.estimate.fit import angles
    monkeypatch.setattr(angles, "MIN_EDGES", 2)
    data = [edge_data(e, k, None) for k, e in enumerate(edges[:3])]
    model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0), data)
    assert [members for members, _ in model.groups] == [[2, 0]] and model.own == [1]
    u = model.initial_vector()[: model.n_free]
    sensor = model.sensor(u)
    shifted = [model.sensor(u + np.eye(model.n_free)[k] * 1e-3) for k in range(model.n_free)]
    model.responses(u)
    esf, lsf = model._changes(sensor, shifted)
    layout = model._last_responses[2]
    _, own_esf, own_lsf = model.edges[1].changes(sensor, shifted)
    start, size = layout.offsets[1], own_esf.shape[-1]
    assert np.array_equal(esf[:, start: start + size], own_esf) and np.array_equal(lsf[:, start: start + size], own_lsf)
    (_, group), = model.groups
    node_esf, node_lsf = group.node_changes(sensor, shifted)
    for k in range(len(shifted)):
        for j, i in enumerate([2, 0]):
            at = slice(layout.offsets[i], layout.offsets[i] + node_esf.shape[-1])
            assert np.array_equal(esf[k, at], group.combine(node_esf[:, k])[j])
            assert np.array_equal(lsf[k, at], group.combine(node_lsf[:, k])[j])


def test_a_targets_solve_reaches_scipys_optimum(edges):
    """A target's four half-edges (a dense Jacobian) are solved by the
    arrowhead Levenberg-Marquardt, stopped as SciPy's trust region was
    (ftol 1e-9): the chi-square within 1e-9 of SciPy's tightest optimum and
    every stage parameter within 3e-4 standard errors of it (6e-5 here)."""
    from scipy.optimize import least_squares

    from imgmtf.estimate.fit.covariance import parameter_covariance
    data = [edge_data(e, k, None) for k, e in enumerate(edges)]
    model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0), data)
    assert not model.sparse
    z0 = model.initial_vector()
    z, jacobian = model.solve(z0)
    np.testing.assert_array_equal(jacobian, model.jacobian(z))      # the Jacobian at the solution
    lower, upper = model.bounds()
    best = least_squares(model.residuals, z, jac=model.jacobian, bounds=(lower, upper),        # polished from z
                         method="trf", x_scale="jac", ftol=1e-15, xtol=1e-15, gtol=1e-15).x
    assert model.chi_square(z) <= model.chi_square(best) * (1 + 1e-9)
    scale = max(model.reduced_chi_square(best), 1.0)
    covariance = parameter_covariance(model.jacobian(best), scale, model.n_free, model.counts)
    errors = np.sqrt(np.diag(covariance))
    n = model.n_free                         # SciPy's own end with the model's settings: 4e-5 of them
    assert np.all(np.abs(z[:n] - best[:n]) < 3e-4 * errors)


def test_the_models_sensors_after_the_first_are_the_constructors(edges):
    """Model.sensor makes the sensors after its first without the
    constructor's checks: each equals the one the constructor makes of the
    same stages (a GSD of the same float), and a moved parameter moves it."""
    data = [edge_data(e, 0, None) for e in edges[:1]]
    model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0), data)
    u = model.initial_vector()[: model.n_free]
    first, again = model.sensor(u), model.sensor(u)
    fresh = im.Sensor(1.0, list(again.stages))
    assert again == first == fresh and type(again.gsd_m) is float and again.stages is not first.stages
    assert again.mtf_nyquist() == fresh.mtf_nyquist()
    moved = u.copy()
    moved[0] *= 1.1
    assert model.sensor(moved) != first and model.sensor(moved).stages[1] is first.stages[1]
