"""Measuring one batch of a scan's candidates (a task, on the workers too):
each candidate's tilted ROI read within its batch's window and cleared of
junctions, fill and partners (:mod:`.roi`), a quick look at the pixels of
all of them at once (:mod:`.screen`), and the estimate of each it passes,
whose quality gate gives the verdict (:mod:`imgmtf.estimate.gate`).  The
gate runs before the estimate's intervals are computed, so only the
accepted candidates pay for them.  What the scan plans and how it ranks
the outcomes is :mod:`.measure`'s job; this module loads neither the
segment graph nor SciPy, so the workers need not.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import ImgmtfError
from ..estimate.detection import noise_of_differences
from ..figures import with_figure
from ..file_notes import file_notes
from ..inputs import saturation_levels
from ..io import RasterInfo, read_raster
from ..kinds import get_kind
from ..records import Record
from .fill import fill_mask, may_hold_fill
from .roi import Roi, clear_extent
from .screen import quick_looks
from .settings import ScanSettings

MIN_CONFIDENCE = 0.3            # an accepted target's SNR is at least this fraction of what its length needs


@dataclass(frozen=True)
class Plan:
    """One candidate to read and measure: its index among the records, its
    largest ROI, the segments it must keep clear of (rows x0, y0, x1, y1)
    and its bar width (0 for an edge)."""

    index: int
    roi: Roi
    partners: np.ndarray
    bar_width_px: float = 0.0


@dataclass(frozen=True)
class Context:
    """What every candidate of a scan shares: the scene, how to measure,
    and the record's provenance."""

    path: str
    info: RasterInfo
    settings: ScanSettings
    track_azimuth_deg: float | None
    params: dict
    run_utc: str
    figures_dir: str | None = None      # where each accepted candidate's figure goes, if anywhere


@dataclass(frozen=True)
class Band:
    """A candidate's ROI clear of what must not enter its estimate, read:
    its pixels row by row (``rows``, ``cols`` in ``data``, the window of
    its bounding box, whose top-left pixel is ``origin`` (x, y) in the
    scene), their values (DN), their positions along its line (``t``) and
    across it (``d``, px), its pixel noise (DN) and its site so far."""

    data: np.ndarray
    origin: tuple[int, int]
    rows: np.ndarray
    cols: np.ndarray
    values: np.ndarray
    t: np.ndarray
    d: np.ndarray
    noise_dn: float
    site: dict


def measure_batch(task) -> list[tuple[int, Record]]:
    """Read one window of the scene and measure every candidate in it: a
    record (accepted or rejected) per candidate, whatever goes wrong with
    one of them (reason ``internal``).  Each candidate's ROI is read and
    cleared (:func:`read_band`), all of them get their quick look at once
    (:func:`imgmtf.scene.screen.quick_looks`), and those it passes are
    estimated (:func:`measure_band`)."""
    context, window, plans = task
    raster = read_raster(context.path, context.settings.band, window=window)

    def safely(step, plan, *args):
        try:
            return step(plan, *args)
        except Exception as exc:       # the safety net: one candidate, never the scan
            return _failed(exc, raster, context)
    out, read = [], []
    fill_possible = may_hold_fill(raster.data, context.info.dtype)
    for plan in plans:
        band = safely(read_band, plan, raster, context, fill_possible)
        if isinstance(band, Band):
            read.append((plan, band))
        else:
            out.append((plan.index, band))
    try:
        verdicts = _quick_looks(read)
    except Exception as exc:           # ... and one batch's quick look, never the scan
        return out + [(plan.index, _failed(exc, raster, context)) for plan, _ in read]
    estimator = _Estimator(context, raster) if read else None    # made once: its settings checked once
    passed = [band for (_, band), verdict in zip(read, verdicts) if not verdict]
    try:    # the estimates of all at once where the estimator can (the fits alike across them stacked)
        estimates = iter(estimator.many([_chip(band) for band in passed]) if estimator and passed else [])
    except Exception:                  # (each then estimated alone, its own failure its own)
        estimates = iter([None] * len(passed))
    for (plan, band), verdict in zip(read, verdicts):
        if verdict:
            out.append((plan.index, _rejected(context, raster, band.site, *verdict, verdict_by="screen")))
        else:
            out.append((plan.index, safely(measure_band, plan, band, raster, context, estimator, next(estimates))))
    return out


