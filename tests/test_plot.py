import numpy as np
from matplotlib.figure import Figure

import imgmtf as im
from imgmtf.plot import plot_locations, plot_mtf


def _measured(angle):
    chip = im.render(im.Sensor(), im.Target("edge", angle, 200.0, 1200.0), 60, noise_std_dn=2.0, seed=1)
    return im.measure_edge(chip.image)


def test_a_near_horizontal_edge_is_drawn_as_the_image_shows_it():
    ax = Figure().subplots()
    plot_locations(_measured(84.0), ax)          # normal at 84 deg: the edge runs along the rows
    line = next(ln for ln in ax.get_lines() if ln.get_label() == "least-squares line")
    x, y = line.get_xdata(), line.get_ydata()
    assert np.ptp(x) > 50 and np.ptp(y) < 10     # across the chip's 60 columns, rising 60 tan(6 deg) = 6.3 rows
    assert abs(np.ptp(y) / np.ptp(x) - np.tan(np.radians(6.0))) < 0.01
    assert ax.get_xlabel() == "column (px)" and ax.get_ylabel() == "row (px)"


def test_two_measurements_on_one_axes_keep_the_callers_colours_and_one_nyquist_entry():
    ax = Figure().subplots()
    result = _measured(6.0)
    plot_mtf(result, ax=ax, color="C2", label="msg")
    plot_mtf(result, ax=ax, color="C3", label="again")
    labels = ax.get_legend_handles_labels()[1]
    assert sum(label.startswith("Nyquist") for label in labels) == 1
    curves = {ln.get_label(): ln.get_color() for ln in ax.get_lines()}
    assert curves["msg"] == "C2" and curves["again"] == "C3"
