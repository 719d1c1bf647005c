import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.special import j0, j1, k1

from imgmtf.errors import ParameterError
from imgmtf.sensor import stages as st

F = np.array([0.0, 0.1, 0.25, 0.5, 0.9])


def test_gaussian_optics_and_jitter_closed_form():
    for cls in (st.GaussianOptics, st.Jitter):
        s = cls(0.39, 0.1)
        assert_allclose(s.transfer(F, 0, 1.0), np.exp(-2 * np.pi**2 * 0.39**2 * F**2))
        assert_allclose(s.transfer(0, F, 1.0), np.exp(-2 * np.pi**2 * 0.01 * F**2))


def test_detector_and_motion_are_sincs_on_their_axes():
    assert_allclose(st.Detector(1.0, 2.0).transfer(F, 0, 1.0), np.sinc(F))
    assert_allclose(st.Detector(1.0, 2.0).transfer(0, 0.5, 1.0), 0.0, atol=1e-15)
    assert_allclose(st.Motion(0.25).transfer(F, 0, 1.0), 1.0)
    assert_allclose(st.Motion(0.25).transfer(0, F, 1.0), np.sinc(0.25 * F))


def test_electronics_half_power_at_cutoff_radially():
    e = st.Electronics(1.4)
    assert_allclose(e.transfer(1.4, 0.0, 1.0), 0.5)
    assert_allclose(st.Electronics(1.0).transfer(0.6, 0.8, 1.0), 0.5)
    assert_allclose(st.Electronics(math.inf).transfer(F, F, 1.0), 1.0)


def test_diffraction_closed_form_cutoff_and_cusp():
    # f/8, 550 nm, 5 um pixels on a 2 m GSD: cut-off 5e-6 / (550e-9 * 8) cy/px
    d = st.Diffraction(8.0, 550e-9, 5e-6)
    fc_px = 5e-6 / (550e-9 * 8.0)
    assert d.cutoff_cy_m(2.0) == pytest.approx(fc_px / 2.0)
    v = np.array([0.0, 0.25, 0.5, 0.75, 1.0, 1.5])
    expected = np.where(v < 1, 2 / np.pi * (np.arccos(np.minimum(v, 1)) - v * np.sqrt(np.clip(1 - v**2, 0, 1))), 0)
    fc = d.cutoff_cy_m(2.0)
    assert_allclose(d.transfer(v * fc * 0.6, v * fc * 0.8, 2.0), expected, atol=1e-15)
    # T ~ 1 - 2 pi b |f| near zero
    b, eps = d.tail_length_m(2.0), 1e-6 * fc
    assert (1 - d.transfer(eps, 0, 2.0)) / eps == pytest.approx(2 * np.pi * b, rel=1e-5)


def test_defocus_disk_is_2_j1_over_x():
    r = 0.8
    z = 2 * np.pi * r * F[1:]
    assert_allclose(st.Defocus(r).transfer(F[1:], 0, 1.0), 2 * j1(z) / z)
    assert st.Defocus(r).transfer(0.0, 0.0, 1.0) == 1.0
    first_zero = 3.831705970207512 / (2 * np.pi * r)     # first zero of J1
    assert abs(st.Defocus(r).transfer(first_zero * 0.6, first_zero * 0.8, 1.0)) < 1e-12


def test_olpf_four_spot_closed_form():
    o = st.OLPF(0.6)
    assert_allclose(o.transfer(F, 0.3, 1.0), np.cos(np.pi * 0.6 * F) * np.cos(np.pi * 0.6 * 0.3))
    assert_allclose(o.transfer(1 / 1.2, 0.0, 1.0), 0.0, atol=1e-15)


def test_support_radii_bound_the_energy_outside():
    # Butterworth: energy outside r is u K1(u), u = 2 pi D0 r
    e = st.Electronics(1.4)
    u = 2 * np.pi * 1.4 * e.support_radius_m(1.0)
    assert 1e-10 < u * k1(u) <= 1e-9
    # diffraction core: 1 - encircled energy = J0^2 + J1^2 of pi r f_c, about 1 %
    d = st.Diffraction(8.0)
    x = np.pi * d.support_radius_m(1.0) * d.cutoff_cy_m(1.0)
    assert 0.005 < j0(x) ** 2 + j1(x) ** 2 < 0.0105
    assert st.Detector(0.6, 0.8).support_radius_m(1.0) == pytest.approx(0.5)
    assert st.OLPF(1.0).support_radius_m(1.0) == pytest.approx(math.sqrt(0.5))


@pytest.mark.parametrize("name", list(st.STAGES))
def test_every_stage_round_trips_and_is_even(name):
    stage = st.STAGES[name]()
    again = st.stage_from_dict(stage.to_dict())
    assert again == stage and again.to_dict()["stage"] == name
    fx, fy = np.meshgrid(np.linspace(-2, 2, 9), np.linspace(-2, 2, 9))
    t = stage.transfer(fx, fy, 1.0)
    assert_allclose(t, stage.transfer(-fx, fy, 1.0)) and t[4, 4] == pytest.approx(1.0)
    # the fit's coordinates map back to the same stage
    back = stage.with_fit_coordinates(stage.fit_coordinates(2.0), 2.0)
    fitted = [name for name in stage.fit_specs()]
    assert [getattr(back, n) for n in fitted] == pytest.approx([getattr(stage, n) for n in fitted], rel=1e-12)
    assert back.to_dict() == {**stage.to_dict(), **{n: getattr(back, n) for n in fitted}}


def test_numpy_scalars_are_plain_floats():
    s = st.GaussianOptics(np.float32(0.5), np.int64(1))
    assert s == st.GaussianOptics(0.5, 1.0) and type(s.sigma_x_m) is float


