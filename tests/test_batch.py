"""Batches over files and folders, and every kind of bad input: each gives a
one-line error naming its file, exit status 1, and the batch goes on."""
import csv
import json
import os

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner
from rasterio.errors import NotGeoreferencedWarning

import imgmtf as im
from imgmtf.batch import MeasureSettings, expand_inputs, measure_file
from imgmtf.cli import main
from imgmtf.io import read_raster, write_geotiff

from conftest import exact_edge_chip, gaussian_pixel_transfer

TRANSFER = gaussian_pixel_transfer(0.5, 6.0)
pytestmark = pytest.mark.filterwarnings(f"ignore::{NotGeoreferencedWarning.__module__}.NotGeoreferencedWarning")


def write(path, bands, dtype=None, nodata=None, colours=None):
    """A plain GeoTIFF of ``bands`` (rows x cols or bands x rows x cols)."""
    bands = np.asarray(bands)
    bands = bands[None] if bands.ndim == 2 else bands
    with rasterio.open(path, "w", driver="GTiff", width=bands.shape[2], height=bands.shape[1],
                       count=bands.shape[0], dtype=dtype or bands.dtype.name, nodata=nodata) as dst:
        dst.write(bands.astype(dtype or bands.dtype))
        if colours:
            dst.colorinterp = colours
    return path


@pytest.fixture
def good(tmp_path):
    return write(tmp_path / "good.tif", exact_edge_chip(TRANSFER, 6.0, (64, 64), noise_std=2.0, seed=3))


def bad_inputs(tmp_path):
    """name -> (path, words the one-line error must contain)."""
    edge = exact_edge_chip(TRANSFER, 6.0, (64, 64)).astype(float)
    (tmp_path / "notes.tif").write_text("not an image\n")
    full = write(tmp_path / "full.tif", edge.astype(np.uint16))
    (tmp_path / "truncated.tif").write_bytes(full.read_bytes()[:600])
    (tmp_path / "empty.tif").write_bytes(b"")
    infinite = edge.copy()
    infinite[10:12, 20:30] = np.inf
    two = edge + np.where(np.arange(64)[None, :] > 50, 800.0, 0.0)
    saturated = np.clip(edge * 60, 0, 65535)
    cases = {
        "non-image": (tmp_path / "notes.tif", "not an image"),
        "truncated": (tmp_path / "truncated.tif", "damaged or truncated"),
        "empty file": (tmp_path / "empty.tif", "not an image"),
        "flat": (write(tmp_path / "flat.tif", np.full((64, 64), 500, np.uint16)), "flat"),
        "all nodata": (write(tmp_path / "nodata.tif", np.zeros((64, 64), np.uint16), nodata=0),
                       "every pixel is nan or nodata"),
        "infinities": (write(tmp_path / "infinite.tif", infinite.astype(np.float32)), "20 pixel(s) are infinite"),
        "saturated": (write(tmp_path / "saturated.tif", saturated.astype(np.uint16)), "saturated"),
        "two edges": (write(tmp_path / "two.tif", two.astype(np.uint16)), "two edges"),
        "too small": (write(tmp_path / "small.tif", edge[:12, 26:38].astype(np.uint16)), "at least 16 x 16"),
        "4 bands": (write(tmp_path / "four.tif", np.stack([edge] * 4).astype(np.uint16)), "has 4 bands"),
        "unreadable": (tmp_path / "missing" / "nowhere.tif", "no such file"),
    }
    return cases


def test_every_bad_input_is_one_line_naming_its_file_and_the_batch_goes_on(tmp_path, good):
    cases = bad_inputs(tmp_path)
    paths = [str(p) for p, _ in cases.values()]
    result = CliRunner().invoke(main, ["measure", "--format", "json", *paths, str(good)])
    assert result.exit_code == 1
    assert "Traceback" not in result.output
    records = [json.loads(line) for line in result.stdout.splitlines()]
    assert [r["path"] for r in records] == [*paths, str(good)]
    for (name, (path, words)), record in zip(cases.items(), records):
        assert record["status"] == "error", name
        assert record["error"].startswith(str(path)), name
        assert words in record["error"].lower(), (name, record["error"])
        assert "\n" not in record["error"]
        assert record["imgmtf_version"] == im.__version__ and record["method"] == "msg"
    assert records[-1]["status"] == "ok"


