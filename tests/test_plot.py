import numpy as np
import pytest
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


def test_arguments_of_the_wrong_kind_are_named():
    from imgmtf.plot import plot_fit_edge, plot_sensor
    result = _measured(6.0)
    for call, message in [(lambda: plot_mtf(None), "this figure draws a measurement .*, got NoneType"),
                          (lambda: plot_sensor(result), "this figure draws an imgmtf.Sensor, got EdgeResult"),
                          (lambda: plot_mtf(result, truth=im.Sensor()), "truth must be a function of frequency"),
                          (lambda: plot_fit_edge(im.fit_sensor([result]), 3), "edge index 3 is outside the fit's 1")]:
        with pytest.raises(im.ParameterError, match=message):
            call()


def test_a_scan_overview_takes_scan_scenes_records_as_they_come():
    from imgmtf.plot import plot_scan
    records = [im.Record.measured("a.tif", 1, {"normal_angle_deg": 6.0}, params={}, run_utc="", status="accepted")]
    records[0] = records[0].with_(site={"id": 1, "x0_px": 5.0, "y0_px": 5.0, "x1_px": 8.0, "y1_px": 40.0,
                                        "roi_polygon_px": [[0, 0], [20, 0], [20, 45], [0, 45]]})
    fig = plot_scan(np.zeros((50, 80)), 1.0, records)
    assert isinstance(fig, Figure)


def test_a_scan_overview_keeps_crowded_targets_labels_apart_and_inside_the_image():
    """Targets a few px apart: each label moves to a free spot (a leader to
    its target when moved off the first ring), none covers another, all
    stay inside the image."""
    from matplotlib.text import Text

    from imgmtf.plot import plot_scan
    from imgmtf.plot.scan import _overlap
    summaries = [{"scope": "target", "target_id": k, "x_px": x, "y_px": y, "summary": "fit",
                  "direction": "across-track", "mtf_nyquist": 0.25, "mtf50_cy_px": 0.36}
                 for k, (x, y) in enumerate([(100, 100), (104, 96), (96, 104), (100, 108), (102, 102), (98, 98),
                                                  (392, 5)], 1)]
    fig = plot_scan(np.zeros((200, 400)), 1.0, [], summaries)
    ax = fig.axes[0]
    labels = [t for t in ax.texts if t.get_text().startswith("T")]
    assert len(labels) == 7
    fig.draw_without_rendering()             # each label's text where it is drawn, its leader left out
    boxes = [Text.get_window_extent(t) for t in labels]
    frame = ax.get_window_extent()
    assert all(_overlap(a, b) == 0 for i, a in enumerate(boxes) for b in boxes[i + 1:])
    assert all(_overlap(b, frame) == pytest.approx(b.width * b.height) for b in boxes)
    assert any(t.arrow_patch is not None for t in labels)       # the crowded ones point back to their targets


def test_a_scan_overview_of_a_chart_shrinks_many_targets_labels_to_the_rows_to_quote():
    """A camera chart's 12 targets with four rows each cannot all be
    labelled in full in a 400 x 300 px image: the labels fall back to the
    rows to quote, each near its own target, none over another or out of
    the image (over the title or the axis labels)."""
    from matplotlib.text import Text

    from imgmtf.plot import plot_scan
    from imgmtf.plot.scan import _overlap
    summaries = [{"scope": "target", "target_id": k, "x_px": x, "y_px": y, "summary": summary,
                  "direction": direction, "normal_angle_deg": 5.0, "mtf_nyquist": 0.1, "mtf50_cy_px": 0.25,
                  "assumption": "bracket", "chosen_assumption": "bracket", "recommended": summary == "sections"}
                 for k, (x, y) in enumerate([(x, y) for y in (50, 150, 250) for x in (50, 150, 250, 350)], 1)
                 for summary in ("combined", "sections") for direction in ("horizontal", "vertical")]
    for s in summaries[:4:2]:       # target 1 horizontal: MTF50 read, the MTF at Nyquist below the noise
        s["mtf_nyquist"] = None
    fig = plot_scan(np.zeros((300, 400)), 1.0, [], summaries)
    ax = fig.axes[0]
    labels = [t for t in ax.texts if t.get_text().startswith("T")]
    assert len(labels) == 12 and all(t.get_text().count("\n") == 2 for t in labels)   # T, *H, *V
    assert "*H -|0.250" in labels[0].get_text()
    fig.draw_without_rendering()
    boxes = [Text.get_window_extent(t) for t in labels]
    frame = ax.get_window_extent()
    assert all(_overlap(a, b) == 0 for i, a in enumerate(boxes) for b in boxes[i + 1:])
    assert all(_overlap(b, frame) == pytest.approx(b.width * b.height) for b in boxes)
    per_px = frame.width / 400.0
    for t, b in zip(labels, boxes):       # beside its own target: its nearest corner within ~60 px of the target
        x, y = ax.transData.transform(t.xy)
        gap = np.hypot(max(b.x0 - x, 0, x - b.x1), max(b.y0 - y, 0, y - b.y1))
        assert gap < 60 * per_px
    assert "rows to quote" in ax.get_title(loc="left")


