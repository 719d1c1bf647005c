"""Scenes with a four-quadrant target: away from the centre each half-edge
is the renderer's exact edge."""
import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.sensor.scenes import QuadrantTarget, render_quadrants, texture


def test_a_half_edge_away_from_the_centre_is_the_exact_rendered_edge():
    sensor, size = im.Sensor(), 101
    target = QuadrantTarget((50.0, 50.0), 12.0, (1200.0, 200.0, 900.0, 500.0), 45.0)
    scene = render_quadrants(sensor, (size, size), target)
    # where d2 > 0 the quadrants are 1 (d1 > 0, 1200 DN) and 2 (d1 < 0, 200 DN): an edge at 12 deg
    edge = im.render(sensor, im.Target("edge", 12.0, 200.0, 1200.0), size).image.astype(float)
    y, x = np.mgrid[0:size, 0:size].astype(float)
    a2 = math.radians(target.normals_deg()[1])
    d1 = (x - 50) * math.cos(math.radians(12.0)) + (y - 50) * math.sin(math.radians(12.0))
    d2 = (x - 50) * math.cos(a2) + (y - 50) * math.sin(a2)
    far = (d2 > 8) & (d2 < 45 - 8) & (np.abs(d1) < 45 - 8)
    assert far.sum() > 500
    assert np.abs(scene.image[far] - edge[far]).max() <= 1.0
    chip = im.render(sensor, im.Target("edge", 12.0), 8)
    assert scene.true_mtf(0.5, 12.0) == pytest.approx(float(chip.true_mtf(0.5)))


def test_fill_cuts_the_target_out_and_the_half_edges_reach_its_border():
    target = QuadrantTarget((50.0, 50.0), 16.8, half_size_px=40.0)
    scene = render_quadrants(im.Sensor(), (101, 101), target, field_dn=3000 + texture((101, 101), 300, seed=2),
                             fill=True, noise_std_dn=20.0, seed=3)
    assert scene.image[0, 0] == 0 and scene.image[50, 50] > 0 and (scene.image == 0).mean() > 0.25
    ends = [(h["x1_px"], h["y1_px"]) for h in target.half_edges()]
    assert [round(math.dist(e, (50, 50)), 6) for e in ends] == [40.0] * 4
    assert target.normals_deg() == pytest.approx((16.8, -73.2))


def test_texture_has_the_asked_spread_and_bad_targets_are_refused():
    assert float(texture((128, 128), 50.0, seed=0).std()) == pytest.approx(50.0)
    with pytest.raises(ParameterError):
        QuadrantTarget((50.0, float("nan")))
    with pytest.raises(ParameterError):
        QuadrantTarget((50.0, 50.0), half_size_px=3.0)
