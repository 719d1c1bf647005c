"""Measure many image files: folders expanded, every file (and band) one
task, tasks run in parallel (:mod:`imgmtf.parallel`), every outcome a
:class:`imgmtf.records.Record`, failures included, so that one bad file
never loses the others: an unexpected exception inside one file's
measurement becomes an error record of reason ``internal`` for that file.
"""
from __future__ import annotations

import functools
import itertools
import os
from collections.abc import Generator, Sequence
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import numpy as np

from .atomic import ensure_folder
from .errors import FileWriteError, ImgmtfError, ParameterError
from .estimate.field import field_position, resolve_centre
from .figures import with_figure
from .file_lists import IMAGE_SUFFIXES, expand_inputs, once_each  # noqa: F401  (where callers found them)
from .file_notes import file_notes as raster_notes
from .io import Raster, many_files, open_raster, read_raster
from .measure_settings import MeasureSettings
from .parallel import run_tasks
from .raster_estimate import edge_centre_px, in_image_axes, measure_rasters
from .records import Record, utc_now
from .vectors import Unplaced, VectorROIs

GROUP_FILES = 32           # files measured in one task at most: their small rasters estimated together
GROUP_BYTES = 4 * 2 ** 20  # and their bytes on disk at most: a larger file is a task of its own
GROUPS_PER_WORKER = 6      # tasks per worker at least, where there are files enough: workers end together
POOLED_MAX_PX = 512 * 512  # a raster larger than this is estimated on its own (memory), as it is read
def measure_file(path: str | os.PathLike, settings: MeasureSettings | None = None, plot_path: str | None = None,
                 *, run_utc: str | None = None, **options: Any) -> list[Record]:
    """Measure one image file as ``imgmtf measure FILE`` does: every
    requested band, one record each, the same records (and numbers) that
    ``imgmtf measure --format json FILE`` prints.

    The file's GSD (figures on the ground), its data type (saturation
    limits), its geometry (the track's direction) and, for an RGB(A) photo,
    its luminance are taken from the file, as the CLI takes them.

    Parameters
    ----------
    path : str or os.PathLike
        The image file (GeoTIFF, JP2, NITF, PNG, JPEG: anything GDAL reads).
    settings : MeasureSettings, optional
        How to measure; or give its fields as keywords (``target``,
        ``method``, ``band``, ``roi``, ``pulse_width``, ``intervals``,
        ``force``, ``saturation``, ``track_azimuth_deg``), which take what
        the CLI's options take (``intervals="bootstrap"``,
        ``pulse_width="1.5m"``, ``band="all"``).
    plot_path : str, optional
        Also save the measurement figure here (``measure --plot``).
    run_utc : str, optional
        The time stamp of the records (default: now).
    **options
        The fields of :class:`MeasureSettings`, without ``settings``.

    Returns
    -------
    list of Record
        One per band measured (one for a single-band file or a photo's
        luminance); a file or band that cannot be measured gives an error
        record (``status`` "error", its ``reason`` and message), never an
        exception, as in a batch.

    Raises
    ------
    ParameterError
        Settings out of range, or both ``settings`` and keywords.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 64, gsd_m=0.5, seed=1)
    >>> imgmtf.write_geotiff("chip.tif", chip.image, gsd_m=chip.gsd_m)
    >>> [record] = imgmtf.measure_file("chip.tif", intervals="bootstrap")
    >>> record.status, record.get("gsd_m"), record.get("params")["intervals"]["method"]
    ('ok', 0.5, 'bootstrap')
    >>> imgmtf.measure_file("missing.tif")
    [Record('missing.tif', error, unreadable: missing.tif: no such file)]
    """
    if settings is None:
        settings = MeasureSettings(**options)
    elif options:
        raise ParameterError(f"give settings or keyword options ({', '.join(options)}), not both")
    elif not isinstance(settings, MeasureSettings):
        raise ParameterError(f"settings must be a MeasureSettings, got {type(settings).__name__}")
    steps = _file_steps(os.fspath(path), settings, plot_path, run_utc or utc_now())
    try:
        raster = next(steps)
        while True:
            raster = steps.send(measure_rasters([raster], settings)[0])
    except StopIteration as done:
        return done.value


