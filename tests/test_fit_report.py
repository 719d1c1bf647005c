"""estimate/fit/report: what the report computes for all edges at once is
each edge's own."""

import imgmtf as im
from imgmtf.estimate.fit import angles
from imgmtf.estimate.fit import report as fit_report
from imgmtf.estimate.fit.data import edge_data
from imgmtf.estimate.fit.model import Model, initial_stages
from imgmtf.estimate.fit.report import MISFIT_GRID_PX, misfit_reaches, transition_reach


def test_the_misfit_tests_reaches_are_each_edges_own(monkeypatch):
    """Four edges whose responses are interpolated in angle (groups of
    two, as a scene's): their transitions' reaches, from one side-by-side
    evaluation, are each response's own to the bit."""
    sensor = im.Sensor(1.0, [im.sensor.stages.GaussianOptics(0.5, 0.4), im.sensor.stages.Detector(1.0, 1.0)])
    chips = [im.render(sensor, im.Target("edge", angle), 40, noise_std_dn=40.0, seed=k).image
             for k, angle in enumerate((5.0, 83.0, -7.0, -84.0))]
    monkeypatch.setattr(angles, "MIN_EDGES", 2)
    monkeypatch.setattr(fit_report, "STACKED_REACH_EDGES", 1)
    model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0),
                  [edge_data(chip, k, None) for k, chip in enumerate(chips)])
    assert model.groups
    responses = model.responses(model.initial_vector()[: model.n_free])
    own = [float(transition_reach(r.esf(MISFIT_GRID_PX))) for r in responses]
    assert misfit_reaches(model, responses).tolist() == own
    assert all(3.0 <= reach < 10.0 for reach in own)
