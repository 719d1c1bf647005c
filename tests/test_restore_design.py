"""The restoration filter's design against closed forms."""
import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.restore.design import MIN_REGULARISER, target_transfer
from imgmtf.sensor.stages import OLPF, Detector, GaussianOptics, Motion


@pytest.fixture(scope="module")
def gaussian_pixel():
    """Gaussian optics (sigma 0.6 px) and a square pixel: MTF at Nyquist exp(-2 pi^2 0.36 / 4) sinc(0.5)."""
    return im.Sensor(1.0, [GaussianOptics(0.6, 0.6), Detector(1.0, 1.0)])


def test_target_transfer_is_one_at_zero_the_target_at_nyquist_and_never_above_one():
    f = np.linspace(0, 0.5, 101)
    g = target_transfer(f, 0.25)
    assert g[0] == 1.0 and g[-1] == pytest.approx(0.25, abs=1e-12)
    assert np.all(np.diff(g) < 0) and np.all(g <= 1.0)
    # separable and Gaussian: the 2-D target at any angle reaches V at |f| = 0.5
    a = math.radians(30)
    assert target_transfer(0.5 * math.cos(a), 0.25) * target_transfer(0.5 * math.sin(a), 0.25) == \
        pytest.approx(0.25)


@pytest.mark.parametrize("kernel_size", [None, 13])
def test_restored_system_reaches_the_target_at_nyquist_and_keeps_dc(gaussian_pixel, kernel_size):
    system = math.exp(-2 * math.pi**2 * 0.36 / 4) * np.sinc(0.5)
    filt = im.design_filter(gaussian_pixel, 0.25, noise_std_dn=1.0, signal_std_dn=1000.0, kernel_size=kernel_size)
    assert filt.taps.sum() == pytest.approx(1.0, abs=1e-12)
    assert filt.regulariser == pytest.approx(1e-6)
    for direction in ("across", "along"):
        assert float(filt.system_transfer(0.5, direction)) == pytest.approx(system, rel=1e-9)
        achieved = float(filt.system_transfer(0.5, direction) * filt.axis_transfer(0.5, direction))
        # the FFT form to the truncation of its taps; a 13 x 13 kernel to its least-squares cut
        assert achieved == pytest.approx(0.25, abs=0.005 if kernel_size is None else 0.02)
    assert filt.taps.shape[0] % 2 == 1
    if kernel_size:
        assert filt.taps.shape == (13, 13) and filt.form == "spatial"


def test_noise_gain_is_the_standard_deviation_ratio_on_white_noise(gaussian_pixel):
    filt = im.design_filter(gaussian_pixel, 0.25, noise_std_dn=3.0, signal_std_dn=500.0)
    assert filt.noise_gain == pytest.approx(math.sqrt((filt.taps ** 2).sum()))
    noise = np.random.default_rng(3).normal(1000.0, 10.0, (768, 768))
    restored = filt(noise)
    r = filt.radius_px          # the mirrored borders repeat samples: away from them the noise is white
    ratio = restored[r:-r, r:-r].std() / noise[r:-r, r:-r].std()
    assert ratio == pytest.approx(filt.noise_gain, rel=0.02)
    assert filt.noise_gain > 1.5        # a real sharpening: the check can fail


def test_noise_gain_limit_wins_over_the_target(gaussian_pixel):
    free = im.design_filter(gaussian_pixel, 0.25)
    limited = im.design_filter(gaussian_pixel, 0.25, max_noise_gain=1.5)
    assert not free.limited and limited.limited
    assert limited.noise_gain == pytest.approx(1.5, abs=1e-4)
    assert limited.regulariser > free.regulariser
    achieved = float(limited.system_transfer(0.5) * limited.axis_transfer(0.5))
    assert free.system_transfer(0.5) < achieved < 0.24
    assert limited.taps.sum() == pytest.approx(1.0)
    # a limit the target does not reach changes nothing
    assert not im.design_filter(gaussian_pixel, 0.25, max_noise_gain=50).limited


