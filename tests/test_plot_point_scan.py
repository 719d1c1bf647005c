"""The point-array overview: every array's label inside the figure, each target marked kept or refused."""
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


def test_each_target_is_marked_where_it_lies_kept_or_refused_and_counted_in_the_legend():
    targets = [{"x_px": 20.0, "y_px": 40.0, "status": "used"}, {"x_px": 32.5, "y_px": 40.0, "status": "used"},
               {"x_px": 44.0, "y_px": 52.0, "status": "faint"}]
    ax = plot_point_scan(np.zeros((80, 80)), 1.0, [{**row(30), "point_targets": targets}]).axes[0]
    marks = {line.get_marker(): line.get_xydata().tolist() for line in ax.lines if line.get_marker() in ("o", "x")}
    assert marks == {"o": [[20.0, 40.0], [32.5, 40.0]], "x": [[44.0, 52.0]]}
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "target kept (2)" in legend and "target refused (1)\n  1 faint" in legend
