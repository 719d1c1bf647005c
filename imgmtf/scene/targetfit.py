"""Across- and along-track MTF of a target: the sensor model fitted to all
of its accepted half-edges.

The combination of :mod:`.combine` gives one result per measured normal;
a target tilted like Baotou's (16.8 deg) then has two "oblique" results,
and neither is the across- or along-track MTF a specification quotes.
Here the sensor model (:func:`imgmtf.fit_sensor`: the same stages, the
same misfit test as ``imgmtf fit``; "optics,detector" by default) is
fitted jointly to every accepted half-edge of a target, from the samples
the scan measured it by (the record's ``measurement``), and the model's
MTF is read along the track and across it: MTF at Nyquist and MTF50 with
the fit's delta-method intervals, FWHM and RER.

A record without its measurement (read back from a file or a store) is
measured again on the masked ROI it describes: the window ``roi`` of its
site, the pixels whose centres lie inside its ``roi_polygon_px``.  Those
corners are rounded to 0.01 px, so along a tilted ROI's border that mask
can take in or leave out 1-3 pixels the scan's own did not.

The fit is in the sensor's frame: each edge's normal is turned by the
track azimuth (``--track-azimuth``; 0, rows along track, for a scene in
sensor geometry), so "across" and "along" are the track's.  A
map-projected scene with no track azimuth has no across/along direction,
and no fit rows.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ImgmtfError, ParameterError
from ..estimate.results import finite
from ..kinds import get_kind
from ..records import CANDIDATE_SCOPE, SCENE_SCOPE, TARGET_SCOPE, Record
from ..safe_json import finite_values

#: the stages fitted to a target's half-edges by default: the simplest
#: candidate that fits (:mod:`imgmtf.estimate.fit.choice`): blur and pixel
#: on a synthetic chip, the exponential wings, lag and halo real L0R needs
DEFAULT_STAGES = "auto"
_DIRECTIONS = {"across": "across-track", "along": "along-track"}
#: the figures of a half-edge's record that a fit's rows read: all a record sent to a worker keeps
FIT_FIGURES = ("rows_used", "snr", "gsd_m", "frequencies_cy_px")


def fit_targets(records: Sequence[Record], *, stages: str | list[str] = DEFAULT_STAGES, workers: int = 1,
                scheduler: str | None = None, progress: bool | None = None) -> list[Record]:
    """Fit the sensor model to each target's accepted half-edges (and to
    the scene's, when it has several targets): two summary records per
    fit, across- and along-track.

    Parameters
    ----------
    records : list of Record
        A scan's records (:func:`imgmtf.scene.measure.scan_scene`) of edge
        targets; accepted half-edges with a ``target_id`` are fitted, from
        their ``measurement``, or, without one, read again from the scene
        (``path``) on their ROI.
    stages : str or list of str
        The stages fitted (:func:`imgmtf.fit_sensor`), default
        "optics,detector".
    workers : int, optional
        Local worker processes (default 1: none, the work runs here);
        one fit per task.
    scheduler : str, optional
        A Dask distributed scheduler's address, or ``"local"`` for a local
        Dask cluster (:func:`imgmtf.parallel.run_tasks`).
    progress : bool, optional
        Show a progress bar on stderr (default: when stderr is a terminal).

    Returns
    -------
    list of Record
        Per target (``scope`` "target", ``target_id``), then for the scene
        (``scope`` "scene", only with two targets or more), an
        "across-track" and an "along-track" record (each only when some
        half-edge lies nearer that axis than the other: the model does not
        extrapolate) with ``status`` "fitted" and ``summary`` "fit": ``mtf_nyquist`` and
        ``mtf_nyquist_ci``, ``mtf50_cy_px`` and ``mtf50_ci_cy_px`` (cy/px),
        ``fwhm_px``, ``rer``, the model's MTF curve, ``n_edges``,
        ``edge_ids``, ``stages``, ``parameters`` (fitted values, m),
        ``reduced_chi_square``, ``misfit`` (the model does not fit; a
        warning says why) and ``misfit_p`` (the smallest p-value of the
        half-edges' residual structure).  A fit that fails gives one
        record per target with ``status`` "rejected" and the reason.
        Empty for a pulse scan, a scene with no accepted half-edge, or an
        unknown track direction.

    Raises
    ------
    ParameterError
        ``records`` is not a list of Records, or ``stages`` names no stage.

    Examples
    --------
    >>> from imgmtf.scene.measure import scan_scene                       # doctest: +SKIP
    >>> [(r.figures["direction"], r.figures["mtf_nyquist"]) for r in fit_targets(scan_scene("baotou.tif"))]
    ...                                                                     # doctest: +SKIP
    [('across-track', 0.1107), ('along-track', 0.0952)]
    """
    try:
        records = list(records)
    except TypeError:
        raise ParameterError(f"records must be a list of a scan's Records, got {records!r}") from None
    if any(not isinstance(r, Record) for r in records):
        raise ParameterError("records must be a scan's Records (imgmtf.scan_scene)")
    tasks, scenes = fit_tasks(records, stages, workers=workers, scheduler=scheduler)
    if not tasks:
        return []
    from ..parallel import run_tasks
    return fitted_rows(list(run_tasks(_fit_task, tasks, workers=workers, scheduler=scheduler, progress=progress,
                                      description="fitting targets")), scenes)


def fit_tasks(records: list[Record], stages: str | list[str], *, workers: int = 1,
              scheduler: str | None = None) -> tuple[list[tuple], int]:
    """:func:`fit_targets`'s tasks for :func:`_fit_task`, the scene's first
    (the longest), then each target's, and how many are the scene's (0 or
    1): none for a scene with nothing to fit.  ``records`` are checked.
    Run here (``workers`` 1, no ``scheduler``), a half-edge without its
    measurement is measured once now for its target's fit and the
    scene's; else each task measures its own on its worker."""
    accepted = [r for r in records if r.ok and get_kind(r.target).fits_sensor and r.site.get("scope") == CANDIDATE_SCOPE
                and r.site.get("target_id") is not None and r.site.get("roi_polygon_px")]
    if not accepted or track_of(accepted[0]) is None:
        return [], 0
    targets = sorted({int(r.site["target_id"]) for r in accepted})
    groups = [[r for r in accepted if r.site["target_id"] == target] for target in targets]
    # a half-edge without its measurement is measured again: by its task on workers, else here, once, for
    # its target's fit and the scene's
    here = workers == 1 and scheduler is None
    known = {id(r): _from_scan(r, shipped=not here) for r in accepted}
    if here:
        missing = [r for r in accepted if r.measurement is None]
        known.update(zip(map(id, missing), _measured(missing)))
    # tasks sent to workers carry each measurement once, beside its record (which then travels without
    # its own: a dense chart's 1936 half-edges were 0.2 GB twice, for its scene's task and its targets'),
    # and with only the figures a fit's rows read (its checks and curves were half of its pickle)
    shipped = {id(r): r if here else replace(r, measurement=None, figures=_fit_figures(r)) for r in accepted}

    def task(members: list[Record], site: dict) -> tuple:
        return [shipped[id(r)] for r in members], site, stages, [known[id(r)] for r in members]

    # the scene's fit, the longest, goes first and beside its targets' (on workers, at once): started
    # from its targets' ends it reached the same optimum no sooner (0.39 s against 0.37 on the 4096 px
    # bench scene, 0.16 against 0.17 on the chart), so it need not wait for them
    scene = [task(accepted, {"scope": SCENE_SCOPE})] if len(targets) > 1 else []
    return scene + [task(members, {"scope": TARGET_SCOPE, "target_id": target})
                    for members, target in zip(groups, targets)], len(scene)


def fitted_rows(fitted: list[list[Record]], scenes: int) -> list[Record]:
    """The rows of :func:`fit_tasks`' tasks (each task's, in their order):
    the targets' first, then the scene's."""
    return [row for task_rows in fitted[scenes:] + fitted[:scenes] for row in task_rows]


def track_of(record: Record) -> float | None:
    """The track azimuth (deg clockwise from up) a scan record was measured with."""
    track = record.params.get("track_azimuth_deg")
    return None if track is None else float(track)


def roi_mask(shape: tuple[int, int], origin: tuple[int, int], polygon: ArrayLike) -> np.ndarray:
    """Pixels of a window (``shape``, its top-left pixel at ``origin`` x, y
    in the scene) whose centres lie inside a convex ``polygon`` (corners x,
    y in scene pixels, in either order round it).

    Examples
    --------
    >>> roi_mask((3, 4), (10, 20), [[10, 20], [12, 20], [12, 22], [10, 22]]).sum()
    np.int64(9)
    """
    y, x = np.mgrid[0:shape[0], 0:shape[1]].astype(float)
    x += origin[0]
    y += origin[1]
    p = np.asarray(polygon, float)
    q = np.roll(p, -1, axis=0)
    orientation = math.copysign(1.0, float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1])))
    inside = np.ones(shape, bool)
    for (x0, y0), (x1, y1) in zip(p, q):
        inside &= orientation * ((x1 - x0) * (y - y0) - (y1 - y0) * (x - x0)) >= -1e-6
    return inside


