"""Apply a restoration filter: to an array, or tile by tile to any raster GDAL reads.

A file is restored in tiles, each read with a halo of the kernel's radius
around it (mirrored at the image's borders, exactly as the whole image would
be), so that tiles join without a seam and memory holds a few tiles however
large the scene.  Tiles run on local workers or a Dask cluster
(:func:`imgmtf.parallel.run_tasks`) and are written as they complete to a
tiled GeoTIFF that keeps the input's georeference, data type, nodata, tags,
band descriptions and colour interpretation, and that appears whole or not
at all (:mod:`imgmtf.atomic`).  A chip's ``IMGMTF`` provenance tag (how it
was rendered, hence its true MTF) is kept as ``IMGMTF_SOURCE``: it no longer
describes the restored pixels.

Integer output is rounded and clipped to its type's range; the clipped
fraction is counted.  Input pixels at the saturation levels (an integer
type's limits, or those given) carry no information about the scene beyond
the level: they are kept as they were, and so is undeclared fill (a region
at the band's least value with a hard boundary, such as the 0 around a target
cut out of its scene), counted apart from the saturated pixels.  Nodata pixels stay nodata; while
filtering they hold a fill value (the band's median, from an overview), so
a pixel's restoration never depends on the tile it falls in.  Alpha bands
are copied.
"""
from __future__ import annotations

import hashlib
import json
import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import FileWriteError, ImageContentError, ParameterError
from ..inputs import check_number, saturation_levels
from .convolve import convolve_padded

if TYPE_CHECKING:
    from .design import RestorationFilter

#: tile sides allowed, px: a tile and its halo stay far below one read's 16 Mpx
TILE_RANGE_PX = (64, 2048)
DEFAULT_TILE_PX = 1024
#: side of the overview a band's fill value (its median) is read from, px
OVERVIEW_PX = 512


@dataclass(frozen=True)
class Tile:
    """One tile: the window it writes (x, y, width, height), the window it
    reads (with its halo) and the mirrored padding that completes the halo
    at the image's borders ((top, bottom), (left, right))."""

    core: tuple[int, int, int, int]
    read: tuple[int, int, int, int]
    pads: tuple[tuple[int, int], tuple[int, int]]


def plan_tiles(width: int, height: int, tile_px: int, radius_px: int) -> list[Tile]:
    """The tiles covering a ``width`` x ``height`` image, row by row.

    Examples
    --------
    >>> from imgmtf.restore.apply import plan_tiles
    >>> [t.core for t in plan_tiles(100, 70, 64, 3)]
    [(0, 0, 64, 64), (64, 0, 36, 64), (0, 64, 64, 6), (64, 64, 36, 6)]
    >>> plan_tiles(100, 70, 64, 3)[1].read, plan_tiles(100, 70, 64, 3)[1].pads
    ((61, 0, 39, 67), ((3, 0), (0, 3)))
    """
    tiles = []
    for y in range(0, height, tile_px):
        for x in range(0, width, tile_px):
            w, h = min(tile_px, width - x), min(tile_px, height - y)
            x0, y0 = max(x - radius_px, 0), max(y - radius_px, 0)
            x1, y1 = min(x + w + radius_px, width), min(y + h + radius_px, height)
            pads = ((radius_px - (y - y0), radius_px - (y1 - y - h)),
                    (radius_px - (x - x0), radius_px - (x1 - x - w)))
            tiles.append(Tile((x, y, w, h), (x0, y0, x1 - x0, y1 - y0), pads))
    return tiles


