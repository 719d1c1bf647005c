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
import os
import stat
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import rasterio
from rasterio.errors import NotGeoreferencedWarning, RasterioError
from rasterio.transform import Affine
from rasterio.windows import Window

from .atomic import atomic_output
from .errors import FileWriteError, ImageContentError, ImageReadError, ImgmtfError, ParameterError
from .inputs import check_roi, luminance

try:     # GDAL's own errors, which rasterio raises as they are from some calls
    from rasterio._err import CPLE_BaseError
except ImportError:       # pragma: no cover - a rasterio without the private module
    CPLE_BaseError = RasterioError
GDAL_ERRORS = (RasterioError, CPLE_BaseError)

# The most pixels one read returns: 16 Mpx (4096 x 4096) is 128 MiB as
# float64, far more than any edge or bar needs, and few enough that the
# estimators' working copies fit in memory.  A larger image is measured
# through a window (``window=``, ``--roi``); scan reads tiles and decimated
# overviews, each far below it.
MAX_READ_PIXELS = 16 * 1024 * 1024


@dataclass(frozen=True, eq=False)
class Raster:
    """One band (or the luminance) of an image file, as :func:`read_raster`
    returns it.

    Attributes
    ----------
    data : numpy.ndarray of float64, shape (rows, cols)
        The pixels, DN; NaN where the file marks nodata.
    path : str
        The file it came from.
    band : int or str
        1-based band number, or ``"luminance"`` for RGB(A) input.
    gsd_m : float or None
        Pixel size in metres when the file is georeferenced, else None.
    tags : dict
        The file's metadata tags.
    dtype : str
        The stored sample type (``"uint16"``...): integer types set the
        saturation limits.
    origin : (int, int)
        (x, y) of ``data``'s top-left pixel in the file (a window's).
    map_projected : bool
        True when the file has a coordinate reference system: a
        map-projected (or geographic) product, whose rows are not along
        the sensor's track.
    compression : str or None
        The lossy codec the file was written with ("JPEG", "lossy JPEG
        2000", "lossy WebP", "LERC"...), None for lossless or none: its
        loss is part of any MTF measured from the file.

    Examples
    --------
    >>> import imgmtf
    >>> imgmtf.write_geotiff("edge.tif", imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 100).image)
    >>> raster = imgmtf.read_raster("edge.tif")
    >>> raster.band, raster.gsd_m, raster.dtype, raster.data.shape
    (1, 1.0, 'uint16', (100, 100))
    """

    data: np.ndarray
    path: str
    band: int | str
    gsd_m: float | None
    tags: dict = field(default_factory=dict)
    dtype: str = "float64"
    origin: tuple[int, int] = (0, 0)
    map_projected: bool = False
    compression: str | None = None

    @property
    def provenance(self) -> dict | None:
        """How imgmtf made the chip (:meth:`imgmtf.Chip.provenance`: sensor,
        target, GSD, noise, seed) when imgmtf wrote it, else None."""
        text = self.tags.get("IMGMTF")
        try:
            return json.loads(text) if text else None
        except ValueError:
            return None