def test_a_figure_prints_with_its_unit_or_says_what_masked_it():
    from imgmtf.plot.measurement import _figure
    assert _figure(0.36431, "cy/px") == "0.3643 cy/px" and _figure(0.2667) == "0.2667"
    assert _figure(float("nan"), "cy/px", "masked by the bar's sinc") == "masked by the bar's sinc"
    assert _figure(float("nan"), "cy/px") == "undefined"


def test_a_missing_figure_is_labelled_by_its_cause():
    """A bar's sinc masks only a bar's figure; a forced edge whose MTF never
    falls to 0.5 says so, not that a sinc masked it."""
    from dataclasses import replace

    from imgmtf.plot.measurement import missing_cause, plot_measurement
    edge = _measured(6.0)
    no_fifty = replace(edge, mtf50_cy_px=float("nan"), mtf=np.maximum(edge.mtf, 0.55),
                       warnings=("mtf-undefined: MTF50 cannot be read off (measured anyway: forced)",))
    assert missing_cause(no_fifty, "mtf50") == "undefined: the MTF stays above 0.5 up to 1 cy/px"
    header = plot_measurement(no_fifty).get_suptitle()
    assert "MTF50 undefined: the MTF stays above 0.5" in header and "sinc" not in header
    bar = im.measure_pulse(im.render(im.Sensor(), im.Target("pulse", 6.0, 200.0, 1200.0, width_px=3.0), 80,
                                     noise_std_dn=1.0, seed=2).image, width_px=3.0)
    masked = replace(bar, mtf50_cy_px=float("nan"), mtf=np.where(bar.frequencies_cy_px < 0.3, 0.8, np.nan))
    assert missing_cause(masked, "mtf50") == "masked by the bar's sinc"
    assert missing_cause(masked, "mtf_nyquist") == "masked by the bar's sinc"
    assert missing_cause(replace(edge, mtf=np.where(edge.frequencies_cy_px < 0.3, 0.8, np.nan)),
                         "mtf_nyquist") == "undefined"


def test_the_header_counts_every_warning_and_drops_none_unsaid():
    from imgmtf.plot._common import HEADER_WARNINGS
    from imgmtf.plot.measurement import plot_measurement
    from imgmtf.plot.scan import _overlap
    result = _measured(6.0)
    warnings = [f"note {k}" for k in range(HEADER_WARNINGS + 2)]
    warnings[1] = "note 1 " + "long " * 40 + "its advice at the end"
    fig = plot_measurement(result, warnings=warnings)
    header = fig.get_suptitle()
    assert f"warning 1 of {len(warnings)}: note 0" in header and "note 2" in header
    assert "its advice at the end" in header and max(map(len, header.splitlines())) <= 150   # wrapped, not cut
    fig.draw_without_rendering()            # the MTF panel's legend below it, off the curve and its markers
    mtf = fig.axes[3]
    assert _overlap(mtf.get_legend().get_window_extent(), mtf.get_window_extent()) == 0
    assert "and 2 more warning(s)" in header and "note 3" not in header
    assert "warning" not in plot_measurement(result).get_suptitle()


