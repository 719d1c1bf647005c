"""The estimate of a raster read from a file, as a batch of files measures
it (:func:`measure_raster`): the file's GSD, data type and geometry handed to
the target's estimator, its ROI reported in the file's pixels, its
directions named by the image's axes when nothing places a track on it."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .inputs import saturation_levels
from .measure_settings import MeasureSettings


def measure_raster(raster, settings: MeasureSettings):
    """The estimate of one raster (a window of the file when ``roi`` is
    set), its ROI reported in the file's pixel coordinates, its direction
    named by the image's axes when nothing places a track on it
    (:func:`in_image_axes`)."""
    estimator = settings.estimator()
    track = settings.track_azimuth_deg
    image_axes = in_image_axes(raster, track)
    if track is None and not raster.map_projected:
        track = 0.0                          # sensor geometry: rows along track (or the image's axes)
    common = dict(gsd_m=raster.gsd_m, dtype=raster.dtype, track_azimuth_deg=track,
                  saturation=settings.saturation or saturation_levels(raster.dtype))
    result = estimator(raster.data, **settings.target_keywords(raster), **common)
    x0, y0 = raster.origin
    x, y, w, h = result.roi
    result = replace(result, roi=(x + x0, y + y0, w, h))
    if image_axes and isinstance(getattr(result, "direction", None), str):
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
