"""One image restored end to end: its noise measured (unless given), the
filter designed from the sensor for its pixel, applied tile by tile, and
the figures of merit; what ``imgmtf restore`` does for each input.

Two restorations are refused before anything is written, because their
result would mislead:

* one from a sensor whose fit says its model does not fit the edges it was
  fitted to (:class:`~imgmtf.estimate.fit.record.FitRecord`, reason
  ``misfit``): the filter would invert a blur the sensor does not have;
  ``allow_misfit`` restores anyway, and the restoration's warnings say so;
* one whose noise dominates the result (reason ``noise-dominated``): a
  filter whose white-noise gain exceeds :data:`NOISE_DOMINATED_GAIN` when no
  noise-gain limit was given.  A noise-gain limit is the caller's noise
  budget: a design within it is made, and warned about above that gain.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import ImageContentError, ImgmtfError
from ..sensor.model import Sensor
from .apply import DEFAULT_TILE_PX, RestoredFile, measure_noise, restore_file
from .design import RestorationFilter, design_filter
from .report import RestorationReport, restoration_report

if TYPE_CHECKING:
    from ..estimate.fit.record import FitRecord

#: relative difference between the image's and the sensor's GSD worth a warning
GSD_TOLERANCE = 1e-3
#: the white-noise gain above which the restored image is more the filter's noise than
#: the scene's detail.  The gain is about the lift the filter gives the MTF near Nyquist
#: (on Gaussian-and-pixel sensors of MTF 0.04-0.23 at Nyquist, targets 1.5, 2, 3 and 4 times the
#: sensor's cost gains of 1.1-1.3, 1.3-1.7, 1.8-2.6 and 2.2-3.6 at SNR 50-200): above 4 the filter
#: lifts frequencies where the sensor passes under a quarter of the target, the restored noise's
#: standard deviation is more than 4 times the image's (its SNR under a quarter, -12 dB) and more
#: than 15/16 of its noise power is the filter's.  The documented restorations stay under 1.4; the
#: Baotou chip restored from its misfit model asks 11.
NOISE_DOMINATED_GAIN = 4.0


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
        What the caller should know (a file's GSD unlike the sensor's, a
        misfit sensor restored with anyway, a target below the sensor's
        own MTF: a blurring filter, a noise gain above
        :data:`NOISE_DOMINATED_GAIN` within the limit given).
    fit : FitRecord or None
        What the sensor's fit said of its model (None: no record).

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
    fit: FitRecord | None = None

    @property
    def restored_noise_std_dn(self) -> float:
        """The restored image's noise std, DN: the noise gain times the image's noise."""
        return self.filter.noise_gain * self.filter.noise_std_dn

    def to_dict(self) -> dict:
        """JSON-ready: the file's figures, the filter's design, ``noise_gain``,
        the restored noise, the per-axis figures (units in the names) and
        the sensor's fit record (``sensor_fit``, null when it has none)."""
        return {**self.file.to_dict(), "noise_source": self.noise_source, "filter": self.filter.to_dict(),
                **self.report.to_dict(), "restored_noise_std_dn": self.restored_noise_std_dn,
                "sensor_fit": self.fit.to_dict() if self.fit else None, "warnings": list(self.warnings)}


def restore_image(path: str | Path, sensor: Sensor, out: str | Path, *, target_nyquist: float,
                  noise_std_dn: float | None = None, signal_std_dn: float | None = None,
                  max_noise_gain: float | None = None, kernel_size: int | None = None,
                  gsd_m: float | None = None, tile_px: int = DEFAULT_TILE_PX,
                  saturation: tuple[float, float] | None = None, workers: int = 1, scheduler: str | None = None,
                  progress: bool | None = None, run_utc: str | None = None, fit: FitRecord | None = None,
                  allow_misfit: bool = False) -> Restoration:
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
        (:func:`imgmtf.design_filter`).  Without it, a design whose gain
        exceeds :data:`NOISE_DOMINATED_GAIN` is refused; with it, the
        caller has set the noise budget and such a design is warned about.
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
    fit : FitRecord, optional
        What the sensor's fit said of its model
        (:func:`imgmtf.estimate.fit.read_fit_record` of its TOML).
    allow_misfit : bool, optional
        Restore with a sensor whose ``fit`` says misfit (warned about).

    Returns
    -------
    Restoration
        The filter, its figures of merit, the file written and where the
        noise figures came from.

    Raises
    ------
    ImgmtfError
        A misfit sensor (reason ``misfit``) unless ``allow_misfit``; a
        filter whose noise dominates the result (reason
        ``noise-dominated``): both before anything is written.
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
    warnings: list[str] = list(check_model_fits(fit, allow_misfit=allow_misfit))
    info = raster_info(path)
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
    noisy = noise_domination(restoration)
    if noisy and max_noise_gain is None:
        raise ImgmtfError(f"{path}: {noisy}", reason="noise-dominated")
    if noisy:
        warnings.append(f"NOISE DOMINATES: {noisy}")
    report = restoration_report(restoration)
    warnings += blurring_note(report)
    done = restore_file(path, restoration, out, tile_px=tile_px, saturation=saturation, workers=workers,
                        scheduler=scheduler, progress=progress, run_utc=run_utc)
    if done.clipped_fraction > 0:
        warnings.append(f"{100 * done.clipped_fraction:.3g} % of the restored pixels were clipped to the "
                        f"{done.dtype} range (overshoot at bright or dark edges)")
    source = sources.pop() if len(sources) == 1 else "given and measured"
    return Restoration(restoration, report, done, source, tuple(warnings), fit)


