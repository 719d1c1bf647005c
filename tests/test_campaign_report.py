"""The campaign report and the commands that fill a store: report's files,
a self-contained page, the figures; measure and fit with --campaign."""
import csv
import dataclasses
import re
from types import SimpleNamespace

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner

import imgmtf
from imgmtf.campaign.acquisitions import Acquisition
from imgmtf.campaign.report import write_report
from imgmtf.campaign.store import read_layer, write_acquisition
from imgmtf.campaign.trend import TREND_COLUMNS
from imgmtf.cli import main
from imgmtf.errors import ParameterError
from imgmtf.plot.campaign import plot_campaign, plot_trend
from imgmtf.records import Record

SLOPE = -0.02                   # MTF at Nyquist per year of the synthetic campaign


def fit_row(direction, value, half=0.004, plot=None):
    return Record("scene.tif", 1, "edge", "", "fitted",
                  figures={"summary": "fit", "direction": direction, "mtf_nyquist": value,
                           "mtf_nyquist_ci": [value - half, value + half], "mtf50_cy_px": 0.3 + value / 4,
                           "mtf50_ci_cy_px": [0.29 + value / 4, 0.31 + value / 4], "fwhm_px": 1.6 - value,
                           "rer": 0.4 + value, "constrained": True},
                  site={"scope": "scene"}, plot=plot)


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """Five yearly acquisitions whose MTF at Nyquist falls SLOPE a year
    (dates one year of 365.25 days apart), and one without a time."""
    tmp_path = tmp_path_factory.mktemp("campaign")
    figure = tmp_path / "edge.png"
    imgmtf.write_png(figure, np.tile(np.arange(64, dtype=np.uint8) * 4, (32, 1)))
    path = tmp_path / "site.gpkg"
    for k in range(5):
        when = np.datetime64("2020-01-01T00:00:00") + np.timedelta64(int(k * 365.25 * 86400), "s")
        acquisition = Acquisition(f"a{k}", f"scene{k}.tif", "0" * 64, f"{when}Z", "Simsat-1", "PAN", "pan",
                                  overview=str(figure) if k == 0 else None)
        write_acquisition(path, acquisition, [], [fit_row("across-track", 0.30 + SLOPE * k, plot=str(figure)),
                                                  fit_row("along-track", 0.28 + SLOPE * k)])
    write_acquisition(path, Acquisition("untimed", "old.tif", "1" * 64, None, "Simsat-1", None, "pan"), [],
                      [fit_row("across-track", 0.5)])
    return path


@pytest.fixture(scope="module")
def written(store, tmp_path_factory):
    """The report of ``store``, with a requirement and the default sensor as the baseline."""
    toml = tmp_path_factory.mktemp("sensor") / "sensor.toml"
    imgmtf.Sensor().to_toml(toml)
    return write_report(store, tmp_path_factory.mktemp("report"), requirement=0.2, baseline=toml)


