"""Measure many image files: folders expanded, every file (and band) one
task, tasks run in parallel (:mod:`imgmtf.parallel`), every outcome a
record, failures included, so that one bad file never loses the others.

A record is a flat, JSON-ready dict: the measurement's figures (see
:meth:`imgmtf.results.MTFResult.to_dict`) or an ``error``, always with its
provenance: ``path``, ``band``, ``target``, ``method``, ``params`` and
``imgmtf_version``.
"""
from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field, replace
from pathlib import Path

from .version import __version__
from .estimate.edge import EdgeEstimator
from .errors import FileWriteError, ImgmtfError, ParameterError
from .inputs import saturation_levels
from .io import raster_info, read_raster
from .parallel import run_tasks
from .estimate.pulse import PulseEstimator, check_width
from .estimate.intervals import Bootstrap

IMAGE_SUFFIXES = frozenset({".tif", ".tiff", ".png", ".jpg", ".jpeg", ".jp2", ".j2k", ".ntf", ".nitf",
                            ".img", ".bmp", ".gif", ".vrt", ".hdr", ".webp"})

CSV_COLUMNS = ("path", "band", "target", "method", "status", "error", "normal_angle_deg", "tilt_deg", "direction",
               "polarity", "rows_used", "snr", "mtf_nyquist", "mtf_nyquist_ci_low",
               "mtf_nyquist_ci_high", "mtf50_cy_px", "mtf50_ci_low_cy_px", "mtf50_ci_high_cy_px",
               "fwhm_px", "mtfa", "gsd_m", "mtf50_cy_m", "fwhm_m", "noise_limit_cy_px", "rer",
               "pulse_width_px", "roi", "warnings", "plot", "params", "imgmtf_version")


@dataclass(frozen=True)
class MeasureSettings:
    """How to measure every file of a batch.

    target : "edge" or "pulse".
    method : resampling method (see :data:`imgmtf.resampling.METHODS`).
    band : 1-based band, "all" for every band, None for the only band or
        RGB luminance.
    roi : (x, y, width, height) window read from every file (px).
    pulse_width : (value, "px" or "m"), or None to estimate it.
    bootstrap : confidence-interval settings.
    """

    target: str = "edge"
    method: str = "msg"
    band: int | str | None = None
    roi: tuple[int, int, int, int] | None = None
    pulse_width: tuple[float, str] | None = None
    bootstrap: Bootstrap = field(default_factory=Bootstrap)

    def __post_init__(self):
        if self.target not in ("edge", "pulse"):
            raise ParameterError(f"target must be 'edge' or 'pulse', got {self.target!r}")
        if self.pulse_width is not None and self.target != "pulse":
            raise ParameterError("a pulse width applies to pulse targets only")
        if self.pulse_width is not None and self.pulse_width[1] == "px":
            check_width(self.pulse_width[0])
        self.estimator()   # an unknown method fails here, before any file is read

    def estimator(self):
        kind = EdgeEstimator if self.target == "edge" else PulseEstimator
        return kind(self.method, bootstrap=self.bootstrap)


def expand_inputs(paths, recursive: bool = False) -> list[str]:
    """Files named, plus the image files (by suffix) in folders named,
    sorted; with ``recursive`` also in their sub-folders.  Paths that do not
    exist are kept, to be reported as errors."""
    out = []
    for path in map(Path, paths):
        if path.is_dir():
            found = path.rglob("*") if recursive else path.iterdir()
            out.extend(sorted(str(p) for p in found if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES))
        else:
            out.append(str(path))
    return out


def measure_file(path: str, settings: MeasureSettings, plot_path: str | None = None) -> list[dict]:
    """Every requested band of one file measured: one record each (an error
    record when the file or a band cannot be measured)."""
    try:
        bands = raster_info(path).bands(settings.band)
    except ImgmtfError as exc:
        return [error_record(path, settings.band, settings, exc)]
    records = []
    for band in bands:
        try:
            raster = read_raster(path, band, window=settings.roi)
            result = measure_raster(raster, settings)
        except ImgmtfError as exc:
            records.append(error_record(path, band, settings, exc))
            continue
        record = {"path": path, "band": raster.band, "status": "ok", **result.to_dict(curves=True)}
        if plot_path:
            target = _band_plot_path(plot_path, band, len(bands))
            try:
                _save_plot(result, target)
                record["plot"] = target
            except ImgmtfError as exc:
                record["warnings"] = [*record["warnings"], str(exc)]
        records.append(record)
    return records


