"""Intervals: their settings, the registry and its dispatcher, and
intervals that behave as intervals should."""
import math

import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.estimate.intervals import Bootstrap
from imgmtf.estimate.intervals.bootstrap import percentile_interval

from conftest import exact_edge_chip, gaussian_pixel_transfer


def test_percentile_interval_and_settings():
    interval = percentile_interval(np.arange(1001.0), 0.95)
    assert (interval.low, interval.high) == pytest.approx((25.0, 975.0))
    assert math.isnan(percentile_interval(np.r_[np.full(20, np.nan), np.ones(80)], 0.95).low)
    for bad in (dict(replicates=5), dict(replicates=-1), dict(confidence=1.0)):
        with pytest.raises(ParameterError):
            Bootstrap(**bad)


def test_intervals_cover_the_truth_and_scale_with_the_noise():
    transfer = gaussian_pixel_transfer(0.5, 6.0)
    true_nyquist = abs(transfer(np.array([0.5]))[0])
    widths = []
    for noise in (5.0, 10.0):
        chip = exact_edge_chip(transfer, 6.0, noise_std=noise, seed=4)
        r = im.measure_edge(chip)
        assert true_nyquist in r.mtf_nyquist_ci
        assert r.mtf_nyquist_ci.low < r.mtf_nyquist < r.mtf_nyquist_ci.high
        assert r.mtf50_ci_cy_px.low < r.mtf50_cy_px < r.mtf50_ci_cy_px.high
        widths.append(r.mtf_nyquist_ci.width)
    assert 1.5 < widths[1] / widths[0] < 2.6       # the noise doubled
    again = im.measure_edge(chip)
    assert again.mtf_nyquist_ci == r.mtf_nyquist_ci  # seeded: the same image gives the same interval


def test_switched_off_bootstrap_gives_nan_intervals():
    chip = exact_edge_chip(gaussian_pixel_transfer(0.5, 6.0), 6.0, noise_std=5.0)
    r = im.measure_edge(chip, bootstrap=Bootstrap(0))
    assert math.isnan(r.mtf_nyquist_ci.low) and r.to_dict()["mtf_nyquist_ci"] == [None, None]


def test_pulse_interval_covers_the_truth():
    chip = im.render(im.Sensor(), im.Target("pulse", 6.0, 200, 1200, width_px=1.5), 64,
                     noise_std_dn=8.0, seed=2)
    r = im.measure_pulse(chip.image, width_px=1.5)
    assert float(chip.true_mtf(0.5)) in r.mtf_nyquist_ci
    assert chip.true_mtf50_cy_px() in r.mtf50_ci_cy_px


def test_the_words_the_cli_takes_name_intervals_in_python_too():
    """intervals="bootstrap" wherever --intervals bootstrap is taken: the
    estimators, a batch's and a scan's settings; an unknown word is refused."""
    from imgmtf.batch import MeasureSettings
    chip = exact_edge_chip(gaussian_pixel_transfer(0.6, 6.0), 6.0, (60, 60), noise_std=2.0, seed=3)
    by_word, by_settings = (im.measure_edge(chip, intervals=i) for i in ("bootstrap", im.Intervals("bootstrap")))
    assert by_word.params["intervals"] == by_settings.params["intervals"]
    assert by_word.mtf_nyquist_ci == by_settings.mtf_nyquist_ci
    assert math.isnan(im.measure_edge(chip, intervals="none").mtf_nyquist_ci.low)
    assert MeasureSettings(intervals="bootstrap").intervals == im.Intervals("bootstrap")
    assert im.ScanSettings(intervals="none").intervals == im.Intervals("none")
    with pytest.raises(ParameterError, match="'bootstrapp'"):
        im.measure_edge(chip, intervals="bootstrapp")
    with pytest.raises(ParameterError, match="'influense'"):
        MeasureSettings(intervals="influense")


def test_an_mtf_interval_never_runs_below_zero():
    """The f/16 camera crop's MTF at Nyquist (0.0073) has a symmetric
    interval reaching below 0: its low end is reported as 0, the estimate
    and the high end as they were."""
    from pathlib import Path
    path = Path(__file__).parent.parent / "data" / "x0552_y1976_F16.png"
    [record] = im.measure_file(path)
    low, high = record.get("mtf_nyquist_ci")
    assert low == 0.0 < record.get("mtf_nyquist") < high == pytest.approx(0.0270, abs=1e-4)
    assert im.Interval(-0.5, 0.2).clipped_at_zero() == im.Interval(0.0, 0.2)
    assert im.Interval(0.1, 0.2).clipped_at_zero() == im.Interval(0.1, 0.2)
    assert math.isnan(im.Interval.none().clipped_at_zero().low)


