"""What each edge gives the fit: its samples' distances and values, its noise."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...errors import ImgmtfError, ParameterError

if TYPE_CHECKING:
    from ..edge import EdgeResult


@dataclass(frozen=True, eq=False)
class EdgeData:
    source: str
    x: np.ndarray
    y: np.ndarray
    normal_angle_deg: float
    gsd_m: float
    gsd_known: bool
    noise: float
    levels: tuple[float, float]
    measurement: EdgeResult


def edge_data(item, k: int, gsd_m, band, roi) -> EdgeData:
    from ...inputs import check_roi, saturation_levels
    from ..edge import EdgeResult, measure_edge
    from ..intervals import Bootstrap
    from ..results import MTFResult
    if isinstance(item, MTFResult) and not isinstance(item, EdgeResult):
        raise ParameterError(f"edge {k + 1}: a {type(item).__name__}; the fit takes edges (an EdgeResult, "
                             "an image array or a file)")
    if isinstance(item, EdgeResult):
        if roi is not None:
            raise ParameterError(f"edge {k + 1}: an EdgeResult is already measured: a roi applies to "
                                 "files and arrays")
        source, result, integer = f"edge {k + 1}", item, False
    else:
        if isinstance(item, (str, Path)):
            from ...io import read_raster
            raster = read_raster(item, band, window=roi)
            source, image, gsd, dtype = str(item), raster.data, raster.gsd_m, np.dtype(raster.dtype)
        else:
            image = np.asarray(item)
            source, gsd, dtype = f"array {k + 1}", None, image.dtype
            if roi is not None:
                left, top, width, height = check_roi(roi, image.shape[:2], source)
                image = image[top: top + height, left: left + width]
        try:
            result = measure_edge(image, gsd_m=gsd_m if gsd_m is not None else gsd,
                                  saturation=saturation_levels(dtype), bootstrap=Bootstrap(0))
        except ImgmtfError as exc:
            # name the input, keeping the error's class, reason and checks
            exc.args = (f"{source}: {exc}",)
            raise
        integer = np.issubdtype(dtype, np.integer)
    x = np.asarray(result.samples_x_px, float)
    y = np.asarray(result.samples_dn, float)
    order = np.argsort(x, kind="stable")
    x, y = x[order], y[order]
    levels = (float(result.levels_dn[0]), float(result.levels_dn[1]))
    step = abs(levels[1] - levels[0])
    if x.size < 20 or not step > 0:
        raise ImgmtfError(f"{source}: too few edge samples to fit", reason="unsuitable")
    # quantisation (1 DN) for integer data, else a floor for noise-free floats
    floor = 1 / math.sqrt(12) if integer else 1e-5 * step
    noise = max(profile_noise(x, y), floor)
    gsd = result.gsd_m if result.gsd_m else (gsd_m or 1.0)
    return EdgeData(source, x, y, float(result.normal_angle_deg), float(gsd), bool(result.gsd_m), noise,
                     levels, result)


def profile_noise(x: np.ndarray, y: np.ndarray) -> float:
    """Noise standard deviation (DN) of profile samples ``y`` at sorted
    positions ``x``, without a model: each sample against the straight line
    through its two neighbours, robust (median absolute deviation), so the
    few samples where the profile curves do not count."""
    left, right = x[1:-1] - x[:-2], x[2:] - x[1:-1]
    span = left + right
    ok = span > 0
    w = np.where(ok, right / np.where(ok, span, 1.0), 0.5)
    misfit = y[1:-1] - (w * y[:-2] + (1 - w) * y[2:])
    scale = np.sqrt(1 + w**2 + (1 - w) ** 2)
    return float(1.4826 * np.median(np.abs(misfit / scale)))