def _quick_looks(read: list[tuple[Plan, Band]]) -> list[tuple[str, str] | None]:
    """The quick look's verdicts on the candidates read, all in one pass."""
    if not read:
        return []
    values, d, t = (np.concatenate([getattr(band, name) for _, band in read]) for name in ("values", "d", "t"))
    which = np.repeat(np.arange(len(read)), [band.values.size for _, band in read])
    return quick_looks(values, d, t, which, [band.noise_dn for _, band in read],
                       [plan.roi.half_width_px for plan, _ in read], [plan.bar_width_px for plan, _ in read])


def _failed(exc: Exception, raster, context: Context) -> Record:
    """A candidate's record when its measurement failed (reason ``internal``)."""
    return Record.failed(context.path, raster.band, context.settings.target, context.settings.method, exc,
                         params=context.params, run_utc=context.run_utc, status="rejected")


def _rejected(context: Context, raster, site: dict, reason: str, message: str, **more) -> Record:
    """A candidate rejected for ``reason``, its site with ``more``."""
    settings = context.settings
    return Record(context.path, raster.band, settings.target, settings.method, "rejected", reason,
                  f"{context.path}: {message}", site={**site, **more}, params=context.params,
                  run_utc=context.run_utc)


def read_band(plan: Plan, raster, context: Context, fill_possible: bool = True) -> Band | Record:
    """A candidate's ROI within ``raster`` (a window of the scene): its
    pixels, the stretch of them clear of fill, partners and border, and
    their pixel noise; or its record rejected when no stretch is clear.
    ``fill_possible`` false: the window holds no fill (:func:`.fill.may_hold_fill`)."""
    info = context.info
    roi = plan.roi
    bx, by = raster.origin
    x, y, w, h = roi.bbox(info.width, info.height)
    data = raster.data[y - by: y - by + h, x - bx: x - bx + w]
    t, d = roi.frame(np.arange(x, x + w, dtype=float)[None, :], np.arange(y, y + h, dtype=float)[:, None])
    band = (np.abs(d) <= roi.half_width_px) & (t >= roi.t0_px) & (t <= roi.t1_px)
    inside = np.flatnonzero(band)            # (flat: faster than nonzero's pair of indices, the same order)
    rows, cols = np.divmod(inside, w)
    t, d = t.ravel()[inside], d.ravel()[inside]
    fill = fill_mask(data, info.dtype) if fill_possible else None
    extent = clear_extent(roi, t, d, x + cols, y + rows, fill, plan.partners, info)
    if isinstance(extent[0], str):
        return _rejected(context, raster, {"roi_polygon_px": roi.corners()}, *extent, verdict_by="screen")
    t0, t1 = extent
    if t0 > roi.t0_px or t1 <= roi.t1_px:         # (else the stretch holds the whole band: nothing to cut)
        inside = (t >= t0) & (t < t1)
        rows, cols, t, d = rows[inside], cols[inside], t[inside], d[inside]
    r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols.min(), cols.max() + 1      # (rows ascend: the band row by row)
    site = {"roi_polygon_px": roi.corners(t0, t1), "roi": [int(x + c0), int(y + r0), int(c1 - c0), int(r1 - r0)]}
    values = data[rows, cols]
    # the noise of the masked chip, from its horizontally adjacent pixels: in the band, row by row,
    # the pairs of consecutive pixels in one row and neighbouring columns
    adjacent = (rows[1:] == rows[:-1]) & (cols[1:] == cols[:-1] + 1)
    noise = noise_of_differences((values[1:] - values[:-1])[adjacent])
    return Band(data, (x, y), rows, cols, values, t, d, noise, site)


