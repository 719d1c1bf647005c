"""Figures of a restoration."""
import pytest

import imgmtf as im
from imgmtf.plot import plot_restoration, plot_restore_tradeoff, plot_restored_edge, plot_restored_mtf
from imgmtf.sensor.stages import Detector, GaussianOptics


@pytest.fixture(scope="module")
def filt():
    return im.design_filter(im.Sensor(), 0.35, kernel_size=11)


def test_the_restoration_figure_shows_both_axes_and_the_edge(filt, tmp_path):
    fig = plot_restoration(filt)
    across, along, edge = fig.axes
    assert across.get_title() == "Across track" and along.get_title() == "Along track"
    labels = [t.get_text() for t in across.get_legend().get_texts()]
    assert labels[2] == "target: 0.350" and labels[1].startswith("restored: 0.3") and labels[3].startswith("filter")
    assert "RER" in edge.get_legend().get_texts()[0].get_text()
    fig.savefig(tmp_path / "r.png")


def test_a_high_gain_leaves_the_mtf_its_axis_and_like_edge_responses_draw_as_one():
    sensor = im.Sensor(1.0, [GaussianOptics(0.9, 0.9), Detector()])     # symmetric: across = along
    high = im.design_filter(sensor, 0.3)
    assert high.noise_gain > 3
    fig = plot_restored_mtf(high, "across")
    ax, gain = fig.axes
    assert ax.get_ylim()[1] < 1.1 and gain.get_ylim()[1] > 3 and gain.get_ylabel() == "filter gain"
    assert [t.get_text() for t in ax.get_legend().get_texts()][-1].endswith("(right axis)")
    edge = plot_restored_edge(high).axes[0]
    assert len(edge.lines) == 4 and "one curve" in edge.get_legend().get_title().get_text()
    low = plot_restored_mtf(im.design_filter(sensor, sensor.mtf_nyquist("across")), "across")
    assert len(low.axes) == 1 and low.axes[0].get_ylabel() == "MTF, filter gain"


def test_the_tradeoff_has_a_curve_per_target():
    fig = plot_restore_tradeoff(im.Sensor(), targets=(0.3, 0.5))
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["target 0.3", "target 0.5", "sensor alone"]
    gains = ax.lines[1].get_xdata()
    assert gains.min() == pytest.approx(1.0, abs=1e-3)


def test_figures_refuse_what_they_do_not_draw():
    for draw in (plot_restoration, plot_restored_edge, lambda x: plot_restored_mtf(x, "across")):
        with pytest.raises(im.ParameterError, match="restoration filter"):
            draw(im.Sensor())
    with pytest.raises(im.ParameterError, match="Sensor"):
        plot_restore_tradeoff("s.toml")
