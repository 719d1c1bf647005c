"""estimate/fit/responses.py: the responses of shifted sensors on one grid."""
import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.estimate.fit.responses import (
    KEPT_TRANSFERS,
    EdgeResponses,
    StackedResponses,
    esf_changes,
    shared_transfers,
)
from imgmtf.sensor import stages as st


def test_changes_are_the_difference_of_the_two_edge_responses():
    """On one grid the change is exactly the difference of the responses;
    against each sensor's own line response, to their 1e-7."""
    sensor = im.Sensor()
    wider = im.Sensor(1.0, [st.GaussianOptics(0.41, 0.39), *sensor.stages[1:]])
    response, esf, lsf = EdgeResponses(6.0, 1.0, 30.0).changes(sensor, [wider])
    d = np.linspace(-30, 30, 601)
    change = esf_changes(response, esf, lsf, d)[0]
    exact = wider.line_response(6.0, reach_px=30.0).esf(d) - sensor.line_response(6.0, reach_px=30.0).esf(d)
    np.testing.assert_allclose(change, exact, atol=1e-7)
    np.testing.assert_allclose(response.esf(d), sensor.line_response(6.0, reach_px=30.0).esf(d), atol=1e-7)


def test_the_derivative_by_a_gaussian_width_is_its_closed_form():
    """ESF = Phi(x / s): d ESF / d s = -x / s^2 phi(x / s)."""
    s, h = 0.6, 1e-6
    sensors = [im.Sensor(1.0, [st.GaussianOptics(w, w)]) for w in (s, s + h)]
    response, esf, lsf = EdgeResponses(0.0, 1.0, 40.0).changes(sensors[0], sensors[1:])
    d = np.linspace(-5, 5, 201)
    derivative = esf_changes(response, esf, lsf, d)[0] / h
    exact = -d / s**2 * np.exp(-0.5 * (d / s) ** 2) / math.sqrt(2 * math.pi)
    np.testing.assert_allclose(derivative, exact, atol=1e-5)


def test_the_grid_reaches_the_samples_only_for_a_cauchy_tail():
    """Without diffraction the grid covers the PSF's support (beyond it the
    reference is the response); with it, the samples' reach."""
    gaussian = EdgeResponses(0.0, 1.0, 60.0).response(im.Sensor())
    assert -gaussian.start_px < 30
    assert gaussian.esf(60.0) == pytest.approx(1.0, abs=1e-12)
    airy = EdgeResponses(0.0, 1.0, 60.0).response(im.Sensor(1.0, [st.Diffraction(8.0)]))
    assert -airy.start_px >= 60


def same_response(a, b):
    return (a.start_px, a.step_px, a.reference) == (b.start_px, b.step_px, b.reference) and np.array_equal(
        a.esf_remainder, b.esf_remainder) and np.array_equal(a.lsf_remainder, b.lsf_remainder)


def fit_like_sensors():
    """The sensors a fit asks for, in its order: residuals at a point, the
    Jacobian's shifts there, a trial point, a point whose grid is twice as
    long (wider optics), a detector held throughout, diffraction (a Cauchy
    grid reaching the samples, its step set by the f-number)."""
    detector = st.Detector(1.0, 1.0)
    for sigma, f_number in ((0.4, None), (0.45, None), (0.45, None), (3.0, None), (0.5, 8.0), (0.5, 9.0)):
        base = [st.GaussianOptics(sigma, sigma), detector]
        if f_number:
            base.append(st.Diffraction(f_number))
        shifts = [[st.GaussianOptics(sigma * 1.001, sigma), *base[1:]], [base[0], st.Detector(1.001, 1.0), *base[2:]]]
        yield im.Sensor(1.0, base), [im.Sensor(1.0, stages) for stages in shifts]


def test_kept_responses_are_those_made_afresh_bit_for_bit():
    """One edge's responses and changes over a fit's evaluations, its grid,
    transfers and last response kept, equal those of a new EdgeResponses
    for each, bit for bit; and the responses are the sensor's own made
    independently (Sensor.line_response, its transfer Sensor.normal_transfer;
    the grid reaching the samples only for a Cauchy tail), bit for bit."""
    edge = EdgeResponses(6.0, 1.0, 25.0)
    for sensor, shifted in fit_like_sensors():
        fresh, fresh_esf, fresh_lsf = EdgeResponses(6.0, 1.0, 25.0).changes(sensor, shifted)
        assert same_response(edge.response(sensor), fresh)
        response, esf, lsf = edge.changes(sensor, shifted)
        assert response is edge.response(sensor)
        assert np.array_equal(esf, fresh_esf) and np.array_equal(lsf, fresh_lsf)
        own = sensor.line_response(6.0, 1.0, reach_px=25.0 if sensor.tail_length_m() > 0 else 0.0)
        assert same_response(response, own)
    assert edge.changes(sensor, [])[1].shape == (0, response.esf_remainder.size)


