"""estimate/fit/angles.py: many edges' responses interpolated in angle."""
import numpy as np

import imgmtf as im
from imgmtf.estimate.fit.angles import AngleGroup, angle_groups, chebyshev_nodes, lagrange_weights
from imgmtf.estimate.fit.responses import EdgeResponses, esf_changes
from imgmtf.sensor import stages as st


def test_lagrange_weights_reproduce_a_polynomial_of_the_nodes_degree():
    nodes = chebyshev_nodes(2.0, 9.0, 5)
    at = np.array([2.0, 3.3, 9.0, 6.1])
    weights = lagrange_weights(nodes, at)
    np.testing.assert_allclose(weights @ (nodes**4 - 3 * nodes), at**4 - 3 * at, rtol=1e-12)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, rtol=1e-14)


def test_groups_split_at_the_span_and_leave_small_ones_out():
    angles = [1.0, 30.0, 2.0, 25.0, 40.0, 3.0, 31.0]
    assert angle_groups(angles, [1.0] * 7, max_span_deg=10.0, min_edges=2) == [[0, 2, 5], [3, 1, 6]]
    assert angle_groups(angles, [1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 1.0], max_span_deg=10.0, min_edges=2) == [
        [0, 5], [3, 1, 6]]


def test_interpolated_responses_and_changes_are_each_edges_own_within_1e_9():
    """Against each edge's own response on its own grid (itself exact to
    1e-7), over a span of 18 deg; a Cauchy tail (diffraction) too."""
    angles = [95.0, 104.2, 113.0]
    d = np.linspace(-12.0, 12.0, 97)
    for sensor in (im.Sensor(), im.Sensor(1.0, [st.Diffraction(), st.Detector(1.0, 1.0)])):
        wider = im.Sensor(1.0, [st.Detector(1.1, 0.9) if s.name == "detector" else s for s in sensor.stages])
        group = AngleGroup(angles, 1.0, 12.0)
        responses = group.responses(sensor)
        esf, lsf = (group.combine(nodes) for nodes in group.node_changes(sensor, [wider]))
        for j, angle in enumerate(angles):
            own, own_esf, own_lsf = EdgeResponses(angle, 1.0, 12.0).changes(sensor, [wider])
            np.testing.assert_allclose(responses[j].esf(d), own.esf(d), atol=1e-9)
            np.testing.assert_allclose(group.responses(sensor)[j].lsf(d), own.lsf(d), atol=1e-8)
            np.testing.assert_allclose(esf_changes(responses[j], esf[j], lsf[j], d),
                                       esf_changes(own, own_esf, own_lsf, d), atol=1e-9)