@pytest.mark.parametrize("stage", [Motion(2.0), OLPF(1.0)], ids=["motion", "olpf"])
def test_an_exact_zero_in_the_transfer_stays_bounded(stage):
    # motion of 2 px (sinc(2f)) and an OLPF split 1 px (cos(pi f)) have an exact zero at Nyquist
    sensor = im.Sensor(1.0, [GaussianOptics(0.3, 0.3), Detector(1.0, 1.0), stage])
    assert abs(float(sensor.transfer(0.0, 0.5))) < 1e-12
    filt = im.design_filter(sensor, 0.3, noise_std_dn=1.0, signal_std_dn=100.0)
    k = filt.regulariser
    assert np.all(np.isfinite(filt.taps))
    # |W| <= (1 + K) / (2 sqrt K), so the root-mean-square of W (the noise gain) is too
    assert filt.noise_gain <= (1 + k) / (2 * math.sqrt(k))
    assert float(np.abs(filt.system_transfer(0.5, "along") * filt.axis_transfer(0.5, "along"))) < 1e-9
    noise = np.random.default_rng(0).normal(500.0, 5.0, (200, 200))
    restored = filt(noise)
    assert np.all(np.isfinite(restored))
    assert np.abs(restored - 500).max() <= np.abs(filt.taps).sum() * np.abs(noise - 500).max()


def test_noise_free_design_uses_the_floor(gaussian_pixel):
    filt = im.design_filter(gaussian_pixel, 0.25)
    assert filt.regulariser == MIN_REGULARISER and math.isnan(filt.signal_std_dn)


@pytest.mark.parametrize("kwargs, words", [
    ({"target_nyquist": 0.0}, "target MTF at Nyquist must be > 0"),
    ({"target_nyquist": 1.2}, "at most 1"),
    ({"target_nyquist": float("nan")}, "target MTF at Nyquist must be finite"),
    ({"kernel_size": 8}, "odd"),
    ({"kernel_size": 1}, "kernel_size must lie in [3, 63]"),
    ({"noise_std_dn": 2.0}, "needs the scene's signal_std_dn"),
    ({"noise_std_dn": 2.0, "signal_std_dn": 0.0}, "signal_std_dn must be > 0"),
    ({"max_noise_gain": 0.5}, "max_noise_gain must be at least 1"),
])
def test_bad_parameters_are_refused_by_name(gaussian_pixel, kwargs, words):
    kwargs = {"target_nyquist": 0.25, **kwargs}
    with pytest.raises(im.ParameterError, match=words.replace("[", r"\[").replace("]", r"\]")):
        im.design_filter(gaussian_pixel, **kwargs)


def test_a_sensor_is_required():
    with pytest.raises(im.ParameterError, match="expected a Sensor"):
        im.design_filter("s.toml", 0.25)


def test_kernel_files_round_trip(gaussian_pixel, tmp_path):
    filt = im.design_filter(gaussian_pixel, 0.25, kernel_size=9)
    filt.save(tmp_path / "k.npy")
    filt.save(tmp_path / "k.txt")
    assert np.array_equal(np.load(tmp_path / "k.npy"), filt.taps)
    assert np.allclose(np.loadtxt(tmp_path / "k.txt"), filt.taps, rtol=1e-8, atol=0)
    assert "noise gain" in (tmp_path / "k.txt").read_text()
    with pytest.raises(im.ParameterError, match="npy"):
        filt.save(tmp_path / "k.csv")
    with pytest.raises(im.FileWriteError, match="cannot write"):
        filt.save(tmp_path / "missing" / "k.npy")


#: the one-sided lag of the stand-in sensor below, m (0.4 px at its 1 m pixel)
LAG_M = 0.4


class LaggedSensor(im.Sensor):
    """A stand-in for a sensor with a one-sided stage along track: its
    transfer is the base sensor's times 1 / (1 + 2 pi i tau fy), complex
    (its MTF the modulus), so that the design's handling of a phase is
    tested without the stage itself."""

    def transfer(self, fx, fy):
        return super().transfer(fx, fy) / (1 + 2j * np.pi * LAG_M * np.asarray(fy, float))