def test_measures_figure_counts_the_files_own_warnings(tmp_path, monkeypatch):
    """A photo measured on its luminance: the figure's header counts the
    luminance warning the text table prints beside the SNR one."""
    from pathlib import Path

    import imgmtf.plot
    from imgmtf.batch import measure_file
    drawn = {}
    real = imgmtf.plot.plot_measurement

    def spy(result, **kwargs):
        drawn.update(kwargs)
        return real(result, **kwargs)
    monkeypatch.setattr(imgmtf.plot, "plot_measurement", spy)
    photo = Path(__file__).parent.parent / "data" / "x2084_y0616_F2.png"
    [record] = measure_file(photo, plot_path=str(tmp_path / "f2.png"))
    assert record.plot and len(record.get("warnings")) == 2
    assert drawn["warnings"] == record.get("warnings") and "luminance" in drawn["warnings"][-1]


def test_the_scan_legend_lists_ids_in_runs_and_counts_the_common_reasons():
    from imgmtf.plot.scan import MAX_LISTED, _legend_label
    group = [{"id": i} for i in (3, 4, 9, 10, 12, 13, 14, 15, 16)]
    assert _legend_label("angle", group) == "angle (9)\n3-4, 9-10, 12-16"
    assert _legend_label("too-short", [{"id": i} for i in range(MAX_LISTED + 1)]) == f"too-short ({MAX_LISTED + 1})"


def test_locations_are_drawn_where_the_image_has_them():
    """Measured through an ROI, the edge's locations are drawn in the
    image's pixel coordinates, not the ROI's (a scan's edge figures: the
    scene's)."""
    chip = im.render(im.Sensor(), im.Target("edge", 6.0, 200.0, 1200.0), 100, noise_std_dn=2.0, seed=1)
    whole, part = im.measure_edge(chip.image), im.measure_edge(chip.image, roi=(20, 10, 60, 80))
    lines = []
    for result in (whole, part):
        ax = Figure().subplots()
        plot_locations(result, ax)
        lines.append(next(ln for ln in ax.get_lines() if ln.get_label() == "least-squares line"))
    (xw, yw), (xp, yp) = [(ln.get_xdata(), ln.get_ydata()) for ln in lines]
    assert yp.min() == 10 and yp.max() == 89 and 20 < xp.min() < xp.max() < 80
    assert np.interp(50.0, yp, xp) == __import__("pytest").approx(np.interp(50.0, yw, xw), abs=0.05)


def test_the_fit_figure_draws_the_models_interval_and_the_truth_with_short_titles(tmp_path):
    """fit.png: the model's interval drawn (and magnified about Nyquist),
    the truth of a simulated chip beside it, titles short enough not to
    run into each other, the frequency in cy/px as everywhere else."""
    from click.testing import CliRunner

    import imgmtf.plot
    from imgmtf.batch import file_truth
    from imgmtf.cli import main
    from imgmtf.plot import plot_fit
    folder = tmp_path / "a_long_folder_name_as_real_data_have"
    folder.mkdir()
    paths = [folder / "scene_2024_05_01_T10_across_track_edge.tif", folder / "along.tif"]
    for path, angle in zip(paths, ("5", "84")):
        assert CliRunner().invoke(main, ["simulate", "--angle", angle, "--size", "60", "--noise-std", "5",
                                         "--seed", "1", "--out", str(path)]).exit_code == 0
    fit = im.fit_sensor([str(p) for p in paths], stages="optics")
    truths = [file_truth(str(p)) for p in paths]
    assert all(truths) and file_truth(str(tmp_path / "missing.tif")) is None
    fig = plot_fit(fit, truths=truths)
    ax = fig.axes[0]
    labels = ax.get_legend_handles_labels()[1]
    assert any(label.startswith("true: 0.26") for label in labels)
    assert any(label.startswith("model's 95 % interval") for label in labels)
    assert ax.get_xlabel() == "frequency along the normal (cy/px)"
    assert ax.get_title().splitlines()[0] == "scene_2024_...ack_edge.tif" and "folder" not in ax.get_title()
    inset = ax.child_axes[0]
    assert inset.get_xlim() == (0.47, 0.53) and inset.collections          # the band, magnified
    fig.canvas.draw()
    boxes = [a.title.get_window_extent() for a in fig.axes[:2]]
    assert boxes[0].x1 < boxes[1].x0                                           # titles apart
    # two edges, residuals and PSF: a 2 x 2 page, not a strip of four panels whose text shrinks when shown
    assert fig.get_figwidth() / fig.get_figheight() < 1.2
    assert imgmtf.plot.plot_fit is plot_fit