@dataclass(frozen=True, eq=False)
class OutputType:
    """How restored DN become stored samples: the type, its nodata value,
    the saturation levels whose pixels are kept (None for none)."""

    dtype: str
    nodata: float | None
    saturation: tuple[float, float] | None

    def limits(self) -> tuple[float, float] | None:
        """The range restored values are clipped to (an integer type's,
        short of a nodata value at either end); None for floats."""
        levels = saturation_levels(self.dtype)
        if levels is None:
            return None
        low, high = levels
        if self.nodata == low:
            low += 1
        if self.nodata == high:
            high -= 1
        return low, high

    def convert(self, restored: np.ndarray, original: np.ndarray,
                fill_value: float | None = None) -> tuple[np.ndarray, int, int, int]:
        """(samples, pixels clipped, saturated pixels kept, fill pixels kept)
        for one tile; ``original`` is the input's DN (NaN at nodata), and
        its pixels at ``fill_value`` (the band's undeclared fill) are fill,
        kept as they were, not saturated."""
        valid = np.isfinite(original)
        kept = np.zeros(original.shape, bool)
        fill = valid & (original == fill_value) if fill_value is not None else kept
        if self.saturation is not None:
            low, high = self.saturation
            kept = valid & ((original <= low) | (original >= high))
        kept = kept | fill
        values = np.where(kept, original, restored)       # the one tile-sized copy; the rest in place
        limits = self.limits()
        clipped = 0
        if limits is not None:
            values[~valid] = limits[0]
            clipped = int(np.count_nonzero(valid & ~kept & ((values < limits[0]) | (values > limits[1]))))
            np.rint(values, out=values)
            np.clip(values, *limits, out=values)
        if self.nodata is not None:
            values[~valid] = self.nodata
        elif limits is None:
            values[~valid] = np.nan          # a float image's NaN stay NaN
        filled = int(np.count_nonzero(fill))
        return values.astype(self.dtype), clipped, int(np.count_nonzero(kept)) - filled, filled


@dataclass(frozen=True, eq=False)
class TileTask:
    """What a worker needs to restore one tile of one band (all picklable)."""

    path: str
    band: int
    tile: Tile
    taps: np.ndarray | None         # None: copy the band (alpha)
    fill: float
    output: OutputType
    fill_value: float | None = None     # the band's undeclared fill, kept and counted as fill


@dataclass(frozen=True, eq=False)
class TileResult:
    band: int
    core: tuple[int, int, int, int]
    samples: np.ndarray
    clipped: int
    saturated: int
    valid: int
    filled: int = 0


def restore_tile(task: TileTask) -> TileResult:
    """Read one tile with its halo, restore it and convert it to the output type."""
    from ..io import read_raster
    raster = read_raster(task.path, task.band, window=task.tile.read)
    data = raster.data
    x, y, w, h = task.tile.core
    rx, ry = task.tile.read[:2]
    core = data[y - ry: y - ry + h, x - rx: x - rx + w]
    if task.taps is None:
        restored = core
    else:
        padded = np.pad(data, task.tile.pads, mode="symmetric")
        padded[~np.isfinite(padded)] = task.fill
        restored = convolve_padded(padded, task.taps)
        del padded
    samples, clipped, saturated, filled = task.output.convert(restored, core, task.fill_value)
    return TileResult(task.band, task.tile.core, samples, clipped, saturated, int(np.isfinite(core).sum()), filled)


@dataclass(frozen=True)
class RestoredFile:
    """What :func:`restore_file` wrote.

    Attributes
    ----------
    path, out : str
        The input and the restored GeoTIFF.
    width, height : int
        The image, px.
    bands : tuple of int
        The bands restored (alpha bands are copied, not listed).
    dtype : str
        The stored type (the input's).
    tiles : int
        Tiles per band.
    clipped_fraction : float
        Fraction of the restored valid pixels clipped to the type's range.
    saturated_fraction : float
        Fraction of the valid pixels at the saturation levels, kept as they were.
    nodata_fraction : float
        Fraction of the pixels that are nodata (kept).
    input_sha256 : str
        The input file's SHA-256.
    fill_fraction : float
        Fraction of the valid pixels that are undeclared fill (a region at
        the band's least value with a hard boundary), kept as they were.

    Examples
    --------
    >>> import imgmtf
    >>> imgmtf.write_geotiff("edge.tif", imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 100).image)
    >>> done = imgmtf.restore_file("edge.tif", imgmtf.design_filter(imgmtf.Sensor(), 0.3), "restored.tif")
    >>> done.out, (done.width, done.height), done.bands, done.clipped_fraction
    ('restored.tif', (100, 100), (1,), 0.0)
    """

    path: str
    out: str
    width: int
    height: int
    bands: tuple[int, ...]
    dtype: str
    tiles: int
    clipped_fraction: float
    saturated_fraction: float
    nodata_fraction: float
    input_sha256: str
    fill_fraction: float = 0.0

    def to_dict(self) -> dict:
        return {"input": self.path, "out": self.out, "width_px": self.width, "height_px": self.height,
                "bands": list(self.bands), "dtype": self.dtype, "tiles": self.tiles,
                "clipped_fraction": self.clipped_fraction, "saturated_fraction": self.saturated_fraction,
                "nodata_fraction": self.nodata_fraction, "fill_fraction": self.fill_fraction,
                "input_sha256": self.input_sha256}


