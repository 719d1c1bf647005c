import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError


def test_signed_distance_follows_the_normal():
    t = im.Target("edge", 30.0, offset_px=0.5)
    a = math.radians(30.0)
    d = t.signed_distance(np.array([2.0 + math.cos(a)]), np.array([3.0 + math.sin(a)]), (2.0, 3.0))
    assert d[0] == pytest.approx(0.5)


def test_pulse_values_are_the_difference_of_two_edges():
    def ramp(d):  # a 2 px linear edge response
        return np.clip(d / 2 + 0.5, 0, 1)
    pulse = im.Target("pulse", 6.0, 100.0, 300.0, width_px=3.0)
    d = np.array([-5.0, -1.5, 0.0, 1.5, 5.0])
    assert np.allclose(pulse.image_values(d, ramp), [100.0, 200.0, 100.0 + 200.0 * 1.0, 200.0, 100.0])
    edge = im.Target("edge", 6.0, 100.0, 300.0)
    assert np.allclose(edge.image_values(d, ramp), 100.0 + 200.0 * ramp(d))


def test_numpy_scalars_are_accepted():
    t = im.Target("edge", np.float32(6), np.int64(10), np.float64(500))
    assert t.angle_deg == pytest.approx(6.0) and type(t.angle_deg) is float
    assert t == im.Target("edge", 6.0, 10.0, 500.0)


@pytest.mark.parametrize("kwargs, message", [
    (dict(kind="bar"), "kind"),
    (dict(angle_deg=95.0), "angle must be in"),
    (dict(angle_deg=-90.0), "angle must be in"),
    (dict(kind="pulse", width_px=-1.0), "pulse width must be > 0"),
    (dict(kind="edge", width_px=2.0), "no width"),
    (dict(low_dn=float("nan")), "finite"),
    (dict(angle_deg="6"), "finite number"),
    (dict(angle_deg=True), "finite number"),
])
def test_invalid_targets(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        im.Target(**kwargs)
