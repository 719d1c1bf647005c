"""Figures of a restoration."""
import pytest

import imgmtf as im
from imgmtf.plot import plot_restoration, plot_restore_tradeoff, plot_restored_edge, plot_restored_mtf


@pytest.fixture(scope="module")
def filt():
    return im.design_filter(im.Sensor(), 0.35, kernel_size=11)


def test_the_restoration_figure_shows_both_axes_and_the_edge(filt, tmp_path):
    fig = plot_restoration(filt)
    across, along, edge = fig.axes
    assert across.get_title() == "Across track" and along.get_title() == "Along track"
    labels = [t.get_text() for t in across.get_legend().get_texts()]
    assert labels[-1] == "target: 0.350" and labels[2].startswith("restored: 0.3")
    assert "RER" in edge.get_legend().get_texts()[0].get_text()
    fig.savefig(tmp_path / "r.png")


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
