"""The pipeline's first stage: the chip prepared, and what it says of its pixels."""
import math

import numpy as np
import pytest

from imgmtf.errors import ParameterError
from imgmtf.estimate.chip import prepare_chip
from imgmtf.estimate.settings import make_settings


def step_chip(dtype=np.uint16, high=1200):
    image = np.full((40, 50), 20, dtype)
    image[:, 25:] = high
    return image


def test_the_chip_is_cropped_and_knows_its_limits_quantum_and_noise():
    chip = prepare_chip(step_chip(), make_settings(), roi=(5, 2, 40, 30), gsd_m=2.0, track_azimuth_deg=None)
    assert chip.roi == (5, 2, 40, 30) and chip.pixels.shape == (30, 40)
    assert chip.limits == (0.0, 65535.0) and chip.quantum_dn == 1.0
    assert chip.noise_dn < 1e-9 and chip.gsd_m == 2.0 and chip.track_azimuth_deg is None
    assert [check.reason for check in chip.checks] == ["fill"] and chip.checks[0].passed
    assert chip.warnings == () and chip.left_out_px == {}


def test_nodata_and_isolated_outliers_are_left_out_and_said():
    image = step_chip().astype(float)
    image[3, 4] = np.nan
    image[10, 8] = 5000.0                       # a hot pixel on the dark side
    chip = prepare_chip(image, make_settings())
    assert chip.left_out_px == {"nodata_px": 1, "outlier_px": 1}
    assert math.isnan(chip.pixels[10, 8]) and len(chip.warnings) == 2


def test_a_transfer_curve_linearises_the_values_and_the_limits():
    chip = prepare_chip(step_chip(np.uint8, 200), make_settings(transfer="gamma:2.0"))
    assert chip.pixels[0, -1] == pytest.approx(255 * (200 / 255) ** 2)
    assert chip.limits == (0.0, 255.0)
    assert chip.warnings[-1].startswith("the values were linearised (gamma")


def test_a_saturation_pair_is_checked():
    assert prepare_chip(step_chip(), make_settings(), saturation=(10, 4000)).limits == (10.0, 4000.0)
    for bad in ((5, 1), "x", (0, math.inf)):
        with pytest.raises(ParameterError, match="saturation"):
            prepare_chip(step_chip(), make_settings(), saturation=bad)