@pytest.mark.parametrize("args, words", [
    (["--roi", "50,50,40,40"], "roi x=50, y=50, width=40, height=40 is not inside the 64 x 64 image"),
    (["--band", "3"], "band 3 does not exist (the file has 1)"),
])
def test_roi_outside_and_missing_band_name_file_and_exit_1(good, args, words):
    result = CliRunner().invoke(main, ["measure", *args, str(good)])
    assert result.exit_code == 1
    assert f"{good}: " in result.stdout and words in result.stdout.lower()


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their permissions")
def test_unreadable_file(tmp_path, good):
    good.chmod(0)
    result = CliRunner().invoke(main, ["measure", str(good)])
    assert result.exit_code == 1 and str(good) in result.stdout


def test_rgb_photo_is_luminance_by_default_and_per_channel_with_band_all(tmp_path):
    edge = exact_edge_chip(TRANSFER, 6.0, (64, 64), low=20, high=220, dtype=np.uint8).astype(float)
    rgb = np.stack([edge, 0.5 * edge, 0.25 * edge]).astype(np.uint8)
    path = write(tmp_path / "photo.tif", rgb, colours=[rasterio.enums.ColorInterp.red,
                                                        rasterio.enums.ColorInterp.green,
                                                        rasterio.enums.ColorInterp.blue])
    settings = MeasureSettings()
    (lum,) = (r.to_dict() for r in measure_file(str(path), settings))
    assert lum["band"] == "luminance" and lum["status"] == "ok"
    per_band = [r.to_dict() for r in measure_file(str(path), MeasureSettings(band="all"))]
    assert [r["band"] for r in per_band] == [1, 2, 3]
    # the same edge in every channel: the same MTF (to quantisation of the dimmer channels)
    for r in per_band:
        assert r["mtf_nyquist"] == pytest.approx(lum["mtf_nyquist"], abs=0.01)


def test_float_image_with_negative_values_measures_like_its_offset_copy(tmp_path):
    edge = exact_edge_chip(TRANSFER, 6.0, (64, 64), low=-300.0, high=700.0, noise_std=1.0, seed=2,
                           dtype=np.float32)
    negative = write(tmp_path / "negative.tif", edge)
    shifted = write(tmp_path / "shifted.tif", edge + 1000.0)
    a, = (r.to_dict() for r in measure_file(str(negative), MeasureSettings()))
    b, = (r.to_dict() for r in measure_file(str(shifted), MeasureSettings()))
    assert a["status"] == "ok" and a["levels_dn"][0] < 0
    assert a["mtf_nyquist"] == pytest.approx(b["mtf_nyquist"], abs=2e-4)


def test_folder_batch_with_workers_csv_and_plots(tmp_path, good):
    folder = tmp_path / "chips"
    folder.mkdir()
    for seed in range(2):          # two chips: each of the two workers draws a figure
        write(folder / f"c{seed}.tif", exact_edge_chip(TRANSFER, 6.0 + seed, (64, 64), noise_std=2.0,
                                                      seed=seed))
    (folder / "readme.txt").write_text("ignored: not an image suffix")
    (folder / "broken.tif").write_text("not a tiff")
    assert len(expand_inputs([folder])) == 3
    out_csv, plots = tmp_path / "summary.csv", tmp_path / "plots"
    result = CliRunner().invoke(main, ["measure", str(folder), "--workers", "2", "--csv", str(out_csv),
                                       "--plot-dir", str(plots)])
    assert result.exit_code == 1                       # broken.tif
    rows = list(csv.DictReader(out_csv.open()))
    assert [r["status"] for r in rows] == ["error", "ok", "ok"]
    for r in rows[1:]:
        assert abs(float(r["normal_angle_deg"]) - (6.0 + int(r["path"][-5]))) < 0.05
        assert float(r["mtf_nyquist_ci_low"]) <= float(r["mtf_nyquist"]) <= float(r["mtf_nyquist_ci_high"])
        assert json.loads(r["params"])["intervals"]["confidence"] == 0.95
        assert r["imgmtf_version"] == im.__version__ and r["band"] == "1"
        assert (plots / f"{os.path.basename(r['path'])[:-4]}_mtf.png").stat().st_size > 10_000
    assert "broken.tif" in rows[0]["error"]


def test_windowed_read_reports_roi_in_file_coordinates(tmp_path):
    scene = np.full((200, 300), 200.0)
    scene[60:124, 100:164] = exact_edge_chip(TRANSFER, 6.0, (64, 64))
    path = write(tmp_path / "scene.tif", scene.astype(np.uint16))
    raster = im.read_raster(path, window=(100, 60, 64, 64))
    assert raster.data.shape == (64, 64) and raster.origin == (100, 60)
    record, = (r.to_dict() for r in measure_file(str(path), MeasureSettings(roi=(100, 60, 64, 64))))
    assert record["roi"] == [100, 60, 64, 64]
    assert record["normal_angle_deg"] == pytest.approx(6.0, abs=0.05)