def restore_file(path: str | Path, restoration: RestorationFilter, out: str | Path, *, tile_px: int = DEFAULT_TILE_PX,
                 saturation: tuple[float, float] | None = None, workers: int = 1, scheduler: str | None = None,
                 progress: bool | None = None, run_utc: str | None = None) -> RestoredFile:
    """Restore every band of an image file (anything GDAL reads) with a
    :class:`~imgmtf.restore.design.RestorationFilter`, tile by tile, into a
    GeoTIFF.

    Parameters
    ----------
    path : str or pathlib.Path
        The image.
    restoration : RestorationFilter
        The filter (:func:`imgmtf.design_filter`).
    out : str or pathlib.Path
        The GeoTIFF to write (replaced if it exists), atomically.
    tile_px : int, optional
        Tile side, px (64 to 2048): memory holds about ``(tile_px + 2 r)^2``
        float64 values per tile in flight (r the kernel's radius).
    saturation : (float, float), optional
        DN levels at or beyond which input pixels are kept as they were
        (default: an integer type's range; none for floats).
    workers : int, optional
        Local worker processes (default 1: none, the work runs here).
    scheduler : str, optional
        A Dask distributed scheduler's address, or ``"local"`` for a local
        Dask cluster (:func:`imgmtf.parallel.run_tasks`).
    progress : bool, optional
        Show a progress bar on stderr (default: when stderr is a terminal).
    run_utc : str, optional
        The run's start (UTC, ISO 8601) for the provenance tag.

    Returns
    -------
    RestoredFile
        What was written: the output's path, size, type, tiles and the
        fractions of pixels clipped, saturated or without data.

    Raises
    ------
    ImageReadError
        The file cannot be read (named, with why).
    ImageContentError
        A band with no valid pixel.
    ParameterError
        A bad ``tile_px`` or ``saturation``.
    FileWriteError
        The output cannot be written.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 100)
    >>> imgmtf.write_geotiff("edge.tif", chip.image)
    >>> filt = imgmtf.design_filter(imgmtf.Sensor(), 0.3)
    >>> done = imgmtf.restore_file("edge.tif", filt, "restored.tif", tile_px=64)
    >>> done.tiles, done.dtype, imgmtf.read_raster("restored.tif").gsd_m
    (4, 'uint16', 1.0)
    """
    import rasterio
    from rasterio.errors import NotGeoreferencedWarning

    from ..atomic import atomic_output
    from ..io import GDAL_ERRORS, raster_info, read_raster
    from ..parallel import run_tasks
    from ..records import utc_now
    from ..version import __version__

    path, out = str(path), str(out)
    tile_px = int(check_number("tile_px", tile_px, low=TILE_RANGE_PX[0], high=TILE_RANGE_PX[1], integer=True))
    info = raster_info(path)
    if saturation is not None:
        low, high = (check_number("saturation level", v, signed=True) for v in saturation)
        if not low < high:
            raise ParameterError(f"saturation levels must be LO < HI, got {saturation!r}")
        saturation = (low, high)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(path) as src:
            nodata = src.nodata
            profile = {"driver": "GTiff", "width": src.width, "height": src.height, "count": src.count,
                       "dtype": src.dtypes[0], "crs": src.crs, "transform": src.transform, "nodata": nodata,
                       "tiled": True, "blockxsize": 256, "blockysize": 256, "BIGTIFF": "IF_SAFER",
                       **({"compress": src.compression.value} if src.compression else {})}
            tags, band_tags = src.tags(), [src.tags(b) for b in range(1, src.count + 1)]
            descriptions, colours = src.descriptions, src.colorinterp
    output = OutputType(info.dtype, nodata, saturation if saturation is not None else saturation_levels(info.dtype))
    alpha = set(info.alpha_bands)
    bands = tuple(b for b in range(1, info.count + 1) if b not in alpha)
    tiles = plan_tiles(info.width, info.height, tile_px, restoration.radius_px)
    tasks = []
    for band in range(1, info.count + 1):
        fill, fill_value = (0.0, None) if band in alpha else _band_fill(read_raster, path, band, info)
        taps = None if band in alpha else restoration.taps
        tasks += [TileTask(path, band, tile, taps, fill, output, fill_value) for tile in tiles]
    sha256 = file_sha256(path)
    provenance = {"imgmtf_version": __version__, "method": "wiener", "filter": restoration.to_dict(),
                  "input": path, "input_sha256": sha256, "run_utc": run_utc or utc_now(), "tile_px": tile_px}
    counts = {"clipped": 0, "saturated": 0, "valid": 0, "filled": 0}
    from rasterio.windows import Window
    with atomic_output(out) as partial, warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)      # a chip without a geotransform stays so
        try:
            with rasterio.open(partial, "w", **profile) as dst:
                for _, result in run_tasks(restore_tile, tasks, workers=workers, scheduler=scheduler,
                                           progress=progress, description="restoring", ordered=False):
                    dst.write(result.samples, result.band, window=Window(*result.core))
                    if result.band not in alpha:
                        for key in counts:
                            counts[key] += getattr(result, key)
                # a chip's rendering provenance (its sensor, its true MTF) no longer describes the
                # restored pixels: it is kept under another name, so that measure draws no false truth
                if "IMGMTF" in tags:
                    tags["IMGMTF_SOURCE"] = tags.pop("IMGMTF")
                dst.update_tags(**tags, IMGMTF_RESTORE=json.dumps(provenance, sort_keys=True))
                for band in range(1, info.count + 1):
                    if band_tags[band - 1]:
                        dst.update_tags(band, **band_tags[band - 1])
                    if descriptions[band - 1]:
                        dst.set_band_description(band, descriptions[band - 1])
                dst.colorinterp = colours
        except (*GDAL_ERRORS, OSError) as exc:
            raise FileWriteError(f"{out}: cannot write: {exc}") from None
    pixels = info.width * info.height * len(bands)
    valid = counts["valid"]
    return RestoredFile(path, out, info.width, info.height, bands, info.dtype, len(tiles),
                        counts["clipped"] / valid if valid else 0.0,
                        counts["saturated"] / valid if valid else 0.0,
                        1.0 - valid / pixels if pixels else 0.0, sha256,
                        counts["filled"] / valid if valid else 0.0)


