"""The sensor fitted to edges given as files, arrays or measurements
(:func:`fit_sensor`, the public entry point): the files are read and their
edges measured here as ``imgmtf measure`` reads and measures them (band,
window, GSD, sample type, nodata, transfer curve, forced checks), and the
fit itself is :func:`imgmtf.estimate.fit.fit_edges` (arrays and results
only)."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import ParameterError
from .estimate.fit.data import EdgeImage, MeasuredEdge
from .estimate.fit.fitting import checked_arguments, fit_edges
from .estimate.fit.model import listed
from .estimate.fit.results import SensorFit
from .inputs import check_roi
from .sensor.model import Sensor
from .vectors import VectorROIs, as_rois

if TYPE_CHECKING:
    from .estimate.edge import EdgeResult


Roi = tuple[int, int, int, int]


def fit_sensor(edges: Sequence[str | os.PathLike | np.ndarray | EdgeResult], *,
               stages: str | Sequence[str] | None = None, start: Sensor | None = None,
               hold: str | Sequence[str] = (), gsd_m: float | None = None,
               band: int | None = None, roi: Roi | Sequence[Roi | None] | VectorROIs | str | None = None,
               confidence: float = 0.95, force: bool = False, transfer: str = "linear",
               saturation: tuple[float, float] | None = None) -> SensorFit:
    """Fit a sensor's stages to the profiles of one or more edges.

    Parameters
    ----------
    edges : sequence
        Each an image file path, a 2-D array (DN) or an
        :class:`imgmtf.EdgeResult` already measured; one edge per image
        (or per window of one: ``roi``).  A file named twice with the same
        window is measured once (the result's warnings say so).
    stages : str or sequence of str, optional
        Stage names to fit (comma-separated or a list; see
        :data:`imgmtf.sensor.stages.STAGES`); default the stages of
        ``start``, or the paper's four.
    start : Sensor, optional
        Starting (and held) values of the stages it has; other stages
        start from their defaults scaled to the GSD.
    hold : str or sequence of str, optional
        Parameters held at their starting values: "stage" or "stage.name".
    gsd_m : float, optional
        Ground sample distance (m); default the first file's, else 1
        (parameters then in pixels).
    band : int, optional
        1-based band of multi-band files (default: the only band or the
        luminance).
    roi : (int, int, int, int), sequence of them, VectorROIs or str, optional
        (x, y, width, height) window, px, taken from every file or array
        (only it is read from a file), or one window per edge (None for
        the whole image); not for EdgeResults.  Or a vector layer (its
        file, or a :class:`imgmtf.vectors.VectorROIs`): every file's edge
        measured in each feature's window (:func:`feature_edges`).
    confidence : float, optional
        Of the intervals, in (0, 1) (default 0.95).
    force : bool, optional
        Measure a file's edge even where a quality check fails (fill,
        saturation, ...), as ``imgmtf measure --force`` does: each failure
        becomes a warning of the fit; a number no one should use (an edge
        that is mostly fill) is still refused.
    transfer : str, optional
        How a file's stored values relate to light: "linear" (default),
        "srgb" or "gamma:G", linearised before measuring (:mod:`imgmtf.transfer`).
    saturation : (float, float), optional
        DN a file's sensor records (default: an integer file's type range).

    Returns
    -------
    SensorFit
        The fitted sensor, each parameter with its standard error, the
        model's MTF across and along track with intervals, and each edge's
        measured and modelled MTF.

    Raises
    ------
    ParameterError
        Unknown stage or parameter names, no edges, bad ``confidence``, a
        ``roi`` outside an input, as many windows as edges not given.
    ImgmtfError
        An input that cannot be read or has no measurable edge (the
        message names it, with the reason a check gave), or a fit that
        does not converge.

    Examples
    --------
    >>> import imgmtf
    >>> chips = [imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", a), 60).image for a in (6.0, 84.0)]
    >>> fit = imgmtf.fit_sensor(chips)
    >>> abs(fit.edges[0].mtf_nyquist - 0.2667) < 0.002
    True
    """
    from .estimate.edge import EdgeResult
    from .transfer import parse_transfer
    checked_arguments(stages, start, gsd_m, confidence)        # before any file is read
    transfer = str(parse_transfer(transfer))
    if isinstance(edges, (str, Path, np.ndarray, EdgeResult)):
        edges = [edges]
    items = listed("edges", edges, "files, arrays or EdgeResults")
    if isinstance(roi, (str, os.PathLike, VectorROIs)):
        items, roi, _ = feature_edges(items, as_rois(roi), band)
    rois = _windows(roi, len(items))
    items, rois, notes = _distinct(items, rois)
    measured = [_read(item, k, band, window, gsd_m, force, transfer, saturation)
                for k, (item, window) in enumerate(zip(items, rois))]
    fit = fit_edges([m for m, _ in measured], stages=stages, start=start, hold=hold, gsd_m=gsd_m,
                    confidence=confidence)
    forced = [w for _, warnings in measured for w in warnings]
    fit = replace(fit, warnings=(*notes, *forced, *fit.warnings)) if notes or forced else fit
    photos = gsd_m is None and all(isinstance(item, (str, os.PathLike)) for item in items) and not any(
        getattr(getattr(m, "result", None), "gsd_m", 1.0) is not None for m, _ in measured)
    return in_image_axes(fit) if photos else fit


def in_image_axes(fit: SensorFit) -> SensorFit:
    """A fit of images with no georeference (a camera's files: no CRS, no
    pixel size) told in their own terms: lengths in px (the model's metres
    at the 1 m GSD it takes), directions the image's axes (horizontal,
    across its columns, for the model's across track; vertical for along).

    Parameters
    ----------
    fit : SensorFit
        The fit, with rows taken along track.

    Returns
    -------
    SensorFit
        The same fit, ``pixel_units`` True, its words and units the image's.
    """
    from .estimate.geometry import image_axis_label

    def words(text: str) -> str:
        for track, axis in (("across-track", "horizontal"), ("along-track", "vertical")):
            text = text.replace(track, axis)
        return text
    gsd_note = next((w for w in fit.warnings if w.startswith("no GSD in the inputs")), None)
    warnings = [words(w) for w in fit.warnings if w is not gsd_note]
    warnings.append("no GSD in the inputs: lengths are in px and directions the image's axes (horizontal: across "
                    "its columns); give the GSD for lengths on the ground")
    parameters = tuple(replace(p, unit="px" if p.unit == "m" else p.unit, note=words(p.note)) for p in fit.parameters)
    edges = tuple(replace(e, direction=image_axis_label(e.direction)) for e in fit.edges)
    return replace(fit, parameters=parameters, edges=edges, warnings=tuple(warnings), pixel_units=True)


def feature_edges(paths: Sequence[str | os.PathLike], rois: VectorROIs, band: int | None = None
                  ) -> tuple[list[str], list[Roi], list[dict[str, Any]]]:
    """Every file once per feature of a vector layer: the files (repeated),
    each feature's window on its file, and what each edge's record carries
    of its feature (``feature_id``, ``feature``).

    Raises
    ------
    ParameterError
        A path that is not a file, a file without a CRS, or a feature
        with no window on a file (outside it: a fit takes every edge it
        is given).
    ImgmtfError
        A file that cannot be read.
    """
    from .io import raster_info
    from .vectors import Unplaced
    files, windows, fields = [], [], []
    for path in paths:
        if not isinstance(path, (str, os.PathLike)):
            raise ParameterError(f"a vector layer's features are windows of files, not of {type(path).__name__}s")
        for placed in rois.windows(raster_info(os.fspath(path))):
            if isinstance(placed, Unplaced):
                raise placed.error
            files.append(os.fspath(path))
            windows.append(placed.window)
            fields.append(placed.record_fields())
    return files, windows, fields


def edge_sources(paths: Sequence[str], roi: Roi | Sequence[Roi | None] | None = None) -> list[str]:
    """What each edge is named by: its file, with its window when windows
    differ from file to file (``chip.tif[x,y,w,h]``).

    Examples
    --------
    >>> edge_sources(["a.tif", "a.tif"], [(0, 0, 40, 40), (40, 0, 40, 40)])
    ['a.tif[0,0,40,40]', 'a.tif[40,0,40,40]']
    >>> edge_sources(["a.tif", "b.tif"], (0, 0, 40, 40))
    ['a.tif', 'b.tif']
    """
    rois = _windows(roi, len(paths))
    if roi is None or _is_window(roi):
        return [str(p) for p in paths]
    return [str(p) if w is None else f"{p}[{','.join(map(str, w))}]" for p, w in zip(paths, rois)]


def _is_window(roi) -> bool:
    return isinstance(roi, (tuple, list)) and len(roi) == 4 and all(
        isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in roi)


def _windows(roi, count: int) -> list[Roi | None]:
    """One window (or None) per edge: ``roi`` for every edge, or one each."""
    if roi is None or _is_window(roi):
        return [tuple(roi) if roi is not None else None] * count
    windows = list(roi)
    if len(windows) != count or not all(w is None or _is_window(w) for w in windows):
        raise ParameterError(f"roi: one (x, y, width, height) window for every edge, or one window per edge; got "
                             f"{len(windows)} for {count} edge(s)")
    return [tuple(w) if w is not None else None for w in windows]


def _distinct(items: list, rois: list) -> tuple[list, list, list[str]]:
    """The edges less a file named again with the same window (measured
    once), and a note for each one left out."""
    seen: dict[tuple, int] = {}
    kept, windows, notes = [], [], []
    for k, (item, window) in enumerate(zip(items, rois)):
        if isinstance(item, (str, os.PathLike)):
            key = (os.path.realpath(os.fspath(item)), window)
            if key in seen:
                name = os.fspath(item) + (f"[{','.join(map(str, window))}]" if window else "")
                notes.append(f"{name}: named twice (edges {seen[key] + 1} and {k + 1}): measured once")
                continue
            seen[key] = k
        kept.append(item)
        windows.append(window)
    return kept, windows, notes


def _read(item, k: int, band: int | None, roi: Roi | None, gsd_m: float | None, force: bool, transfer: str,
          saturation: tuple[float, float] | None) -> tuple[Any, list[str]]:
    """Edge ``k`` (0-based) as the fit takes it, and the warnings its
    measurement gave: a file read and measured as ``imgmtf measure`` does
    (its window ``roi``), an array's window; measurements (and what is no
    image) as they are."""
    from .estimate.edge import EdgeResult
    from .estimate.results import MTFResult
    if isinstance(item, EdgeResult) and roi is not None:
        raise ParameterError(f"edge {k + 1}: an EdgeResult is already measured: a roi applies to "
                             "files and arrays")
    if isinstance(item, MTFResult):
        return item, []
    if isinstance(item, (str, Path)):
        return _measured_file(str(item), band, roi, gsd_m, force, transfer, saturation)
    if roi is None:
        return item, []
    image = np.asarray(item)
    source = f"array {k + 1}"
    left, top, width, height = check_roi(roi, image.shape[:2], source)
    return EdgeImage(image[top: top + height, left: left + width], source, None, image.dtype), []


def _measured_file(path: str, band: int | None, roi: Roi | None, gsd_m: float | None, force: bool, transfer: str,
                   saturation: tuple[float, float] | None) -> tuple[MeasuredEdge, list[str]]:
    """A file's edge measured as ``imgmtf measure`` measures it (no
    intervals: the fit makes its own), named by the file and its window."""
    from .errors import ImgmtfError
    from .estimate.gate import untrusted_when_forced
    from .estimate.intervals import Intervals
    from .io import open_raster
    from .measure_settings import MeasureSettings
    from .raster_estimate import measure_raster
    source = edge_sources([path], [roi])[0]
    settings = MeasureSettings("edge", band=band, roi=roi, intervals=Intervals("none"), force=force,
                               saturation=saturation, transfer=transfer)
    try:
        with open_raster(path) as file:
            raster = file.read(band, window=roi)
        if gsd_m is not None:
            raster = replace(raster, gsd_m=gsd_m)
        result = measure_raster(raster, settings)
    except ImgmtfError as exc:
        if not str(exc).startswith(path):
            exc.args = (f"{source}: {exc}",)       # name the input, keeping the error's class, reason and checks
        raise
    if force:
        failed = untrusted_when_forced(result.checks)
        if failed is not None:
            raise ImgmtfError(f"{source}: forced, but not to be trusted: {failed.message}", reason="untrusted")
    integer = transfer == "linear" and np.issubdtype(np.dtype(raster.dtype), np.integer)
    warnings = [f"{source}: {w}" for w in result.warnings if "forced" in w]
    return MeasuredEdge(result, source, integer), warnings
