import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from imgmtf.cli import main


@pytest.fixture
def run():
    def invoke(*args):
        return CliRunner().invoke(main, [str(a) for a in args])
    return invoke


@pytest.fixture
def chip(run, tmp_path):
    path = tmp_path / "edge.tif"
    result = run("simulate", "--angle", 6, "--size", 64, "--seed", 1, "--out", path)
    assert result.exit_code == 0, result.output
    return path


def test_simulate_then_measure_json_contract(run, chip, tmp_path):
    result = run("measure", "--format", "json", chip)
    assert result.exit_code == 0
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert len(rows) == 1
    row = rows[0]
    for key in ("path", "target", "method", "normal_angle_deg", "orientation", "snr", "mtf_nyquist",
                "mtf50_cy_px", "fwhm_px", "rer", "mtfa", "gsd_m", "frequencies_cy_px", "mtf",
                "warnings", "imgmtf_version", "params", "band"):
        assert key in row
    assert row["path"] == str(chip) and row["target"] == "edge" and row["gsd_m"] == 1.0
    assert abs(row["normal_angle_deg"] - 6.0) < 0.05
    assert len(row["frequencies_cy_px"]) == len(row["mtf"]) and row["frequencies_cy_px"][-1] == 1.0


def test_batch_keeps_going_past_a_bad_file(run, chip, tmp_path):
    bad = tmp_path / "bad.tif"
    bad.write_text("junk")
    result = run("measure", "--format", "json", bad, chip, tmp_path / "missing.tif")
    assert result.exit_code == 1
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert [r["status"] for r in rows] == ["error", "ok", "error"]
    assert [r["reason"] for r in rows] == ["unreadable", None, "unreadable"]
    assert "bad.tif" in rows[0]["error"] and "no such file" in rows[2]["error"]


def test_a_file_that_cannot_be_read_is_an_error_line_on_stderr_as_scan_and_fit_say_it(run, chip, tmp_path):
    bad, missing, summary = tmp_path / "bad.tif", tmp_path / "missing.tif", tmp_path / "summary.csv"
    bad.write_text("junk")
    result = run("measure", bad, chip, missing, "--csv", summary)
    assert result.exit_code == 1
    assert "error" not in result.stdout and str(chip.name) in result.stdout       # the table: the chip alone
    errors = [line for line in result.stderr.splitlines() if line.startswith("imgmtf: error: ")]
    assert len(errors) == 2 and f"{bad}: not an image" in errors[0] and f"{missing}: no such file" in errors[1]
    rows = summary.read_text().splitlines()[1:]
    assert len(rows) == 3 and sum(",error," in row for row in rows) == 2             # no row lost in the CSV


def test_text_output_plots_and_methods_and_says_each_figure_it_writes_and_why_none(run, chip, tmp_path):
    png = tmp_path / "edge.png"
    result = run("measure", "--method", "sliding", "--plot", png, chip)
    assert result.exit_code == 0 and "MTF@Nyq" in result.stdout
    assert png.stat().st_size > 10_000 and f"wrote {png}" in result.stdout.splitlines()
    out_dir = tmp_path / "plots"
    assert run("measure", "--plot-dir", out_dir, chip, chip).exit_code == 0
    assert (out_dir / "edge_mtf.png").exists()
    bad = tmp_path / "bad.tif"
    bad.write_text("junk")
    result = run("measure", "--plot", tmp_path / "bad.png", bad)
    assert result.exit_code == 1 and not (tmp_path / "bad.png").exists()
    assert f"no figure written for {bad}" in result.stderr and "wrote" not in result.output


def test_plot_names_a_figure_per_band_apart():
    from imgmtf.batch import _band_plot_path
    assert _band_plot_path("a.png", 2, 3) == "a_b2.png" and _band_plot_path("a.png", 1, 1) == "a.png"
    assert _band_plot_path("d/x_mtf.png", 2, 3) == "d/x_b2_mtf.png"


def test_roi_and_band(run, chip):
    assert run("measure", "--roi", "0,0,64,64", "--band", 1, chip).exit_code == 0
    r = run("measure", "--band", 2, chip)
    assert r.exit_code == 1 and "band 2 does not exist" in r.stdout
    r = run("measure", "--roi", "1,2,3", chip)
    assert r.exit_code == 2