def test_a_quick_runs_threshold_figure_says_na_as_its_report_does():
    from imgmtf.plot import plot_threshold
    found = {"msg": {"threshold": 200.0, "fractions": {100: 0.9, 200: 1.0}}}
    quick = plot_threshold(found, 0.05, 0.95, 8, thresholds=False).axes[0].get_legend_handles_labels()[1]
    full = plot_threshold(found, 0.05, 0.95, 100).axes[0].get_legend_handles_labels()[1]
    assert quick[0] == "msg: threshold n/a (too few chips)" and full[0] == "msg: threshold SNR 200"


def test_the_sensor_figures_legends_lie_off_the_curves():
    """The LSF panel's legend is not where the FWHM is read (the half
    maximum): it lies under the axes, as the MTF panels' do."""
    from imgmtf.plot import plot_sensor
    fig = plot_sensor(im.Sensor())
    fig.canvas.draw()
    for ax in fig.axes[1:4]:
        assert ax.get_legend().get_window_extent().y1 < ax.get_window_extent().y0
    assert fig.axes[2].get_xlabel() == "frequency (cy/px)"
    assert min(ax.get_tightbbox().x0 for ax in fig.axes) >= 0          # nothing cut at the left edge


def test_the_sections_figure_draws_each_assumption_and_the_measured_sections():
    from imgmtf.errors import ParameterError
    from imgmtf.estimate.mtf2d import mtf2d_from_sections, sd_from_nyquist
    from imgmtf.plot import plot_sections
    f = np.linspace(0.0, 1.0, 101)
    normals = [16.8, -73.2]
    m = np.array([np.sinc(f) * np.exp(-2 * (f * np.cos(np.radians(a))) ** 2 - 3 * (f * np.sin(np.radians(a))) ** 2)
                  for a in normals])
    result = mtf2d_from_sections(normals, f, m, sd_from_nyquist([0.01, 0.01], f), draws=20)
    ax = plot_sections(result, (f, m)).axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[:2] == ["measured along 16.8 deg", "measured along -73.2 deg"]
    assert "across, bracket (chosen)" in labels and "along, elliptical" in labels
    assert len(ax.collections) == 2           # the chosen assumption's intervals, across and along
    with pytest.raises(ParameterError, match="MTF2D"):
        plot_sections("not a result")


def test_the_point_figure_keeps_its_panels_labels_on_the_page_and_its_truth_above_the_curves():
    """The 2-D MTF panel's colour bar once pushed its y tick labels and axis
    label off the figure's left edge; the truth, drawn in the curves'
    colour under them, did not show."""
    from imgmtf.estimate.mtf2d import measure_points
    from imgmtf.plot.points import plot_points
    from imgmtf.sensor.points import PointArray, render_points
    sensor = im.Sensor()
    chip = render_points(sensor, PointArray(3, 3), 48)
    fig = plot_points(measure_points(chip.image, intervals="none"), chip.image,
                      truth=lambda f, angle: abs(sensor.normal_transfer(f, angle)))
    fig.draw_without_rendering()
    renderer = fig._get_renderer()
    page = fig.bbox
    for ax in fig.axes:
        box = ax.get_tightbbox(renderer)
        assert page.x0 - 1 <= box.x0 and box.x1 <= page.x1 + 1, ax.get_title()
    mtf = next(ax for ax in fig.axes if ax.get_title().startswith("MTF from"))
    truths = [line for line in mtf.lines if line.get_label().startswith("truth")]
    measured = [line for line in mtf.lines if "at Nyquist" in line.get_label()]
    assert len(truths) == len(measured) == 2
    assert min(t.get_zorder() for t in truths) > max(m.get_zorder() for m in measured)
    assert all(t.get_linestyle() != "-" and t.get_color() not in {m.get_color() for m in measured} for t in truths)


