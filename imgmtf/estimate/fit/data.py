"""What each edge gives the fit: its samples' distances and values, its
noise; from an image (an array, or an :class:`EdgeImage` with what its
file said) or a measurement.  No file is opened here: :func:`imgmtf.fit_sensor`
reads them."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import DTypeLike

from ...errors import ImgmtfError, ParameterError

if TYPE_CHECKING:
    from ..edge import EdgeResult


@dataclass(frozen=True, eq=False)
class EdgeImage:
    """An image of one edge and what its file said of it: an input of the
    fit where an array alone does not say enough (what
    :func:`imgmtf.fit_sensor` makes of a file).

    Attributes
    ----------
    image : numpy.ndarray, shape (rows, cols)
        The pixels, DN.
    source : str
        What messages and results name it by (the file).
    gsd_m : float or None
        The pixel, m, when known.
    dtype : numpy dtype or str, optional
        The stored sample type when ``image`` is not in it (a file's pixels
        read as floats): an integer type sets the saturation levels and the
        quantisation's noise floor (default ``image``'s own).

    Examples
    --------
    >>> import numpy as np
    >>> EdgeImage(np.zeros((2, 2)), "chip.tif", 0.5, "uint16").source
    'chip.tif'
    """

    image: np.ndarray
    source: str
    gsd_m: float | None = None
    dtype: DTypeLike | None = None


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


def edge_data(item: np.ndarray | EdgeImage | EdgeResult, k: int, gsd_m: float | None) -> EdgeData:
    """What edge ``k`` (0-based) gives the fit: an image measured (its
    geometry only), or a measurement taken as it is."""
    from ...inputs import saturation_levels
    from ..edge import EdgeResult, measure_edge
    from ..intervals import Bootstrap
    from ..results import MTFResult
    if isinstance(item, MTFResult) and not isinstance(item, EdgeResult):
        raise ParameterError(f"edge {k + 1}: a {type(item).__name__}; the fit takes edges (an EdgeResult, "
                             "an image array or a file)")
    if isinstance(item, (str, os.PathLike)):
        raise ParameterError(f"edge {k + 1}: a file ({item}); the fit takes images and measurements: "
                             "imgmtf.fit_sensor reads files")
    if isinstance(item, EdgeResult):
        source, result, integer = f"edge {k + 1}", item, False
    else:
        if not isinstance(item, EdgeImage):
            item = EdgeImage(np.asarray(item), f"array {k + 1}")
        source = item.source
        dtype = np.dtype(item.dtype if item.dtype is not None else item.image.dtype)
        try:
            result = measure_edge(item.image, gsd_m=gsd_m if gsd_m is not None else item.gsd_m,
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