def _fit_figures(record: Record) -> dict:
    """The figures of a half-edge's record that its fit's rows read
    (:func:`_direction_row`)."""
    return {k: record.figures[k] for k in FIT_FIGURES if k in record.figures}


def _from_scan(record: Record, shipped: bool = False) -> Any:
    """The scan's own measurement of a half-edge, its normal turned into
    the sensor's frame; None when the record has none.  ``shipped`` (to a
    worker): without its MTF function (more than half of a pickled
    measurement: the transform it interpolates) or its checks (half of
    what remains, pickled in band), which the fit does not use."""
    if record.measurement is None:
        return None
    result = record.measurement
    dropped = {"mtf_function": None, "checks": ()} if shipped else {}
    return replace(result, normal_angle_deg=_turned(result.normal_angle_deg, track_of(record) or 0.0), **dropped)


def _measured(records: list[Record]) -> list[Any]:
    """Each accepted half-edge measured again on its masked ROI (no
    intervals: the fit needs its samples and geometry), its normal turned
    into the sensor's frame; why not (a message) where that fails."""
    from ..estimate.edge import measure_edge
    from ..inputs import saturation_levels
    from ..io import read_raster
    out: list[Any] = []
    for record in records:
        x, y, w, h = (int(v) for v in record.site["roi"])
        try:
            raster = read_raster(record.path, record.params.get("band"), window=(x, y, w, h))
            mask = roi_mask(raster.data.shape, raster.origin, record.site["roi_polygon_px"])
            given = record.params.get("saturation")
            saturation = (float(given[0]), float(given[1])) if given else saturation_levels(raster.dtype)
            result = measure_edge(raster.data, mask=mask, method=record.method, gsd_m=raster.gsd_m,
                                  saturation=saturation, dtype=raster.dtype, intervals=False)
        except ImgmtfError as exc:
            out.append(" ".join(str(exc).split()))
            continue
        out.append(replace(result, normal_angle_deg=_turned(result.normal_angle_deg, track_of(record) or 0.0)))
    return out


