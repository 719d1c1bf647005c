"""Acquisitions: facts from product names, metadata items, TIFF tags and
options, in that order of precedence reversed; a stable identity."""
import numpy as np
import pytest
import rasterio

from imgmtf.campaign.acquisitions import (
    parse_product_name,
    parse_time,
    read_acquisition,
)
from imgmtf.errors import ImageReadError, ParameterError
from imgmtf.io import write_geotiff


def scene(path, tags=None, gsd_m=10.0, value=0):
    """A small GeoTIFF with metadata items ``tags``; ``value`` changes its bytes."""
    image = np.full((16, 16), 100 + value, np.uint16)
    write_geotiff(path, image, gsd_m=gsd_m)
    if tags:
        with rasterio.open(path, "r+") as dst:
            dst.update_tags(**tags)
    return str(path)


@pytest.mark.parametrize(("name", "expected"), [
    ("LC09_L1TP_181040_20230315_20230320_02_T1_B8.TIF",
     {"platform": "Landsat 9", "instrument": "OLI-2", "acquired_utc": "2023-03-15", "band_name": "B8",
      "level": "L1TP", "site": "WRS-2 181/040", "product_id": "LC09_L1TP_181040_20230315_20230320_02_T1"}),
    ("LC08_L2SP_044034_20200101_20200823_02_T1_SR_B4.TIF",
     {"platform": "Landsat 8", "instrument": "OLI", "acquired_utc": "2020-01-01", "band_name": "SR_B4",
      "level": "L2SP"}),
    ("LC09_L1TP_181040_20211121_20211122_02_T1_B10.TIF", {"platform": "Landsat 9", "instrument": "TIRS-2"}),
    ("LE07_L1TP_127032_20010301_20200917_02_T1_B8.TIF", {"platform": "Landsat 7", "instrument": "ETM+"}),
    ("LC09_L1TP_181040_20211121_20230505_02_T1_B5_rad_crop_2.tif",     # a user's crop keeps the name's facts
     {"platform": "Landsat 9", "band_name": "B5", "acquired_utc": "2021-11-21",
      "product_id": "LC09_L1TP_181040_20211121_20230505_02_T1"}),
    ("LC08_L1TP_044034_20200101_20200823_02_T1_QA_PIXEL.TIF", {"band_name": "QA_PIXEL"}),
    ("T32TNR_20240619T101559_B04_10m.tif",
     {"platform": "Sentinel-2", "instrument": "MSI", "acquired_utc": "2024-06-19T10:15:59Z", "band_name": "B04",
      "site": "MGRS 32TNR", "level": "L2A"}),
    ("T32TNR_20250619T101559_B04.jp2", {"platform": "Sentinel-2", "band_name": "B04", "level": None}),
    ("T32TNR_20250619T101559_B04_10m_mtf_roi.tiff", {"platform": "Sentinel-2", "band_name": "B04", "level": "L2A",
                                                    "acquired_utc": "2025-06-19T10:15:59Z"}),
    ("S2B_MSIL1C_20250619T101559_N0511_R065_T32TNR_20250619T121212.SAFE/GRANULE/x/IMG_DATA/"
     "T32TNR_20250619T101559_B08.jp2",
     {"platform": "Sentinel-2B", "level": "L1C", "band_name": "B08", "acquired_utc": "2025-06-19T10:15:59Z",
      "product_id": "S2B_MSIL1C_20250619T101559_N0511_R065_T32TNR_20250619T121212"}),
])
def test_product_names_state_platform_time_band_and_site(name, expected):
    facts = parse_product_name(name)
    for key, value in expected.items():
        assert facts.get(key) == value, key


@pytest.mark.parametrize("name", ["scene.tif", "baotou_2019.tif", "LC09_L1TP_18104_20211121.TIF", "T32TNR_B04.jp2"])
def test_other_names_state_nothing(name):
    assert parse_product_name(name) == {}


@pytest.mark.parametrize(("text", "utc"), [
    ("2021-11-21", "2021-11-21"), ("2021-11-21T08:15:02Z", "2021-11-21T08:15:02Z"),
    ("2021-11-21T08:15:02", "2021-11-21T08:15:02Z"), ("2021-11-21T10:15:02+02:00", "2021-11-21T08:15:02Z"),
    ("2021-11-21 23:30:00-01:00", "2021-11-22T00:30:00Z"), ("2020:01:02 03:04:05", "2020-01-02T03:04:05Z"),
])
def test_times_become_utc(text, utc):
    assert parse_time(text) == utc


@pytest.mark.parametrize("text", ["yesterday", "2021-13-01", "2021-02-30", "21/11/2021", ""])
def test_a_bad_time_is_a_clear_error(text):
    with pytest.raises(ParameterError, match="--acquired .* not"):
        parse_time(text, "--acquired")