def _file_steps(path: str, settings: MeasureSettings, plot_path, run_utc: str
                ) -> Generator[Raster, Any, list[Record]]:
    """:func:`measure_file` as a generator that yields each raster to
    estimate (a band, a vector feature's window) and takes its estimate
    (:func:`.raster_estimate.measure_raster`'s result or exception), so
    that many files' rasters can be estimated together
    (:func:`.raster_estimate.measure_rasters`); it returns the records."""
    with ExitStack() as stack:
        try:
            file = stack.enter_context(open_raster(path))       # once for the header and every band
            bands = file.info.bands(settings.band)
        except Exception as exc:               # the safety net: a record, never an abort
            return [settings.failed(path, settings.band, exc, run_utc)]
        return (yield from _bands_steps(file, bands, settings, plot_path, run_utc))


def _bands_steps(file, bands, settings: MeasureSettings, plot_path, run_utc: str
                 ) -> Generator[Raster, Any, list[Record]]:
    """One record per band of an open file (see :func:`_file_steps`)."""
    path, info = file.path, file.info
    skipped = info.alpha_bands if settings.band == "all" or (settings.band is None and info.is_grey_alpha) else []
    # what the file's reading adds to its first record's warnings (and to its figure's count of them)
    skipped_note = ([f"{path}: band {', '.join(map(str, skipped))} is alpha (transparency, not DN): not measured"]
                    if skipped else [])
    try:
        windows = _windows(info, settings)
    except Exception as exc:
        return [settings.failed(path, settings.band, exc, run_utc)]
    records = []
    for index, band in enumerate(bands):
        for feature in windows:
            file_notes = skipped_note if index == 0 and feature is windows[0] else []
            records.extend((yield from _window_steps(file, band, len(bands), feature, file_notes, settings,
                                                     plot_path, run_utc)))
    return records


def _windows(info, settings: MeasureSettings) -> list:
    """What is read of a file: the settings' pixel window (or the whole
    image), or each feature of a vector layer's window on it, or why that
    feature has none (an error, its record's)."""
    if isinstance(settings.roi, VectorROIs):
        return settings.roi.windows(info)
    return [None]


def _window_steps(file, band, n_bands, feature, file_notes, settings, plot_path, run_utc
                  ) -> Generator[Raster, Any, list[Record]]:
    """The records of one band read through one window: the settings' own
    (``feature`` None), or a vector feature's (with its attributes), or the
    error of a feature with no window; the raster read is yielded for its
    estimate (see :func:`_file_steps`)."""
    path = file.path
    fields = {} if feature is None else {"site": feature.record_fields()}
    if isinstance(feature, Unplaced):
        return [settings.failed(path, band, feature.error, run_utc, **fields)]
    window = settings.roi if feature is None else feature.window
    notes = [*file_notes, *(feature.notes() if feature is not None else [])]
    try:
        raster = file.read(band, window=window)
        result = yield raster
        if isinstance(result, Exception):       # its estimate's error: the same record as raised here
            raise result
        # one record per result, or per direction of a kind that measures several (points)
        summaries = result.summaries(curves=True)
        if in_image_axes(raster, settings.track_azimuth_deg):       # each direction, a points record's too
            from .estimate.geometry import image_axis_label
            for summary in summaries:
                if isinstance(summary.get("direction"), str):
                    summary["direction"] = image_axis_label(summary["direction"])
    except Exception as exc:
        failed = settings.failed(path, band, exc, run_utc, **fields)
        return [failed.with_(figures={"warnings": notes}) if notes else failed]
    if feature is not None and plot_path:
        plot_path = _feature_plot_path(plot_path, feature.fid)
    return [r.with_(**fields) if fields else r
            for r in _band_records(file, band, n_bands, raster, result, summaries, notes, settings, plot_path,
                                   run_utc)]