def test_the_report_writes_trends_and_a_self_contained_page(written):
    with open(written.trend_csv, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == TREND_COLUMNS
    nyquist = {r["direction"]: r for r in rows if r["figure"] == "mtf_nyquist"}
    assert set(nyquist) == {"across-track", "along-track"}
    for r in nyquist.values():
        assert float(r["slope_per_year"]) == pytest.approx(SLOPE, rel=1e-4)
        assert r["drift"] == "True" and r["n_acquisitions"] == "5" and r["method"] == "fit"
    page = open(written.report_html, encoding="utf-8").read()
    assert "<script" not in page and "<link" not in page and "@import" not in page
    assert not re.search(r"(src|href)\s*=\s*[\"']?(https?:)?//", page) and "url(" not in page
    sources = re.findall(r"<img [^>]*src=\"([^\"]*)\"", page)
    assert all(s.startswith("data:image/png;base64,") for s in sources)
    assert len(sources) == 2 + 1 + 5     # a figure per direction, the overview, each acquisition's edge figure
    assert "1 without an acquisition time" in page and "no time" in page
    assert "Simsat-1, band pan: across-track, scene, fit" in page


def test_a_baseline_sensor_gives_the_prelaunch_values(written):
    page = open(written.report_html, encoding="utf-8").read()
    sensor = imgmtf.Sensor()
    assert f"across-track {sensor.mtf_nyquist('across'):.4f}" in page
    assert f"along-track {sensor.mtf_nyquist('along'):.4f}" in page


def test_an_empty_store_gives_a_report_that_says_so(tmp_path):
    from imgmtf.campaign.store import ensure_store
    ensure_store(tmp_path / "empty.gpkg")
    written = write_report(tmp_path / "empty.gpkg", tmp_path / "out")
    assert open(written.trend_csv).read().strip() == ",".join(TREND_COLUMNS)
    assert "holds no acquisition" in open(written.report_html).read()


def test_trend_figures_draw_points_line_requirement_and_baseline(store):
    rows = [r for r in read_layer(store, "targets") if r["direction"] == "across-track" and r["acquired_utc"]]
    from imgmtf.campaign.trend import trends
    found = [t for t in trends(rows) if t.figure == "mtf_nyquist"]
    fig = plot_trend(rows, trend=found[0], requirement=0.2, baseline=0.31)
    ax = fig.axes[0]
    flat = sorted(round(float(line.get_ydata()[0]), 6) for line in ax.lines if len(set(line.get_ydata())) == 1)
    assert flat == [0.2, 0.31]                           # the requirement and the pre-launch value
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("/year" in label and "drift" in label for label in labels)
    assert ax.get_ylabel() == "MTF at Nyquist"
    grid = plot_campaign(rows, found, requirement=0.2, title="t")
    assert [a.get_ylabel() for a in grid.axes] == ["MTF at Nyquist", "MTF50 (cycles/pixel)",
                                                   "FWHM of the LSF (px)", "RER (relative edge response)"]
    with pytest.raises(ParameterError, match="figure must be one of"):
        plot_trend(rows, "mtf10")


def test_the_report_command(tmp_path):
    store = tmp_path / "small.gpkg"                       # one direction: one figure to draw
    for k in range(3):
        write_acquisition(store, Acquisition(f"a{k}", "s.tif", "0" * 64, f"{2020 + k}-01-01T00:00:00Z", "Simsat-1",
                                             None, "pan"), [], [fit_row("across-track", 0.30 + SLOPE * k)])
    result = CliRunner().invoke(main, ["report", str(store), "--out", str(tmp_path / "per"),
                                       "--requirement", "across=0.25,along=0.1"])
    assert result.exit_code == 0, result.output
    assert "drift: Simsat-1, band pan, across-track, scene, fit: MTF at Nyquist -0.0200/year" in result.output
    assert (tmp_path / "per" / "report.html").is_file() and (tmp_path / "per" / "trend.csv").is_file()
    missing = CliRunner().invoke(main, ["report", str(tmp_path / "none.gpkg"), "--out", str(tmp_path / "o")])
    assert missing.exit_code == 1 and "none.gpkg: no such campaign store" in missing.output
    bad = CliRunner().invoke(main, ["report", str(store), "--out", str(tmp_path / "o"), "--requirement", "nan"])
    assert bad.exit_code == 2
    page = (tmp_path / "per" / "report.html").read_text(encoding="utf-8")
    assert "at least across-track 0.25, along-track 0.1." in page
    assert '<span class="pass">pass</span> (&ge; 0.25)' in page      # the latest, 0.26 +- 0.004
    wrong = CliRunner().invoke(main, ["report", str(store), "--out", str(tmp_path / "o"), "--requirement", "across"])
    assert wrong.exit_code == 2 and "DIRECTION=MTF" in wrong.output


def chip(path, angle, when=None, sigma=0.4):
    sensor = imgmtf.Sensor(optics_sigma_x_m=sigma, optics_sigma_y_m=sigma)
    imgmtf.write_geotiff(path, imgmtf.render(sensor, imgmtf.Target("edge", angle), 64).image)
    if when:
        with rasterio.open(path, "r+") as dst:
            dst.update_tags(ACQUISITION_DATETIME=when, PLATFORM="Simsat-1", BAND_NAME="pan")
    return str(path)


def test_measure_adds_each_chip_once_and_says_once_which_have_no_time(tmp_path):
    store = str(tmp_path / "c.gpkg")
    timed = chip(tmp_path / "timed.tif", 6.0, "2022-05-01T10:00:00Z")
    plain = [chip(tmp_path / f"plain{k}.tif", 6.0 + k) for k in range(2)]
    for _ in range(2):                                    # the second run replaces the first's rows
        result = CliRunner().invoke(main, ["measure", timed, *plain, "--campaign", store])
        assert result.exit_code == 0, result.output
    assert result.output.count("no acquisition time") == 1 and "give --acquired" in result.output
    assert len(read_layer(store, "acquisitions")) == 3 and len(read_layer(store, "edges")) == 3
    [row] = [r for r in read_layer(store, "edges") if r["acquired_utc"]]
    assert (row["platform"], row["band_name"], row["direction"], row["acquired_utc"]) == (
        "Simsat-1", "pan", "across-track", "2022-05-01T10:00:00Z")
    named = CliRunner().invoke(main, ["measure", plain[0], "--campaign", store, "--acquired", "2021-02-03",
                                      "--platform", "Other", "--band-name", "B8", "--instrument", "X"])
    assert named.exit_code == 0 and "no acquisition time" not in named.output
    bad = CliRunner().invoke(main, ["measure", plain[0], "--campaign", store, "--acquired", "31/12/2021"])
    assert bad.exit_code == 2 and "'31/12/2021' is not an ISO 8601 date or time" in bad.output


def test_fit_adds_one_acquisition_with_its_across_and_along_rows(tmp_path):
    store = str(tmp_path / "c.gpkg")
    when = "2023-03-15T09:00:00Z"
    files = [chip(tmp_path / "across.tif", 6.0, when), chip(tmp_path / "along.tif", -84.0, when)]
    result = CliRunner().invoke(main, ["fit", *files, "--campaign", store])
    assert result.exit_code == 0, result.output
    rows = read_layer(store, "targets")
    assert sorted((r["direction"], r["method"], r["acquired_utc"]) for r in rows) == [
        ("across-track", "fit", when), ("along-track", "fit", when)]
    truth = imgmtf.Sensor(optics_sigma_x_m=0.4, optics_sigma_y_m=0.4)
    across = next(r for r in rows if r["direction"] == "across-track")
    assert across["mtf_nyquist"] == pytest.approx(truth.mtf_nyquist("across"), abs=0.01)
    assert across["mtf_nyquist_ci_low"] < across["mtf_nyquist"] < across["mtf_nyquist_ci_high"]
    other = chip(tmp_path / "later.tif", -84.0, "2024-01-01")
    mixed = CliRunner().invoke(main, ["fit", files[0], other, "--campaign", store])
    assert mixed.exit_code == 1 and "different acquisitions" in mixed.output


def test_a_fit_that_misfits_is_marked(store):
    rows = [dict(r) for r in read_layer(store, "targets") if r["direction"] == "along-track"]
    rows[1]["misfit"] = 1
    ax = plot_trend(rows).axes[0]
    crosses = [line for line in ax.lines if line.get_marker() == "x"]
    assert len(crosses) == 1 and len(crosses[0].get_xdata()) == 1
    assert "the model misfits: may be biased" in [t.get_text() for t in ax.get_legend().get_texts()]


def test_the_page_embeds_the_latest_acquisitions_figures_only(tmp_path):
    from imgmtf.campaign.report import MAX_ACQUISITIONS_WITH_FIGURES
    figure = tmp_path / "overview.png"
    imgmtf.write_png(figure, np.zeros((8, 8), np.uint8))
    store = tmp_path / "many.gpkg"
    count = MAX_ACQUISITIONS_WITH_FIGURES + 2
    for k in range(count):
        write_acquisition(store, Acquisition(f"a{k}", f"s{k}.tif", "0" * 64, f"{2000 + k}-01-01", overview=str(figure)),
                          [], [])
    page = open(write_report(store, tmp_path / "out").report_html, encoding="utf-8").read()
    assert page.count("<img ") == MAX_ACQUISITIONS_WITH_FIGURES
    assert "2 earlier ones" in page and f"{2000 + count - 1}-01-01: s{count - 1}.tif" in page
    assert "2000-01-01: s0.tif" not in page


def direction_row(direction, value, method, *, misfit=None, recommended=None, assumption=None, plot=None):
    figures = {"summary": method, "direction": direction, "mtf_nyquist": value,
               "mtf_nyquist_ci": [value - 0.004, value + 0.004], "fwhm_px": 1.5}
    if misfit is not None:
        figures["misfit"] = misfit
    if recommended is not None:
        figures.update(recommended=recommended, recommended_because="the data decide")
    if assumption:
        figures["assumption"] = assumption
    return Record("scene.tif", 1, "edge", "", "fitted" if method == "fit" else "combined", figures=figures,
                  site={"scope": "scene"}, plot=plot)


@pytest.fixture(scope="module")
def real_like(tmp_path_factory):
    """Three yearly acquisitions as the real chips give them: across track a
    misfit fit and the recommended model-free sections; along track only a
    misfit fit; and one acquisition of another platform: the report the
    command writes (its files, and what it prints in ``output``)."""
    tmp_path = tmp_path_factory.mktemp("real")
    store = tmp_path / "site.gpkg"
    for k in range(3):
        rows = [direction_row("across-track", 0.002, "fit", misfit=True, recommended=False),
                direction_row("across-track", 0.12 - 0.02 * k, "sections", recommended=True, assumption="bracket"),
                direction_row("along-track", 0.003, "fit", misfit=True, recommended=False)]
        write_acquisition(store, Acquisition(f"a{k}", f"s{k}.tif", "0" * 64, f"{2020 + k}-06-01", "Sat-A"), [], rows)
    write_acquisition(store, Acquisition("b0", "b.tif", "1" * 64, "2021-01-01", "Sat-B"), [],
                      [direction_row("across-track", 0.09, "combined")])
    out = tmp_path / "report"
    result = CliRunner().invoke(main, ["report", str(store), "--out", str(out), "--requirement", "0.105"])
    assert result.exit_code == 0, result.output
    return SimpleNamespace(report_html=str(out / "report.html"), trend_csv=str(out / "trend.csv"),
                           output=result.output)


def test_the_drift_table_quotes_the_recommended_rows_and_marks_the_others(real_like):
    page = open(real_like.report_html, encoding="utf-8").read()
    table = page[page.index("<h2>Drift of the MTF at Nyquist"):page.index("<h2>Figures of merit")]
    rows = re.findall(r"<tr class=\"([^\"]*)\">(.*?)</tr>", table)
    cells = [(kind, re.sub(r"<[^>]+>", "", row)) for kind, row in rows]
    assert [(kind, "recommended" in text, "Sat-A" in text) for kind, text in cells] == [
        ("drift", True, True), ("misfit", False, True), ("misfit", False, True), ("", True, False)]
    assert "sections (bracket)" in cells[0][1] and "misfit" in cells[1][1] and "nothing to quote" not in cells[1][1]
    assert "only misfit rows:nothing to quote" in cells[2][1]            # along track: the fit alone, misfit
    assert "misfit: not trended" in cells[2][1]
    assert "one acquisition: no slope" in cells[3][1]
    # the requirement judged on the latest acquisition: 0.08 +- 0.004 against 0.105 fails; 0.09 fails
    assert re.findall(r'<span class="(pass|fail|undecided)">', table) == ["fail", "fail"]
    # one figure: the recommended series of Sat-A across track, and Sat-B's single point; nothing misfit drawn
    drawn = re.findall(r'<div class="figure"><h3>([^<]*)</h3>', page)
    assert drawn == ["Sat-A: across-track, scene, sections (bracket)", "Sat-B: across-track, scene, combined"]


def test_the_command_says_which_directions_have_only_misfit_rows(real_like):
    assert "note: Sat-A, along-track: only misfit rows, nothing to quote or trend" in real_like.output
    assert real_like.output.count("note:") == 1
    assert "drift: Sat-A, across-track, scene, sections: MTF at Nyquist -0.0200/year" in real_like.output


def test_trend_csv_holds_every_group_with_method_assumption_recommended_and_misfit(real_like):
    with open(real_like.trend_csv, newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["figure"] == "mtf_nyquist"]
    got = sorted((r["sensor"], r["direction"], r["method"], r["assumption"], r["recommended"], r["misfit"],
                  r["slope_per_year"] != "", r["meets_requirement"]) for r in rows)
    assert got == [("Sat-A", "across-track", "fit", "", "False", "True", False, ""),
                   ("Sat-A", "across-track", "sections", "bracket", "True", "False", True, "fail"),
                   ("Sat-A", "along-track", "fit", "", "False", "True", False, ""),
                   ("Sat-B", "across-track", "combined", "", "True", "False", False, "fail")]


def test_a_scenes_and_a_targets_recommended_rows_are_told_apart_by_their_scope(tmp_path):
    # a scan recommends one row per scope: here the scene's sections and its target's fit, equal values
    store = tmp_path / "site.gpkg"
    for k in range(3):
        value = 0.3 - 0.01 * k
        target = dataclasses.replace(direction_row("across-track", value, "fit", recommended=True),
                                     site={"scope": "target", "target_id": 1})
        rows = [direction_row("across-track", value, "sections", recommended=True, assumption="bracket"), target]
        write_acquisition(store, Acquisition(f"a{k}", f"s{k}.tif", "0" * 64, f"{2020 + k}-06-01", "S"), [], rows)
    written = write_report(store, tmp_path / "report")
    assert sorted((t.scope, t.method) for t in written.trends if t.figure == "mtf_nyquist") == [
        ("scene", "sections"), ("targets", "fit")]
    page = open(written.report_html, encoding="utf-8").read()
    table = page[page.index("<h2>Drift of the MTF at Nyquist"):page.index("<h2>Figures of merit")]
    assert "<th>scope</th>" in table
    assert [re.findall(r"<td>(scene|targets)</td>", row) for row in re.findall(r"<tr class.*?</tr>", table)] == [
        ["scene"], ["targets"]]
    with open(written.trend_csv, newline="") as fh:
        assert {r["scope"] for r in csv.DictReader(fh)} == {"scene", "targets"}


def test_a_single_acquisition_is_a_point_not_a_line():
    from imgmtf.campaign.trend import trends
    rows = [{"acquisition_id": "a", "acquired_utc": "2021-06-01", "platform": "S", "direction": "across-track",
             "method": "combined", "mtf_nyquist": 0.1}]
    [trend] = [t for t in trends(rows) if t.figure == "mtf_nyquist"]
    ax = plot_trend(rows, trend=trend).axes[0]
    assert ax.lines and all(len(line.get_xdata()) == 1 for line in ax.lines)   # the point, no line through it
    assert not any("/year" in t.get_text() for t in ax.get_legend().get_texts())


def test_every_figure_opens_at_full_resolution_and_a_missing_one_is_reported(tmp_path):
    out = tmp_path / "scan"
    out.mkdir()
    for name in ("overview.png", "edge1.png", "edge2.png"):
        imgmtf.write_png(out / name, np.zeros((8, 8), np.uint8))
    store = tmp_path / "site.gpkg"
    rows = [direction_row("across-track", 0.3 - 0.01 * k, "combined", plot=str(out / f"edge{k + 1}.png"))
            for k in range(2)]
    for k, row in enumerate(rows):
        write_acquisition(store, Acquisition(f"a{k}", f"s{k}.tif", "0" * 64, f"{2020 + k}-01-01", "S",
                                             overview=str(out / "overview.png")), [], [row])
    (out / "edge2.png").unlink()                                        # moved away after the scan
    written = write_report(store, tmp_path / "report")
    page = open(written.report_html, encoding="utf-8").read()
    links = re.findall(r'<a href="([^"]+)"><img ', page)
    assert len(links) == page.count("<img ") == 1 + 2 + 1               # trend, two overviews, one edge figure
    assert all((tmp_path / "report" / link).is_file() for link in links)
    assert links[0].startswith("figures/") and links[1] == "../scan/overview.png"
    assert written.warnings == (f"{store}: figure scan/edge2.png is missing (looked for {out / 'edge2.png'}): "
                                "moved or deleted",)
    assert "1 figure(s) the store names are missing" in page and "<code title=" in page
    (tmp_path / "report" / "figures" / "07-trend.png").write_bytes(b"an earlier report's")
    result = CliRunner().invoke(main, ["report", str(store), "--out", str(tmp_path / "report")])
    assert sorted(p.name for p in (tmp_path / "report" / "figures").iterdir()) == ["01-trend.png"]
    assert result.exit_code == 0 and "warning: " in result.output and "edge2.png is missing" in result.output


def test_the_page_escapes_what_the_store_holds(tmp_path):
    # the template autoescapes: a platform or file name is text, never markup
    store = tmp_path / "site.gpkg"
    for k in range(2):
        write_acquisition(store, Acquisition(f"a{k}", f"<b>s{k}.tif", "0" * 64, f"{2020 + k}-01-01",
                                             "<script>alert(1)</script>"), [], [fit_row("across-track", 0.3)])
    page = open(write_report(store, tmp_path / "out").report_html, encoding="utf-8").read()
    assert "<script" not in page and "&lt;script&gt;alert(1)&lt;/script&gt;" in page and "&lt;b&gt;s1.tif" in page