def test_metadata_items_are_read_and_options_win(tmp_path):
    path = scene(tmp_path / "LC08_L1TP_181040_20211121_20211122_02_T1_B8.TIF",
                 {"ACQUISITION_DATETIME": "2022-03-04T05:06:07Z", "PLATFORM": "Simsat-1", "INSTRUMENT": "PAN",
                  "BAND_NAME": "pan", "PROCESSING_LEVEL": "L1", "TIFFTAG_DATETIME": "2000:01:01 00:00:00"})
    a = read_acquisition(path, band=1)
    assert (a.acquired_utc, a.platform, a.instrument, a.band_name, a.level) == (
        "2022-03-04T05:06:07Z", "Simsat-1", "PAN", "pan", "L1")
    assert a.site == "WRS-2 181/040" and a.sources["site"] == "product name"   # what the metadata does not say
    assert a.gsd_m == 10.0 and a.sources["platform"] == "metadata"
    b = read_acquisition(path, band=1, acquired="2023-01-01T00:00:00+01:00", platform="Landsat 8",
                         instrument="OLI", band_name="B8", level="L1GT")
    assert (b.acquired_utc, b.platform, b.instrument, b.band_name, b.level) == (
        "2022-12-31T23:00:00Z", "Landsat 8", "OLI", "B8", "L1GT")
    assert set(b.sources.values()) >= {"option"}


def test_the_product_name_beats_the_tiff_tag_which_is_the_last_resort(tmp_path):
    tagged = {"TIFFTAG_DATETIME": "2019:05:06 07:08:09"}
    named = read_acquisition(scene(tmp_path / "LC09_L1TP_181040_20211121_20211122_02_T1_B8.TIF", tagged))
    assert (named.acquired_utc, named.platform, named.sources["acquired_utc"]) == (
        "2021-11-21", "Landsat 9", "product name")
    plain = read_acquisition(scene(tmp_path / "scene.tif", tagged))
    assert (plain.acquired_utc, plain.sources["acquired_utc"], plain.platform) == (
        "2019-05-06T07:08:09Z", "TIFF tag", None)


def test_a_scene_without_time_has_none(tmp_path):
    a = read_acquisition(scene(tmp_path / "scene.tif"))
    assert a.acquired_utc is None and "acquired_utc" not in a.sources


def test_a_malformed_metadata_time_names_the_file_unless_a_time_is_given(tmp_path):
    path = scene(tmp_path / "scene.tif", {"ACQUISITION_DATETIME": "last tuesday"})
    with pytest.raises(ImageReadError, match="scene.tif: the metadata's acquisition time 'last tuesday'"):
        read_acquisition(path)
    assert read_acquisition(path, acquired="2024-01-02").acquired_utc == "2024-01-02"


def test_the_identity_is_the_files_bytes_band_and_settings(tmp_path):
    first = scene(tmp_path / "a.tif")
    copy = scene(tmp_path / "b.tif")                 # the same bytes under another name
    changed = scene(tmp_path / "c.tif", value=1)
    settings = {"method": "ESF", "bootstrap": 0}
    a = read_acquisition(first, band=1, settings=settings)
    assert read_acquisition(first, band=1, settings=dict(settings), run_utc="2030-01-01T00:00:00Z"
                            ).acquisition_id == a.acquisition_id
    assert read_acquisition(copy, band=1, settings=settings).acquisition_id == a.acquisition_id
    others = {read_acquisition(changed, band=1, settings=settings).acquisition_id,
              read_acquisition(first, band=2, settings=settings).acquisition_id,
              read_acquisition(first, band=1, settings={**settings, "method": "LSF"}).acquisition_id}
    assert a.acquisition_id not in others and len(others) == 3
    assert len(a.sha256) == 64 and a.to_dict()["settings"] == settings


def test_an_unreadable_file_is_a_clear_error(tmp_path):
    (tmp_path / "x.tif").write_text("not an image")
    with pytest.raises(ImageReadError, match="x.tif"):
        read_acquisition(tmp_path / "x.tif")


def test_the_sensor_key_tells_sensors_apart_by_camera_tags_or_image_signature(tmp_path):
    from dataclasses import replace

    from imgmtf.campaign.acquisitions import sensor_key
    from imgmtf.io import raster_info, raster_metadata
    a = read_acquisition(scene(tmp_path / "a.tif", gsd_m=2.0), band=1)
    b = read_acquisition(scene(tmp_path / "b.tif", gsd_m=2.0, value=5), band=1)
    assert a.sensor_key == b.sensor_key == "16 x 16 px uint16, GSD 2 m"       # one sensor's chips, cut alike
    other = read_acquisition(scene(tmp_path / "c.tif", {"TIFFTAG_SOFTWARE": "SSTL Terra v1.1.4.0"}, gsd_m=2.0), band=1)
    assert other.sensor_key == "16 x 16 px uint16, GSD 2 m, SSTL Terra v1.1.4.0"
    info = raster_info(tmp_path / "a.tif")
    camera = {"default": {"EXIF_Make": "Canon", "EXIF_Model": "EOS 5D", "EXIF_BodySerialNumber": "0421"}}
    assert sensor_key(info, camera) == "camera Canon EOS 5D 0421"
    assert sensor_key(replace(info, count=3, width=20), raster_metadata(tmp_path / "a.tif")) == (
        "20 x 16 px uint16, 3 bands, GSD 2 m")


def test_the_real_baotou_and_pan_chips_are_two_sensors():
    # neither names a platform: a store of both must not trend them together (issue #31)
    from conftest import real_scene
    keys = {read_acquisition(real_scene(name), band=1).sensor_key
            for name in ("baotou_l0r_checkerboard.tif", "pan_l0r_checkerboard.tif")}
    assert keys == {"101 x 101 px uint16", "80 x 80 px uint16, SSTL Terra v1.1.4.0"}