def _turned(normal_deg: float, track_deg: float) -> float:
    """A normal (deg from the image's x axis) in the sensor's frame (from
    the across-track axis), in (-90, 90]."""
    angle = (normal_deg - track_deg) % 180.0
    return angle - 180.0 if angle > 90.0 else angle


def _fit_task(task) -> list[Record]:
    """One fit's rows: ``task`` is (its half-edges' records, its site, the
    stages, each half-edge's measurement, or None to measure it again
    here)."""
    records, site, stages, measured = task
    missing = [r for r, m in zip(records, measured) if m is None]
    again = iter(_measured(missing))
    measured = [next(again) if m is None else m for m in measured]
    return _fit_rows(list(zip(records, measured)), site, stages)


def _fit_rows(members: list[tuple[Record, Any]], site: dict, stages) -> list[Record]:
    from ..estimate.fit import fit_edges
    records = [r for r, _ in members]
    first = records[0]
    edges = [e for _, e in members if not isinstance(e, str)]
    used = [r for r, e in members if not isinstance(e, str)]
    where = _where(records, site)
    try:
        if not edges:
            raise ImgmtfError(f"no half-edge could be measured again: {members[0][1]}", reason="unsuitable")
        fit = fit_edges(edges, stages=stages, confidence=_confidence(first))
    except ImgmtfError as exc:
        what = f"target {site['target_id']}" if site["scope"] == TARGET_SCOPE else "the scene"
        return [Record(first.path, first.band, first.target, first.method, "rejected", exc.reason,
                       f"{first.path}: the sensor model could not be fitted to {what}: {' '.join(str(exc).split())}",
                       figures={"summary": "fit"}, site=where, params=_params(first, stages),
                       run_utc=first.run_utc)]
    lost = [f"half-edge {r.site.get('id')} could not be measured again for the fit: {e}"
            for r, e in members if isinstance(e, str)]
    # an axis no edge lies nearer to is the model's extrapolation (tied or held parameters): no row
    return [_direction_row(fit, direction, used, where, stages, lost) for direction in ("across", "along")
            if fit.directions[direction]["constrained"]]