def test_the_star_figure_draws_its_truth_above_the_curves():
    """The truth, in each direction's colour under its curve, did not show."""
    from imgmtf.plot.star import plot_star_mtf
    sensor = im.Sensor()
    chip = im.render_star(sensor, im.SiemensStar(cycles=32), 101)
    truth = lambda f, angle: abs(sensor.normal_transfer(f, angle))  # noqa: E731
    ax = plot_star_mtf(im.measure_star(chip.image), truth=truth).axes[0]
    measured = [line for line in ax.lines if line.get_linestyle() == "-" and line.get_label()[0] != "_"]
    truths = [line for line in ax.lines if line.get_linestyle() == "--" and len(line.get_xdata())]
    assert len(truths) == len(measured) > 1
    assert all(t.get_color() == "black" for t in truths)
    assert min(t.get_zorder() for t in truths) > max(m.get_zorder() for m in measured)


def test_a_scan_overview_of_a_checkerboard_crop_puts_its_target_label_beside_the_image():
    """One target whose half-edges cross the whole image (Baotou's crop):
    no spot inside is free, so the label goes right of the image and the
    target carries its id only, off its half-edges."""
    from matplotlib.offsetbox import AnchoredText

    from imgmtf.plot import plot_scan
    ends = [(50.0, 0.0), (0.0, 50.0), (50.0, 99.0), (99.0, 50.0)]
    accepted = [{"id": k, "status": "accepted", "x0_px": 50.0, "y0_px": 50.0, "x1_px": a, "y1_px": b}
                for k, (a, b) in enumerate(ends, 1)]
    target = [{"scope": "target", "target_id": 1, "x_px": 50.0, "y_px": 50.0, "summary": "sections",
               "direction": d, "assumption": "bracket", "chosen_assumption": "bracket", "recommended": True,
               "mtf_nyquist": 0.2, "mtf50_cy_px": 0.3} for d in ("across-track", "along-track")]
    fig = plot_scan(np.zeros((100, 100)), 1.0, accepted, target, width_in=4.5)    # an image 1.4 in wide
    ax = fig.axes[0]
    fig.draw_without_rendering()
    aside = [a for a in ax.artists if isinstance(a, AnchoredText)]
    assert len(aside) == 1 and "*across (bracket): 0.200 | 0.300" in aside[0].txt.get_text()
    assert aside[0].get_window_extent().x0 >= ax.get_window_extent().x1
    tag = next(t for t in ax.texts if t.get_text().startswith("T1"))
    assert tag.get_text() == "T1"
    box = tag.get_window_extent()
    for a, b in ends:
        for f in np.linspace(0.0, 1.0, 30):
            px, py = ax.transData.transform((50 + f * (a - 50), 50 + f * (b - 50)))
            assert not (box.x0 < px < box.x1 and box.y0 < py < box.y1)


def test_the_point_and_star_headers_wrap_a_long_warning():
    from imgmtf.estimate.mtf2d import measure_points
    from imgmtf.plot.points import plot_points
    from imgmtf.plot.star import plot_star
    from imgmtf.sensor.points import PointArray, render_points
    long = "long " * 60 + "its advice at the end"
    star = im.render_star(im.Sensor(), im.SiemensStar(cycles=32), 101)
    chip = render_points(im.Sensor(), PointArray(3, 3), 48)
    for fig in (plot_star(im.measure_star(star.image), warnings=[long]),
                plot_points(measure_points(chip.image, intervals="none"), warnings=[long])):
        header = fig.get_suptitle()
        assert "its advice at the end" in header and max(map(len, header.splitlines())) <= 150


