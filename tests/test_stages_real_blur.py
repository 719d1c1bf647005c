"""The stages real L0R blur needs (diffusion, halo, lag): their transfers
against closed forms, their spatial functions against their analytic
LSFs, and the one-sided lag's side and sign through a line response."""
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.sensor import stages as st

F = np.array([0.0, 0.1, 0.25, 0.5, 0.9])


def test_diffusion_is_a_lorentzian_per_axis():
    d = st.Diffusion(0.5, 0.8)
    assert_allclose(d.transfer(F, 0, 1.0), 1 / (1 + (2 * np.pi * 0.5 * F) ** 2))
    assert_allclose(d.transfer(0, F, 1.0), 1 / (1 + (2 * np.pi * 0.8 * F) ** 2))
    assert_allclose(d.transfer(0.3, 0.4, 1.0), d.transfer(0.3, 0, 1.0) * d.transfer(0, 0.4, 1.0))


def test_diffusion_line_response_is_the_exponential_lsf():
    # along x alone: the LSF exp(-|x| / L) / 2L, the ESF 1 - exp(-x / L) / 2 beyond the edge
    length = 0.7
    response = im.Sensor(1.0, [st.Diffusion(length, 0.0)]).line_response(0.0)
    d = np.array([-3.0, -1.0, -0.2, 0.2, 1.0, 3.0])
    esf = np.where(d > 0, 1 - 0.5 * np.exp(-d / length), 0.5 * np.exp(d / length))
    assert_allclose(response.esf(d), esf, atol=2e-5)


def test_halo_moves_its_share_of_the_energy_into_a_broad_kernel():
    h = st.Halo(0.1, 3.0)
    assert float(h.transfer(0.0, 0.0, 1.0)) == 1.0
    assert_allclose(h.transfer(5.0, 0.0, 1.0), 0.9, atol=1e-5)             # far past the kernel: 1 - eta
    # the 2-D exponential kernel's transfer, (1 + (2 pi R f)^2)^(-3/2), radially
    f = 0.05
    assert_allclose(h.transfer(0.6 * f, 0.8 * f, 1.0), 0.9 + 0.1 * (1 + (6 * np.pi * f) ** 2) ** -1.5)
    with pytest.raises(ParameterError, match="fraction"):
        st.Halo(1.5, 3.0)


def test_lag_is_one_sided_hermitian_and_signed():
    lag = st.Lag(0.0, 0.8)
    t = lag.transfer(0.0, F, 1.0)
    assert np.iscomplexobj(t)
    assert_allclose(t, 1 / (1 + 2j * np.pi * 0.8 * F))
    assert_allclose(lag.transfer(0.0, -F, 1.0), np.conj(t))                # a real PSF
    assert_allclose(np.abs(st.Lag(0.0, -0.8).transfer(0.0, F, 1.0)), np.abs(t))   # the same MTF either way
    # alone, the ESF along +y is 1 - exp(-y / L) beyond the edge, 0 before it; mirrored for -L
    d = np.array([-1.0, -0.3, 0.3, 1.0, 2.5])
    up = im.Sensor(1.0, [lag]).line_response(90.0)
    assert_allclose(up.esf(d), np.where(d > 0, 1 - np.exp(-d / 0.8), 0.0), atol=1e-4)
    down = im.Sensor(1.0, [st.Lag(0.0, -0.8)]).line_response(90.0)
    assert_allclose(down.esf(d), 1 - up.esf(-d), atol=1e-4)


def test_a_lagged_sensor_leans_toward_the_lag_and_keeps_its_mtf_real():
    sensor = im.Sensor(1.0, [st.GaussianOptics(0.3, 0.3), st.Detector(1.0, 1.0), st.Lag(0.5, -0.4)])
    for angle, mean in ((0.0, 0.5), (90.0, -0.4), (-90.0, 0.4)):
        x, lsf = sensor.normal_lsf(angle)
        assert (x * lsf).sum() / lsf.sum() == pytest.approx(mean, abs=1e-3)
    plain = im.Sensor(1.0, [st.GaussianOptics(0.3, 0.3), st.Detector(1.0, 1.0)])
    expected = plain.mtf_nyquist("across") / math.sqrt(1 + (2 * np.pi * 0.5 * 0.5) ** 2)
    assert sensor.mtf_nyquist("across") == pytest.approx(expected, rel=1e-9)
    psf = sensor.psf(oversampling=2)
    # the point-sampled PSF rings about the jumps (the pixel's, the lag's) by a few 1e-4 of its peak
    assert psf.data.min() > -2e-3 * psf.data.max() and psf.data.sum() == pytest.approx(1.0)


def test_new_stages_round_trip_through_their_table():
    for stage in (st.Diffusion(0.4, 0.9), st.Halo(0.07, 2.0), st.Lag(-0.3, 0.6)):
        assert st.stage_from_dict(stage.to_dict()) == stage
    assert [name for name in st.STAGES][-4:-1] == ["diffusion", "halo", "lag"]