def write_geotiff(path: str | Path, image: np.ndarray, *, gsd_m: float = 1.0,
                  provenance: dict | None = None, crs: str | None = None,
                  origin_m: tuple[float, float] = (0.0, 0.0), tags: dict[str, str] | None = None) -> None:
    """Write an 8/16-bit chip as a GeoTIFF that carries its GSD and how it
    was made.

    Without ``crs`` the chip is in a local metric frame: the geotransform
    is (``gsd_m``, 0, 0, 0, -``gsd_m``, 0), which :func:`read_raster` reads
    back as the GSD.  The file appears whole or not at all (written under a
    temporary name, then renamed).

    Parameters
    ----------
    path : str or pathlib.Path
        The GeoTIFF to write (replaced if it exists).
    image : numpy.ndarray of uint8 or uint16, shape (rows, cols) or (bands, rows, cols)
        The pixels, DN.
    gsd_m : float, optional
        Ground sample distance, m (default 1).
    provenance : dict, optional
        How the chip was made (:meth:`imgmtf.Chip.provenance`), stored as
        JSON in the ``IMGMTF`` tag and read back by
        :attr:`Raster.provenance`; its main items also as plain tags for
        ``gdalinfo``.
    crs : str, optional
        A coordinate reference system (``"EPSG:32633"``) placing the chip on
        a map.
    origin_m : (float, float), optional
        Map x, y of the top-left corner, m (with ``crs``).
    tags : dict of str, optional
        More metadata items of the default domain (``ACQUISITION_DATETIME``,
        ``PLATFORM``...), as a product's reader finds them.

    Raises
    ------
    ParameterError
        The image is not uint8 or uint16.
    FileWriteError
        The file cannot be written (no such folder, no permission, disk
        full...).

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 40, gsd_m=0.5)
    >>> imgmtf.write_geotiff("chip.tif", chip.image, gsd_m=chip.gsd_m, provenance=chip.provenance())
    >>> raster = imgmtf.read_raster("chip.tif")
    >>> raster.gsd_m, raster.provenance["target"]["angle_deg"]
    (0.5, 6.0)
    """
    tags = {key: str(value) for key, value in (tags or {}).items()}
    if provenance:
        tags["IMGMTF"] = json.dumps(provenance, sort_keys=True)
        target = provenance.get("target", {})
        for key in ("kind", "angle_deg", "low_dn", "high_dn", "width_px", "offset_px"):
            if key in target:
                tags[f"TARGET_{key.upper()}"] = str(target[key])
        for key in ("noise_std_dn", "seed", "imgmtf_version"):
            tags[key.upper()] = str(provenance.get(key))
    _write_image(path, image, "GTiff", tags,
                 transform=Affine(gsd_m, 0.0, origin_m[0], 0.0, -gsd_m, origin_m[1]), crs=crs)


def write_png(path: str | Path, image: np.ndarray) -> None:
    """Write an 8/16-bit image as a grey (or RGB) PNG, for viewers and
    tools that read no TIFF.

    A PNG keeps the pixels only: no GSD and no provenance (use
    :func:`write_geotiff` for those), so :func:`read_raster` gives it
    ``gsd_m`` None and figures in pixel units.

    Parameters
    ----------
    path : str or pathlib.Path
        The PNG to write (replaced if it exists), atomically.
    image : numpy.ndarray of uint8 or uint16, shape (rows, cols) or (bands, rows, cols)
        The pixels, DN (1 band: grey; 3: RGB; 4: RGBA).

    Raises
    ------
    ParameterError
        The image is not uint8 or uint16.
    FileWriteError
        The file cannot be written.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 40, bits=8)
    >>> imgmtf.write_png("chip.png", chip.image)
    >>> raster = imgmtf.read_raster("chip.png")
    >>> raster.dtype, raster.gsd_m
    ('uint8', None)
    """
    _write_image(path, image, "PNG", {})


def _write_image(path: str | Path, image: np.ndarray, driver: str, tags: dict, **georeference) -> None:
    """Write uint8/uint16 pixels with a GDAL ``driver``, atomically."""
    image = np.asarray(image)
    kind = {"GTiff": "GeoTIFF chips", "PNG": "PNG images"}[driver]
    if image.dtype not in (np.uint8, np.uint16):
        raise ParameterError(f"{path}: {kind} are 8 or 16 bit, got {image.dtype}")
    if image.ndim not in (2, 3):
        raise ParameterError(f"{path}: expected (rows, cols) or (bands, rows, cols) pixels, "
                             f"got shape {image.shape}")
    bands = image[None] if image.ndim == 2 else image
    profile = dict(driver=driver, width=bands.shape[2], height=bands.shape[1], count=bands.shape[0],
                   dtype=bands.dtype.name, **georeference)
    with atomic_output(path) as partial:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", NotGeoreferencedWarning)
                with rasterio.open(partial, "w", **profile) as dst:
                    dst.write(bands)
                    if tags:
                        dst.update_tags(**tags)
        except (*GDAL_ERRORS, OSError) as exc:
            raise FileWriteError(f"{path}: cannot write: {_reason(exc)}") from None