def measure_raster(raster, settings: MeasureSettings):
    """The estimate of one raster (a window of the file when ``roi`` is
    set), its ROI reported in the file's pixel coordinates."""
    estimator = settings.estimator()
    if settings.target == "edge":
        result = estimator(raster.data, gsd_m=raster.gsd_m, saturation=saturation_levels(raster.dtype))
    else:
        result = estimator(raster.data, width_px=pulse_width_px(settings.pulse_width, raster),
                           gsd_m=raster.gsd_m)
    x0, y0 = raster.origin
    x, y, w, h = result.roi
    return replace(result, roi=(x + x0, y + y0, w, h))


def pulse_width_px(width, raster) -> float | None:
    """A pulse width (value, unit) in pixels for this raster (metres need
    its GSD)."""
    if width is None:
        return None
    value, unit = width
    if unit == "px":
        return value
    if raster.gsd_m is None:
        raise ParameterError(f"{raster.path}: a width in metres needs a georeferenced image "
                             "(its GSD is unknown); give the width in px")
    check_width(value / raster.gsd_m)
    return value / raster.gsd_m


def error_record(path, band, settings: MeasureSettings, exc: Exception) -> dict:
    """A record for a file (or band) that could not be measured.  Messages
    name the file; a message that does not gets it prefixed."""
    message = str(exc)
    if not message.startswith(str(path)):
        where = f"{path}: band {band}" if isinstance(band, int) else str(path)
        message = f"{where}: {message}"
    return {"path": str(path), "band": band, "status": "error", "error": message,
            "target": settings.target, "method": settings.method,
            "params": {"bootstrap": settings.bootstrap.as_dict(), "roi": settings.roi},
            "imgmtf_version": __version__}


def measure_files(paths, settings: MeasureSettings, *, workers: int = 1, scheduler: str | None = None,
                  plot_dir: str | None = None, progress: bool | None = None):
    """Measure every file (expand folders first with :func:`expand_inputs`);
    yields each file's list of records, in input order."""
    paths = list(paths)
    plots = plot_paths(paths, plot_dir) if plot_dir else [None] * len(paths)
    tasks = [(path, settings, plot) for path, plot in zip(paths, plots)]
    yield from run_tasks(_measure_task, tasks, workers=workers, scheduler=scheduler,
                         progress=progress, description="measuring")


def _measure_task(task) -> list[dict]:
    path, settings, plot = task
    return measure_file(path, settings, plot)


def plot_paths(paths, plot_dir: str) -> list[str]:
    """One figure path per input in ``plot_dir``, named after the input's
    stem (``_2``, ``_3``... for inputs that share a stem)."""
    Path(plot_dir).mkdir(parents=True, exist_ok=True)
    seen: dict[str, int] = {}
    out = []
    for path in paths:
        stem = Path(path).stem
        seen[stem] = seen.get(stem, 0) + 1
        suffix = f"_{seen[stem]}" if seen[stem] > 1 else ""
        out.append(str(Path(plot_dir) / f"{stem}{suffix}_mtf.png"))
    return out


def _band_plot_path(plot_path: str, band, n_bands: int) -> str:
    if n_bands == 1:
        return plot_path
    p = Path(plot_path)
    return str(p.with_name(p.name.replace("_mtf.png", f"_b{band}_mtf.png")))


def _save_plot(result, path: str) -> None:
    from .plot import plot_measurement
    try:
        plot_measurement(result).savefig(path, dpi=110)
    except OSError as exc:
        raise FileWriteError(f"{path}: cannot write the figure: {exc.strerror or exc}") from None


def csv_row(record: dict) -> dict:
    """A record flattened to :data:`CSV_COLUMNS` (lists and dicts as JSON)."""
    row = {k: record.get(k) for k in CSV_COLUMNS}
    for name, key in (("mtf_nyquist_ci", "mtf_nyquist_ci"), ("mtf50_ci", "mtf50_ci_cy_px")):
        low, high = record.get(key) or (None, None)
        unit = "_cy_px" if name == "mtf50_ci" else ""
        row[f"{name}_low{unit}"], row[f"{name}_high{unit}"] = low, high
    for key in ("roi", "warnings", "params"):
        if row[key] is not None:
            row[key] = json.dumps(row[key], sort_keys=True)
    return {k: ("" if v is None else v) for k, v in row.items()}


def write_csv(records, path: str, columns=CSV_COLUMNS, flatten=csv_row) -> None:
    """Write records as CSV with a header of ``columns``."""
    try:
        with open(path, "w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(columns), extrasaction="ignore")
            writer.writeheader()
            for record in records:
                writer.writerow(flatten(record))
    except OSError as exc:
        raise FileWriteError(f"{path}: cannot write: {exc.strerror or exc}") from None
