"""One image restored end to end: its noise measured (unless given), the
filter designed from the sensor for its pixel, applied tile by tile, and
the figures of merit; what ``imgmtf restore`` does for each input."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ImageContentError
from ..sensor.model import Sensor
from .apply import DEFAULT_TILE_PX, RestoredFile, measure_noise, restore_file
from .design import RestorationFilter, design_filter
from .report import RestorationReport, restoration_report

#: relative difference between the image's and the sensor's GSD worth a warning
GSD_TOLERANCE = 1e-3


@dataclass(frozen=True, eq=False)
class Restoration:
    """What :func:`restore_image` did: the filter, its figures of merit,
    the file written, where the noise figures came from and any warnings.

    Attributes
    ----------
    filter : RestorationFilter
        The filter designed (:func:`imgmtf.design_filter`).
    report : RestorationReport
        Its figures of merit per axis (:func:`imgmtf.restoration_report`).
    file : RestoredFile
        The file written (:func:`imgmtf.restore_file`).
    noise_source : str
        ``"measured"`` (from the image), ``"given"`` or ``"given and measured"``.
    warnings : tuple of str
        What the caller should know (a file's GSD unlike the sensor's).

    Examples
    --------
    >>> import imgmtf
    >>> sensor = imgmtf.Sensor()
    >>> imgmtf.write_geotiff("edge.tif", imgmtf.render(sensor, imgmtf.Target("edge", 6.0), 64).image)
    >>> done = imgmtf.restore_image("edge.tif", sensor, "sharp.tif", target_nyquist=0.35,
    ...                             noise_std_dn=1.0, signal_std_dn=100.0)
    >>> done.noise_source, done.file.out, done.warnings
    ('given', 'sharp.tif', ())
    """

    filter: RestorationFilter
    report: RestorationReport
    file: RestoredFile
    noise_source: str
    warnings: tuple[str, ...] = field(default=())

    def to_dict(self) -> dict:
        """JSON-ready: the file's figures, the filter's design, ``noise_gain``
        and the per-axis figures (units in the names)."""
        return {**self.file.to_dict(), "noise_source": self.noise_source, "filter": self.filter.to_dict(),
                **self.report.to_dict(), "warnings": list(self.warnings)}


def restore_image(path: str | Path, sensor: Sensor, out: str | Path, *, target_nyquist: float,
                  noise_std_dn: float | None = None, signal_std_dn: float | None = None,
                  max_noise_gain: float | None = None, kernel_size: int | None = None,
                  gsd_m: float | None = None, tile_px: int = DEFAULT_TILE_PX,
                  saturation: tuple[float, float] | None = None, workers: int = 1, scheduler: str | None = None,
                  progress: bool | None = None, run_utc: str | None = None) -> Restoration:
    """Restore an image file to a target MTF at Nyquist with a filter
    designed from ``sensor`` and the image's noise.

    Parameters
    ----------
    path : str or pathlib.Path
        The image (anything GDAL reads).
    sensor : Sensor
        The system to compensate (``imgmtf fit --out``).
    out : str or pathlib.Path
        The GeoTIFF to write.
    target_nyquist : float
        The restored MTF at Nyquist (0.5 cy/px), in (0, 1]
        (:func:`imgmtf.design_filter`).
    noise_std_dn, signal_std_dn : float, optional
        The noise and the scene's contrast (DN); each measured from the
        first band's central window when not given
        (:func:`imgmtf.restore.apply.measure_noise`).
    max_noise_gain : float, optional
        Upper bound (>= 1) of the filter's white-noise gain
        (:func:`imgmtf.design_filter`).
    kernel_size : int, optional
        Side (odd, 3 to 63 px) of a spatial kernel; None for the FFT form.
    gsd_m : float, optional
        The image's pixel, m (default the file's, else the sensor's); a
        file's GSD that differs from the sensor's is warned about.
    tile_px : int, optional
        Tile side, px (64 to 2048; :func:`imgmtf.restore_file`).
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
    Restoration
        The filter, its figures of merit, the file written and where the
        noise figures came from.

    Raises
    ------
    ImageReadError, ImageContentError, ParameterError, FileWriteError
        As :func:`imgmtf.design_filter` and :func:`imgmtf.restore_file`.

    Examples
    --------
    >>> import imgmtf
    >>> sensor = imgmtf.Sensor()
    >>> chip = imgmtf.render(sensor, imgmtf.Target("edge", 6.0), 100, noise_std_dn=2.0, seed=1)
    >>> imgmtf.write_geotiff("edge.tif", chip.image)
    >>> done = imgmtf.restore_image("edge.tif", sensor, "sharp.tif", target_nyquist=0.35)
    >>> done.noise_source, round(done.report.axes["across"].achieved_mtf_nyquist, 2)
    ('measured', 0.35)
    """
    from ..io import raster_info
    info = raster_info(path)
    warnings: list[str] = []
    if gsd_m is None:
        gsd_m = info.gsd_m or sensor.gsd_m
        if info.gsd_m and abs(info.gsd_m / sensor.gsd_m - 1) > GSD_TOLERANCE:
            warnings.append(f"{path}: the image's pixel is {info.gsd_m:g} m, the sensor's {sensor.gsd_m:g} m: "
                            "the filter is designed for the image's (give the GSD if the file's is not the "
                            "sensor's ground pixel)")
    sources = {"given" if v is not None else "measured" for v in (noise_std_dn, signal_std_dn)}
    if noise_std_dn is None or signal_std_dn is None:
        noise, signal = measure_noise(path, band=_first_band(info))
        if signal_std_dn is None and signal == 0.0:
            raise ImageContentError(f"{path}: the image's centre holds no signal above its noise ({noise:.3g} DN) "
                                    "to weigh the noise against: give the scene's contrast", reason="no-signal")
        noise_std_dn = noise if noise_std_dn is None else noise_std_dn
        signal_std_dn = signal if signal_std_dn is None else signal_std_dn
    restoration = design_filter(sensor, target_nyquist, noise_std_dn=noise_std_dn, signal_std_dn=signal_std_dn,
                                max_noise_gain=max_noise_gain, kernel_size=kernel_size, gsd_m=gsd_m)
    if restoration.limited:
        warnings.append(f"the noise-gain limit {max_noise_gain:g} won over the target: the restored MTF at "
                        "Nyquist is below it (see achieved_mtf_nyquist)")
    report = restoration_report(restoration)
    done = restore_file(path, restoration, out, tile_px=tile_px, saturation=saturation, workers=workers,
                        scheduler=scheduler, progress=progress, run_utc=run_utc)
    if done.clipped_fraction > 0:
        warnings.append(f"{100 * done.clipped_fraction:.3g} % of the restored pixels were clipped to the "
                        f"{done.dtype} range (overshoot at bright or dark edges)")
    source = sources.pop() if len(sources) == 1 else "given and measured"
    return Restoration(restoration, report, done, source, tuple(warnings))


def _first_band(info) -> int:
    """The first band that is not transparency."""
    return next((b for b in range(1, info.count + 1) if b not in info.alpha_bands), 1)