@dataclass(frozen=True)
class RasterInfo:
    """What a raster file holds, read from its header only.

    ``width``/``height`` in pixels; ``count`` bands; ``colours`` their
    colour interpretations; ``gsd_m`` as in :class:`Raster`; ``transform``
    the pixel-to-map affine and ``crs`` its CRS (WKT or None).
    """

    path: str
    width: int
    height: int
    count: int
    colours: tuple[str, ...]
    dtype: str
    gsd_m: float | None
    transform: Affine
    crs: str | None

    @property
    def is_rgb(self) -> bool:
        return self.count in (3, 4) and list(self.colours[:3]) == ["red", "green", "blue"]

    @property
    def is_grey_alpha(self) -> bool:
        """A grey band and its transparency (a grey+alpha PNG): the grey band is the image."""
        return self.count == 2 and list(self.colours) == ["gray", "alpha"]

    @property
    def alpha_bands(self) -> list[int]:
        """1-based numbers of the bands that hold transparency, not DN."""
        return [i + 1 for i, colour in enumerate(self.colours) if colour == "alpha"]

    def bands(self, band: int | str | None) -> list[int | None]:
        """The band selections ``band`` stands for: ``"all"`` every band but
        alpha, otherwise just ``band`` (None: the single band or RGB
        luminance)."""
        if band == "all":
            return [i for i in range(1, self.count + 1) if i not in self.alpha_bands]
        if isinstance(band, str):
            raise ParameterError(f"band must be a 1-based number or 'all', got {band!r}")
        return [band]

    def check_window(self, window) -> tuple[int, int, int, int]:
        """``window`` = (x, y, width, height) validated against the image."""
        return check_roi(window, (self.height, self.width), self.path)


def raster_info(path: str | Path) -> RasterInfo:
    """Read a raster file's header (size, bands, type, georeferencing)."""
    with open_raster(path) as file:
        return file.info


class RasterFile:
    """An image file held open by :func:`open_raster`: its header
    (``info``) and its bands, read by :meth:`read` as :func:`read_raster`
    reads them, without opening the file again for each."""

    def __init__(self, path: str, src):
        self.path, self._src = path, src
        self.info = RasterInfo(path, src.width, src.height, src.count, tuple(c.name for c in src.colorinterp),
                               src.dtypes[0], _gsd_m(src), src.transform,
                               src.crs.to_wkt() if src.crs else None)

    def read(self, band: int | None = None, window: tuple[int, int, int, int] | None = None,
             out_shape: tuple[int, int] | None = None) -> Raster:
        """One band, a window of it, or the luminance: see :func:`read_raster`."""
        return _read(self._src, self.info, band, window, out_shape)


@contextmanager
def open_raster(path: str | Path) -> Iterator[RasterFile]:
    """An image file open for its header and any number of reads (the
    file is opened once: a batch of small chips pays GDAL's open once per
    file, not once per question).

    Raises
    ------
    ImageReadError
        As :func:`read_raster`: the file cannot be opened, or a GDAL or
        OS error arises within the block (reported as the file's).

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.io import open_raster
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 64)
    >>> imgmtf.write_geotiff("chip.tif", chip.image, gsd_m=2.0)
    >>> with open_raster("chip.tif") as file:
    ...     file.info.count, file.read(1).data.shape
    (1, (64, 64))
    """
    path = _file_name(path)
    with _opened(path) as src:
        yield RasterFile(path, src)