# -- the registry and its dispatcher ---------------------------------------------
def _estimate(target="edge", noise=8.0, seed=5):
    """A rendered 64 x 64 chip's estimate (its intervals not computed) and its true MTF at Nyquist."""
    from imgmtf.estimate.edge import EdgeKind
    from imgmtf.estimate.pipeline import run
    from imgmtf.estimate.pulse import PulseKind
    from imgmtf.estimate.settings import make_settings
    shape = im.Target("edge", 6.0, 200, 1200) if target == "edge" else im.Target("pulse", 6.0, 200, 1200,
                                                                                  width_px=1.5)
    chip = im.render(im.Sensor(), shape, 64, noise_std_dn=noise, seed=seed)
    kind = EdgeKind() if target == "edge" else PulseKind(1.5)
    return run(kind, chip.image, make_settings(intervals="none")).estimate, float(chip.true_mtf(0.5))


def test_the_dispatcher_runs_the_method_it_names_with_the_options_it_takes():
    from imgmtf.estimate.intervals import intervals
    from imgmtf.estimate.intervals.bootstrap import bootstrap_intervals
    from imgmtf.estimate.intervals.influence import influence_intervals
    estimate, _ = _estimate()
    assert intervals(estimate) == influence_intervals(estimate).clipped_at_zero()
    assert intervals(estimate, "influence", confidence=0.9) == influence_intervals(estimate, confidence=0.9)
    # the seed reaches the bootstrap and nothing else
    assert intervals(estimate, "influence", seed=3) == intervals(estimate, "influence")
    boot = intervals(estimate, "bootstrap", replicates=40, seed=3)
    assert boot == bootstrap_intervals(estimate, replicates=40, seed=3)
    assert boot != intervals(estimate, "bootstrap", replicates=40, seed=4)
    narrower = intervals(estimate, "influence", confidence=0.5).mtf_nyquist
    wider = intervals(estimate, "influence").mtf_nyquist
    assert wider.low < narrower.low < narrower.high < wider.high


def test_an_unknown_method_or_option_out_of_range_is_refused():
    from imgmtf.estimate.intervals import intervals
    estimate, _ = _estimate()
    with pytest.raises(ParameterError, match="'jackknife'"):
        intervals(estimate, "jackknife")
    with pytest.raises(ParameterError, match="replicates"):
        intervals(estimate, "bootstrap", replicates=5)
    with pytest.raises(ParameterError, match="confidence"):
        intervals(estimate, "influence", confidence=1.5)


def test_none_gives_no_interval():
    from imgmtf.estimate.intervals import FigureIntervals, intervals
    estimate, _ = _estimate()
    found = intervals(estimate, "none")
    assert all(math.isnan(end) for end in (found.mtf_nyquist.low, found.mtf_nyquist.high,
                                           found.mtf50_cy_px.low, found.mtf50_cy_px.high))
    assert found.warnings == () and found == FigureIntervals.none()


def test_influence_and_bootstrap_agree_on_a_rendered_bar():
    """Both cover the truth, and their widths agree within what 200
    replicates and the linearisation allow (a third); an edge's are
    compared in test_pipeline.py."""
    from imgmtf.estimate.intervals import intervals
    estimate, true_nyquist = _estimate("bar")
    linear, boot = intervals(estimate, "influence"), intervals(estimate, "bootstrap")
    for found in (linear, boot):
        assert true_nyquist in found.mtf_nyquist
        assert found.mtf_nyquist.low < estimate.spectrum.mtf_nyquist < found.mtf_nyquist.high
        assert found.mtf50_cy_px.low < estimate.spectrum.mtf50_cy_px < found.mtf50_cy_px.high
    assert boot.mtf_nyquist.width == pytest.approx(linear.mtf_nyquist.width, rel=0.35)
    assert boot.mtf50_cy_px.width == pytest.approx(linear.mtf50_cy_px.width, rel=0.35)


def test_every_registered_method_is_a_choice_of_the_cli_and_of_the_settings():
    from imgmtf.cli.options import interval_options
    from imgmtf.estimate.intervals import METHODS, Intervals
    choices = next(p for p in interval_options(lambda **kw: None).__click_params__
                   if p.name == "interval_method").type.choices
    assert list(choices) == list(METHODS)
    assert all(Intervals(name).method == name for name in METHODS)
