"""Detection: the straight segments of a scene.

The scene is read tile by tile (windowed reads: a large scene is never
loaded whole; one task per tile, on the workers too), scaled to 8 bits with
levels taken from a decimated overview, and OpenCV's line segment detector
finds straight segments in each tile.  LSD orients every segment by its
gradient (the brighter side always on the same hand), so a line whose
polarity flips (a checkerboard's inner line at its centre) comes as two
segments.  The pieces of one line, across tiles too, are merged
(:func:`imgmtf.scene.segments.merge_pieces`); how segments meet is
:mod:`.segments`' job.
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from ..errors import ImgmtfError
from ..inputs import check_magnitude, saturation_levels
from ..io import RasterInfo, raster_info, read_raster
from .fill import FILL_SIDE_PX, fill_mask, may_hold_fill
from .geometry import sample_points, unit_vectors
from .settings import ScanSettings

# Scenes larger than this are refused: detection reads every tile, and 1 Gpx
# (32768 x 32768) is already minutes of it.  Crop a part to scan it.
MAX_SCAN_PIXELS = 2 ** 30

TILE_OVERLAP_PX = 32


def detect_segments(path: str, settings: ScanSettings | None = None, *, workers: int = 1,
                    scheduler: str | None = None, progress: bool | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Every straight piece LSD finds in the scene's tiles, at least
    ``MIN_SEGMENT_PX`` long, with the pieces of one line merged
    (:func:`merge_segments`): (segments as rows x0, y0, x1, y1 in scene
    pixels in LSD's orientation, and the fraction of each segment's length
    along which fill or nodata lies beside it, within ``FILL_SIDE_PX``).
    The tiles are read and searched one task each
    (:func:`imgmtf.parallel.run_tasks`: ``workers``, ``scheduler`` and
    ``progress`` as there).

    Raises
    ------
    ImgmtfError
        The scene is too large (reason ``too-large``), flat or all nodata
        (``image``), or unreadable.
    """
    from ..parallel import run_tasks
    settings = settings or ScanSettings()
    info = raster_info(path)
    check_scene_size(info)
    lo, hi = display_levels(path, settings.band, info)
    tiles = [(path, settings.band, window, lo, hi, info.dtype) for window in tile_windows(info, settings.tile_px)]
    found = _searched_while_workers_start(tiles, workers) if _workers_start_apart(workers, scheduler) else []
    found += run_tasks(tile_segments, tiles[len(found):], workers=workers, scheduler=scheduler, progress=progress,
                       description="detecting segments")
    found = [f for f in found if len(f[0])]
    if not found:
        return np.zeros((0, 4)), np.zeros(0)
    from .segments import merge_pieces  # (the graph's module loads SciPy; the tiles' workers need not)
    return merge_pieces(np.concatenate([f[0] for f in found]), np.concatenate([f[1] for f in found]))


