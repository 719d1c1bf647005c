"""Image files: GeoTIFF chips written with rasterio, and any raster GDAL
reads (GeoTIFF, PNG, JPEG, JP2, NITF...) read back as float arrays.

Chips are written in a local metric frame without a CRS: the geotransform
is (gsd, 0, 0, 0, -gsd, 0), so the pixel size carries the GSD in metres and
the origin is the chip's top-left corner.  Provenance (sensor, target,
levels, noise, seed, version) is stored as JSON in the ``IMGMTF`` tag, with
the main figures also as plain tags for ``gdalinfo``.
"""
from __future__ import annotations

import json
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import rasterio
from rasterio.errors import NotGeoreferencedWarning, RasterioIOError
from rasterio.transform import Affine

from .errors import FileWriteError, ImageContentError, ImageReadError, ParameterError

# Rec. 709 luma weights, applied to the stored (encoded) values of RGB input
LUMA_WEIGHTS = (0.2126, 0.7152, 0.0722)


@dataclass(frozen=True, eq=False)
class Raster:
    """One band (or the luminance) of an image file.

    Attributes
    ----------
    data : 2-D float64 array (DN), NaN where the file marks nodata.
    path : the file it came from.
    band : 1-based band number, or "luminance" for RGB(A) input.
    gsd_m : pixel size in metres when the file is georeferenced, else None.
    tags : the file's metadata tags.
    dtype : the stored sample type (e.g. "uint16").
    """

    data: np.ndarray
    path: str
    band: int | str
    gsd_m: float | None
    tags: dict = field(default_factory=dict)
    dtype: str = "float64"

    @property
    def provenance(self) -> dict | None:
        """The imgmtf provenance record of a chip imgmtf wrote, else None."""
        text = self.tags.get("IMGMTF")
        try:
            return json.loads(text) if text else None
        except ValueError:
            return None


def write_geotiff(path: str | Path, image: np.ndarray, *, gsd_m: float = 1.0,
                  provenance: dict | None = None) -> None:
    """Write a uint8/uint16 chip (rows x cols, or bands x rows x cols) as a
    GeoTIFF whose geotransform carries ``gsd_m`` and whose tags carry
    ``provenance``."""
    image = np.asarray(image)
    if image.dtype not in (np.uint8, np.uint16):
        raise ParameterError(f"{path}: GeoTIFF chips are 8 or 16 bit, got {image.dtype}")
    bands = image[None] if image.ndim == 2 else image
    tags = {}
    if provenance:
        tags["IMGMTF"] = json.dumps(provenance, sort_keys=True)
        target = provenance.get("target", {})
        for key in ("kind", "angle_deg", "low_dn", "high_dn", "width_px", "offset_px"):
            if key in target:
                tags[f"TARGET_{key.upper()}"] = str(target[key])
        for key in ("noise_std_dn", "seed", "imgmtf_version"):
            tags[key.upper()] = str(provenance.get(key))
    profile = dict(driver="GTiff", width=bands.shape[2], height=bands.shape[1],
                   count=bands.shape[0], dtype=bands.dtype.name,
                   transform=Affine(gsd_m, 0.0, 0.0, 0.0, -gsd_m, 0.0))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            with rasterio.open(path, "w", **profile) as dst:
                dst.write(bands)
                dst.update_tags(**tags)
    except (RasterioIOError, OSError) as exc:
        raise FileWriteError(f"{path}: cannot write: {_reason(exc)}") from None


def read_raster(path: str | Path, band: int | None = None) -> Raster:
    """Read one band of an image file as float64 DN.

    With ``band=None`` a single-band file gives its band and an RGB or RGBA
    file (8/16-bit, colour-interpreted as such) gives the Rec. 709 luminance
    of its stored values (alpha ignored; no gamma decoding).  Any other
    multi-band file needs ``band``.  Nodata pixels become NaN.
    """
    path = str(path)
    if not Path(path).exists():
        raise ImageReadError(f"{path}: no such file")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            with rasterio.open(path) as src:
                count = src.count
                colours = [c.name for c in src.colorinterp]
                if band is not None:
                    if not 1 <= band <= count:
                        raise ParameterError(f"{path}: band {band} does not exist (the file has {count})")
                    chosen: int | str = band
                    data = _band(src, band)
                elif count == 1:
                    chosen, data = 1, _band(src, 1)
                elif count in (3, 4) and colours[:3] == ["red", "green", "blue"]:
                    chosen = "luminance"
                    data = sum(w * _band(src, i + 1) for i, w in enumerate(LUMA_WEIGHTS))
                else:
                    raise ParameterError(f"{path}: has {count} bands; choose one with --band")
                gsd = _gsd_m(src)
                tags = src.tags()
                dtype = src.dtypes[0]
    except RasterioIOError as exc:
        raise ImageReadError(f"{path}: not an image GDAL can read ({_reason(exc)})") from None
    except OSError as exc:
        raise ImageReadError(f"{path}: cannot read: {_reason(exc)}") from None
    if data.size == 0:
        raise ImageContentError(f"{path}: the image is empty")
    return Raster(data, path, chosen, gsd, tags, dtype)


def _band(src, index: int) -> np.ndarray:
    """Band ``index`` as float64 with nodata (mask) set to NaN."""
    try:
        values = src.read(index, masked=True)
    except RasterioIOError as exc:
        raise ImageReadError(f"{src.name}: the file is damaged or truncated ({_reason(exc)})") from None
    data = values.data.astype(np.float64)
    data[np.ma.getmaskarray(values)] = np.nan
    return data


def _gsd_m(src) -> float | None:
    """Pixel size in metres: from a projected CRS, or from a geotransform
    without CRS (taken as metres, the convention of imgmtf chips); None for
    identity transforms, rotated grids and geographic CRSs."""
    t = src.transform
    if t.is_identity or t.b != 0 or t.d != 0 or abs(abs(t.a) - abs(t.e)) > 1e-9 * abs(t.a):
        return None
    if src.crs is None:
        return abs(t.a)
    if src.crs.is_projected:
        return abs(t.a) * src.crs.linear_units_factor[1]
    return None


def _reason(exc: Exception) -> str:
    text = str(exc).strip() or type(exc).__name__
    return text.splitlines()[0]