@contextmanager
def many_files() -> Iterator[None]:
    """GDAL set to open many files in a row without listing a file's folder
    at each open (a folder of 2000 chips: 1-2 ms an open); side-cars (a
    ``.tfw``, ``.aux.xml``, ``.msk``) are looked for by name instead, the
    same files found.  A ``GDAL_DISABLE_READDIR_ON_OPEN`` the user set is kept."""
    if "GDAL_DISABLE_READDIR_ON_OPEN" in os.environ:
        yield
        return
    with rasterio.Env(GDAL_DISABLE_READDIR_ON_OPEN="TRUE"):
        yield


def raster_metadata(path: str | Path, band: int | None = None) -> dict[str, dict[str, str]]:
    """A raster file's metadata items as GDAL reports them, by domain:
    ``"default"`` (the dataset's own items and TIFF tags such as
    ``TIFFTAG_DATETIME``), ``"imagery"`` (GDAL's IMAGERY domain:
    ``SATELLITEID``, ``ACQUISITIONDATETIME`` from a product's sidecar files)
    and ``"band"`` (the band's own items, with its description as
    ``DESCRIPTION`` when it has one; band 1 when ``band`` is None).

    Raises
    ------
    ImageReadError
        The file cannot be opened.
    """
    with _opened(path) as src:
        index = band if isinstance(band, int) and 1 <= band <= src.count else 1
        band_items = dict(src.tags(index))
        if src.descriptions[index - 1]:
            band_items["DESCRIPTION"] = src.descriptions[index - 1]
        imagery = dict(src.tags(ns="IMAGERY")) if "IMAGERY" in (src.tag_namespaces() or []) else {}
        return {"default": dict(src.tags()), "imagery": imagery, "band": band_items}


def read_raster(path: str | Path, band: int | None = None, window: tuple[int, int, int, int] | None = None,
                out_shape: tuple[int, int] | None = None) -> Raster:
    """Read one band of an image file (anything GDAL reads: GeoTIFF, PNG,
    JPEG, JP2, NITF...) as float64 DN.

    With ``band=None`` a single-band file (or a grey one with alpha) gives
    its band and an RGB or RGBA file (8/16-bit, colour-interpreted as
    such) gives the Rec. 709 luminance of its stored values (alpha
    ignored; no gamma decoding).  Any other multi-band file needs ``band``.  Nodata pixels become NaN.

    ``window`` = (x, y, width, height) reads only that part of the image
    (``Raster.origin`` is its top-left pixel), so a large scene is never
    loaded whole for a small ROI.  ``out_shape`` = (rows, cols) reads the
    window decimated (nearest), for overviews.

    Parameters
    ----------
    path : str or pathlib.Path
        The image file (a regular file).
    band : int, optional
        1-based band to read.
    window : (int, int, int, int), optional
        (x, y, width, height) in pixels: read only this part.
    out_shape : (int, int), optional
        (rows, cols) to read the window decimated to (nearest).

    Returns
    -------
    Raster
        The pixels with the file's GSD, tags, type and provenance.

    Raises
    ------
    ImageReadError
        The file is missing, not a regular file (a FIFO or a device is
        never opened), not an image, damaged, of a complex pixel type, or
        larger than :data:`MAX_READ_PIXELS` for one read (reason
        ``too-large``: read a window of it).
    ParameterError
        A bad ``band``, ``window`` or ``out_shape``.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 200)
    >>> imgmtf.write_geotiff("scene.tif", chip.image, gsd_m=2.0)
    >>> raster = imgmtf.read_raster("scene.tif", window=(100, 60, 64, 64))
    >>> raster.data.shape, raster.origin, raster.gsd_m
    ((64, 64), (100, 60), 2.0)
    """
    with open_raster(path) as file:
        return file.read(band, window, out_shape)