def test_a_scan_overview_s_target_label_leaves_its_roi_s_outline_clear():
    """A target's label sat where it covered no half-edge but its ROI's dashed outline."""
    from matplotlib.text import Text

    from imgmtf.plot import plot_scan
    roi = [[40.0, 0.0], [60.0, 0.0], [60.0, 56.0], [40.0, 56.0]]
    accepted = [{"id": 1, "status": "accepted", "x0_px": 50.0, "y0_px": 50.0, "x1_px": 50.0, "y1_px": 2.0,
                 "roi_polygon_px": roi}]
    target = [{"scope": "target", "target_id": 1, "x_px": 50.0, "y_px": 50.0, "summary": "combined",
               "direction": "across-track", "normal_angle_deg": 0.0, "mtf_nyquist": 0.2, "mtf50_cy_px": 0.3}]
    ax = plot_scan(np.zeros((100, 200)), 1.0, accepted, target, width_in=8.0).axes[0]
    ax.figure.draw_without_rendering()
    box = Text.get_window_extent(next(t for t in ax.texts if t.get_text().startswith("T1")))
    for k in range(4):
        for f in np.linspace(0.0, 1.0, 40):
            (x0, y0), (x1, y1) = roi[k - 1], roi[k]
            px, py = ax.transData.transform((x0 + f * (x1 - x0), y0 + f * (y1 - y0)))
            assert not (box.x0 < px < box.x1 and box.y0 < py < box.y1)


def test_a_target_label_beside_the_image_goes_below_a_tall_legend():
    from matplotlib.offsetbox import AnchoredText

    from imgmtf.plot import plot_scan
    from imgmtf.plot.scan import _overlap
    ends = [(50.0, 0.0), (0.0, 50.0), (50.0, 99.0), (99.0, 50.0)]     # a checkerboard's crop: no free spot
    accepted = [{"id": k, "status": "accepted", "x0_px": 50.0, "y0_px": 50.0, "x1_px": a, "y1_px": b}
                for k, (a, b) in enumerate(ends, 1)]
    rejected = [{"id": 5 + k, "status": "rejected", "reason": f"reason-{k}", "x0_px": 5.0 + 8 * k, "y0_px": 90.0,
                 "x1_px": 8.0 + 8 * k, "y1_px": 98.0} for k in range(6)]
    target = [{"scope": "target", "target_id": 1, "x_px": 50.0, "y_px": 50.0, "summary": "sections",
               "direction": d, "assumption": "bracket", "chosen_assumption": "bracket", "recommended": True,
               "mtf_nyquist": 0.2, "mtf50_cy_px": 0.3} for d in ("across-track", "along-track")]
    ax = plot_scan(np.zeros((100, 100)), 1.0, accepted + rejected, target, width_in=6.0).axes[0]
    ax.figure.draw_without_rendering()
    [aside] = [a for a in ax.artists if isinstance(a, AnchoredText)]
    assert _overlap(aside.get_window_extent(), ax.get_legend().get_window_extent()) == 0
    assert aside.get_window_extent().y0 >= 0


def test_the_measurement_figure_s_profile_and_lsf_legends_sit_under_their_axes_off_the_data():
    """A double bar's profile fills its panel: 'best' put the legend over the pixels."""
    from imgmtf.plot import plot_measurement
    from imgmtf.plot.scan import _overlap
    chip = im.render(im.Sensor(), im.Target("edge", 6.0), 40, noise_std_dn=2.0, seed=1)
    fig = plot_measurement(im.measure_edge(chip.image))
    fig.draw_without_rendering()
    for ax in fig.axes[1:3]:            # the profile, the LSF
        assert _overlap(ax.get_legend().get_window_extent(), ax.get_window_extent()) == 0


def test_the_ids_of_short_collinear_candidates_stack_apart_instead_of_over_each_other():
    """A road's short pieces, each rejected: their ids sat on one another."""
    from matplotlib.text import Text

    from imgmtf.plot import plot_scan
    from imgmtf.plot.scan import _overlap
    pieces = [{"id": 100 + k, "status": "rejected", "reason": "angle", "x0_px": 200.0 + 4 * k, "y0_px": 300.0,
               "x1_px": 203.0 + 4 * k, "y1_px": 300.0} for k in range(4)]
    ax = plot_scan(np.zeros((600, 600)), 1.0, pieces).axes[0]
    ax.figure.draw_without_rendering()
    boxes = [Text.get_window_extent(t) for t in ax.texts if t.get_text().isdigit()]
    assert len(boxes) == 4 and all(_overlap(a, b) == 0 for i, a in enumerate(boxes) for b in boxes[i + 1:])
