import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ImageContentError, TargetNotFoundError
from imgmtf.estimate.detection import find_edge, parallel_within


@pytest.mark.parametrize("angle", [2.0, 6.0, -17.0, 38.0, 84.0, -70.0])
def test_finds_the_edge_within_a_degree(angle):
    img = im.render(im.Sensor(), im.Target("edge", angle), 80, noise_std_dn=20, seed=1).image
    line, rival = find_edge(img.astype(float))
    assert rival is None
    diff = (line.theta_deg - angle + 90) % 180 - 90
    assert abs(diff) <= 1.0


def test_a_second_edge_is_reported_as_a_rival():
    img = im.render(im.Sensor(), im.Target("pulse", 6.0, 200, 1200, 0, 8.0), 60).image
    line, rival = find_edge(img.astype(float))
    assert rival is not None
    assert parallel_within(line, rival, img.shape, 9.0) and not parallel_within(line, rival, img.shape, 7.0)


def test_noise_only_and_flat_images():
    noise = np.random.default_rng(0).normal(500, 20, (60, 60))
    with pytest.raises(TargetNotFoundError):
        find_edge(noise)
    with pytest.raises(ImageContentError, match="flat"):
        find_edge(np.full((40, 40), 7.0))
