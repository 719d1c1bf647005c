"""The sensor fitted to edges: files, arrays or measurements
(:func:`fit_sensor`, the public entry point; the method is
:mod:`imgmtf.estimate.fit`'s)."""
from __future__ import annotations

import importlib
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ._blas import one_blas_thread
from .errors import ParameterError
from .estimate.fit.data import edge_data
from .estimate.fit.fitting import run_fit
from .estimate.fit.model import Model, initial_stages, listed, stage_names
from .estimate.fit.results import SensorFit
from .inputs import check_number
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
    if not (isinstance(confidence, (int, float, np.floating)) and 0 < confidence < 1):
        raise ParameterError(f"confidence must be in (0, 1), got {confidence!r}")
    if gsd_m is not None:
        gsd_m = check_number("gsd_m", gsd_m, positive=True)
    if start is not None and not isinstance(start, Sensor):
        raise ParameterError(f"start must be a Sensor, got {start!r}")
    names = stage_names(stages, start)
    from .estimate.edge import EdgeResult
    if isinstance(edges, (str, Path, np.ndarray, EdgeResult)):
        edges = [edges]
    items = listed("edges", edges, "files, arrays or EdgeResults")
    data = [edge_data(item, k, gsd_m, band, roi) for k, item in enumerate(items)]
    if not data:
        raise ParameterError("no edges to fit")
    gsd = gsd_m if gsd_m is not None else next((d.gsd_m for d in data if d.gsd_known), 1.0)
    importlib.import_module("scipy.optimize")      # (its BLAS loaded before the next line limits it)
    with one_blas_thread():
        return run_fit(Model(gsd, initial_stages(names, start, gsd), data), hold, confidence)
