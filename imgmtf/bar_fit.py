"""The sensor model fitted to bars and double bars given as files
(:func:`fit_bar_files`, what ``imgmtf fit --target pulse|double-bar``
calls): each file read and its target measured as ``imgmtf measure``
reads and measures it, then :func:`imgmtf.estimate.fit.bars.fit_bars`
(arrays and results only) fits the stages to their profiles, as
:func:`imgmtf.fit_sensor` does to edges."""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from .errors import ImgmtfError, ParameterError
from .estimate.fit.bars import BarFit, bar_profile, fit_bars
from .kinds import get_kind
from .sensor.model import Sensor

Roi = tuple[int, int, int, int]


def fit_bar_files(paths: Sequence[str], *, target: str, pulse_width: tuple[float, str] | float | str | None = None,
                  gap: tuple[float, str] | float | str | None = None,
                  stages: str | None = "optics,detector", band: int | None = None, roi: Roi | None = None,
                  gsd_m: float | None = None, confidence: float = 0.95, force: bool = False,
                  transfer: str = "linear", saturation: tuple[float, float] | None = None,
                  start: Sensor | None = None, hold: str | Sequence[str] = ()) -> BarFit:
    """Fit the sensor's stages to the bars (or double bars) of image files.

    Parameters
    ----------
    paths : sequence of str
        The files, one target each.
    target : str
        A kind with a width: "pulse" or "double-bar".
    pulse_width, gap : (float, str), float or str, optional
        Each bar's width and a double bar's gap, as :class:`imgmtf.MeasureSettings`
        takes them (a bar's width is read off its profile when None).
    stages : str, optional
        The stages fitted (default "optics,detector").
    band : int, optional
        1-based band of multi-band files.
    roi : (int, int, int, int), optional
        (x, y, width, height) window read from every file, px.
    gsd_m : float, optional
        The pixel, m (default the files', else 1: parameters in px).
    confidence : float, optional
        Of the intervals, in (0, 1).
    force : bool, optional
        Measure a file's target even where a quality check fails.
    transfer : str, optional
        How the stored values relate to light ("linear", "srgb", "gamma:G").
    saturation : (float, float), optional
        DN the sensor records (default an integer file's type range).
    start : Sensor, optional
        Starting (and held) values of its stages (``--sensor``); its
        stages are fitted when ``stages`` is None.
    hold : str or sequence of str, optional
        Parameters held at their starting values (``--hold``).

    Returns
    -------
    BarFit
        The fitted sensor and the model's MTF along each target's normal.

    Raises
    ------
    ParameterError
        A kind without a width, no files, bad settings.
    ImgmtfError
        A file that cannot be read or measured (named), or a fit that does
        not converge.

    Examples
    --------
    >>> import imgmtf, tempfile, os
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("double-bar", 5.0, width_px=0.6, gap_px=1.2), 40)
    >>> path = os.path.join(tempfile.mkdtemp(), "pair.tif")
    >>> imgmtf.write_geotiff(path, chip.image, gsd_m=1.0)
    >>> fit = fit_bar_files([path], target="double-bar", pulse_width=0.6, gap=1.2)
    >>> abs(fit.mtf_nyquist[0] - float(chip.true_mtf(0.5))) < 0.005
    True
    """
    from .estimate.intervals import Intervals
    from .io import open_raster
    from .measure_settings import MeasureSettings
    from .raster_estimate import measure_raster
    if not get_kind(target).has_width:
        raise ParameterError(f"the bars' fit takes targets with a width, not a {target}")
    if not paths:
        raise ParameterError("no bars to fit")
    from .inputs import parse_length
    settings = MeasureSettings(target, band=band, roi=roi,
                               pulse_width=None if pulse_width is None else parse_length(pulse_width),
                               gap=None if gap is None else parse_length(gap),
                               intervals=Intervals("none"), force=force, saturation=saturation, transfer=transfer)
    profiles, gsd = [], gsd_m
    for path in paths:
        try:
            with open_raster(path) as file:
                raster = file.read(band, window=roi)
            if gsd_m is not None:
                raster = replace(raster, gsd_m=gsd_m)
            result = measure_raster(raster, settings)
        except ImgmtfError as exc:
            if not str(exc).startswith(str(path)):
                exc.args = (f"{path}: {exc}",)
            raise
        integer = transfer == "linear" and np.issubdtype(np.dtype(raster.dtype), np.integer)
        profiles.append(bar_profile(result, str(path), 1.0 if integer else 0.0))
        gsd = gsd or raster.gsd_m
    return fit_bars(profiles, stages=stages, gsd_m=gsd or 1.0, confidence=confidence, start=start, hold=hold)