def _band_records(file, band, n_bands, raster, result, summaries, file_notes, settings, plot_path, run_utc):
    """The records of one band's result: one per summary, the figure drawn
    once and named by each."""
    path, info = file.path, file.info
    records: list[Record] = []
    # what the file says about every number in it, as a scan says it of each edge it accepts
    file_notes = [*file_notes, *raster_notes(raster, settings.transfer, bool(info.alpha_bands))]
    centre = resolve_centre(settings.optical_centre, info.width, info.height)
    for summary in summaries:
        summary["warnings"] = [*summary.get("warnings", []), *file_notes]
        if centre is not None and getattr(result, "geometry", None) is not None:
            summary.update(field_position(*edge_centre_px(result), result.normal_angle_deg, centre))
        record = Record.measured(path, raster.band, summary, params=settings.params(), run_utc=run_utc)
        record = _untrusted_when_forced(record, settings, result.checks)
        if plot_path and records and records[0].plot:
            record = record.with_(plot=records[0].plot)
        elif plot_path:
            record = with_figure(record, functools.partial(_measurement_figure, result, raster,
                                                           summary["warnings"], record.reason
                                                           if record.status == "untrusted" else None,
                                                           _place(summary)),
                                 _band_plot_path(plot_path, band, n_bands))
        records.append(record)
    return records


def _untrusted_when_forced(record: Record, settings: MeasureSettings, checks) -> Record:
    """A number forced past a refusal: status ``untrusted`` (printed, and a
    failure), its reason the check that makes it unusable where one does
    (:func:`.estimate.gate.untrusted_when_forced`), else the first that
    failed.  A forced chip that fails no check is a plain success."""
    if settings.force:
        from .estimate.gate import untrusted_when_forced
        failed = untrusted_when_forced(checks) or next((c for c in checks if c.failed), None)
        if failed is not None:
            record = record.with_(status="untrusted", reason=failed.reason,
                                  error=f"{record.path}: forced, but not to be trusted: {failed.message}")
    return record


def measure_files(paths, settings: MeasureSettings, *, workers: int = 1, scheduler: str | None = None,
                  plot_dir: str | None = None, progress: bool | None = None,
                  run_utc: str | None = None, ordered: bool = True):
    """Measure every file (expand folders first with :func:`expand_inputs`);
    yields each file's list of records, in input order (with ``ordered``
    false: ``(index, records)`` pairs as files complete).  Files go to the
    workers in groups (:func:`group_sizes`), each group's small rasters
    estimated together (:func:`_measure_group`): the same records as each
    file's :func:`measure_file`.  A task that dies with its worker process
    still gives each of its files an error record."""
    paths = list(paths)
    run_utc = run_utc or utc_now()
    plots = plot_paths(paths, plot_dir) if plot_dir else [None] * len(paths)
    starts = list(itertools.accumulate(group_sizes([_file_bytes(p) for p in paths], workers), initial=0))
    tasks = [(paths[a:b], settings, plots[a:b], run_utc) for a, b in itertools.pairwise(starts)]

    def lost(task, exc):
        return [[settings.failed(path, settings.band, exc, run_utc)] for path in task[0]]
    groups = run_tasks(_measure_group, tasks, workers=workers, scheduler=scheduler, progress=progress,
                       description="measuring", on_error=lost, ordered=ordered)
    if ordered:
        for group in groups:
            yield from group
    else:
        for index, group in groups:
            yield from enumerate(group, starts[index])