def _read(src, info: RasterInfo, band, window, out_shape) -> Raster:
    """One band (or the luminance) of an open dataset: see :func:`read_raster`."""
    path, count = info.path, info.count
    map_projected = src.crs is not None
    x, y, w, h = info.check_window(window) if window is not None else (0, 0, info.width, info.height)
    if out_shape is not None:
        out_shape = _check_shape(path, out_shape)
    check_read_size(path, (w, h) if out_shape is None else (out_shape[1], out_shape[0]),
                    windowed=window is not None)
    region = Window(x, y, w, h)
    if band is not None:
        if isinstance(band, (bool, np.bool_)) or not isinstance(band, (int, np.integer)):
            raise ParameterError(f"{path}: band must be a 1-based integer, got {band!r}")
        if not 1 <= band <= count:
            raise ParameterError(f"{path}: band {band} does not exist (the file has {count})")
        chosen: int | str = int(band)
        data = _band(src, int(band), region, out_shape)
    elif count == 1 or info.is_grey_alpha:
        chosen, data = 1, _band(src, 1, region, out_shape)
    elif info.is_rgb:
        chosen = "luminance"
        data = luminance(np.stack([_band(src, i, region, out_shape) for i in (1, 2, 3)]), channel_axis=0)
    else:
        raise ParameterError(f"{path}: has {count} bands and no RGB colour interpretation; "
                             "choose one band", reason="bands")
    tags = src.tags()
    codec = lossy_codec(src)
    if data.size == 0:
        raise ImageContentError(f"{path}: the image is empty")
    return Raster(data, path, chosen, info.gsd_m, tags, info.dtype, (x, y), map_projected, codec)


def lossy_codec(src) -> str | None:
    """The lossy codec an open dataset was written with, from its driver,
    its TIFF compression tag and GDAL's reversibility note; None for
    lossless storage."""
    structure = src.tags(ns="IMAGE_STRUCTURE")
    reversible = structure.get("COMPRESSION_REVERSIBILITY", "").upper()
    compression = (structure.get("COMPRESSION") or (src.compression.name if src.compression else "")).upper()
    if src.driver == "JPEG" or compression in ("JPEG", "OJPEG", "YCBCR JPEG"):
        return "JPEG"
    if reversible.startswith("LOSSY"):
        return {"JP2OpenJPEG": "lossy JPEG 2000", "JP2KAK": "lossy JPEG 2000", "JP2ECW": "lossy JPEG 2000",
                "WEBP": "lossy WebP"}.get(src.driver, f"lossy {compression or src.driver}")
    if compression == "LERC" and float(structure.get("MAX_Z_ERROR", "0") or 0) > 0:
        return "LERC (lossy)"
    return None


def _check_shape(path: str, shape) -> tuple[int, int]:
    """``shape`` = (rows, cols), two whole numbers >= 1, else a ParameterError naming ``path``."""
    try:
        rows, cols = shape
        if all(isinstance(n, (int, np.integer)) and not isinstance(n, (bool, np.bool_)) and n >= 1
               for n in (rows, cols)):
            return int(rows), int(cols)
    except (TypeError, ValueError):
        pass
    raise ParameterError(f"{path}: out_shape must be (rows, cols), two whole numbers >= 1, got {shape!r}")


def check_read_size(path: str, size: tuple[int, int], windowed: bool = False) -> None:
    """Refuse to read ``size`` = (width, height) px at once when it is more
    than :data:`MAX_READ_PIXELS`: the header's word is taken before a byte
    of pixels is read, so a small file declaring a huge image costs
    nothing."""
    width, height = size
    if width * height > MAX_READ_PIXELS:
        what, advice = ("the window", "measure a smaller window") if windowed else ("the image",
                                                                                    "measure a window of it")
        # in millions of pixels, as a camera's megapixels are counted (2^20 made 36.0 million read 34.33)
        raise ImageReadError(
            f"{path}: {what} is {width} x {height} px ({width * height / 1e6:.1f} million pixels), more than "
            f"the {MAX_READ_PIXELS / 1e6:.1f} million read at once; {advice}", reason="too-large")


