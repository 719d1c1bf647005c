"""Tiled application of a restoration filter to raster files."""
import json
import math
import pickle

import numpy as np
import pytest
import rasterio
from rasterio.transform import Affine

import imgmtf as im
from imgmtf.restore.apply import OutputType, TileTask, measure_noise, plan_tiles, restore_tile
from imgmtf.restore.convolve import restore_array
from imgmtf.sensor.stages import Detector, GaussianOptics


@pytest.fixture(scope="module")
def filt():
    sensor = im.Sensor(1.0, [GaussianOptics(0.6, 0.6), Detector(1.0, 1.0)])
    return im.design_filter(sensor, 0.25, kernel_size=15)


def scene(shape=(203, 261), seed=0):
    """A textured scene: smooth blobs and sharp steps, 200..3000 DN."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:shape[0], 0:shape[1]]
    values = 1500 + 600 * np.sin(x / 7.0) * np.cos(y / 11.0) + 800 * ((x // 40 + y // 30) % 2)
    return values + rng.normal(0, 4, shape)


def write(path, data, dtype, nodata=None, crs="EPSG:32633", tags=None):
    profile = dict(driver="GTiff", width=data.shape[1], height=data.shape[0], count=1, dtype=dtype,
                   crs=crs, transform=Affine(0.5, 0, 500000, 0, -0.5, 4e6), nodata=nodata)
    with rasterio.open(path, "w", **profile) as dst:
        dst.write(data.astype(dtype), 1)
        dst.update_tags(**(tags or {}))
        dst.update_tags(1, WAVELENGTH="650")
        dst.set_band_description(1, "pan")


def test_tiles_cover_the_image_once():
    tiles = plan_tiles(261, 203, 64, 7)
    cover = np.zeros((203, 261), int)
    for t in tiles:
        x, y, w, h = t.core
        cover[y:y + h, x:x + w] += 1
        (top, bottom), (left, right) = t.pads
        assert t.read[2] + left + right == w + 14 and t.read[3] + top + bottom == h + 14
    assert np.all(cover == 1)


def test_tiles_join_without_a_seam(filt, tmp_path):
    data = scene().astype(np.float32)
    write(tmp_path / "in.tif", data, "float32")
    done = im.restore_file(tmp_path / "in.tif", filt, tmp_path / "out.tif", tile_px=64)
    assert done.tiles == 20
    tiled = im.read_raster(tmp_path / "out.tif").data
    whole = restore_array(data, filt.taps)
    assert np.abs(tiled - whole).max() < 1e-3          # float32 storage; the issue asks < 0.5 DN
    # and the restoration did something: the steps are sharper
    assert np.abs(whole - data).max() > 50


def test_keeps_georeference_type_nodata_and_tags(filt, tmp_path):
    data = scene()
    data[10:30, 50:90] = 0          # a nodata hole
    write(tmp_path / "in.tif", data, "uint16", nodata=0, tags={"SENSOR": "pan"})
    done = im.restore_file(tmp_path / "in.tif", filt, tmp_path / "out.tif", tile_px=64)
    with rasterio.open(tmp_path / "in.tif") as a, rasterio.open(tmp_path / "out.tif") as b:
        assert b.crs == a.crs and b.transform == a.transform and b.dtypes == a.dtypes
        assert b.nodata == 0 and b.tags()["SENSOR"] == "pan" and b.tags(1)["WAVELENGTH"] == "650"
        assert b.descriptions == ("pan",)
        out = b.read(1)
        provenance = json.loads(b.tags()["IMGMTF_RESTORE"])
    assert np.all(out[10:30, 50:90] == 0) and np.all(out[data > 0] > 0)
    assert done.nodata_fraction == pytest.approx(800 / data.size)
    assert provenance["filter"]["target_nyquist"] == 0.25 and provenance["input_sha256"] == done.input_sha256
    assert len(done.input_sha256) == 64


def test_saturated_pixels_are_kept_and_clipping_counted(filt, tmp_path):
    data = np.full((120, 120), 40.0)
    # a sharp step (its undershoot goes below 0 DN), saturated at the top over 20 rows
    data[:, 60:] = np.where(np.arange(120)[:, None] < 20, 4095, 3000)
    write(tmp_path / "in.tif", data, "uint16")
    done = im.restore_file(tmp_path / "in.tif", filt, tmp_path / "out.tif", tile_px=64,
                           saturation=(0, 4095))
    out = im.read_raster(tmp_path / "out.tif").data
    assert np.all(out[:20, 60:] == 4095)
    whole = restore_array(data, filt.taps)
    clipped = ((whole < 0) & (data < 4095)).sum()
    assert clipped > 0 and done.clipped_fraction == pytest.approx(clipped / data.size)
    assert done.saturated_fraction == pytest.approx(20 * 60 / data.size)
    assert out.min() == 0


def test_zero_fill_around_a_target_is_kept_and_counted_as_fill_not_saturation(filt, tmp_path):
    data = np.zeros((100, 100))
    data[20:80, 20:80] = np.where(np.arange(60) < 30, 400, 3000)[None, :]     # a target cut out of its scene
    write(tmp_path / "in.tif", data, "uint16")
    done = im.restore_file(tmp_path / "in.tif", filt, tmp_path / "out.tif", tile_px=64)
    assert done.saturated_fraction == 0 and done.fill_fraction == pytest.approx(1 - 0.36)
    assert np.all(im.read_raster(tmp_path / "out.tif").data[data == 0] == 0)


def test_integer_clip_avoids_a_nodata_value_at_the_range_end():
    output = OutputType("uint8", 0.0, None)
    samples, clipped, _, _ = output.convert(np.array([[-5.0, 7.4, 300.0]]), np.array([[3.0, 7.0, 200.0]]))
    assert samples.tolist() == [[1, 7, 255]] and clipped == 2


def test_a_tile_task_travels_to_a_worker_and_back_unchanged(filt, tmp_path):
    # what run_tasks sends a worker process or a Dask cluster: a pickled task, a pickled result
    write(tmp_path / "in.tif", scene(), "uint16")
    tile = plan_tiles(261, 203, 64, filt.radius_px)[6]
    task = TileTask(str(tmp_path / "in.tif"), 1, tile, filt.taps, 1500.0, OutputType("uint16", None, (0.0, 65535.0)))
    here = restore_tile(task)
    there = pickle.loads(pickle.dumps(restore_tile(pickle.loads(pickle.dumps(task)))))
    assert there.core == here.core == tile.core and np.array_equal(there.samples, here.samples)


def test_unreadable_inputs_and_bad_options_are_refused(filt, tmp_path):
    with pytest.raises(im.ImageReadError, match="no such file"):
        im.restore_file(tmp_path / "none.tif", filt, tmp_path / "out.tif")
    (tmp_path / "notes.txt").write_text("not an image")
    with pytest.raises(im.ImageReadError, match="not an image"):
        im.restore_file(tmp_path / "notes.txt", filt, tmp_path / "out.tif")
    write(tmp_path / "in.tif", scene(), "uint16")
    with pytest.raises(im.ParameterError, match="tile_px"):
        im.restore_file(tmp_path / "in.tif", filt, tmp_path / "out.tif", tile_px=10)
    with pytest.raises(im.FileWriteError):
        im.restore_file(tmp_path / "in.tif", filt, tmp_path / "no" / "out.tif")
    assert not list(tmp_path.glob("*.partial*"))


def test_restore_array_refuses_what_is_not_an_image(filt):
    with pytest.raises(im.ImageContentError, match="2-D"):
        restore_array(np.zeros((3, 4, 5)), filt.taps)
    with pytest.raises(im.ImageContentError, match="every pixel"):
        restore_array(np.full((8, 8), np.nan), filt.taps)


def test_noise_and_signal_are_measured(tmp_path):
    rng = np.random.default_rng(1)
    data = 1000 + 5.0 * rng.standard_normal((300, 300))
    data[:, 150:] += 400             # a step: std of the signal 200 DN
    write(tmp_path / "in.tif", data, "float32")
    noise, signal = measure_noise(tmp_path / "in.tif")
    assert noise == pytest.approx(5.0, rel=0.05)
    assert signal == pytest.approx(200.0, rel=0.01)
    write(tmp_path / "flat.tif", np.full((64, 64), 100.0), "uint16")
    assert measure_noise(tmp_path / "flat.tif")[1] == 0.0
    # a quantised noise-free image has at least the rounding noise
    write(tmp_path / "q.tif", np.tile(np.arange(64.0), (64, 1)) * 10, "uint16")
    assert measure_noise(tmp_path / "q.tif")[0] == pytest.approx(1 / math.sqrt(12))


def test_float_nan_stays_nan_and_a_chips_truth_is_not_carried_over(filt, tmp_path):
    data = scene().astype(np.float32)
    data[5:9, 5:9] = np.nan
    write(tmp_path / "in.tif", data, "float32")
    im.restore_file(tmp_path / "in.tif", filt, tmp_path / "out.tif", tile_px=64)
    out = im.read_raster(tmp_path / "out.tif").data
    assert np.isnan(out[5:9, 5:9]).all() and np.isfinite(out).sum() == data.size - 16
    chip = im.render(im.Sensor(), im.Target("edge", 6.0), 64)
    im.write_geotiff(tmp_path / "chip.tif", chip.image, provenance=chip.provenance())
    im.restore_file(tmp_path / "chip.tif", filt, tmp_path / "chip_r.tif")
    restored = im.read_raster(tmp_path / "chip_r.tif")
    assert restored.provenance is None and "sensor" in json.loads(restored.tags["IMGMTF_SOURCE"])
