import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.sensor.targets import cell_coverage


@pytest.mark.parametrize("angle", [0.0, 6.0, 30.0, 45.0, 84.0, -20.0])
def test_cell_coverage_is_area_exact(angle):
    """Cells of a fine grid covering a large square: the covered fractions
    add up to the exact area on the positive side of the line."""
    a = math.radians(angle)
    c, s = math.cos(a), math.sin(a)
    n = 200
    centres = np.arange(n) - (n - 1) / 2
    # line through (0.3, -0.2): area of the square [-n/2, n/2]^2 where d > 0
    d = (centres[None, :] - 0.3) * c + (centres[:, None] + 0.2) * s
    total = cell_coverage(d, abs(c), abs(s)).sum()
    # exact area by fine sampling is too slow; use the 1-D integral of the chord
    t = np.linspace(-n / 2, n / 2, 200001)
    if abs(s) > 1e-9:
        # for each x, the y range above/below the line inside the square
        y_line = 0.2 * -1 + (0.3 - t) * c / s
        inside = np.clip(n / 2 - y_line, 0, n) if s > 0 else np.clip(y_line + n / 2, 0, n)
    else:
        inside = np.where((t - 0.3) * c > 0, n, 0.0)
    exact = np.trapezoid(inside, t)
    assert total == pytest.approx(exact, abs=1e-3 * n)


def test_cell_coverage_limits_and_symmetry():
    t = np.array([-5.0, 0.0, 5.0])
    for c, s in [(1.0, 0.0), (0.8, 0.6), (math.sqrt(0.5), math.sqrt(0.5))]:
        assert np.allclose(cell_coverage(t, c, s), [0.0, 0.5, 1.0])
    t = np.linspace(-1, 1, 41)
    v = cell_coverage(t, 0.8, 0.6)
    assert np.allclose(v + v[::-1], 1.0)
    assert np.all(np.diff(v) >= -1e-12)
    # a vertical line at distance 0.25 from a cell centre covers 3/4 of it
    assert cell_coverage(np.array([0.25]), 1.0, 0.0)[0] == pytest.approx(0.75)


def test_scene_pulse_has_width_times_height():
    t = im.Target("pulse", 6.0, 0.0, 1.0, 0.0, 2.5)
    scene = t.scene((41, 41), 10, 0)
    # one row of cells crosses the bar: its covered length is width / cos(a)
    assert scene[200].sum() / 10 == pytest.approx(2.5 / math.cos(math.radians(6.0)), rel=1e-6)


@pytest.mark.parametrize("kwargs, message", [
    (dict(kind="bar"), "kind"),
    (dict(angle_deg=95.0), "angle must be in"),
    (dict(angle_deg=-90.0), "angle must be in"),
    (dict(kind="pulse", width_px=-1.0), "pulse width must be > 0"),
    (dict(kind="edge", width_px=2.0), "no width"),
    (dict(low_dn=float("nan")), "finite"),
])
def test_invalid_targets(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        im.Target(**kwargs)
