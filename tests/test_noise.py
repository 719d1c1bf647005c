import numpy as np
import pytest

from imgmtf.errors import ParameterError
from imgmtf.sensor.noise import GroundNoise, add_system_noise


def test_ground_noise_variance_is_sum_of_layers():
    field = GroundNoise().sample((600, 600), np.random.default_rng(3))
    # the coarse layers have few independent grains, so allow 10 %
    assert field.var() == pytest.approx(2000.0, rel=0.10)


def test_layer_is_constant_over_grains():
    layer = GroundNoise().layer(5, (50, 50), np.random.default_rng(0))
    values_per_block = {len(np.unique(layer[i:i + 1, :])) for i in range(50)}
    assert max(values_per_block) <= 11            # 50 px of 5-px grains, offset: at most 11
    assert layer.var() == pytest.approx(100.0, rel=0.5)


def test_seeded_noise_is_reproducible():
    a = GroundNoise().sample((64, 64), np.random.default_rng(7))
    b = GroundNoise().sample((64, 64), np.random.default_rng(7))
    assert np.array_equal(a, b)


def test_system_noise_std_and_errors():
    out = add_system_noise(np.zeros((400, 400)), 7.0, np.random.default_rng(1))
    assert out.std() == pytest.approx(7.0, rel=0.02)
    with pytest.raises(ParameterError):
        add_system_noise(np.zeros(3), -1.0, np.random.default_rng(1))
    with pytest.raises(ParameterError):
        GroundNoise(layers=0)