def test_a_complex_transfer_gets_real_taps_that_undo_its_phase():
    sensor = LaggedSensor(1.0, [GaussianOptics(0.5, 0.5), Detector(1.0, 1.0)])
    filt = im.design_filter(sensor, 0.3, noise_std_dn=1.0, signal_std_dn=500.0)
    k = (1.0 / 500.0) ** 2
    # real taps summing to 1, not point-symmetric: the filter's own transfer is complex
    assert filt.taps.dtype == np.float64 and filt.taps.sum() == pytest.approx(1.0, abs=1e-12)
    assert not filt.point_symmetric and np.iscomplexobj(filt.axis_transfer(0.3, "along"))
    # below 0.4 cy/px in both axes the taps' transfer is T conj(H) (1 + K) / (|H|^2 + K), to the crop of the
    # taps (measured within 4e-4); the phase is then undone less and less up to Nyquist, where a real
    # filter's transfer is real (W(0.5) = W(-0.5) = conj(W(0.5))) and the lag's phase is not
    fx, fy = np.meshgrid(np.linspace(-0.4, 0.4, 17), np.linspace(-0.4, 0.4, 17))
    h = sensor.transfer(fx, fy)
    closed = target_transfer(fx, 0.3) * target_transfer(fy, 0.3) * np.conj(h) * (1 + k) / (np.abs(h) ** 2 + k)
    assert np.abs(filt.transfer(fx, fy) - closed).max() < 1e-3
    # the restored system H W: real (the phase undone) to 0.4 cy/px, its modulus the target's to Nyquist
    f = np.linspace(0.0, 0.5, 11)
    restored = sensor.transfer(0.0, f) * filt.axis_transfer(f, "along")
    assert np.abs(restored.imag[f <= 0.4]).max() < 1e-3 and restored.real[f <= 0.4].min() > 0
    assert np.abs(np.abs(restored) - target_transfer(f, 0.3)).max() < 3e-3
    # W is continuous across Nyquist: its taps decay within the design grid (cropped below 257)
    assert filt.taps.shape[0] < 257
    # across track the lag does nothing: that axis's design is the real sensor's (to the taps' crop)
    real = im.design_filter(im.Sensor(1.0, [GaussianOptics(0.5, 0.5), Detector(1.0, 1.0)]), 0.3,
                            noise_std_dn=1.0, signal_std_dn=500.0)
    f = np.linspace(0.0, 0.4, 5)
    assert np.abs(filt.axis_transfer(f, "across") - real.axis_transfer(f, "across")).max() < 1e-3
    assert abs(filt.axis_transfer(0.5, "across") - real.axis_transfer(0.5, "across")) < 0.01    # (measured 4e-3)
    # the report reads the MTF, |H|: 1 / sqrt(1 + (2 pi tau f)^2) of the real sensor's along track
    report = im.restoration_report(filt)
    lag = 1 / math.sqrt(1 + (2 * math.pi * LAG_M * 0.5) ** 2)
    assert report.axes["along"].system_mtf_nyquist == pytest.approx(
        im.restoration_report(real).axes["along"].system_mtf_nyquist * lag, rel=1e-9)
    assert report.axes["along"].achieved_mtf_nyquist == pytest.approx(0.3, abs=3e-3)
    assert np.isrealobj(filt(np.full((20, 20), 500.0)))


def test_the_phase_weight_and_a_real_transfer_kept_with_its_sign():
    from imgmtf.restore.design import phase_tapered_conjugate, phase_weight
    assert phase_weight([0.0, 0.4, 0.45, 0.5, -0.5]).tolist() == pytest.approx([1.0, 1.0, 0.5, 0.0, 0.0])
    real = np.array([0.5, -0.2, 0.0])
    assert phase_tapered_conjugate(real, np.zeros(3)) is real          # a sinc's negative lobe keeps its sign
    h = np.array([0.3 - 0.4j, -0.3 - 0.4j])
    assert phase_tapered_conjugate(h, np.ones(2)) == pytest.approx(np.conj(h))
    # no phase undone: the signed modulus, real (-0.5 where the real part is negative)
    assert phase_tapered_conjugate(h, np.zeros(2)) == pytest.approx([0.5, -0.5])


def test_the_lag_stage_restored_to_its_target_with_a_symmetric_edge():
    from imgmtf.restore.report import edge_responses
    from imgmtf.sensor.stages import Lag
    sensor = im.Sensor(1.0, [GaussianOptics(0.5, 0.5), Detector(1.0, 1.0), Lag(0.0, 0.6)])
    filt = im.design_filter(sensor, 0.3, noise_std_dn=1.0, signal_std_dn=500.0)
    along = im.restoration_report(filt).axes["along"]
    assert along.system_mtf_nyquist == pytest.approx(float(np.abs(sensor.transfer(0.0, 0.5))), rel=1e-12)
    assert along.achieved_mtf_nyquist == pytest.approx(0.3, abs=3e-3)
    # the lag leans the edge: 1 px before it the response has risen 0.012, 1 px after it still lacks 0.276;
    # restored, the phase undone below 0.4 cy/px, the two sides differ by 0.04 (measured), not 0.26
    x, before, after = edge_responses(filt, "along")

    def lean(esf):
        return abs(np.interp(-1.0, x, esf) - (1.0 - np.interp(1.0, x, esf)))
    assert lean(before) > 0.25 and lean(after) < 0.2 * lean(before)