def group_sizes(file_bytes: Sequence[int], workers: int = 1) -> list[int]:
    """How many files each task of a batch measures, in order, given the
    files' sizes on disk (bytes): at most :data:`GROUP_FILES` and
    :data:`GROUP_BYTES` a group (a file larger alone), and with several
    workers at least :data:`GROUPS_PER_WORKER` groups per worker where
    there are files enough, so that the workers finish together.  Small
    chips gain from being estimated together; large files would only keep
    their rows (and, on an interrupt, what was measured) waiting.

    Examples
    --------
    >>> group_sizes([20_000] * 100), group_sizes([20_000] * 100, workers=2)
    ([25, 25, 25, 25], [9, 9, 9, 9, 8, 8, 8, 8, 8, 8, 8, 8])
    >>> group_sizes([20_000] * 3 + [50_000_000] + [20_000] * 2), group_sizes([])
    ([3, 1, 2], [])
    """
    files = len(file_bytes)
    if files == 0:
        return []
    count = -(-files // GROUP_FILES)
    if workers > 1:
        count = max(count, min(files, GROUPS_PER_WORKER * workers))
    size, extra = divmod(files, count)
    sizes: list[int] = []
    for target in [size + 1] * extra + [size] * (count - extra):
        start = sum(sizes)
        group = file_bytes[start: start + target]
        # cut where the bytes would pass the budget: a group holds one file at least
        taken = next((n for n in range(1, len(group)) if sum(group[:n + 1]) > GROUP_BYTES), len(group))
        sizes.append(taken)
        sizes += group_sizes(group[taken:], 1) if taken < len(group) else []
    return sizes


def _file_bytes(path: str) -> int:
    """A file's size on disk, 0 where it cannot be told (its measurement says why)."""
    try:
        return os.stat(path).st_size if path else 0
    except (OSError, ValueError):
        return 0


def _measure_group(task) -> list[list[Record]]:
    """Each file's records (:func:`measure_file`) of a group of files, their
    small rasters (at most :data:`POOLED_MAX_PX`) estimated together
    (:func:`.raster_estimate.measure_rasters`) a round at a time: every
    file's first band (or window), then every file's next; a larger raster
    is estimated on its own as it is read, so that a group holds no more
    than a few small rasters at once."""
    paths, settings, plots, run_utc = task
    with many_files():
        return _measured_group(paths, settings, plots, run_utc)


def _measured_group(paths, settings: MeasureSettings, plots, run_utc: str) -> list[list[Record]]:
    steps = [_file_steps(path, settings, plot, run_utc) for path, plot in zip(paths, plots)]
    out: list[list[Record]] = [[] for _ in paths]
    waiting: dict[int, Raster] = {}

    def advance(i: int, outcome: Any = None, started: bool = True) -> None:
        """File ``i``'s steps run on to its next small raster, or to its records."""
        try:
            raster = steps[i].send(outcome) if started else next(steps[i])
            while raster.data.size > POOLED_MAX_PX:
                raster = steps[i].send(measure_rasters([raster], settings)[0])
            waiting[i] = raster
        except StopIteration as done:
            out[i] = done.value
        except Exception as exc:        # as a task's failure would be: this file's error record only
            out[i] = [settings.failed(paths[i], settings.band, exc, run_utc)]
    for i in range(len(steps)):
        advance(i, started=False)
    while waiting:
        rasters = dict(waiting)
        waiting.clear()
        for i, outcome in zip(rasters, measure_rasters(list(rasters.values()), settings)):
            advance(i, outcome)
    return out


def plot_paths(paths, plot_dir: str) -> list[str]:
    """One figure path per input in ``plot_dir`` (created), named after
    the input's stem (``_2``, ``_3``... for inputs that share a stem)."""
    folder = ensure_folder(plot_dir)
    if not os.access(folder, os.W_OK):
        raise FileWriteError(f"{plot_dir}: cannot write figures there: permission denied")
    seen: dict[str, int] = {}
    out = []
    for path in paths:
        stem = Path(path).stem
        seen[stem] = seen.get(stem, 0) + 1
        suffix = f"_{seen[stem]}" if seen[stem] > 1 else ""
        out.append(str(folder / f"{stem}{suffix}_mtf.png"))
    return out


def _feature_plot_path(plot_path: str, fid: str) -> str:
    """A feature's figure: the file's with ``_f<id>`` before its suffix."""
    p = Path(plot_path)
    stem = p.name[:-len("_mtf.png")] if p.name.endswith("_mtf.png") else p.stem
    tail = "_mtf.png" if p.name.endswith("_mtf.png") else p.suffix
    return str(p.with_name(f"{stem}_f{fid}{tail}"))


def _band_plot_path(plot_path: str, band, n_bands: int) -> str:
    if n_bands == 1:
        return plot_path
    p = Path(plot_path)
    if p.name.endswith("_mtf.png"):
        return str(p.with_name(p.name.replace("_mtf.png", f"_b{band}_mtf.png")))
    return str(p.with_name(f"{p.stem}_b{band}{p.suffix}"))      # --plot FILE: not one figure per band over it


def _place(summary: dict) -> str:
    """Where an edge lies in a lens's field, as its figure's title says it
    (``""`` without an optical centre)."""
    if summary.get("radial_distance_px") is None:
        return ""
    return (f"{summary.get('field_direction') or 'at the optical centre'}, "
            f"{summary['radial_distance_px']:g} px from the optical centre")


def _measurement_figure(result, raster, warnings, untrusted=None, place: str = ""):
    """The measurement figure, titled with the file (and band) and the
    edge's place in a lens's field when asked (``place``), counting every
    warning its record carries (the file's own among them), with the true
    MTF when the file is a chip imgmtf simulated; a number forced past a
    refusal (``untrusted``: its reason) is said not to be trusted in the
    title."""
    from .kinds import get_kind
    from .plot import plot_measurement
    title = raster.path if raster.band in (1, "luminance") else f"{raster.path}, band {raster.band}"
    title += f": {place}" if place else ""
    if untrusted:
        title = f"{title}: NOT TO BE TRUSTED (forced past the refusal {untrusted})"
    kind = get_kind(result.target)
    if kind.figure is not None:             # a kind with a figure of its own (points: the 2-D PSF and MTF)
        return kind.load("figure")(result, raster.data, truth=kind_truth(raster), title=title, warnings=warnings)
    return plot_measurement(result, truth=true_mtf(raster), title=title, warnings=warnings)


def true_mtf(raster):
    """The true MTF along the target's normal, a function of cy/px, of a
    chip imgmtf simulated (its GeoTIFF records the sensor, the target's
    angle and the GSD); None for any other file."""
    provenance = raster.provenance
    if not isinstance(provenance, dict):
        return None
    from .sensor.model import Sensor
    try:
        sensor = Sensor.from_dict(provenance["sensor"])
        angle_deg = float(provenance["target"]["angle_deg"])
        gsd_m = float(provenance["gsd_m"])
        sensor.normal_transfer(0.5, angle_deg, gsd_m)           # a provenance it cannot use fails here
    except (KeyError, TypeError, ValueError, ImgmtfError):
        return None
    return lambda f_cy_px: np.abs(sensor.normal_transfer(f_cy_px, angle_deg, gsd_m))


def kind_truth(raster):
    """The true MTF of a chip imgmtf simulated as a function of (cy/px,
    angle in deg from the x axis), for kinds measured in several directions;
    None for any other file."""
    provenance = raster.provenance
    if not isinstance(provenance, dict):
        return None
    from .sensor.model import Sensor
    try:
        sensor = Sensor.from_dict(provenance["sensor"])
        gsd_m = float(provenance["gsd_m"])
        sensor.normal_transfer(0.5, 0.0, gsd_m)
    except (KeyError, TypeError, ValueError, ImgmtfError):
        return None
    return lambda f_cy_px, angle_deg: np.abs(sensor.normal_transfer(f_cy_px, angle_deg, gsd_m))


def file_truth(path: str, band=None, window=None):
    """:func:`true_mtf` of the chip in file ``path`` (None for a file
    imgmtf did not simulate, or one it cannot read)."""
    try:
        return true_mtf(read_raster(path, band, window=window))
    except ImgmtfError:
        return None