def _searched_while_workers_start(tiles: list, workers: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """The first tiles' pieces, searched here while a thread starts the
    pool of ``workers`` (:func:`imgmtf.parallel.prestart_workers`, which
    :func:`imgmtf.parallel.run_tasks` then takes): its workers are forked
    from a server that imports the scan's modules first (0.3-0.8 s, more
    with the fits'), while this process had nothing to do but wait; a tile
    takes 0.06-0.1 s.  The tiles' order is kept, so the segments are the
    same.  The thread only starts processes (no task of the scan's), and
    as a daemon it never holds the process open."""
    import threading
    starting = threading.Thread(target=_start_workers, args=(workers,), daemon=True, name="imgmtf-workers-start")
    starting.start()
    found: list[tuple[np.ndarray, np.ndarray]] = []
    while starting.is_alive() and len(found) < len(tiles) - 1:
        found.append(tile_segments(tiles[len(found)]))
    starting.join()
    return found


def _workers_start_apart(workers: int, scheduler: str | None) -> bool:
    """Whether a thread may start the local pool while this process
    searches tiles: a fork server runs already with the tiles' modules (a
    scan's, or the command's, started it), so the thread only forks the
    workers from it; or the system has none, and the thread starts them."""
    from ..parallel import can_preload, preloaded
    from ..preloads import SCAN_TASK_MODULES
    return workers > 1 and scheduler is None and (preloaded(SCAN_TASK_MODULES) or not can_preload())


def _start_workers(workers: int) -> None:
    """A pool of ``workers`` started (:func:`imgmtf.parallel.prestart_workers`)."""
    from ..parallel import prestart_workers
    from ..preloads import SCAN_TASK_MODULES
    prestart_workers(workers, SCAN_TASK_MODULES)


def tile_windows(info: RasterInfo, tile_px: int) -> list[tuple[int, int, int, int]]:
    """The windows (x, y, w, h) detection reads: tiles of ``tile_px``
    overlapping by ``TILE_OVERLAP_PX``, row by row."""
    step = tile_px - TILE_OVERLAP_PX
    return [(x, y, min(tile_px, info.width - x), min(tile_px, info.height - y))
            for y in range(0, max(info.height - TILE_OVERLAP_PX, 1), step)
            for x in range(0, max(info.width - TILE_OVERLAP_PX, 1), step)]


def tile_segments(task) -> tuple[np.ndarray, np.ndarray]:
    """One tile's LSD pieces (rows x0, y0, x1, y1 in scene pixels) and the
    fraction of each with fill beside it; ``task`` is (path, band, window,
    lo, hi, dtype): the tile read and scaled to 8 bits with [lo, hi]."""
    path, band, (x, y, w, h), lo, hi, dtype = task
    tile = read_raster(path, band, window=(x, y, w, h)).data
    found = cv2.createLineSegmentDetector(cv2.LSD_REFINE_STD).detect(to_8bit(tile, lo, hi))[0]
    if found is None:
        return np.zeros((0, 4)), np.zeros(0)
    found = found.reshape(-1, 4).astype(float)
    # (two reductions tell a tile that cannot hold fill, sparing it fill_mask's five passes)
    fill = fill_mask(tile, dtype) if may_hold_fill(tile, dtype) else None
    return found + np.array([x, y, x, y], float), _fill_beside(found, fill)


def _fill_beside(pieces: np.ndarray, fill: np.ndarray | None) -> np.ndarray:
    """Per piece (tile coordinates), the fraction of 1-px steps along it
    with fill within ``FILL_SIDE_PX`` on either side (none where ``fill``
    is None: the tile holds none)."""
    if fill is None or not fill.any() or len(pieces) == 0:
        return np.zeros(len(pieces))
    points, owner = sample_points(pieces, 1.0)
    units = unit_vectors(pieces)[owner]
    normal = np.column_stack([-units[:, 1], units[:, 0]])
    rows, cols = fill.shape
    hit = np.zeros(len(points), bool)
    for offset in (-FILL_SIDE_PX, -1.0, 1.0, FILL_SIDE_PX):
        px = np.clip(np.rint(points + offset * normal).astype(int), 0, [cols - 1, rows - 1])
        hit |= fill[px[:, 1], px[:, 0]]
    return np.bincount(owner, hit, len(pieces)) / np.bincount(owner, None, len(pieces))


def check_scene_size(info: RasterInfo) -> None:
    """Refuse a scene above :data:`MAX_SCAN_PIXELS` (its header's word)."""
    if info.width * info.height > MAX_SCAN_PIXELS:
        raise ImgmtfError(
            f"{info.path}: the scene is {info.width} x {info.height} px "
            f"({info.width * info.height / 2**30:.1f} Gpx), more than the {MAX_SCAN_PIXELS // 2**30} Gpx "
            "a scan reads; scan a part of it (crop it, e.g. gdal_translate -srcwin X Y W H)",
            reason="too-large")


def display_levels(path: str | Path, band: int | None, info: RasterInfo) -> tuple[float, float]:
    """The 0.5 and 99.5 percentiles of a decimated read of the whole scene,
    fill (0, NaN) and saturated pixels (at an integer type's limits) left
    out so that neither can squash the rest of the scene into a few levels;
    an ImageContentError for values no sensor records (beyond 1e15 DN).
    """
    scale = max(info.width, info.height) / 1024
    shape = (max(int(info.height / scale), 1), max(int(info.width / scale), 1)) if scale > 1 else None
    data = read_raster(path, band, out_shape=shape).data
    finite = data[np.isfinite(data)]
    check_magnitude(finite, str(path))
    limits = saturation_levels(info.dtype)
    if limits is not None:
        finite = finite[(finite > limits[0]) & (finite < limits[1])]
    if finite.size == 0:
        raise ImgmtfError(f"{path}: every pixel is nodata or saturated", reason="image")
    lo, hi = np.percentile(finite, [0.5, 99.5])
    if not hi > lo:
        raise ImgmtfError(f"{path}: the image is flat: no contrast to scan", reason="image")
    return float(lo), float(hi)


def to_8bit(tile: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """The tile scaled so that [lo, hi] fills 0-255 (nodata as the tile's median)."""
    finite = np.isfinite(tile)
    filled = tile if finite.all() else np.where(finite, tile, np.median(tile[finite]) if finite.any() else lo)
    # (filled - lo) / (hi - lo) * 255, rounded and clipped, in one buffer: a megapixel tile's
    # five temporary arrays cost three times the arithmetic
    scaled = np.subtract(filled, lo)
    np.divide(scaled, hi - lo, out=scaled)
    np.multiply(scaled, 255, out=scaled)
    np.rint(scaled, out=scaled)
    np.clip(scaled, 0, 255, out=scaled)
    return scaled.astype(np.uint8)
