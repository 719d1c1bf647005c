"""estimate/fit: where a fit starts (a Guess pooled from fits of subsets)
and how its Jacobian is stored change no fitted value."""
import numpy as np
import pytest

import imgmtf as im
from imgmtf.estimate.fit import Guess, fit_edges, fitted_coordinates, pooled_guess
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


def test_pooled_guess_weights_each_fit_by_its_precision_and_skips_unknown_variances():
    guess = pooled_guess([{"a": (1.0, 1.0), "b": (5.0, np.nan)}, {"a": (4.0, 2.0)}], [(0.0, 1.0, 0.1), None])
    assert guess.coordinates == {"a": pytest.approx((1.0 + 4.0 / 2) / 1.5)}
    assert guess.nuisance == ((0.0, 1.0, 0.1), None)


def test_a_fit_started_from_its_halves_ends_where_a_fit_from_the_defaults_does(edges):
    """The scene's fit from its targets' (scan's fit_targets): the same optimum."""
    halves = [fit_edges(edges[:2], stages="optics,detector"), fit_edges(edges[2:], stages="optics,detector")]
    ends = [(*e.levels_dn, e.offset_px) for fit in halves for e in fit.edges]
    cold = fit_edges(edges, stages="optics,detector")
    warm = fit_edges(edges, stages="optics,detector", guess=pooled_guess([fitted_coordinates(f) for f in halves], ends))
    assert [p.status for p in warm.parameters] == [p.status for p in cold.parameters]
    for a, b in zip(warm.parameters, cold.parameters):
        if a.status == "fitted":
            assert abs(a.value - b.value) < 0.05 * a.standard_error
    # a guess moves where the fit starts, never what it holds
    held = fit_edges(edges, stages="optics,detector", hold="detector",
                     guess=Guess({"detector.width_x_m": 2.0, "detector.width_y_m": 2.0}))
    assert {p.key: p.value for p in held.parameters if p.stage == "detector"} == {
        "detector.width_x_m": 1.0, "detector.width_y_m": 1.0}


def test_the_sparse_jacobian_holds_exactly_the_dense_ones_entries(edges, monkeypatch):
    data = [edge_data(e, k, None) for k, e in enumerate(edges)]
    model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0), data)
    z = model.initial_vector()
    dense = model.jacobian(z)
    monkeypatch.setattr(fit_model, "DENSE_EDGES", 0)
    sparse = model.jacobian(z)
    assert sparse.shape == dense.shape and sparse.nnz == dense.shape[0] * (model.n_free + 3)
    np.testing.assert_array_equal(sparse.toarray(), dense)