def _band_fill(read_raster, path: str, band: int, info) -> tuple[float, float | None]:
    """The band's median over an overview (the value nodata pixels hold
    while filtering), and the value of its undeclared fill: its least value
    where a region at it has a hard boundary (:func:`imgmtf.scene.fill.fill_mask`),
    else None."""
    from ..scene.fill import fill_mask
    scale = max(info.width / OVERVIEW_PX, info.height / OVERVIEW_PX, 1.0)
    shape = (max(int(info.height / scale), 1), max(int(info.width / scale), 1))
    data = read_raster(path, band, out_shape=shape).data
    values = data[np.isfinite(data)]
    if not values.size:
        raise ImageContentError(f"{path}: band {band} has no valid pixel (all nodata): nothing to restore")
    least = float(values.min())
    at_fill = fill_mask(data, info.dtype) & (data == least)
    return float(np.median(values)), least if at_fill.any() else None


def file_sha256(path: str) -> str:
    """The SHA-256 of a file's bytes (hex), read in 1 MiB chunks."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def measure_noise(path: str | Path, *, band: int = 1, window_px: int = 1024) -> tuple[float, float]:
    """(noise std, signal std) of a band, DN, from its central window of up
    to ``window_px`` square at full resolution: the noise from the median
    absolute difference of neighbouring pixels (at least the quantisation's
    1/sqrt(12) DN), the signal as the standard deviation of the window less
    that noise (0 when the window holds nothing but noise).

    Raises
    ------
    ImageReadError, ImageContentError
        The file cannot be read, or the window is all nodata.
    """
    from ..estimate.detection import robust_noise
    from ..inputs import quantum
    from ..io import raster_info, read_raster
    info = raster_info(path)
    w, h = min(window_px, info.width), min(window_px, info.height)
    raster = read_raster(path, band, window=((info.width - w) // 2, (info.height - h) // 2, w, h))
    data = raster.data
    values = data[np.isfinite(data)]
    if values.size < 4:
        raise ImageContentError(f"{path}: too few valid pixels in the central {w} x {h} px to measure the noise")
    noise = max(robust_noise(data), quantum(data, raster.dtype) / math.sqrt(12.0))
    return noise, math.sqrt(max(float(values.var()) - noise ** 2, 0.0))
