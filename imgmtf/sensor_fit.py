"""The sensor fitted to edges given as files, arrays or measurements
(:func:`fit_sensor`, the public entry point): the files are read here, with
their band, window, GSD and sample type, and the fit itself is
:func:`imgmtf.estimate.fit.fit_edges` (arrays and results only)."""
from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .errors import ParameterError
from .estimate.fit.data import EdgeImage
from .estimate.fit.fitting import checked_arguments, fit_edges
from .estimate.fit.model import listed
from .estimate.fit.results import SensorFit
from .inputs import check_roi
from .sensor.model import Sensor

if TYPE_CHECKING:
    from .estimate.edge import EdgeResult


def fit_sensor(edges: Sequence[str | os.PathLike | np.ndarray | EdgeResult], *,
               stages: str | Sequence[str] | None = None, start: Sensor | None = None,
               hold: str | Sequence[str] = (), gsd_m: float | None = None,
               band: int | None = None, roi: tuple[int, int, int, int] | None = None,
               confidence: float = 0.95) -> SensorFit:
    """Fit a sensor's stages to the profiles of one or more edges.

    Parameters
    ----------
    edges : sequence
        Each an image file path, a 2-D array (DN) or an
        :class:`imgmtf.EdgeResult` already measured; one edge per image.
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
    roi : (int, int, int, int), optional
        (x, y, width, height) window, px, taken from every file or array
        (only it is read from a file); not for EdgeResults.
    confidence : float, optional
        Of the intervals, in (0, 1) (default 0.95).

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
        ``roi`` outside an input.
    ImgmtfError
        An input that cannot be read or has no measurable edge (the
        message names it), or a fit that does not converge.

    Examples
    --------
    >>> import imgmtf
    >>> chips = [imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", a), 60).image for a in (6.0, 84.0)]
    >>> fit = imgmtf.fit_sensor(chips)
    >>> abs(fit.edges[0].mtf_nyquist - 0.2667) < 0.002
    True
    """
    from .estimate.edge import EdgeResult
    checked_arguments(stages, start, gsd_m, confidence)        # before any file is read
    if isinstance(edges, (str, Path, np.ndarray, EdgeResult)):
        edges = [edges]
    items = listed("edges", edges, "files, arrays or EdgeResults")
    return fit_edges([_read(item, k, band, roi) for k, item in enumerate(items)], stages=stages, start=start,
                     hold=hold, gsd_m=gsd_m, confidence=confidence)


def _read(item, k: int, band: int | None, roi: tuple[int, int, int, int] | None):
    """Edge ``k`` (0-based) as the fit takes it: a file read (its window
    ``roi``) with its GSD and sample type, an array's window; measurements
    (and what is no image) as they are."""
    from .estimate.edge import EdgeResult
    from .estimate.results import MTFResult
    if isinstance(item, EdgeResult) and roi is not None:
        raise ParameterError(f"edge {k + 1}: an EdgeResult is already measured: a roi applies to "
                             "files and arrays")
    if isinstance(item, MTFResult):
        return item
    if isinstance(item, (str, Path)):
        from .io import read_raster
        raster = read_raster(item, band, window=roi)
        return EdgeImage(raster.data, str(item), raster.gsd_m, raster.dtype)
    if roi is None:
        return item
    image = np.asarray(item)
    source = f"array {k + 1}"
    left, top, width, height = check_roi(roi, image.shape[:2], source)
    return EdgeImage(image[top: top + height, left: left + width], source, None, image.dtype)
