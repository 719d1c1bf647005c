"""The estimate of a raster read from a file, as a batch of files measures
it (:func:`measure_raster`): the file's GSD, data type and geometry handed to
the target's estimator, its ROI reported in the file's pixels, its
directions named by the image's axes when nothing places a track on it."""
from __future__ import annotations

import functools
from collections.abc import Hashable, Sequence
from dataclasses import replace

import numpy as np

from .inputs import saturation_levels
from .measure_settings import MeasureSettings


def measure_raster(raster, settings: MeasureSettings):
    """The estimate of one raster (a window of the file when ``roi`` is
    set), its ROI reported in the file's pixel coordinates, its direction
    named by the image's axes when nothing places a track on it
    (:func:`in_image_axes`)."""
    keywords = _estimator_keywords(raster, settings)
    return _placed(settings.estimator()(raster.data, **keywords), raster, settings)


def measure_rasters(rasters: Sequence, settings: MeasureSettings) -> list:
    """:func:`measure_raster` of every raster, the work alike across them
    made together where the target's estimator can
    (:meth:`imgmtf.estimate.edge.EdgeEstimator.measure_many`: a batch of
    small chips costs the interpreter less so): each the same result, to
    the bit, as :func:`measure_raster` gives, or the exception it raises.

    Parameters
    ----------
    rasters : sequence of imgmtf.io.Raster
        Rasters read from files (:meth:`imgmtf.io.RasterFile.read`).
    settings : MeasureSettings
        How to measure them.

    Returns
    -------
    list of MTFResult or Exception
        One per raster, in order.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.measure_settings import MeasureSettings
    >>> for k, angle in enumerate((5.0, 8.0)):
    ...     chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", angle), 40, noise_std_dn=2.0, seed=1)
    ...     imgmtf.write_geotiff(f"chip{k}.tif", chip.image, gsd_m=chip.gsd_m)
    >>> rasters = [imgmtf.read_raster(f"chip{k}.tif") for k in range(2)]
    >>> settings = MeasureSettings()
    >>> [r.mtf_nyquist for r in measure_rasters(rasters, settings)] == [
    ...     measure_raster(r, settings).mtf_nyquist for r in rasters]
    True
    """
    estimator = settings.estimator()
    out: list = [None] * len(rasters)
    alike: dict[tuple, list[tuple[int, dict]]] = {}     # the estimator's keywords -> the rasters taking them
    for k, raster in enumerate(rasters):
        try:
            keywords = _estimator_keywords(raster, settings)
        except Exception as exc:        # as measure_raster raises it
            out[k] = exc
            continue
        alike.setdefault(tuple((name, _key(value)) for name, value in keywords.items()), []).append((k, keywords))
    for members in alike.values():
        together = _together(estimator, [rasters[k].data for k, _ in members], members[0][1])
        for (k, keywords), result in zip(members, together or [None] * len(members)):
            if together is None:       # one at a time: alone, or where making them together failed
                result = _outcome(functools.partial(estimator, rasters[k].data, **keywords))
            out[k] = result if isinstance(result, Exception) else _outcome(_placed, result, rasters[k], settings)
    return out


def _together(estimator, images: list, keywords: dict) -> list | None:
    """The estimator's results (or exceptions) of ``images`` measured
    together, each as its own call gives it; None where they are to be
    measured one at a time: one image, an estimator that measures one only,
    or a failure of the batch as a whole (each image's own call then
    decides what is its error)."""
    if len(images) < 2 or not hasattr(estimator, "measure_many"):
        return None
    try:
        return estimator.measure_many(images, [None] * len(images), **keywords)
    except Exception:
        return None


def _key(value) -> Hashable:
    """A keyword's value as a key that tells apart what the estimator could
    treat apart (a float by its bits: 0.5 and 0.5 alike, NaN with NaN)."""
    if isinstance(value, float):
        return ("float", value.hex())
    if isinstance(value, tuple | list):
        return (type(value).__name__, *map(_key, value))
    if value is None or isinstance(value, bool | int | str | np.dtype):
        return (type(value).__name__, value)
    return ("object", id(value))        # anything else: a group of its own object


def _outcome(function, *args, **keywords):
    """``function(*args, **keywords)``, or the exception it raised."""
    try:
        return function(*args, **keywords)
    except Exception as exc:
        return exc


def _estimator_keywords(raster, settings: MeasureSettings) -> dict:
    """What the estimator takes with the raster's pixels: its GSD, data
    type, track and saturation, and the target's own keywords."""
    track = settings.track_azimuth_deg
    if track is None and not raster.map_projected:
        track = 0.0                          # sensor geometry: rows along track (or the image's axes)
    common = dict(gsd_m=raster.gsd_m, dtype=raster.dtype, track_azimuth_deg=track,
                  saturation=settings.saturation or saturation_levels(raster.dtype))
    return {**settings.target_keywords(raster), **common}


def _placed(result, raster, settings: MeasureSettings):
    """An estimate of ``raster`` with its ROI in the file's pixels and its
    direction named by the image's axes where :func:`in_image_axes` says."""
    x0, y0 = raster.origin
    x, y, w, h = result.roi
    result = replace(result, roi=(x + x0, y + y0, w, h))
    if in_image_axes(raster, settings.track_azimuth_deg) and isinstance(getattr(result, "direction", None), str):
        from .estimate.geometry import image_axis_label
        result = replace(result, direction=image_axis_label(result.direction))
    return result


def edge_centre_px(result) -> tuple[float, float]:
    """The middle of a measured target's fitted line, in the file's pixels
    (pixel centres at integers): the mean of the rows it was fitted on."""
    geometry = result.geometry
    along = float(np.mean(geometry.rows[geometry.kept]))
    across = geometry.slope * along + geometry.intercept
    x, y = (along, across) if geometry.transposed else (across, along)
    return x + result.roi[0], y + result.roi[1]


def in_image_axes(raster, track_azimuth_deg: float | None) -> bool:
    """Whether a file's directions are named by its own axes (horizontal,
    vertical): it has no georeference (no CRS, no pixel size) and no track
    azimuth was given, so nothing says where a track lies (a camera's
    photo; an L0 product says it with ``track_azimuth_deg=0``)."""
    return track_azimuth_deg is None and not raster.map_projected and raster.gsd_m is None