@pytest.mark.parametrize("args, message", [
    (["simulate", "--out", "{tmp}/no/such/dir/a.tif"], "cannot write"),
    (["simulate", "--sensor", "{tmp}/bad.toml", "--out", "{tmp}/a.tif"], "malformed TOML"),
    (["sensor", "--sensor", "{tmp}/missing.toml"], "cannot read"),
])
def test_bad_input_is_one_line_and_exit_1(run, tmp_path, args, message):
    (tmp_path / "bad.toml").write_text("[sensor\n")
    result = CliRunner().invoke(main, [a.format(tmp=tmp_path) for a in args])
    assert result.exit_code == 1
    assert message in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output


def test_usage_errors_exit_2(run):
    assert run("simulate").exit_code == 2                      # --out missing
    result = run("simulate", "--target", "pulse", "--pulse-width", "-2", "--out", "a.tif")
    assert result.exit_code == 2 and "a -2 px wide pulse" in result.stderr
    assert run("simulate", "--angle", "abc", "--out", "x.tif").exit_code == 2
    assert run("measure").exit_code == 2
    assert run("frobnicate").exit_code == 2


def test_sensor_command_prints_and_plots(run, tmp_path):
    result = run("sensor", "--plot", tmp_path / "s.png", "--save", tmp_path / "s.toml")
    assert result.exit_code == 0
    assert "system" in result.stdout and "0.2665" in result.stdout
    assert (tmp_path / "s.png").stat().st_size > 10_000
    assert run("sensor", "--sensor", tmp_path / "s.toml").exit_code == 0


def test_simulated_chip_describes_itself(run, tmp_path):
    from imgmtf.io import read_raster
    path = tmp_path / "p.tif"
    r = run("simulate", "--target", "pulse", "--pulse-width", "2.5m", "--gsd", "0.5", "--bits", "8",
            "--low", "20", "--high", "200", "--ground-noise", "--seed", "3", "--out", path)
    assert r.exit_code == 0, r.output
    raster = read_raster(path)
    assert raster.gsd_m == 0.5 and raster.dtype == "uint8"
    prov = raster.provenance
    assert prov["target"]["width_px"] == 5.0 and prov["seed"] == 3
    assert prov["ground_noise"] == {"layers": 20, "layer_variance_dn2": 100.0}
    assert np.nanmax(raster.data) <= 255


def test_pulse_measure_json_fields_and_width_units(run, tmp_path):
    path = tmp_path / "bar.tif"
    assert run("simulate", "--target", "pulse", "--pulse-width", "3", "--gsd", "0.5", "--size", 80,
               "--out", path).exit_code == 0              # a bare width is in px, as in measure
    for width in ("3px", "3", "1.5m"):
        r = run("measure", "--target", "pulse", "--pulse-width", width, "--format", "json", path)
        assert r.exit_code == 0, r.output
        row = json.loads(r.stdout)
        assert row["target"] == "pulse" and row["pulse_width_px"] == pytest.approx(3.0)
        assert row["usable_band_cy_px"] == pytest.approx(0.3027, abs=1e-3)
        assert row["width_estimated"] is False
    r = run("measure", "--target", "pulse", "--format", "json", path)
    assert json.loads(r.stdout)["width_estimated"] is True
    r = run("measure", "--target", "pulse", "--plot", tmp_path / "bar.png", path)
    header, units = [line for line in r.stdout.splitlines() if not line.startswith("paths below ")][:2]
    assert r.exit_code == 0 and header.split()[-1] == "W" and units.split()[-1] == "px"
    assert (tmp_path / "bar.png").exists()


def test_simulate_fits_its_default_step_to_the_bit_depth(run, tmp_path):
    path = tmp_path / "e8.tif"
    result = run("simulate", "--bits", 8, "--out", path)
    assert result.exit_code == 0 and "clipped" not in result.output
    r = run("measure", "--format", "json", path)
    assert r.exit_code == 0 and json.loads(r.stdout)["mtf_nyquist"] == pytest.approx(0.2667, abs=0.005)