def _direction_row(fit, direction: str, records: list[Record], site: dict, stages, lost: list[str]) -> Record:
    from ..estimate.spectrum import relative_edge_response
    from ..sensor.model import direction_angle
    first = records[0]
    sensor = fit.sensor
    gsd = sensor.gsd_m
    angle = direction_angle(direction)
    figures_of = fit.directions[direction]
    grid = np.arange(-8.0, 8.0, 1.0 / 64.0)
    esf = sensor.line_response(angle, reach_px=8.0).esf(grid)
    fwhm_px = sensor.fwhm_m(direction) / gsd
    track = track_of(first) or 0.0
    warnings = [*_warnings(fit, site, [r.site.get("id") for r in records]), *lost]
    figures: dict[str, Any] = {
        "summary": "fit", "direction": _DIRECTIONS[direction],
        "normal_angle_deg": round(_turned(angle + track, 0.0), 3),
        "n_edges": len(records), "edge_ids": [r.site.get("id") for r in records],
        "mtf_nyquist": finite(figures_of["mtf_nyquist"]),
        "mtf_nyquist_ci": [finite(v) for v in figures_of["mtf_nyquist_ci"]],
        "mtf50_cy_px": finite(figures_of["mtf50_cy_px"]),
        "mtf50_ci_cy_px": [finite(v) for v in figures_of["mtf50_cy_px_ci"]],
        "fwhm_px": finite(fwhm_px), "rer": finite(relative_edge_response(grid, esf, _half_point(grid, esf))),
        "stages": [s.name for s in sensor.stages],
        "model_choice": fit.choice.reason if fit.choice is not None else None,
        "parameters": {p.key: finite(p.value) for p in fit.parameters if p.status == "fitted"},
        "reduced_chi_square": finite(fit.reduced_chi_square), "misfit": bool(fit.misfit),
        "misfit_p": finite(min((e.misfit_p for e in fit.edges if e.misfit_tested), default=math.nan)),
        "rows_used": int(sum(r.figures.get("rows_used") or 0 for r in records)),
        "snr_min": finite(min((r.figures.get("snr") or math.inf) for r in records)),
        "gsd_m": first.figures.get("gsd_m"), "warnings": warnings,
    }
    if figures["gsd_m"]:
        figures["mtf50_cy_m"] = finite((figures["mtf50_cy_px"] or math.nan) / figures["gsd_m"])
        figures["fwhm_m"] = finite(fwhm_px * figures["gsd_m"])
    frequencies = first.figures.get("frequencies_cy_px")
    if frequencies:
        # the model's curve alone (its band, not reported, would cost a transfer per parameter)
        curve = np.abs(sensor.normal_transfer(np.asarray(frequencies, float), angle, gsd))
        figures.update(frequencies_cy_px=list(frequencies), mtf=finite_values(curve))
    return Record(first.path, first.band, first.target, first.method, "fitted", figures=figures, site=site,
                  params=_params(first, stages), run_utc=first.run_utc)


def _warnings(fit, site: dict, ids: list):
    """The fit's own warnings, the misfit said first and for the target;
    an edge named by the scan's id (the fit numbers its inputs 1, 2...)."""
    what = f"target {site['target_id']}" if site["scope"] == TARGET_SCOPE else "the scene"
    if fit.misfit:
        yield (f"the sensor model ({', '.join(s.name for s in fit.sensor.stages)}) does not fit {what}'s "
               "half-edges: its across/along-track figures may be biased")
    for warning in fit.warnings:
        if warning.startswith("no GSD in the inputs") or "MTF is an extrapolation" in warning:
            continue            # the scan's rows say so already (lengths here are px); no row extrapolates
        for k, edge_id in enumerate(ids, 1):
            if warning.startswith(f"edge {k}: "):
                warning = f"half-edge {edge_id}: " + warning.removeprefix(f"edge {k}: ")
        yield warning


def _half_point(grid: np.ndarray, esf: np.ndarray) -> float:
    """Where a rising normalised ESF crosses 0.5."""
    return float(np.interp(0.5, esf, grid))


def _confidence(record: Record) -> float:
    return float((record.params.get("intervals") or {}).get("confidence") or 0.95)


def _params(record: Record, stages) -> dict:
    names = stages if isinstance(stages, str) else ",".join(stages)
    return {"intervals": record.params.get("intervals"), "track_azimuth_deg": record.params.get("track_azimuth_deg"),
            "scan": record.params.get("scan"), "fit": {"stages": names}}


def _where(records: list[Record], site: dict) -> dict:
    """A target's site: its centre, the mean of its half-edges' ends."""
    where = dict(site)
    if site["scope"] == TARGET_SCOPE:
        ends = np.array([[r.site[k] for k in ("x0_px", "y0_px", "x1_px", "y1_px")] for r in records]).reshape(-1, 2)
        where.update(x_px=round(float(ends[:, 0].mean()), 2), y_px=round(float(ends[:, 1].mean()), 2))
    return where
