"""Across- and along-track MTF of a target (and of the scene) without a
model: the 2-D MTF's sections from its combined directions, and which of a
scan's across/along rows to quote.

:mod:`.combine` gives one row per direction family, along the measured
normals (16.8 and -73.2 deg on Baotou's checkerboard).  Here those rows'
MTF curves are inverted for the across-track and along-track sections
(:func:`imgmtf.estimate.mtf2d.mtf2d_from_sections`) under each named
assumption: ``separable`` and ``elliptical``, and with two orientations
only the ``bracket`` spanning both; a third orientation chooses.  Each
family's MTF is drawn within its interval at Nyquist (a standard deviation
growing with frequency) for the sections' intervals.

:func:`recommend` then marks, per scope, target and direction, the one
across/along row to quote: the sensor model's fit when it fits and agrees
with the sections within their intervals, else the sections' chosen
assumption; a misfit fit is never recommended.  Where a point array
measured the direction (``summary`` "points", :mod:`.points`), it is the
reference instead of the sections: it needs no assumption.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from statistics import NormalDist
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..estimate.results import finite
from ..records import TARGET_SCOPE, Record
from ..safe_json import finite_values

ACROSS, ALONG = "across-track", "along-track"
SECTIONS = "sections"
#: a point array's rows (:mod:`.points`): across and along measured directly, no assumption to choose
POINTS = "points"
#: draws of the families' curves for the sections' intervals
DRAWS = 100
#: targets per worker before the sections take the workers (a target's sections take 20-60 ms; a pool's
#: start and the records' travel cost a few hundred ms)
AUTO_TARGETS_PER_WORKER = 16
#: targets per task sent to a worker (fewer, larger tasks: less pickling and waiting per target)
TARGETS_PER_TASK = 8


def section_rows(summaries: Sequence[Record], *, workers: int | None = 1, scheduler: str | None = None,
                 progress: bool | None = False) -> list[Record]:
    """The across- and along-track rows of every target and of the scene
    whose combined rows (``summary`` "combined") span two orientations at
    least 30 deg apart.

    Parameters
    ----------
    summaries : list of Record
        A scan's summaries (:func:`imgmtf.scene.combine.summarise_scan`).
    workers : int or None, optional
        Local worker processes for the targets' sections (default 1: none,
        the work runs here); None chooses them, one per
        ``AUTO_TARGETS_PER_WORKER`` targets up to the available cores.  Fewer
        are used when the targets are too few to pay for them; the rows are
        the same whatever the workers.
    scheduler : str, optional
        A Dask distributed scheduler's address, or ``"local"``
        (:func:`imgmtf.parallel.run_tasks`), for the targets' sections when
        they take more than one worker.
    progress : bool, optional
        Show a progress bar on stderr (default False; None: when stderr is
        a terminal).

    Returns
    -------
    list of Record
        Per target (then the scene): for each direction a row per
        assumption (``figures["assumption"]`` "separable", "elliptical",
        and "bracket" when two orientations cannot tell them apart), with
        ``summary`` "sections", ``status`` "combined", the chosen one named
        in ``chosen_assumption`` and why in ``assumption_because``.  Empty
        without a known track direction (a map-projected scene).

    Raises
    ------
    ParameterError
        ``summaries`` is not a list of Records, or ``workers`` is not an
        integer from 1 to :data:`imgmtf.parallel.MAX_WORKERS`.

    Examples
    --------
    >>> from imgmtf.scene.combine import summarise_scan                    # doctest: +SKIP
    >>> rows = section_rows(summarise_scan(scan_scene("baotou.tif")))      # doctest: +SKIP
    >>> [(r.figures["assumption"], r.figures["mtf_nyquist"]) for r in rows][:2]  # doctest: +SKIP
    [('separable', 0.1811), ('separable', 0.1615)]
    """
    ordered = section_groups(summaries)
    chosen = sections_workers(len(ordered), workers)
    if chosen == 1:
        return _task_rows(ordered)
    from ..parallel import run_tasks
    return [row for rows in run_tasks(_task_rows, section_tasks(ordered), workers=chosen, scheduler=scheduler,
                                      progress=progress, description="2-D sections") for row in rows]


def section_groups(summaries: Sequence[Record]) -> list[list[Record]]:
    """The combined rows of each target, then of the scene, that
    :func:`section_rows` inverts (those with an MTF and a track azimuth).

    Raises
    ------
    ParameterError
        ``summaries`` is not a list of Records.
    """
    if any(not isinstance(r, Record) for r in summaries):
        raise ParameterError("summaries must be a scan's summary Records (imgmtf.summarise_scan)")
    combined = [r for r in summaries if r.ok and r.figures.get("summary") == "combined" and r.figures.get("mtf")
                and r.params.get("track_azimuth_deg") is not None]
    groups: dict[tuple, list[Record]] = {}
    for r in combined:
        groups.setdefault((r.site.get("scope"), r.site.get("target_id")), []).append(r)
    return [group for _, group in sorted(groups.items(),
                                         key=lambda item: (item[0][0] != TARGET_SCOPE, item[0][1] or 0))]


def section_tasks(groups: list[list[Record]]) -> list[list[list[Record]]]:
    """:func:`section_groups`' groups as workers' tasks for
    :func:`_task_rows`, ``TARGETS_PER_TASK`` each: their rows, joined in
    order, are :func:`section_rows`' (a target's the same in any task)."""
    return [groups[k: k + TARGETS_PER_TASK] for k in range(0, len(groups), TARGETS_PER_TASK)]


def sections_workers(targets: int, workers: int | None) -> int:
    """The workers for the sections of ``targets`` targets: ``workers``
    (None: the available cores), but no more than give each worker
    ``AUTO_TARGETS_PER_WORKER`` targets, and at least 1.

    Raises
    ------
    ParameterError
        ``workers`` is neither None nor an integer from 1 to
        :data:`imgmtf.parallel.MAX_WORKERS`.

    Examples
    --------
    >>> sections_workers(484, 2), sections_workers(5, 2), sections_workers(40, 1)
    (2, 1, 1)
    """
    from ..parallel import auto_workers, check_workers
    if workers is not None:
        check_workers(workers)
    return auto_workers(targets, AUTO_TARGETS_PER_WORKER, cores=workers)


def _task_rows(groups: list[list[Record]]) -> list[Record]:
    """The rows of a few targets (a worker's task) or of all of them, in
    their order: their sections inverted together
    (:func:`imgmtf.estimate.mtf2d.mtf2d_from_sections_many`), a call per
    confidence level."""
    from ..estimate.mtf2d import mtf2d_from_sections_many
    inputs = [_group_inputs(group) for group in groups]
    results: list = [None] * len(groups)
    levels: dict[float, list[int]] = {}
    for k, (*_, confidence) in enumerate(inputs):
        levels.setdefault(confidence, []).append(k)
    for confidence, members in levels.items():
        found = mtf2d_from_sections_many([inputs[k][1] for k in members], draws=DRAWS, confidence=confidence)
        for k, result in zip(members, found):
            results[k] = result
    return [row for (curves, _, track, _), result in zip(inputs, results) for row in _group_rows(curves, result, track)]


def _group_inputs(group: list[Record]) -> tuple[list[Record], tuple, float, float]:
    """A target's combined rows that share the first's frequencies, the
    sections to invert (normals in the sensor's frame, frequencies, MTFs,
    standard deviations), the track azimuth and the intervals' confidence."""
    first = group[0]
    frequencies = first.figures.get("frequencies_cy_px") or []
    curves = [r for r in group if len(r.figures.get("frequencies_cy_px") or []) == len(frequencies)]
    track = float(first.params["track_azimuth_deg"])
    normals = [sensor_frame(r.figures["normal_angle_deg"], track) for r in curves]
    mtfs = np.array([[math.nan if v is None else v for v in r.figures["mtf"]] for r in curves], float)
    sd = _sd(curves, np.asarray(frequencies, float))
    confidence = float((first.params.get("intervals") or {}).get("confidence") or 0.95)
    return curves, (normals, frequencies, mtfs, sd), track, confidence


def _group_rows(curves: list[Record], result, track: float) -> list[Record]:
    """A target's rows from its sections' ``result`` (none when they were
    refused: one orientation, or two too close, nothing to invert)."""
    from ..estimate.mtf2d import BRACKET
    if isinstance(result, ParameterError):
        return []
    shown = ("separable", "elliptical", *((BRACKET,) if result.assumption == BRACKET else ()))
    shared = _shared_figures(curves)
    return [_row(curves, result, assumption, k, track, shared) for assumption in shown for k in (0, 1)]


def _shared_figures(records: list[Record]) -> dict[str, Any]:
    """What every row of a target takes from its combined rows (the same
    for each assumption and axis: made once, not by each of its 4-6
    rows)."""
    snrs = [float(r.figures["snr_min"]) for r in records if r.figures.get("snr_min") is not None]
    return {"normals_deg": [r.figures["normal_angle_deg"] for r in records],   # the image's, as the combined rows'
            "n_edges": int(sum(r.figures.get("n_edges") or 0 for r in records)),
            "edge_ids": [i for r in records for i in (r.figures.get("edge_ids") or [])],
            "rows_used": int(sum(r.figures.get("rows_used") or 0 for r in records)),
            "snr_min": finite(min(snrs, default=math.nan))}


def sensor_frame(normal_deg: float, track_deg: float) -> float:
    """A normal (deg from the image's x axis) from the across-track axis,
    in (-90, 90] (the track azimuth is clockwise from up; 0: rows along
    track, across is x).

    Examples
    --------
    >>> sensor_frame(16.8, 0.0), sensor_frame(-73.2, 90.0)
    (16.8, 16.8)
    """
    angle = (normal_deg - track_deg) % 180.0
    return round(angle - 180.0 if angle > 90.0 else angle, 9)


def _sd(records: list[Record], frequencies: np.ndarray) -> np.ndarray | None:
    """Each family's standard deviation per frequency, from its interval at
    Nyquist (None when a family has none: no intervals)."""
    from ..estimate.mtf2d import sd_from_nyquist
    sds = []
    for r in records:
        low, high = r.figures.get("mtf_nyquist_ci") or (None, None)
        confidence = float((r.params.get("intervals") or {}).get("confidence") or 0.95)
        if low is None or high is None:
            return None
        sds.append((high - low) / 2.0 / NormalDist().inv_cdf(0.5 + confidence / 2.0))
    return sd_from_nyquist(sds, frequencies)


def _row(records: list[Record], result, assumption: str, axis: int, track: float, shared: dict[str, Any]) -> Record:
    first = records[0]
    section = result.alternatives[assumption][axis]
    gsd = first.figures.get("gsd_m")
    normal = sensor_frame(track - 90.0 * axis, 0.0)       # across lies at the azimuth, along 90 deg before
    figures: dict[str, Any] = {
        "summary": SECTIONS, "direction": section.direction, "assumption": assumption,
        "chosen_assumption": result.assumption, "assumption_because": result.because,
        "assumption_tests": {k: finite(v) for k, v in result.tests.items()},
        "aspect": finite(result.aspect) if assumption == "elliptical" else None,
        "normal_angle_deg": round(normal, 3),
        "normals_deg": list(shared["normals_deg"]), "n_edges": shared["n_edges"], "edge_ids": list(shared["edge_ids"]),
        "mtf_nyquist": finite(section.mtf_nyquist), "mtf_nyquist_ci": [finite(v) for v in section.mtf_nyquist_ci],
        "mtf50_cy_px": finite(section.mtf50_cy_px), "mtf50_ci_cy_px": [finite(v) for v in section.mtf50_ci_cy_px],
        "fwhm_px": finite(section.fwhm_px),
        "rows_used": shared["rows_used"], "snr_min": shared["snr_min"], "gsd_m": gsd,
        "frequencies_cy_px": np.asarray(section.frequencies_cy_px, float).tolist(),
        "mtf": finite_values(section.mtf),
        "warnings": [f"across/along from {len(records)} orientations: {result.because}"]
                    if assumption == result.assumption else [],
    }
    if gsd:
        figures["mtf50_cy_m"] = finite((figures["mtf50_cy_px"] or math.nan) / gsd)
        figures["fwhm_m"] = finite((figures["fwhm_px"] or math.nan) * gsd)
    site = {k: v for k, v in first.site.items() if k in ("scope", "target_id", "x_px", "y_px")}
    return Record(first.path, first.band, first.target, first.method, "combined", figures=figures, site=site,
                  params={"intervals": first.params.get("intervals"), "track_azimuth_deg": track,
                          "scan": first.params.get("scan"), SECTIONS: {"draws": DRAWS}},
                  run_utc=first.run_utc)


def recommend(summaries: Sequence[Record]) -> list[Record]:
    """``summaries`` with every across/along row (``summary`` "fit" or
    "sections") marked ``recommended`` True or False and
    ``recommended_because``: per scope, target and direction one row, the
    fit when it fits and its interval at Nyquist meets the chosen
    sections', else the chosen sections row; a misfit fit never (a
    direction whose only rows misfit has none).

    Examples
    --------
    >>> summaries = summarise_scan(records)                                 # doctest: +SKIP
    >>> rows = recommend(summaries + section_rows(summaries) + fit_targets(records))  # doctest: +SKIP
    >>> [(r.figures["summary"], r.figures["recommended"]) for r in rows
    ...  if r.figures.get("direction") == "across-track"]                   # doctest: +SKIP
    [('sections', False), ('sections', False), ('sections', True), ('fit', False)]
    """
    marks: dict[int, tuple[bool, str]] = {}
    groups: dict[tuple, list[int]] = {}
    for k, r in enumerate(summaries):
        if r.ok and r.figures.get("summary") in ("fit", SECTIONS, POINTS) and \
                r.figures.get("direction") in (ACROSS, ALONG):
            groups.setdefault((r.site.get("scope"), r.site.get("target_id"), r.figures["direction"]), []).append(k)
    for members in groups.values():
        marks.update(_marks([summaries[k] for k in members], members))
    out = []
    for k, r in enumerate(summaries):
        if k in marks:
            chosen, because = marks[k]
            r = r.with_(figures={**r.figures, "recommended": chosen, "recommended_because": because})
        out.append(r)
    return out


def _marks(rows: list[Record], indices: list[int]) -> dict[int, tuple[bool, str]]:
    points = [(k, r) for k, r in zip(indices, rows) if r.figures["summary"] == POINTS]
    if points:
        return _point_marks(rows, indices, points[0])
    fits = [(k, r) for k, r in zip(indices, rows) if r.figures["summary"] == "fit"]
    sections = [(k, r) for k, r in zip(indices, rows) if r.figures["summary"] == SECTIONS
                and r.figures.get("assumption") == r.figures.get("chosen_assumption")]
    chosen = sections[0] if sections else None
    marks: dict[int, tuple[bool, str]] = {}
    pick, why = None, ""
    good_fits = [(k, r) for k, r in fits if not r.figures.get("misfit")]
    if good_fits and chosen is not None:
        k, fit = good_fits[0]
        intervals = fit.figures.get("mtf_nyquist_ci"), chosen[1].figures.get("mtf_nyquist_ci")
        if not all(_interval(i) for i in intervals):
            pick, why = k, "the model fits (no intervals to compare it with the sections)"
        elif _overlap(*intervals):
            pick, why = k, "the model fits and agrees with the sections"
        else:
            pick, why = chosen[0], (f"{chosen[1].figures['assumption']} sections: the model fits but disagrees "
                                    "with them at Nyquist")
    elif good_fits:
        pick, why = good_fits[0][0], "the model fits (no sections to compare)"
    elif chosen is not None:
        pick, why = chosen[0], (f"{chosen[1].figures['assumption']} sections: "
                                f"{'the model does not fit' if fits else 'no fit row to compare'}")
    fit_picked = any(k == pick for k, _ in fits)
    for k, r in zip(indices, rows):
        if k == pick:
            marks[k] = (True, why)
        elif r.figures["summary"] == "fit":
            marks[k] = (False, "the model does not fit" if r.figures.get("misfit") else
                        "it disagrees with the sections at Nyquist")
        elif fit_picked:
            marks[k] = (False, "the model fits and agrees with the sections")
        else:
            marks[k] = (False, f"{r.figures['chosen_assumption']} chosen: {r.figures.get('assumption_because')}")
    return marks


def _point_marks(rows: list[Record], indices: list[int], point: tuple[int, Record]) -> dict[int, tuple[bool, str]]:
    """A direction a point array measures: its row, or the model's fit when
    it fits and agrees with the array within their intervals; the sections
    of edges never (the array needs no assumption)."""
    k_point, reference = point
    good_fits = [(k, r) for k, r in zip(indices, rows) if r.figures["summary"] == "fit" and not r.figures.get("misfit")
                 and _interval(r.figures.get("mtf_nyquist_ci")) and _interval(reference.figures.get("mtf_nyquist_ci"))
                 and _overlap(r.figures["mtf_nyquist_ci"], reference.figures["mtf_nyquist_ci"])]
    pick, why = ((good_fits[0][0], "the model fits and agrees with the point array") if good_fits else
                 (k_point, "the point array measures this direction directly (no separability assumption)"))
    marks: dict[int, tuple[bool, str]] = {}
    for k, r in zip(indices, rows):
        if k == pick:
            marks[k] = (True, why)
        elif r.figures["summary"] == "fit":
            marks[k] = (False, "the model does not fit" if r.figures.get("misfit") else
                        "it disagrees with the point array at Nyquist")
        elif r.figures["summary"] == POINTS:
            marks[k] = (False, "the model fits and agrees with it" if good_fits else "another array's row is quoted")
        else:
            marks[k] = (False, "a point array measures this direction directly")
    return marks


def _interval(pair) -> bool:
    """Whether ``pair`` is an interval (low, high), not missing."""
    return bool(pair) and None not in pair


def _overlap(first, second) -> bool:
    """Whether two intervals (low, high) meet."""
    return first[0] <= second[1] and second[0] <= first[1]