def test_a_bar_whose_mtf50_hides_behind_its_sinc_prints_a_dash_on_the_ground(run, tmp_path):
    path = tmp_path / "bar3.tif"        # 3 px: the sinc's zero at 0.33 cy/px hides MTF50 (0.36)
    assert run("simulate", "--target", "pulse", "--pulse-width", "3", "--size", 100, "--noise-std", 2,
               "--seed", 1, "--out", path).exit_code == 0
    r = run("measure", "--target", "pulse", path)
    assert r.exit_code == 0, r.output
    assert "on the ground (GSD 1 m): MTF50 - cy/m, FWHM 1.2" in r.stdout


def test_pulse_width_errors(run, chip, tmp_path):
    r = run("measure", "--target", "pulse", "--pulse-width", "-1", chip)
    assert r.exit_code == 2 and "must be > 0" in r.stderr
    r = run("measure", "--target", "pulse", "--pulse-width", "15px", chip)
    assert r.exit_code == 2 and "below 0.1 cy/px" in r.stderr
    assert run("measure", "--target", "pulse", "--pulse-width", "wide", chip).exit_code == 2
    assert run("measure", "--pulse-width", "2", chip).exit_code == 2          # edge target
    png = tmp_path / "plain.png"
    import warnings

    import rasterio
    from rasterio.errors import NotGeoreferencedWarning
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(png, "w", driver="PNG", width=40, height=40, count=1, dtype="uint8") as dst:
            dst.write(np.full((1, 40, 40), 9, np.uint8))
    r = run("measure", "--target", "pulse", "--pulse-width", "2m", "--format", "json", png)
    assert r.exit_code == 1 and "needs a georeferenced image" in json.loads(r.stdout)["error"]


@pytest.mark.parametrize("args, words", [
    (["simulate", "--size", "100000", "--out", "a.tif"], "2<=x<=4096"),
    (["simulate", "--oversampling", "100000", "--out", "a.tif"], "1<=x<=100"),
    (["simulate", "--seed", "-1", "--out", "a.tif"], "x>=0"),
    (["simulate", "--angle", "120", "--out", "a.tif"], "-90<x<=90"),
    (["simulate", "--gsd", "-1", "--out", "a.tif"], "x>0"),
    (["simulate", "--noise-std", "nan", "--out", "a.tif"], "not a finite number"),
    (["measure", "--roi", "0,0,0,5", "x.tif"], "W, H >= 16 px"),
    (["measure", "--roi", "20,20,10,10", "x.tif"], "W, H >= 16 px (the smallest chip measured)"),
    (["measure", "--band", "0", "x.tif"], "numbered from 1"),
    (["scan", "--margin", "2", "x.tif"], "6<=x<=1000"),
])
def test_out_of_range_options_are_usage_errors_naming_the_limit(run, args, words):
    result = run(*args)
    assert result.exit_code == 2 and words in result.output and "Traceback" not in result.output


@pytest.mark.parametrize("args, words", [
    (["--gsd", "1e-9"], "check the stage parameters"),
    (["--target", "pulse", "--pulse-width", "1e-300px"], "narrower than the 0.2 px"),
])
def test_simulate_refuses_what_would_not_fit_before_allocating(run, tmp_path, args, words):
    result = run("simulate", *args, "--out", tmp_path / "a.tif")
    assert result.exit_code == 2 and words in result.stderr       # simulate reads no input: an option's fault
    assert result.stderr.strip().splitlines()[-1].startswith("Error: ") and not (tmp_path / "a.tif").exists()


def test_unwritable_outputs_are_named_before_any_work(run, chip, tmp_path):
    blocker = tmp_path / "afile.txt"
    blocker.write_text("x")
    for args in (["--plot-dir", blocker / "sub"], ["--csv", blocker / "sub" / "out.csv"],
                 ["--plot", blocker / "p.png"]):
        result = run("measure", *args, chip)
        assert result.exit_code == 1, args
        assert str(args[1]) in result.stderr and "Traceback" not in result.output
        assert len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("command", [["measure"], ["sensor"], ["fit"]])
def test_a_figure_with_an_unknown_suffix_is_refused_before_any_work(run, chip, tmp_path, command):
    out = tmp_path / "figure.txt"
    result = run(*command, "--plot", out, *([chip] if command != ["sensor"] else []))
    assert result.exit_code == 2 and f"{out}: a figure is written as png" in result.stderr
    assert result.stdout == "" and not out.exists()