def test_fifo_and_complex_pixels_are_refused_by_name_and_the_batch_goes_on(tmp_path, good):
    fifo = tmp_path / "pipe.tif"
    os.mkfifo(fifo)
    complex_tif = write(tmp_path / "complex.tif", np.ones((32, 32), np.complex64))
    result = CliRunner().invoke(main, ["measure", "--format", "json", str(fifo), str(complex_tif),
                                       str(good)])
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert result.exit_code == 1 and [r["status"] for r in rows] == ["error", "error", "ok"]
    assert rows[0]["error"] == f"{fifo}: is a FIFO (named pipe), not an image file; imgmtf reads regular files only"
    assert rows[1]["reason"] == "unsupported-type" and "complex64" in rows[1]["error"]


def test_a_fifo_in_a_folder_is_reported_not_skipped(tmp_path, good):
    os.mkfifo(tmp_path / "pipe.tif")
    assert str(tmp_path / "pipe.tif") in expand_inputs([tmp_path])


def test_an_unexpected_failure_is_an_internal_error_record_for_that_file_only(tmp_path, good, monkeypatch):
    # the chips of a batch are estimated together (batch._measure_group): one chip's failure inside the
    # estimator, or the whole group's, stays that file's
    from imgmtf.estimate.edge import EdgeEstimator
    real = EdgeEstimator._result

    def fails_on_one(self, m):
        if m.chip.pixels.shape == (60, 60):
            raise TypeError("unsupported operand")
        return real(self, m)
    monkeypatch.setattr(EdgeEstimator, "_result", fails_on_one)
    boom = write(tmp_path / "boom.tif", exact_edge_chip(TRANSFER, 6.0, (60, 60)))
    twin = write(tmp_path / "twin.tif", exact_edge_chip(TRANSFER, 6.0, (64, 64), noise_std=2.0, seed=3))
    result = CliRunner().invoke(main, ["measure", "--format", "json", str(boom), str(good), str(twin)])
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert result.exit_code == 1 and "Traceback" not in result.output
    assert rows[0]["reason"] == "internal"
    assert rows[0]["error"] == f"{boom}: internal error: TypeError: unsupported operand"
    assert [r["status"] for r in rows[1:]] == ["ok", "ok"] and rows[1]["mtf"] == rows[2]["mtf"]


def test_mixed_batch_keeps_every_row_in_input_order_with_workers(tmp_path, good):
    cases = bad_inputs(tmp_path)
    # distinct files (a file named twice is measured once): the good one copied under three names
    copies = [tmp_path / f"good{i}.tif" for i in range(3)]
    for copy in copies:
        copy.write_bytes(good.read_bytes())
    paths = [str(p) for p, _ in cases.values()] + [str(c) for c in copies]
    out_csv = tmp_path / "rows.csv"
    result = CliRunner().invoke(main, ["measure", "--format", "json", "--workers", "2", "--bootstrap", "0",
                                       "--csv", str(out_csv), *paths])
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert [r["path"] for r in rows] == paths
    assert [r["path"] for r in csv.DictReader(out_csv.open())] == paths
    assert all(r["reason"] and r["error"] for r in rows if r["status"] == "error")


