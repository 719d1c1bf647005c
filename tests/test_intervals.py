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