def test_bootstrap_replicates_are_bounded_and_intervals_selectable(run, chip):
    result = run("measure", "--bootstrap", "100000", chip)
    assert result.exit_code == 2 and "100000 is not in the range 0 or 20<=x<=5000" in result.stderr
    for args, method in ((), "influence"), (("--intervals", "none"), "none"), (("--bootstrap", "50"), "bootstrap"):
        result = run("measure", "--format", "json", *args, chip)
        row = json.loads(result.stdout)
        assert result.exit_code == 0 and row["params"]["intervals"]["method"] == method
        assert (row["mtf_nyquist_ci"][0] is None) == (method == "none")
    result = run("measure", "--intervals", "none", "--bootstrap", "200", chip)
    assert result.exit_code == 2 and "--bootstrap 200 asks for bootstrap intervals" in result.output
    assert run("measure", "--intervals", "bootstrap", "--bootstrap", "50", chip).exit_code == 0


def test_workers_bound_is_the_pools_and_the_default_method_a_registered_one():
    from imgmtf import parallel
    from imgmtf.cli import options
    from imgmtf.estimate.resampling import METHODS
    assert options.MAX_WORKERS == parallel.MAX_WORKERS and options.DEFAULT_METHOD in METHODS


def test_a_batch_and_a_scan_start_their_workers_fork_server_before_they_load_numpy():
    # the server's imports (0.3-0.8 s) are the workers' start: they begin as the command does, beside
    # the parent's own, not after its options are parsed with NumPy loaded (the method registry's, a
    # batch's readers, a scan's modules)
    import subprocess
    import sys
    for command in (["measure", "--workers", "2", "chip.tif", "other.tif"], ["scan", "chart.tif"]):
        code = ("import sys, imgmtf.parallel as parallel; "
                "parallel.prestart_workers = lambda *a: (print(sorted(m for m in ('numpy', 'scipy', 'cv2', "
                "'rasterio') if m in sys.modules)), sys.exit(0)); "
                f"from imgmtf.cli import main; main({command!r})")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
        assert out.returncode == 0 and out.stdout.strip() == "[]", (command, out.stdout, out.stderr)


def test_binary_sensor_file_is_one_line(run, tmp_path):
    toml = tmp_path / "bin.toml"
    toml.write_bytes(bytes(range(256)))
    result = run("simulate", "--sensor", toml, "--out", tmp_path / "a.tif")
    assert result.exit_code == 1 and str(toml) in result.stderr and "Traceback" not in result.output


