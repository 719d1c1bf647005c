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


def test_linearisation_scales_the_noise_by_the_curves_slope():
    from imgmtf.transfer import noise_gain
    gamma = parse_transfer("gamma:2.2")
    u = np.array([0.01, 0.2, 0.9])
    # d(V^G)/dV at V = u^(1/G): G u^((G-1)/G)
    assert noise_gain(gamma, 255 * u, 255.0) == pytest.approx(2.2 * u ** (1.2 / 2.2))
    # the sRGB curve's slope by finite differences of its own decoding
    srgb, v = parse_transfer("srgb"), np.array([0.02, 0.3, 0.95])
    linear = srgb.linearise(v, 1.0)
    slope = (srgb.linearise(v + 1e-6, 1.0) - srgb.linearise(v - 1e-6, 1.0)) / 2e-6
    assert noise_gain(srgb, linear, 1.0) == pytest.approx(slope, rel=1e-4)
    assert noise_gain(parse_transfer("linear"), u, 1.0) == pytest.approx(1.0)


def test_a_clean_low_contrast_camera_edge_linearised_is_measured_and_a_textured_side_is_not():
    # camera noise (3 DN) added to the sRGB-encoded values: linearised, it grows with the level, and the
    # bright side's scatter is its own noise, not texture (judged against the chip's one noise, refused)
    linear = exact_edge_chip(H, 6.0, offset=0.2, low=0.01, high=0.1, dtype=np.float64, shape=(80, 80))
    code = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055) * 255
    noisy = code + np.random.default_rng(1).normal(0, 3.0, code.shape)
    r = im.measure_edge(np.clip(np.rint(noisy), 0, 255).astype(np.uint8), transfer="srgb")
    assert abs(r.mtf_nyquist - H(0.5)) < 0.03 and not any(c.failed for c in r.checks)
    # real texture on the bright side (in light, 12 % of the contrast) stays refused
    texture = 1 + 0.12 * (0.1 - 0.01) / 0.1 * np.random.default_rng(2).standard_normal(linear.shape)
    lit = np.where(linear > 0.055, linear * texture, linear)
    code = np.where(lit <= 0.0031308, 12.92 * lit, 1.055 * lit ** (1 / 2.4) - 0.055) * 255
    with pytest.raises(im.ImgmtfError) as info:
        im.measure_edge(np.clip(np.rint(code + np.random.default_rng(1).normal(0, 3.0, code.shape)), 0, 255)
                        .astype(np.uint8), transfer="srgb")
    assert info.value.reason == "non-uniform" and "texture" in str(info.value)
