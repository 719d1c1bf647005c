"""estimate/fit/responses.py: the responses of shifted sensors on one grid."""
import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.estimate.fit.responses import esf_changes, line_responses
from imgmtf.sensor import stages as st


def test_changes_are_the_difference_of_the_two_edge_responses():
    """On one grid the change is exactly the difference of the responses;
    against each sensor's own line response, to their 1e-7."""
    sensor = im.Sensor()
    wider = im.Sensor(1.0, [st.GaussianOptics(0.41, 0.39), *sensor.stages[1:]])
    response, esf, lsf = line_responses([sensor, wider], 6.0, 1.0, reach_px=30.0)
    d = np.linspace(-30, 30, 601)
    change = esf_changes(response, esf, lsf, d)[0]
    exact = wider.line_response(6.0, reach_px=30.0).esf(d) - sensor.line_response(6.0, reach_px=30.0).esf(d)
    np.testing.assert_allclose(change, exact, atol=1e-7)
    np.testing.assert_allclose(response.esf(d), sensor.line_response(6.0, reach_px=30.0).esf(d), atol=1e-7)


def test_the_derivative_by_a_gaussian_width_is_its_closed_form():
    """ESF = Phi(x / s): d ESF / d s = -x / s^2 phi(x / s)."""
    s, h = 0.6, 1e-6
    sensors = [im.Sensor(1.0, [st.GaussianOptics(w, w)]) for w in (s, s + h)]
    response, esf, lsf = line_responses(sensors, 0.0, 1.0, reach_px=40.0)
    d = np.linspace(-5, 5, 201)
    derivative = esf_changes(response, esf, lsf, d)[0] / h
    exact = -d / s**2 * np.exp(-0.5 * (d / s) ** 2) / math.sqrt(2 * math.pi)
    np.testing.assert_allclose(derivative, exact, atol=1e-5)


def test_the_grid_reaches_the_samples_only_for_a_cauchy_tail():
    """Without diffraction the grid covers the PSF's support (beyond it the
    reference is the response); with it, the samples' reach."""
    gaussian, _, _ = line_responses([im.Sensor()], 0.0, 1.0, reach_px=60.0)
    assert -gaussian.start_px < 30
    assert gaussian.esf(60.0) == pytest.approx(1.0, abs=1e-12)
    airy, _, _ = line_responses([im.Sensor(1.0, [st.Diffraction(8.0)])], 0.0, 1.0, reach_px=60.0)
    assert -airy.start_px >= 60