def check_regular_file(path: str) -> None:
    """Refuse anything but a regular file (following links) before GDAL
    sees it: GDAL blocks forever reading a FIFO and reads a device whole."""
    if not path:
        raise ImageReadError("'': an empty path names no file")
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise ImageReadError(f"{path}: no such file") from None
    except (OSError, ValueError) as exc:      # ValueError: a NUL byte in the path
        raise ImageReadError(f"{path!r}: cannot read: {getattr(exc, 'strerror', None) or exc}") from None
    if stat.S_ISDIR(mode):
        raise ImageReadError(f"{path}: is a folder, not an image")
    if not stat.S_ISREG(mode):
        kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(mode) else "a device" if stat.S_ISCHR(mode)
                or stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode) else "not a regular file")
        raise ImageReadError(f"{path}: is {kind}, not an image file; imgmtf reads regular files only")


def _file_name(path) -> str:
    """``path`` (str or os.PathLike) as a str; a ParameterError for anything else (None, an array)."""
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"expected an image file's name (str or os.PathLike), got {type(path).__name__}")
    return str(path)


@contextmanager
def _opened(path):
    """An open rasterio dataset of a regular file with real pixels, GDAL's
    failures turned into ImageReadError; a ParameterError for a path that
    is no file name (None, an array)."""
    path = _file_name(path)
    check_regular_file(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            with rasterio.open(path) as src:
                complex_types = sorted({t for t in src.dtypes if "complex" in t})
                if complex_types:
                    raise ImageReadError(f"{path}: has complex pixels ({', '.join(complex_types)}); "
                                         "an MTF needs real DN: convert the band you want first "
                                         "(e.g. its magnitude)", reason="unsupported-type")
                yield src
    except ImgmtfError:
        raise                     # already says what is wrong (an OSError too: not to be wrapped again)
    except GDAL_ERRORS as exc:
        kind = _image_kind(path)
        if kind:
            raise ImageReadError(f"{path}: a {kind} file that is damaged or truncated "
                                 f"(GDAL: {_reason(exc)})") from None
        raise ImageReadError(f"{path}: not an image GDAL can read ({_reason(exc, path)})") from None
    except OSError as exc:
        raise ImageReadError(f"{path}: cannot read: {_reason(exc, path)}") from None


# leading bytes of the formats users bring, to tell a damaged image from a non-image
_SIGNATURES = {b"II*\x00": "TIFF", b"MM\x00*": "TIFF", b"II+\x00": "BigTIFF", b"MM\x00+": "BigTIFF",
               b"\x89PNG": "PNG", b"\xff\xd8\xff": "JPEG", b"\x00\x00\x00\x0cjP  ": "JPEG 2000",
               b"\xffO\xffQ": "JPEG 2000", b"NITF": "NITF"}


def _image_kind(path: str) -> str | None:
    """The image format a file's leading bytes announce, if any."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(12)
    except OSError:
        return None
    return next((kind for magic, kind in _SIGNATURES.items() if head.startswith(magic)), None)


def _band(src, index: int, window: Window, out_shape=None) -> np.ndarray:
    """Band ``index`` as float64, nodata (mask) NaN; no mask read where GDAL says all is valid."""
    masked = rasterio.enums.MaskFlags.all_valid not in src.mask_flag_enums[index - 1]
    try:
        values = src.read(index, window=window, masked=masked, out_shape=out_shape)
    except GDAL_ERRORS as exc:
        raise ImageReadError(f"{src.name}: the file is damaged or truncated ({_reason(exc)})") from None
    data = (values.data if masked else values).astype(np.float64)
    if masked:
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


def _reason(exc: Exception, path: object = None) -> str:
    """GDAL's own first line; rasterio sometimes wraps it in "see previous
    exception", whose text is the cause's.  GDAL names the file again
    (``'x.tif' not recognized as ...``); the message already starts with
    ``path``, so that repeat is dropped."""
    text = str(exc).strip() or type(exc).__name__
    if "previous exception" in text and exc.__cause__ is not None:
        text = str(exc.__cause__).strip() or text
    text = text.splitlines()[0]
    if path is not None:
        text = text.replace(f"'{path}' ", "").replace(f"{path}: ", "")
    return text