def test_an_empty_path_is_an_error_row_not_the_current_folder(tmp_path, good, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert expand_inputs(["", str(good)]) == ["", str(good)]
    rows = [json.loads(line) for line in
            CliRunner().invoke(main, ["measure", "--format", "json", "", str(good)]).stdout.splitlines()]
    assert [r["status"] for r in rows] == ["error", "ok"] and "empty path" in rows[0]["error"]


def test_a_simulated_chip_knows_its_true_mtf_and_its_figure_shows_it(tmp_path):
    from imgmtf.batch import true_mtf
    chip = im.render(im.Sensor(), im.Target("edge", 8.0), 40, gsd_m=0.5)
    write_geotiff(tmp_path / "c.tif", chip.image, gsd_m=chip.gsd_m, provenance=chip.provenance())
    truth = true_mtf(read_raster(tmp_path / "c.tif"))
    f = np.linspace(0, 1, 11)
    assert np.allclose(truth(f), chip.true_mtf(f))
    im.write_png(tmp_path / "c.png", chip.image)
    assert true_mtf(read_raster(tmp_path / "c.png")) is None
    record, = measure_file(str(tmp_path / "c.tif"), MeasureSettings(), str(tmp_path / "c_mtf.png"))
    assert record.plot and (tmp_path / "c_mtf.png").stat().st_size > 10_000


def test_measure_file_returns_what_measure_format_json_prints_on_the_sample_data():
    """imgmtf.measure_file is the Python twin of `imgmtf measure FILE`: on
    every sample file (simulated chips, RGBA photos, the scene it refuses)
    the same records, number for number, the run's time stamp aside."""
    import json
    from pathlib import Path

    from click.testing import CliRunner

    import imgmtf
    from imgmtf.cli import main
    from imgmtf.records import json_safe
    data = Path(__file__).parent.parent / "data"
    files = sorted(str(p) for p in data.iterdir() if p.suffix in (".tif", ".png"))
    assert len(files) >= 6
    result = CliRunner().invoke(main, ["measure", "--format", "json", *files])
    printed = [json.loads(line) for line in result.stdout.splitlines()]
    assert len(printed) == len(files) and result.exit_code == 1          # scene.tif: several edges
    for path, row in zip(files, printed):
        [record] = imgmtf.measure_file(path)
        got = json.loads(json.dumps(json_safe(record.to_dict())))
        assert got.pop("run_utc") and row.pop("run_utc")
        assert got == row, path
    assert {r["status"] for r in printed} == {"ok", "error"}
    by_words = imgmtf.measure_file(files[0], intervals="none", method="spline")[0]
    by_settings = imgmtf.measure_file(files[0], imgmtf.MeasureSettings(method="spline", intervals="none"))[0]
    assert json_safe(by_words.figures) == json_safe(by_settings.figures)
    assert by_words.method == "spline" and by_words.get("params")["intervals"]["method"] == "none"
    with pytest.raises(im.ParameterError, match="not both"):
        imgmtf.measure_file(files[0], imgmtf.MeasureSettings(), method="spline")


def test_a_file_named_twice_in_one_batch_is_measured_once_and_said_so(tmp_path, good):
    from imgmtf.batch import once_each
    other = os.path.join(os.path.dirname(good), ".", os.path.basename(good))       # the same file, another name
    assert once_each([str(good), "b.tif", other, str(good)]) == ([str(good), "b.tif"], {str(good): 3})
    result = CliRunner().invoke(main, ["measure", "--format", "json", str(good), other, str(tmp_path)])
    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert result.exit_code == 0 and [row["path"] for row in rows] == [str(good)]
    assert f"{good} is named 3 times: measured once" in result.stderr


def test_a_group_of_files_gives_each_file_the_records_measure_file_gives(tmp_path, good, monkeypatch):
    # files of one task: chips of two types estimated together, an RGB photo's luminance, a raster too
    # large to hold (estimated alone as it is read), a file that is no image, one that is missing
    import imgmtf.batch as batch
    from imgmtf.records import to_json
    monkeypatch.setattr(batch, "POOLED_MAX_PX", 70 * 70)
    edge = exact_edge_chip(TRANSFER, 8.0, (64, 64), noise_std=2.0, seed=5)
    rgb = np.stack([edge * f for f in (0.18, 0.2, 0.22)]).astype(np.uint8)
    paths = [str(p) for p in (
        good, write(tmp_path / "eight.tif", (edge * 0.2).astype(np.uint8)),
        write(tmp_path / "rgb.tif", rgb, colours=[rasterio.enums.ColorInterp.red, rasterio.enums.ColorInterp.green,
                                                  rasterio.enums.ColorInterp.blue]),
        write(tmp_path / "large.tif", exact_edge_chip(TRANSFER, 5.0, (80, 80), noise_std=2.0, seed=6)),
        tmp_path / "missing.tif", write(tmp_path / "second.tif", edge))]
    (tmp_path / "notes.tif").write_text("not an image\n")
    paths.insert(3, str(tmp_path / "notes.tif"))
    settings, run_utc = MeasureSettings(), "2026-01-01T00:00:00Z"
    together = batch._measure_group((paths, settings, [None] * len(paths), run_utc))
    alone = [measure_file(p, settings, run_utc=run_utc) for p in paths]
    assert [[to_json(r) for r in records] for records in together] == [[to_json(r) for r in records]
                                                                       for records in alone]
    assert [r.status for records in together for r in records] == ["ok"] * 3 + ["error", "ok", "error", "ok"]