def test_help_imports_no_numerical_library():
    import subprocess
    import sys
    # as `python -m imgmtf --help` runs it
    code = ("import runpy, sys; sys.argv = ['imgmtf', '--help']\n"
            "try:\n    runpy.run_module('imgmtf', run_name='__main__')\n"
            "except SystemExit as done:\n    assert not done.code, done.code\n"
            "print(sorted(m for m in ('numpy', 'scipy', 'skimage', 'cv2', 'rasterio', 'matplotlib', "
            "'dask', 'tqdm') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.startswith("Usage: imgmtf ") and out.stdout.strip().splitlines()[-1] == "[]"


def test_a_batchs_parent_and_an_edge_files_measurement_load_no_estimator_library(tmp_path):
    # the parent of --workers N only collects records: SciPy and scikit-image
    # load in the workers, in parallel, not in its start-up; and a one-chip
    # measurement's start-up is mostly imports: the default edge estimate runs
    # on NumPy, and OpenCV (0.03 s to import) for the seed search.  One fresh
    # interpreter checks both in turn (what the first loads, the second prints too).  Nor does the
    # measurement load what it does not use: figures, vector files, reports, Dask, a worker pool, a
    # progress bar, or the package metadata's reader (20-30 ms for the version its records carry)
    import subprocess
    import sys
    chip = Path(__file__).parent.parent / "data" / "edge_16bit.tif"
    unused = ("scipy", "skimage", "matplotlib", "fiona", "jinja2", "dask", "distributed", "PIL", "tqdm",
              "multiprocessing", "concurrent.futures", "importlib.metadata")
    code = ("import sys; from imgmtf.cli.options import MethodName; from imgmtf.batch import MeasureSettings, "
            "expand_inputs; MethodName().convert('spline', None, None); "
            "MeasureSettings('pulse', 'spline', pulse_width=(3.0, 'px')); "
            f"expand_inputs([{str(tmp_path)!r}]); "
            "print(sorted(m for m in ('scipy', 'skimage', 'cv2', 'matplotlib') if m in sys.modules)); "
            "from click.testing import CliRunner; from imgmtf.cli import main; "
            f"r = CliRunner().invoke(main, ['measure', '--format', 'json', {str(chip)!r}]); "
            "assert r.exit_code == 0, r.output; "
            f"print(sorted(m for m in {unused!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split("\n")[:2] == ["[]", "[]"]


def test_simulate_writes_png_or_refuses_other_formats(run, tmp_path):
    from imgmtf.io import read_raster
    for bits in ("8", "16"):
        path = tmp_path / f"edge{bits}.png"
        r = run("simulate", "--bits", bits, "--low", "20", "--high", "220", "--out", path)
        assert r.exit_code == 0 and "a PNG keeps the pixels only" in r.stdout
        assert path.read_bytes()[:4] == b"\x89PNG"
        raster = read_raster(path)
        assert raster.dtype == f"uint{bits}" and raster.gsd_m is None and raster.provenance is None
    r = run("simulate", "--out", tmp_path / "edge.jpg")
    assert r.exit_code == 2 and "GeoTIFF (.tif, .tiff)" in r.stderr and not (tmp_path / "edge.jpg").exists()


def test_band_all_on_an_rgba_photo_measures_the_colours_and_skips_alpha(run, tmp_path):
    import imgmtf as im
    grey = im.render(im.Sensor(), im.Target("edge", 6.0, 30.0, 200.0), 48, bits=8, noise_std_dn=1.0, seed=2).image
    rgba = np.stack([grey, grey, grey, np.full_like(grey, 255)])
    im.write_png(tmp_path / "photo.png", rgba)
    r = run("measure", "--band", "all", "--format", "json", tmp_path / "photo.png")
    rows = [json.loads(line) for line in r.stdout.splitlines()]
    assert r.exit_code == 0 and [row["band"] for row in rows] == [1, 2, 3]
    assert any("band 4 is alpha" in w for w in rows[0]["warnings"])
    text = run("measure", "--band", "all", tmp_path / "photo.png").stdout
    header = next(line for line in text.splitlines() if line.startswith("path "))
    assert "band" in header.split() and "band 4 is alpha" in " ".join(text.split())    # warnings wrap at 120 columns
    assert not any("luminance" in w for row in rows for w in row["warnings"])
    row = json.loads(run("measure", "--format", "json", tmp_path / "photo.png").stdout)
    assert row["band"] == "luminance"
    assert any("luminance of the stored RGB values" in w and "alpha ignored" in w for w in row["warnings"])


def test_text_table_names_units_and_fits_long_paths(run, chip, tmp_path):
    long_name = tmp_path / ("a_rather_long_file_name_for_a_chip_" + "x" * 10 + ".tif")
    long_name.write_bytes(chip.read_bytes())
    deep = tmp_path / ("a_folder_with_a_long_name_" * 4)
    deep.mkdir()
    deeper = deep / long_name.name
    deeper.write_bytes(chip.read_bytes())
    lines = run("measure", chip, long_name, deeper).stdout.splitlines()
    # paths shortened below the folder they share, each still told apart: the rows fit 120 columns
    assert lines[0] == f"paths below {tmp_path}/" and all(len(line) <= 120 for line in lines)
    assert [line.split()[0] for line in lines[3:] if not line.startswith(" ")] == [
        "edge.tif", "a_rather_lo..._a_chip_xxxxxxxxxx.tif", "a_folder_wi..._a_chip_xxxxxxxxxx.tif"]
    header, units, first = lines[1], lines[2], lines[3]
    assert "cy/px" in units and "deg" in units and "px" in units
    assert header.index("normal") == first.index("6.00") + len("6.00") - len("normal")   # columns line up
    assert "band" not in header                                   # no band asked for: no band column
    from imgmtf.cli.tables import snr_cell
    assert [snr_cell(v) for v in (199.4, 99999.0, 136212.0, None)] == ["  199", "99999", " 136k", "    -"]


def test_help_explains_methods_and_lists_every_command_in_full(run):
    from imgmtf.estimate.resampling import METHODS
    text = "".join(run("measure", "--help").stdout.split())          # wrapped anywhere, even at hyphens
    for method in METHODS.values():
        assert "".join(f"{method.name}: {method.description}".split()) in text
    assert "None" not in run("simulate", "--help").stdout          # an unbounded number says "finite"
    listing = run("--help").stdout
    assert "Rerun the paper's study and find each method's SNR threshold." in listing
    assert "Figs.\n" not in listing


def test_a_fit_with_no_gsd_names_its_parameters_in_px_and_wraps_long_notes_to_120_columns(monkeypatch):
    from types import SimpleNamespace

    from imgmtf.cli.tables import print_fit
    lines: list[str] = []
    monkeypatch.setattr("click.echo", lambda text="", **_: lines.extend(str(text).splitlines()))
    held = SimpleNamespace(key="electronics.cutoff_cy_m", value=0.62, standard_error=0.0, unit="cy/m",
                           status="held", note="not determined by the data (within one standard error its blur "
                                               "length spans 11 px); held at its starting value")
    result = SimpleNamespace(edges=[], pixel_units=True, sensor=SimpleNamespace(stages=[]), reduced_chi_square=1.0,
                             choice=None, parameters=[held], correlations=[], confidence=0.95, directions={},
                             warnings=[])
    print_fit(result)
    row = next(i for i, line in enumerate(lines) if line.startswith("electronics."))
    assert lines[row].split()[:4] == ["electronics.cutoff_cy_px", "0.62", "-", "cy/px"]
    assert max(len(line) for line in lines[row:row + 2]) <= 120 and "held at its starting value" in lines[row + 1]


def test_the_closing_count_is_of_files_measured_not_of_a_point_array_s_direction_rows(run, tmp_path):
    chip = tmp_path / "points.tif"
    assert run("simulate", "--target", "points", "--size", 48, "--seed", 1, "--out", chip).exit_code == 0
    result = run("measure", "--target", "points", "--intervals", "none", "--workers", 1, chip, tmp_path / "missing.tif")
    assert result.stdout.count("points.tif") == 2                  # two rows, across and along, of one file
    assert "1 measured, 1 failed" in result.stderr                 # it said "2 measured, 1 failed"


def test_a_long_warning_under_a_row_wraps_to_the_table_width_under_its_words():
    from imgmtf.cli.tables import TABLE_WIDTH, warning_text
    warning = "the targets' sub-pixel phases are not spread evenly over the pixel " * 5 + "/a/very/long/path/" * 8
    lines = warning_text(" " * 12, warning, hint=False).splitlines()
    assert len(lines) > 2 and lines[0].startswith(" " * 12 + "warning: the targets'")
    assert all(len(line) <= TABLE_WIDTH for line in lines[:-1])     # a path longer than a line is not cut
    assert all(line.startswith(" " * 21) and line[21] != " " for line in lines[1:])
    assert " ".join(" ".join(lines).split()[1:]) == " ".join(warning.split())
    # never between a figure and its per cent sign
    spaced = warning_text("", "the residuals are structured (0.25 % of the step) " * 6, hint=False).splitlines()
    assert len(spaced) > 1 and not any(line.lstrip().startswith("%") for line in spaced)


def test_a_scans_headings_and_rejection_lines_wrap_to_the_table_width(capsys):
    from imgmtf.cli.tables import TABLE_WIDTH, echo_wrapped
    echo_wrapped("rejected    6 fill (id 5, 6, 7, 8, 9 and 1 more): e.g. a boundary of fill or nodata along 100 % "
                 "of its length (not an edge of the scene)", indent=" " * 14)
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2 and all(len(line) <= TABLE_WIDTH for line in lines)
    assert lines[1].startswith(" " * 14 + "edge of the scene")


def test_an_error_row_of_the_measure_table_stays_on_one_line_to_grep():
    from imgmtf.cli.tables import text_row
    error = "x.tif: two edges found (at normal 0.1 deg, 383 px from the top-left pixel and normal 8.0 deg) " * 2
    [line] = text_row({"path": "x.tif", "status": "error", "error": error, "reason": None}, "edge", 20).splitlines()
    assert line.startswith("x.tif" + " " * 16 + "error: x.tif")
