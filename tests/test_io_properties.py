"""Property-based tests of the file readers: whatever the bytes, the header's
size or the pixel type, reading gives a Raster or an ImgmtfError, never
another exception, a hang or an allocation of the declared size."""
import struct
import warnings

import numpy as np
import pytest
import rasterio
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from rasterio.errors import NotGeoreferencedWarning

from imgmtf.errors import ImgmtfError
from imgmtf.io import MAX_READ_PIXELS, Raster, raster_info, read_raster

FEW = settings(max_examples=25, deadline=None, derandomize=True,  # the same examples on every run
               suppress_health_check=[HealthCheck.function_scoped_fixture])
DTYPES = ["uint8", "int8", "uint16", "int16", "uint32", "int32", "float32", "float64", "complex64"]


def read_outcome(path, **kwargs):
    """read_raster's result, or the ImgmtfError it raised (any other
    exception fails the test)."""
    try:
        raster = read_raster(path, **kwargs)
    except ImgmtfError as exc:
        assert str(exc).startswith(str(path)) and "\n" not in str(exc)
        return exc
    assert isinstance(raster, Raster) and raster.data.dtype == np.float64
    return raster


def tiff_header(width, height, bits=8, sample_format=1, offset=0, bigtiff=False):
    """A minimal little-endian TIFF (or BigTIFF) of one strip at ``offset``
    whose header declares width x height px, with no pixel data behind it."""
    tags = [(256, width), (257, height), (258, bits), (259, 1), (262, 1), (273, offset),
            (277, 1), (278, height), (279, (width * height * bits // 8) % 2**32), (339, sample_format)]
    if bigtiff:
        out = struct.pack("<2sHHHQ", b"II", 43, 8, 0, 16) + struct.pack("<Q", len(tags))
        for tag, value in tags:
            out += struct.pack("<HHQQ", tag, 16, 1, value)
        return out + struct.pack("<Q", 0)
    out = struct.pack("<2sHI", b"II", 42, 8) + struct.pack("<H", len(tags))
    for tag, value in tags:
        out += struct.pack("<HHII", tag, 4, 1, value % 2**32)
    return out + b"\0\0\0\0"


@FEW
@given(data=st.binary(max_size=2000), suffix=st.sampled_from([".tif", ".png", ".jpg", ".vrt", ".jp2"]))
def test_random_bytes(tmp_path, data, suffix):
    path = tmp_path / f"random{suffix}"
    path.write_bytes(data)
    read_outcome(path)


@FEW
@given(width=st.integers(1, 2**31 - 1), height=st.integers(1, 2**31 - 1),
       kind=st.sampled_from([(8, 1), (16, 1), (16, 2), (32, 3), (64, 3), (64, 6)]),
       bigtiff=st.booleans())
def test_headers_declaring_any_size(tmp_path, width, height, kind, bigtiff):
    path = tmp_path / "declared.tif"
    path.write_bytes(tiff_header(width, height, *kind, bigtiff=bigtiff))
    outcome = read_outcome(path)
    if width * height > MAX_READ_PIXELS:
        assert isinstance(outcome, ImgmtfError) and outcome.reason in ("too-large", "unreadable",
                                                                       "unsupported-type")


@FEW
@given(dtype=st.sampled_from(DTYPES), rows=st.integers(1, 40), cols=st.integers(1, 40),
       cut=st.floats(0.0, 1.0), nodata=st.booleans(), seed=st.integers(0, 2**16))
def test_written_files_whole_and_truncated(tmp_path, dtype, rows, cols, cut, nodata, seed):
    rng = np.random.default_rng(seed)
    values = rng.normal(0, 1e4, (rows, cols))
    if dtype.startswith("complex"):
        values = values + 1j * values
    elif not dtype.startswith("float"):
        info = np.iinfo(dtype)
        values = np.clip(values, info.min, info.max)
    path = tmp_path / "written.tif"
    path.unlink(missing_ok=True)        # the last example's truncated copy
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(path, "w", driver="GTiff", width=cols, height=rows, count=1, dtype=dtype,
                           nodata=0 if nodata and not dtype.startswith("complex") else None) as dst:
            dst.write(values.astype(dtype)[None])
    whole = read_outcome(path)
    if dtype.startswith("complex"):
        assert isinstance(whole, ImgmtfError) and whole.reason == "unsupported-type"
    else:
        assert isinstance(whole, Raster) and whole.data.shape == (rows, cols)
    data = path.read_bytes()
    path.write_bytes(data[: int(cut * len(data))])
    read_outcome(path)


@pytest.mark.parametrize("bigtiff", [False, True])
def test_huge_declared_image_is_refused_by_name_and_read_through_a_window(tmp_path, bigtiff):
    path = tmp_path / "huge.tif"
    path.write_bytes(tiff_header(200_000, 200_000, bigtiff=bigtiff))
    assert path.stat().st_size < 300
    outcome = read_outcome(path)
    assert outcome.reason == "too-large"
    assert "200000 x 200000 px (40000.0 million pixels), more than the 16.8 million" in str(outcome)
    assert str(outcome).endswith("measure a window of it")
    from imgmtf.io import check_read_size
    with pytest.raises(ImgmtfError, match=r"the window is 6000 x 6000 px \(36.0 million pixels\).*a smaller window"):
        check_read_size("big.tif", (6000, 6000), windowed=True)
    from imgmtf.cli.hints import refusal_hint
    assert "--roi" in refusal_hint(outcome.reason, str(outcome))         # the CLI names the option
    info = raster_info(path)
    assert (info.width, info.height) == (200_000, 200_000)
    read_outcome(path, window=(0, 0, 64, 64))          # a window is allowed (the file has no data)


def test_vrt_declaring_a_huge_image(tmp_path):
    small = tmp_path / "small.tif"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(small, "w", driver="GTiff", width=4, height=4, count=1, dtype="uint8") as dst:
            dst.write(np.ones((1, 4, 4), np.uint8))
    vrt = tmp_path / "mosaic.vrt"
    vrt.write_text(f"""<VRTDataset rasterXSize="100000" rasterYSize="100000">
  <VRTRasterBand dataType="Byte" band="1"><SimpleSource>
    <SourceFilename relativeToVRT="0">{small}</SourceFilename><SourceBand>1</SourceBand>
    <SrcRect xOff="0" yOff="0" xSize="4" ySize="4"/><DstRect xOff="0" yOff="0" xSize="4" ySize="4"/>
  </SimpleSource></VRTRasterBand></VRTDataset>""")
    assert read_outcome(vrt).reason == "too-large"
    assert read_outcome(vrt, window=(0, 0, 16, 16)).data.shape == (16, 16)
