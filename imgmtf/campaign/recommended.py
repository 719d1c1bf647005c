"""Which of a campaign store's rows to quote: per acquisition, place
(scene or target) and direction, the recommended row, and whose sensor
each row measures.

A row written by an imgmtf that names the recommended row per direction
(``recommended``, ``recommended_because`` in the targets layer) keeps its
mark; a misfit row is never recommended.  Rows without the mark (a store
older than schema 2, a ``fit`` or ``measure`` run) are marked here the way
those imgmtf versions meant them to be read: the fit when the sensor
model fits, or else the model-free rows (combined, sections, a measured
chip).  A direction whose only rows misfit has no recommended row.

A point array measures across and along track directly, with no
separability assumption (``method`` "points", :mod:`imgmtf.scene.points`);
where one was scanned in the same image (the same sensor, band name and
acquisition time) as edges, it settles their scene-wide across/along
choice (:func:`settle_with_points`): the edges' recommended row stays when
it agrees with the array at Nyquist (their intervals meet), else the first
that agrees of the model's fit, the sections under each assumption and
the combined rows takes its place, and the reasons say so; when none
agrees, the row stays and its reason names the disagreement.
"""
from __future__ import annotations

from collections.abc import Iterable, Mapping

from ..estimate.geometry import AXIS_DIRECTIONS

POINTS = "points"
#: the order in which edges' rows are offered to a point array's verdict
_EDGE_PREFERENCE = {"fit": 0, "sections": 1, "combined": 2}


def sensor_of(row: Mapping) -> str:
    """The sensor a row measures, as the campaign's trends group it: the
    platform named, else ``unnamed: `` and what identifies the file's
    sensor (:func:`imgmtf.campaign.acquisitions.sensor_key`), else (a
    store older than schema 2) the acquisition alone: two sensors are
    never taken for one.

    Examples
    --------
    >>> sensor_of({"platform": "Landsat 9"}), sensor_of({"sensor_key": "101 x 101 px uint16"})
    ('Landsat 9', 'unnamed: 101 x 101 px uint16')
    >>> sensor_of({"acquisition_id": "3f2a9c01d4e5b6a7"})
    'unnamed: acquisition 3f2a9c01 alone'
    """
    if row.get("platform"):
        return str(row["platform"])
    if row.get("sensor_key"):
        return f"unnamed: {row['sensor_key']}"
    return f"unnamed: acquisition {str(row.get('acquisition_id'))[:8]} alone"


def _place(row: Mapping) -> tuple:
    """Acquisition, scope, target and direction (an oblique one by its normal, to a degree)."""
    direction = row.get("direction")
    normal = row.get("normal_angle_deg")
    if direction not in AXIS_DIRECTIONS and normal is not None:
        direction = f"{direction} {round(float(normal)) % 180}"
    return row.get("acquisition_id"), row.get("scope"), row.get("target_id"), direction


def mark_recommended(rows: Iterable[Mapping]) -> list[dict]:
    """``rows`` (of a store's targets layer, or :func:`campaign_rows`) as
    new dicts with ``recommended`` (bool), ``recommended_because`` (why, or
    why not), ``misfit`` (bool) and ``sensor`` (:func:`sensor_of`).

    Examples
    --------
    >>> rows = [{"acquisition_id": "a", "direction": "across-track", "method": "fit", "misfit": 1},
    ...         {"acquisition_id": "a", "direction": "across-track", "method": "combined"}]
    >>> [(r["method"], r["recommended"]) for r in mark_recommended(rows)]
    [('fit', False), ('combined', True)]
    """
    out = [{**row, "misfit": bool(row.get("misfit")), "sensor": sensor_of(row)} for row in rows]
    places: dict[tuple, list[dict]] = {}
    for row in out:
        places.setdefault(_place(row), []).append(row)
    for members in places.values():
        if any(r.get("recommended") is not None for r in members):
            for r in members:
                r["recommended"] = bool(r.get("recommended")) and not r["misfit"]
                if r["misfit"]:
                    r["recommended_because"] = "misfit: the sensor model does not fit these edges"
            continue
        fits = [r for r in members if r.get("method") == "fit" and not r["misfit"]]
        free = [r for r in members if r.get("method") != "fit" and not r["misfit"]]
        chosen = fits or free
        for r in members:
            r["recommended"] = any(r is c for c in chosen)
            if r["misfit"]:
                r["recommended_because"] = "misfit: the sensor model does not fit these edges"
            elif r["recommended"]:
                r["recommended_because"] = ("the sensor model fits its edges" if fits
                                            else "model-free: no fit of this direction fits")
            else:
                r["recommended_because"] = "the fit, which fits, is recommended"
    return settle_with_points(out)


def _image(row: Mapping) -> tuple | None:
    """What one image is known by across acquisitions (an edge scan and a
    point scan of it): its sensor, band name and time; None without a time."""
    if not row.get("acquired_utc"):
        return None
    return sensor_of(row), row.get("band_name"), row["acquired_utc"]