def check_model_fits(fit: FitRecord | None, source: str = "the sensor", *,
                     allow_misfit: bool = False) -> tuple[str, ...]:
    """Refuse a sensor whose fit record says its model does not fit, unless
    ``allow_misfit``; the warnings a restoration with it then carries.

    Parameters
    ----------
    fit : FitRecord or None
        The sensor file's ``[fit]`` record (None: no record, no claim).
    source : str, optional
        What the message names (the sensor file).
    allow_misfit : bool, optional
        Go ahead with a misfit sensor, warned.

    Returns
    -------
    tuple of str
        The warning of a misfit restored anyway, else none.

    Raises
    ------
    ImgmtfError
        A misfit (reason ``misfit``) not allowed.

    Examples
    --------
    >>> from imgmtf import ImgmtfError
    >>> from imgmtf.estimate.fit.record import FitRecord
    >>> from imgmtf.restore.restoration import check_model_fits
    >>> record = FitRecord(True, 3.8, 0.0, 0.025, ("optics", "detector"), ("chip.tif",))
    >>> try:
    ...     check_model_fits(record, "s.toml")
    ... except ImgmtfError as refusal:
    ...     print(refusal.reason, "|", str(refusal)[:60])
    misfit | s.toml: the model (optics, detector) does not fit the 1 edge
    >>> check_model_fits(record, "s.toml", allow_misfit=True)[0][:40]
    'MISFIT SENSOR, restored with anyway: the'
    """
    if fit is None or not fit.misfit:
        return ()
    if not allow_misfit:
        raise ImgmtfError(f"{source}: {fit.summary()}: a filter designed from it inverts a blur the sensor does "
                          "not have", reason="misfit")
    return (f"MISFIT SENSOR, restored with anyway: {fit.summary()}; the restored MTF is the model's, not the "
            "image's",)


def noise_domination(restoration: RestorationFilter) -> str:
    """Why the restored image would be more the filter's noise than the
    scene's detail (a white-noise gain above :data:`NOISE_DOMINATED_GAIN`),
    or ``""``.

    Examples
    --------
    >>> from imgmtf import Sensor, design_filter
    >>> from imgmtf.restore.restoration import noise_domination
    >>> noise_domination(design_filter(Sensor(), 0.35, noise_std_dn=5.0, signal_std_dn=500.0))
    ''
    >>> blurry = Sensor(optics_sigma_x_m=0.7, optics_sigma_y_m=0.7)      # MTF 0.05 at Nyquist
    >>> noise_domination(design_filter(blurry, 0.4, noise_std_dn=1.0, signal_std_dn=500.0))[:40]
    'the filter multiplies the noise by 8.5 ('
    """
    gain = restoration.noise_gain
    if gain <= NOISE_DOMINATED_GAIN:
        return ""
    noise = restoration.noise_std_dn
    signal = ("" if restoration.signal_std_dn != restoration.signal_std_dn
              else f" against the scene's {restoration.signal_std_dn:.4g} DN")
    return (f"the filter multiplies the noise by {gain:.2g} (over {NOISE_DOMINATED_GAIN:g}): the restored noise, "
            f"{gain * noise:.3g} DN{signal}, is {1 - 1 / gain ** 2:.0%} the filter's, and its MTF is lifted "
            "where the sensor passes a small fraction of the target")


def blurring_note(report: RestorationReport) -> list[str]:
    """A note for each axis whose target lies below the sensor's own MTF at
    Nyquist: the filter blurs it."""
    return [f"the target MTF at Nyquist, {a.designed_mtf_nyquist:g}, is below the sensor's own {direction} track, "
            f"{a.system_mtf_nyquist:.4f}: the filter blurs {direction} track rather than sharpening"
            for direction, a in report.axes.items() if a.designed_mtf_nyquist < a.system_mtf_nyquist]


def _first_band(info) -> int:
    """The first band that is not transparency."""
    return next((b for b in range(1, info.count + 1) if b not in info.alpha_bands), 1)