def measure_band(plan: Plan, band: Band, raster, context: Context, estimator: _Estimator | None = None,
                 estimate=None) -> Record:
    """A candidate's record from the gate's verdict on the estimate of its
    ROI (``band``, which passed the quick look): ``estimate`` made with the
    batch's (:meth:`_Estimator.many`: a result, or the exception its
    estimator raised), else made now by ``estimator`` (the batch's
    :class:`_Estimator`, else one made for it)."""
    settings = context.settings
    try:
        # the quality gate refuses a chip before its intervals are computed
        # (imgmtf.estimate.pipeline.run): a rejected candidate never pays for them
        if estimate is None:
            estimate = (estimator or _Estimator(context, raster))(*_chip(band))
        elif isinstance(estimate, Exception):
            raise estimate
        result = estimate
    except ImgmtfError as exc:
        return _rejected(context, raster, band.site, exc.reason, _one_line(exc), verdict_by="gate",
                         **_gate_figures(getattr(exc, "checks", ())))
    needed = _confident_snr(settings.target, result.rows_used)
    if result.snr < MIN_CONFIDENCE * needed:
        # measure would report it with a warning; a scan chooses its targets, and at a small fraction
        # of the SNR its length needs, ground texture beside a target biases it beyond its interval
        return _rejected(context, raster, band.site, "snr",
                         f"SNR {result.snr:.0f} is below {MIN_CONFIDENCE:g} x the {needed:.0f} a "
                         f"{result.rows_used}-row {result.target} needs for 95 % of estimates within 5 %: "
                         "too noisy for its length to calibrate with", verdict_by="gate", snr=result.snr)
    x_, y_, w_, h_ = result.roi
    roi_box = band.site["roi"]
    figures = {**result.to_dict(curves=True), "roi": [x_ + roi_box[0], y_ + roi_box[1], w_, h_],
               "line_rms_px": _line_rms(result.geometry), **_gate_figures(result.checks)}
    # what the file says about every number in it, as measure says it (one set of warnings)
    figures["warnings"] = [*figures["warnings"], *file_notes(raster, settings.measure_settings().transfer,
                                                             bool(context.info.alpha_bands))]
    record = Record.measured(context.path, raster.band, figures, params=context.params, run_utc=context.run_utc,
                             status="accepted", site={**band.site, "verdict_by": "gate"}, measurement=result)
    if context.figures_dir:
        record = _with_figure(record, result, context, plan)
    return record


def _chip(band: Band) -> tuple[np.ndarray, np.ndarray]:
    """The candidate's chip (its band's bounding box) and the mask of the
    band's pixels in it."""
    rows, cols = band.rows, band.cols
    r0, c0 = rows[0], cols.min()
    chip = band.data[r0:rows[-1] + 1, c0:cols.max() + 1]
    mask = np.zeros(chip.shape, bool)
    mask[rows - r0, cols - c0] = True
    return chip, mask


def _with_figure(record: Record, result, context: Context, plan: Plan) -> Record:
    """The accepted candidate's measurement figure saved (under its
    measuring order, renamed to its id later), or a warning saying why not."""
    from ..plot import plot_measurement
    title = f"{context.path}: ROI {','.join(str(v) for v in record.figures['roi'])}"
    in_scene = replace(result, roi=tuple(record.figures["roi"]))      # its locations drawn where the scene has them
    return with_figure(record, lambda: plot_measurement(in_scene, title=title, warnings=record.get("warnings")),
                       str(Path(context.figures_dir or ".") / f"candidate{plan.index}.png"))


def _confident_snr(target: str, rows: int) -> float:
    """The SNR from which the estimator trusts a target of this kind and
    length (:meth:`imgmtf.estimate.kind.TargetKind.confident_snr`)."""
    return get_kind(target).load("measuring").confident_snr(rows)


class _Estimator:
    """The estimator of a scan's candidates in one window of the scene:
    made once for all of them (the settings' checks cost about a
    millisecond), called on each masked chip."""

    def __init__(self, context: Context, raster):
        settings = context.settings
        measuring = settings.measure_settings()
        self.estimate = measuring.estimator()
        self.keywords = {**measuring.target_keywords(raster), "gsd_m": raster.gsd_m, "dtype": raster.dtype,
                         "track_azimuth_deg": context.track_azimuth_deg,
                         "saturation": settings.saturation or saturation_levels(raster.dtype)}

    def __call__(self, chip, mask):
        """The estimator's result on the masked chip."""
        return self.estimate(chip, mask=mask, **self.keywords)

    def many(self, chips: list[tuple[np.ndarray, np.ndarray]]) -> list:
        """The masked chips' estimates made together where the estimator can
        (an edge's: :meth:`imgmtf.estimate.edge.EdgeEstimator.measure_many`),
        each a result or the exception its call raises; None for each
        where it cannot (each then estimated alone)."""
        many = getattr(self.estimate, "measure_many", None)
        if many is None:
            return [None] * len(chips)
        return many([chip for chip, _ in chips], [mask for _, mask in chips], **self.keywords)


def _gate_figures(checks) -> dict:
    """The gate's own measure of the sides' variation: the largest level
    drift or texture of either side, as a fraction of the contrast."""
    values = [c.value for c in checks if c.reason == "non-uniform" and c.value is not None]
    return {"side_variation": round(float(max(values)), 4)} if values else {}


def _line_rms(geometry) -> float:
    """RMS (px) of the kept per-row locations about the fitted line."""
    kept = geometry.kept
    resid = geometry.locations[kept] - (geometry.slope * geometry.rows[kept] + geometry.intercept)
    return round(float(np.sqrt(np.mean(resid ** 2))), 4)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())