def test_an_edge_keeps_its_base_stages_transfers_not_a_shifts(monkeypatch):
    """Each stage's transfer on the grid is computed once: the held
    detector's once for all evaluations on one grid, a shifted copy's own stage once
    and not kept; at most KEPT_TRANSFERS are kept."""
    calls = []

    def counted(transfer):
        def on_grid(stage, fx, fy, gsd):      # the grid's, not line_grid's at one frequency
            if np.size(fx) > 1:
                calls.append(stage)
            return transfer(stage, fx, fy, gsd)
        return on_grid
    for cls in (st.GaussianOptics, st.Detector):
        monkeypatch.setattr(cls, "transfer", counted(cls.transfer))
    edge = EdgeResponses(6.0, 1.0, 25.0)
    detector = st.Detector(1.0, 1.0)
    for sigma in (0.4, 0.41, 0.42):
        sensor = im.Sensor(1.0, [st.GaussianOptics(sigma, sigma), detector])
        edge.response(sensor)
        edge.changes(sensor, [im.Sensor(1.0, [st.GaussianOptics(sigma + 1e-4, sigma), detector])] * 2)
    assert calls.count(detector) == 1
    assert calls.count(st.GaussianOptics(0.41, 0.41)) == 1
    assert calls.count(st.GaussianOptics(0.41 + 1e-4, 0.41)) == 2      # a shift's own stage: not kept
    for sigma in np.linspace(0.4, 0.45, 3 * KEPT_TRANSFERS):
        edge.response(im.Sensor(1.0, [st.GaussianOptics(sigma, sigma), detector]))
    assert len(edge._transfers) == KEPT_TRANSFERS
    assert (detector, 1.0) in edge._transfers                           # used at every evaluation


def test_transfers_shared_by_edges_give_each_edge_its_own_responses_bit_for_bit():
    """Stages' transfers computed for several edges at once (shared_transfers)
    give each edge the responses and changes it makes alone, bit for bit,
    over a fit's sensors (a grid twice as long included: what was computed
    on the old grid is not read on the new)."""
    angles = (3.0, 40.0, 84.0)
    shared = [EdgeResponses(a, 1.0, 25.0) for a in angles]
    alone = [EdgeResponses(a, 1.0, 25.0) for a in angles]
    for sensor, shifted in fit_like_sensors():
        given = shared_transfers(shared, sensor.stages, sensor.gsd_m)
        for edge, own, g in zip(shared, alone, given):
            assert same_response(edge.response(sensor, g), own.response(sensor))
        given = shared_transfers(shared, [s for other in shifted for s in other.stages], sensor.gsd_m)
        assert any(given)
        for edge, own, g in zip(shared, alone, given):
            _, esf, lsf = edge.changes(sensor, shifted, g)
            _, own_esf, own_lsf = own.changes(sensor, shifted)
            assert np.array_equal(esf, own_esf) and np.array_equal(lsf, own_lsf)


def test_stacked_esf_is_each_responses_own_bit_for_bit():
    responses = [im.Sensor().line_response(angle, reach_px=reach) for angle, reach in ((5.0, 0.0), (80.0, 30.0))]
    stacked = StackedResponses(responses, [3, 2])
    d = np.array([-0.5, 0.25, 40.0, 0.5, -3.0])
    np.testing.assert_array_equal(stacked.esf(d), [*responses[0].esf(d[:3]), *responses[1].esf(d[3:])])


def test_edges_responses_together_are_each_edges_alone():
    """Edges' responses made with one inverse FFT per kind of grid (reaches
    that make grids of two sizes; a Cauchy tail too) are each edge's own
    response, bit for bit, and kept as the next evaluation's start."""
    from imgmtf.estimate.fit.responses import edges_responses
    for sensor in (im.Sensor(), im.Sensor(1.0, [st.Diffraction(), st.Detector(1.0, 1.0)])):
        edges = [EdgeResponses(angle, 1.0, reach) for angle, reach in ((5.0, 10.0), (80.0, 60.0), (-7.0, 12.0))]
        together = edges_responses(edges, sensor)
        assert len({r.esf_remainder.size for r in together}) == 2 or sensor.tail_length_m() == 0
        for edge, response in zip(edges, together):
            alone = EdgeResponses(edge.angle_deg, 1.0, edge.reach_px).response(sensor)
            assert response.reference == alone.reference and response.start_px == alone.start_px
            assert np.array_equal(response.esf_remainder, alone.esf_remainder)
            assert np.array_equal(response.lsf_remainder, alone.lsf_remainder)
            assert edge.response(sensor) is response
