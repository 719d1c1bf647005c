"""The exact point-array renderer (imgmtf.sensor.points) against the closed
form of Gaussian optics and a square pixel: the erf differences of the
Gaussian integrated over each pixel."""
import math

import numpy as np
import pytest
from scipy.special import erf

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.sensor.points import PointArray, quarter_pixel_offsets, render_points
from imgmtf.sensor.stages import Detector, GaussianOptics

SENSOR = im.Sensor(stages=[GaussianOptics(0.45, 0.55), Detector(1.0, 1.0)])


def pixel_gaussian(n, centre, sigma):
    """A unit Gaussian integrated over unit pixels centred at ``n``."""
    root = sigma * math.sqrt(2.0)
    return 0.5 * (erf((n + 0.5 - centre) / root) - erf((n - 0.5 - centre) / root))


def test_points_are_the_psf_integrated_over_each_pixel_exactly():
    chip = render_points(SENSOR, PointArray(4, 4, spacing_px=12.0), 64, bits=None)
    n = np.arange(64)
    expected = 200.0 + 1000.0 * sum(np.outer(pixel_gaussian(n, y, 0.55), pixel_gaussian(n, x, 0.45))
                                    for x, y in chip.centres_px)
    assert np.abs(chip.image - expected).max() < 1e-9


def test_a_square_is_the_pixel_gaussian_of_a_wider_box():
    # a 1 px square through a Gaussian and a 1 px pixel: per axis, the Gaussian convolved with a triangle
    chip = render_points(SENSOR, PointArray(1, 1, size_px=1.0, low_dn=1000.0, high_dn=100.0,
                                            offsets_px=((0.25, 0.5),)), 24, bits=None)
    (x, y), = chip.centres_px
    u = np.linspace(-1.0, 1.0, 4001)
    tri = (1.0 - np.abs(u)) * (u[1] - u[0])
    n = np.arange(24)

    def axis(centre, sigma):      # the square's box and the pixel's make a triangle; the Gaussian blurs it
        d = n[:, None] - centre - u[None, :]
        return (np.exp(-0.5 * (d / sigma) ** 2) / (sigma * math.sqrt(2 * math.pi))) @ tri
    expected = 1000.0 - 900.0 * np.outer(axis(y, 0.55), axis(x, 0.45))
    assert np.abs(chip.image - expected).max() < 1e-3


def test_truth_and_offsets():
    chip = render_points(SENSOR, PointArray(2, 2, spacing_px=10.0), 32, bits=16, noise_std_dn=1.0, seed=2)
    assert chip.image.dtype == np.uint16
    assert chip.true_mtf(0.5, "across") == pytest.approx(math.exp(-2 * math.pi ** 2 * 0.45 ** 2 / 4) * 2 / math.pi)
    assert chip.true_mtf(0.5, "along") == pytest.approx(math.exp(-2 * math.pi ** 2 * 0.55 ** 2 / 4) * 2 / math.pi)
    assert chip.provenance()["target"]["kind"] == "points"
    assert len({tuple(o) for o in quarter_pixel_offsets(4, 4)}) == 16


@pytest.mark.parametrize("array", [dict(spacing_px=1.0), dict(size_px=-1.0), dict(rows=0),
                                   dict(offsets_px=((0.0, 0.0),))])
def test_bad_arrays_are_refused(array):
    with pytest.raises(ParameterError):
        PointArray(**array)


def test_an_array_too_large_for_the_chip_is_refused():
    with pytest.raises(ParameterError, match="does not fit"):
        render_points(SENSOR, PointArray(4, 4, spacing_px=12.0), 30)
