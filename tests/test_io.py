import warnings

import numpy as np
import pytest
import rasterio
from rasterio.errors import NotGeoreferencedWarning

import imgmtf as im
from imgmtf.errors import FileWriteError, ImageReadError, ParameterError
from imgmtf.io import read_raster, write_geotiff


def test_geotiff_round_trip_with_gsd_and_provenance(tmp_path):
    chip = im.render(im.Sensor(), im.Target("edge", 6.0), 32, gsd_m=0.5, seed=3)
    path = tmp_path / "c.tif"
    write_geotiff(path, chip.image, gsd_m=chip.gsd_m, provenance=chip.provenance())
    r = read_raster(path)
    assert np.array_equal(r.data, chip.image) and r.dtype == "uint16"
    assert r.gsd_m == 0.5 and r.band == 1
    assert r.provenance["target"]["angle_deg"] == 6.0
    assert r.provenance["sensor"] == im.Sensor().to_dict()
    assert r.tags["TARGET_KIND"] == "edge"


def test_multiband_8bit(tmp_path):
    bands = np.stack([np.full((20, 20), 10 * k, np.uint8) for k in range(1, 4)])
    path = tmp_path / "m.tif"
    write_geotiff(path, bands)
    assert read_raster(path, band=3).data[0, 0] == 30
    with pytest.raises(ParameterError, match="band 5 does not exist"):
        read_raster(path, band=5)


def test_rgb_png_reads_as_luminance_without_gsd(tmp_path):
    rgb = np.zeros((3, 20, 20), np.uint8)
    rgb[0], rgb[1], rgb[2] = 100, 200, 50
    path = tmp_path / "c.png"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(path, "w", driver="PNG", width=20, height=20, count=3, dtype="uint8") as dst:
            dst.write(rgb)
    r = read_raster(path)
    assert r.band == "luminance" and r.gsd_m is None
    assert r.data[0, 0] == pytest.approx(0.2126 * 100 + 0.7152 * 200 + 0.0722 * 50)


def test_a_grey_png_with_alpha_reads_as_its_grey_band_and_says_alpha_is_not_measured(tmp_path):
    from PIL import Image

    from imgmtf.batch import MeasureSettings, measure_file
    grey = im.render(im.Sensor(), im.Target("edge", 6.0, 30, 210), 40, bits=8).image
    path = tmp_path / "la.png"
    Image.fromarray(np.stack([grey, np.full_like(grey, 255)], -1), "LA").save(path)
    r = read_raster(path)
    assert r.band == 1 and np.array_equal(r.data, grey)
    record = measure_file(str(path), MeasureSettings())[0].to_dict()
    assert record["status"] == "ok" and f"{path}: band 2 is alpha (transparency, not DN): not measured" in \
        record["warnings"]


@pytest.mark.parametrize("kwargs, message", [
    (dict(band="1"), "band must be a 1-based integer, got '1'"),
    (dict(band=1.0), "band must be a 1-based integer, got 1.0"),
    (dict(out_shape=(-1, 5)), r"out_shape must be \(rows, cols\), two whole numbers >= 1, got \(-1, 5\)"),
    (dict(out_shape="a"), "out_shape must be"),
])
def test_read_arguments_of_the_wrong_kind_are_named(tmp_path, kwargs, message):
    path = tmp_path / "a.tif"
    write_geotiff(path, np.zeros((20, 20), np.uint16))
    with pytest.raises(ParameterError, match=message):
        read_raster(path, **kwargs)
    with pytest.raises(ParameterError, match=r"expected an image file's name \(str or os.PathLike\), got NoneType"):
        read_raster(None)
    with pytest.raises(ParameterError, match=r"channel_axis must be an axis of a 3-D array \(-3 to 2\), got 5"):
        im.luminance(np.zeros((3, 4, 4)), channel_axis=5)