def settle_with_points(rows: list[dict]) -> list[dict]:
    """``rows`` (marked by :func:`mark_recommended`) with each image's
    scene-wide across/along choice among edges' rows settled by a point
    array of the same image (see the module); changed in place, returned.

    Parameters
    ----------
    rows : list of dict
        Marked rows (``recommended``, ``recommended_because``, ``misfit``,
        ``sensor``).

    Returns
    -------
    list of dict
        The same rows.

    Examples
    --------
    >>> image = {"scope": "scene", "direction": "across-track", "acquired_utc": "2024-01-01", "platform": "Sim"}
    >>> rows = [{**image, "acquisition_id": "e", "method": "sections", "assumption": "separable",
    ...          "mtf_nyquist": 0.20, "mtf_nyquist_ci_low": 0.19, "mtf_nyquist_ci_high": 0.21, "recommended": 1},
    ...         {**image, "acquisition_id": "e", "method": "sections", "assumption": "elliptical",
    ...          "mtf_nyquist": 0.23, "mtf_nyquist_ci_low": 0.22, "mtf_nyquist_ci_high": 0.24, "recommended": 0},
    ...         {**image, "acquisition_id": "p", "method": "points",
    ...          "mtf_nyquist": 0.234, "mtf_nyquist_ci_low": 0.225, "mtf_nyquist_ci_high": 0.243}]
    >>> [(r["assumption"], r["recommended"]) for r in mark_recommended(rows)[:2]]
    [('separable', False), ('elliptical', True)]
    """
    places: dict[tuple, list[dict]] = {}
    for row in rows:
        image = _image(row)
        if image is not None and row.get("scope") == "scene" and row.get("direction") in AXIS_DIRECTIONS \
                and row.get("mtf_nyquist") is not None:
            places.setdefault((image, row["direction"]), []).append(row)
    for members in places.values():
        points = [r for r in members if r.get("method") == POINTS]
        if not points:
            continue
        reference = min(points, key=_width)
        for acquisition in dict.fromkeys(r.get("acquisition_id") for r in members if r.get("method") != POINTS):
            own = [r for r in members if r.get("acquisition_id") == acquisition and r.get("method") != POINTS
                   and not r["misfit"]]
            if own:
                _settle(own, reference)
    return rows


def _settle(own: list[dict], reference: Mapping) -> None:
    """One acquisition's edge rows of one direction judged by a point array's row."""
    seen = f"the point array's {_figure(reference)}"
    current = [r for r in own if r.get("recommended")]
    order = current + sorted((r for r in own if not r.get("recommended")),
                             key=lambda r: _EDGE_PREFERENCE.get(str(r.get("method")), 3))
    agreeing = [r for r in order if _agrees(r, reference)]
    if current and agreeing and agreeing[0] is current[0]:
        current[0]["recommended_because"] = f"{current[0].get('recommended_because')}; {seen} agrees"
        return
    if not agreeing:
        for r in current:
            r["recommended_because"] = (f"{r.get('recommended_because')}; {seen} disagrees at Nyquist "
                                        f"({_figure(r)}): no row of the edges agrees with it")
        return
    pick = agreeing[0]
    for r in own:
        r["recommended"] = r is pick
        if r is pick:
            r["recommended_because"] = (f"settled by a point array of the image: {seen} agrees with {_label(r)}"
                                        + (f", not with {_label(current[0])}" if current else ""))
        elif r in current:
            r["recommended_because"] = f"{seen} disagrees with it at Nyquist ({_figure(r)})"


def _width(row: Mapping) -> float:
    low, high = row.get("mtf_nyquist_ci_low"), row.get("mtf_nyquist_ci_high")
    return float("inf") if low is None or high is None else float(high) - float(low)


def _agrees(row: Mapping, reference: Mapping) -> bool:
    """Whether a row's MTF at Nyquist meets the reference's within their
    intervals (a row without one: its value within the reference's)."""
    low, high = reference.get("mtf_nyquist_ci_low"), reference.get("mtf_nyquist_ci_high")
    if low is None or high is None:
        return False
    own_low, own_high = row.get("mtf_nyquist_ci_low"), row.get("mtf_nyquist_ci_high")
    if own_low is None or own_high is None:
        own_low = own_high = row["mtf_nyquist"]
    return float(own_low) <= float(high) and float(low) <= float(own_high)


def _figure(row: Mapping) -> str:
    low, high = row.get("mtf_nyquist_ci_low"), row.get("mtf_nyquist_ci_high")
    interval = f" [{low:.3f}, {high:.3f}]" if low is not None and high is not None else ""
    return f"MTF at Nyquist {row['mtf_nyquist']:.3f}{interval}"


def _label(row: Mapping) -> str:
    method = row.get("method")
    return f"the {row.get('assumption')} sections" if method == "sections" and row.get("assumption") else \
        f"the {method} row"
