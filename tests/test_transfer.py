"""Transfer curves: gamma-encoded values linearised before measuring give
the linear edge's MTF; as stored they read low."""
import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.transfer import Transfer, full_scale, parse_transfer

from conftest import exact_edge_chip, gaussian_pixel_transfer

H = gaussian_pixel_transfer(0.5, 6.0)


def encoded(name: str, dtype=np.uint8) -> np.ndarray:
    """An exact linear edge (10 % to 80 % of full scale) encoded with the
    inverse of ``name``'s decoding, rounded to ``dtype``."""
    linear = exact_edge_chip(H, 6.0, offset=0.2, low=0.1, high=0.8, dtype=np.float64)
    grid = np.linspace(0.0, 1.0, 400001)
    code = np.interp(linear, parse_transfer(name).linearise(grid, 1.0), grid)
    return np.rint(code * full_scale(dtype)).astype(dtype)


@pytest.mark.parametrize("name", ["srgb", "gamma:2.2"])
def test_a_gamma_encoded_edge_linearised_reads_its_linear_mtf(name):
    chip = encoded(name)
    as_stored = im.measure_edge(chip)
    linearised = im.measure_edge(chip, transfer=name)
    assert as_stored.mtf_nyquist < H(0.5) - 0.015                     # the encoding's error
    assert abs(linearised.mtf_nyquist - H(0.5)) < 0.006                 # 8-bit steps, decoded unevenly
    assert linearised.params["transfer"] == name and as_stored.params["transfer"] == "linear"
    assert any("linearised" in w for w in linearised.warnings)


def test_the_curves_and_their_names():
    srgb = parse_transfer("sRGB")
    v = np.array([0.0, 0.04045 * 255, 0.5 * 255, 255.0])
    assert np.allclose(srgb.linearise(v, 255.0), [0.0, 0.04045 / 12.92 * 255, ((0.5 + 0.055) / 1.055) ** 2.4 * 255,
                                                   255.0])
    assert np.allclose(parse_transfer("gamma:2").linearise(np.array([0.5]), 1.0), [0.25])
    assert parse_transfer(None) == Transfer() and str(parse_transfer("gamma:2.2")) == "gamma:2.2"
    assert full_scale(np.uint16) == 65535.0 and full_scale(np.float32) == 1.0
    for bad in ("log", "gamma:", "gamma:9", 2.2):
        with pytest.raises(ParameterError):
            parse_transfer(bad)
    with pytest.raises(ParameterError):
        im.measure_edge(encoded("srgb"), transfer="cubic")