@pytest.mark.parametrize("make, message", [
    (lambda: st.GaussianOptics(-0.1, 0.2), "optics sigma_x_m must be finite and >= 0"),
    (lambda: st.Detector(float("nan")), "detector width_x_m must be finite"),
    (lambda: st.Motion("0.2"), "motion length_m must be a number"),
    (lambda: st.OLPF(True), "olpf split_m must be a number"),
    (lambda: st.Diffraction(0.0), "diffraction f_number must be > 0"),
    (lambda: st.Electronics(0.0), "electronics cutoff_cy_m must be > 0"),
    (lambda: st.Defocus(math.inf), "defocus radius_m must be finite"),
    (lambda: st.stage_from_dict({"stage": "astigmatism"}), "unknown stage 'astigmatism'"),
    (lambda: st.stage_from_dict({"stage": "optics", "sigma": 1}), r"unknown optics parameter\(s\) sigma"),
])
def test_bad_parameters_are_named(make, message):
    with pytest.raises(ParameterError, match=message):
        make()


@pytest.mark.parametrize("name", [n for n, cls in st.STAGES.items() if cls.fit_specs()])
def test_with_fit_coordinates_is_the_constructors_stage(name):
    # the copy checks only the parameters it sets: it must equal (and hash as) the stage built afresh,
    # with the fields' types the constructor gives, and refuse what the constructor refuses
    stage = st.STAGES[name]()
    moved = {k: 1.01 * v + 1e-3 for k, v in stage.fit_coordinates(1.0).items()}
    copy = stage.with_fit_coordinates(moved, 1.0)
    fresh = type(stage)(**copy.to_dict(include_name=False))
    assert copy == fresh and hash(copy) == hash(fresh) and repr(copy) == repr(fresh)
    assert all(type(getattr(copy, k)) is float for k in moved)
    assert stage.to_dict() == type(stage)().to_dict()             # the original untouched
    specs = stage.fit_specs()
    extreme = {k: 1e-60 if specs[k].kind == "frequency" else 1e40 for k in moved}
    with pytest.raises(ParameterError) as refused:
        stage.with_fit_coordinates(extreme, 1.0)
    with pytest.raises(ParameterError) as built:
        _rebuilt(stage, extreme)
    assert str(refused.value) == str(built.value)


def _rebuilt(stage, coordinates):
    """The constructor's refusal of what ``coordinates`` make (the values as with_fit_coordinates makes them)."""
    values = {}
    for name, u in coordinates.items():
        spec = stage.fit_specs()[name]
        if spec.kind == "fraction":
            values[name] = max(u, 0.0)
        elif spec.kind == "f-number":
            values[name] = max(u, 1e-6) * stage.pixel_pitch_m / stage.wavelength_m
        else:
            length = max(u, 0.0) ** (1.0 / spec.power)
            values[name] = length if spec.kind == "length" else 1.0 / length
    return type(stage)(**{**stage.to_dict(include_name=False), **values})


def test_optics_transfer_underflows_to_exact_zero():
    optics = st.GaussianOptics(0.4, 0.5)
    f = np.linspace(0.0, 40.0, 4001)
    assert np.array_equal(optics.transfer(f, f / 3, 1.0),
                          np.exp(-2.0 * np.pi**2 * (0.4**2 * f**2 + 0.5**2 * (f / 3) ** 2)))


def test_a_fits_floats_pass_the_checks_they_would_pass():
    """The checked copy's quick path for a float in (0, MAX_PARAMETER]
    keeps every refusal: a field's own bound, zero where it must be
    positive, the largest parameter."""
    from imgmtf.sensor.stages.base import MAX_PARAMETER
    halo = st.Halo()
    assert halo._replaced({"fraction": 0.25}).fraction == 0.25
    with pytest.raises(ParameterError, match="halo fraction must be at most 1"):
        halo._replaced({"fraction": 1.5})
    with pytest.raises(ParameterError, match="diffraction f_number must be > 0"):
        st.Diffraction()._replaced({"f_number": 0.0})
    optics = st.GaussianOptics()
    assert optics._replaced({"sigma_x_m": MAX_PARAMETER}).sigma_x_m == MAX_PARAMETER
    for bad, message in ((MAX_PARAMETER * 1.5, "must be at most"), (-0.1, ">= 0"), (math.nan, "finite")):
        with pytest.raises(ParameterError, match=message):
            optics._replaced({"sigma_x_m": bad})


def test_sinc_is_numpys_bit_for_bit():
    """Ours writes in place and gives all ones for arguments whose sines
    round to themselves (an axis a normal at 0 or 90 deg does not lean on):
    NumPy's numbers, shapes and scalars, NaN included."""
    from imgmtf.sensor.stages.detector import SINC_ONE_BELOW, sinc
    rng = np.random.default_rng(3)
    tiny = SINC_ONE_BELOW / np.pi
    cases = [rng.normal(0.0, 8.0, 3001), np.linspace(-40.0, 40.0, 8001), np.zeros(7),
             np.linspace(0.0, 200.0, 4001) * math.cos(math.radians(90.0)), rng.uniform(-tiny, tiny, 500),
             np.array([0.0, 1e-300, -2.5, 3.0, np.nan, 0.999 * tiny, 1.001 * tiny]), np.zeros((2, 3))]
    for t in cases:
        ours, theirs = sinc(t), np.sinc(t)
        assert ours.shape == theirs.shape and np.array_equal(ours, theirs, equal_nan=True)
    for scalar in (0.0, 0.5, 1e-30, np.float64(2.25)):
        assert sinc(scalar) == np.sinc(scalar) and np.ndim(sinc(scalar)) == 0
