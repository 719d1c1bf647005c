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
"""
from __future__ import annotations

from collections.abc import Iterable, Mapping

from ..estimate.geometry import AXIS_DIRECTIONS


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
    return out
