"""The point-array overview: every array's label inside the figure."""
import numpy as np

from imgmtf.plot import plot_point_scan


def row(y):
    return {"target_id": 1, "roi": [10, y, 40, 30], "status": "accepted", "direction": "across-track",
            "mtf_nyquist": 0.23, "mtf_nyquist_ci": [0.21, 0.25]}


def test_a_label_sits_above_its_array_or_inside_it_at_the_images_top():
    for y, inside in ((30, False), (0, True)):
        ax = plot_point_scan(np.zeros((80, 80)), 1.0, [row(y)]).axes[0]
        [label] = [t for t in ax.texts if t.get_text().startswith("A1")]
        top = label.get_position()[1]
        assert (top > y) == inside and 0 <= top <= 80      # image rows grow downwards
        assert label.get_va() == ("top" if inside else "bottom")