def test_nodata_becomes_nan(tmp_path):
    data = np.arange(400, dtype=np.uint16).reshape(20, 20)
    path = tmp_path / "n.tif"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(path, "w", driver="GTiff", width=20, height=20, count=1, dtype="uint16",
                           nodata=5) as dst:
            dst.write(data, 1)
    r = read_raster(path)
    assert np.isnan(r.data[0, 5]) and np.isfinite(r.data).sum() == 399


def test_read_errors_name_the_file(tmp_path):
    with pytest.raises(ImageReadError, match="no such file"):
        read_raster(tmp_path / "missing.tif")
    junk = tmp_path / "junk.tif"
    junk.write_text("not an image")
    with pytest.raises(ImageReadError, match="junk.tif: not an image") as refused:
        read_raster(junk)
    assert str(refused.value).count("junk.tif") == 1           # GDAL's own repeat of the path dropped
    with pytest.raises(FileWriteError, match="cannot write"):
        write_geotiff(tmp_path / "no" / "dir.tif", np.zeros((4, 4), np.uint8))


def test_read_and_write_errors_are_oserrors_as_rasterio_and_open_raise_them(tmp_path):
    """A caller catching OSError around a read catches imgmtf's too; the
    message is the one imgmtf wrote, not wrapped twice."""
    with pytest.raises(OSError, match=r"missing.tif: no such file$"):
        read_raster(tmp_path / "missing.tif")
    with pytest.raises(OSError, match=r"cannot write"):
        write_geotiff(tmp_path / "no" / "dir.tif", np.zeros((4, 4), np.uint8))
    complex_path = tmp_path / "c.tif"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(complex_path, "w", driver="GTiff", width=20, height=20, count=1,
                           dtype="complex64") as dst:
            dst.write(np.ones((20, 20), np.complex64), 1)
    with pytest.raises(ImageReadError, match="has complex pixels") as refused:    # raised inside the open file
        read_raster(complex_path)
    assert refused.value.reason == "unsupported-type" and "cannot read" not in str(refused.value)
    assert issubclass(ImageReadError, OSError) and issubclass(FileWriteError, OSError)


def test_truncated_tiff(tmp_path):
    chip = im.render(im.Sensor(), im.Target("edge", 6.0), 64).image
    path = tmp_path / "t.tif"
    write_geotiff(path, chip)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(ImageReadError, match="t.tif"):
        read_raster(path)


def test_luminance_is_what_the_reader_computes_and_arrays_of_colour_are_pointed_to_it(tmp_path):
    rgba = np.zeros((4, 20, 20), np.uint8)
    rgba[0], rgba[1], rgba[2], rgba[3] = 100, 200, 50, 255
    im.write_png(tmp_path / "c.png", rgba)
    assert np.array_equal(read_raster(tmp_path / "c.png").data, im.luminance(np.moveaxis(rgba, 0, -1)))
    assert np.array_equal(im.luminance(rgba, channel_axis=0), im.luminance(np.moveaxis(rgba, 0, -1)))
    with pytest.raises(im.ImageContentError, match=r"imgmtf.luminance\(image\)"):
        im.measure_edge(np.moveaxis(rgba, 0, -1))
    with pytest.raises(im.ImageContentError, match="shape"):
        im.luminance(np.zeros((20, 20)))


def test_many_files_opens_without_listing_the_folder_and_finds_the_same_side_cars(tmp_path, monkeypatch):
    """Set for a batch: a world file beside a GeoTIFF without a georeference is still read."""
    from imgmtf.io import many_files, raster_info
    path = tmp_path / "plain.tif"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(path, "w", driver="GTiff", width=8, height=8, count=1, dtype="uint8") as dst:
            dst.write(np.zeros((1, 8, 8), np.uint8))
    (tmp_path / "plain.tfw").write_text("2.0\n0\n0\n-2.0\n100\n200\n")
    with many_files():
        assert rasterio.env.getenv()["GDAL_DISABLE_READDIR_ON_OPEN"] == "TRUE"
        assert raster_info(path).gsd_m == 2.0
    monkeypatch.setenv("GDAL_DISABLE_READDIR_ON_OPEN", "EMPTY_DIR")       # the user's own setting stays
    with many_files():
        assert raster_info(path).gsd_m is None
