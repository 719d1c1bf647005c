"""MeasureSettings: how every file of a batch (and every candidate of a scan)
is measured: its checks, and what the target's estimator is given."""
from types import SimpleNamespace

import pytest

from imgmtf.errors import ParameterError
from imgmtf.measure_settings import MeasureSettings, pulse_width_px


def raster(gsd_m=None):
    return SimpleNamespace(path="scene.tif", gsd_m=gsd_m)


def test_the_estimator_is_the_targets_and_carries_the_settings():
    edge = MeasureSettings(method="spline", intervals="none", force=True).estimator()
    pulse = MeasureSettings(target="pulse").estimator()
    assert type(edge).__name__ == "EdgeEstimator" and type(pulse).__name__ == "PulseEstimator"
    assert (edge.settings.method, edge.settings.force, edge.settings.intervals.method) == ("spline", True, "none")


def test_an_edge_takes_no_width_and_a_bar_its_width_in_px_for_the_raster():
    assert MeasureSettings().target_keywords(raster()) == {}
    assert MeasureSettings(target="pulse").target_keywords(raster()) == {"width_px": None}
    assert MeasureSettings(target="pulse", pulse_width="3px").target_keywords(raster()) == {"width_px": 3.0}
    metres = MeasureSettings(target="pulse", pulse_width="18m")
    assert metres.target_keywords(raster(gsd_m=6.0)) == {"width_px": 3.0}
    with pytest.raises(ParameterError, match="scene.tif: a width in metres needs a georeferenced image"):
        metres.target_keywords(raster())


def test_pulse_width_px_converts_metres_with_the_gsd_and_checks_the_result():
    assert pulse_width_px(None, raster()) is None
    assert pulse_width_px((1.5, "px"), raster()) == 1.5
    assert pulse_width_px((3.0, "m"), raster(gsd_m=2.0)) == 1.5
    with pytest.raises(ParameterError):
        pulse_width_px((0.1, "m"), raster(gsd_m=10.0))       # 0.01 px: too narrow to measure


@pytest.mark.parametrize("options, words", [
    (dict(target="spoke"), "target must be one of ('edge', 'pulse', 'points', 'double-bar', 'star'), got 'spoke'"),
    (dict(pulse_width="2px"), "a pulse width applies to pulse targets only"),
    (dict(target="pulse", pulse_width="-1px"), "width"),
    (dict(method="cubic"), "cubic"),
])
def test_bad_settings_are_refused_before_any_file_is_read(options, words):
    with pytest.raises(ParameterError) as info:
        MeasureSettings(**options)
    assert words in str(info.value)
