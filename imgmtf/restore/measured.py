"""The system a restoration compensates, read from a scan's rows measured
without a model: its across- and along-track sections (the 2-D MTF under
the assumption the scan chose), as a sensor of one
:class:`imgmtf.sensor.stages.MeasuredMTF` stage.

A scan of a target with two or more directions of edge
(``imgmtf scan SCENE --format json``) gives, per direction, the 2-D MTF's
sections under each assumption and says which the data support
(``chosen_assumption``; :mod:`imgmtf.estimate.mtf2d`).  Where the sensor
model misfits (every real L0R target here) those rows, not the fit, are
the ones to quote, and a restoration designed from them assumes no form
of blur.  The scene's rows are taken when there are several targets."""
from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ..errors import ImgmtfError, ParameterError
from ..estimate.geometry import IMAGE_AXES
from ..sensor.model import Sensor
from ..sensor.stages import MeasuredMTF

#: the image axes' names of the track's directions, as a scan gives them for an image with no
#: track information (horizontal: across its columns, the x axis)
TRACK_OF = {axis: track for track, axis in IMAGE_AXES.items()}
#: the row a direction takes, by preference: the scene's, else a target's
SCOPES = ("scene", "target")


def read_scan_rows(path: str | Path) -> list[dict[str, Any]]:
    """The rows of ``imgmtf scan --format json`` (JSON Lines) in ``path``.

    Raises
    ------
    ImgmtfError
        The file cannot be read or a line is not JSON (named, reason
        ``unreadable``).
    """
    try:
        lines = Path(path).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise ImgmtfError(f"{path}: cannot read the scan's rows: {getattr(exc, 'strerror', None) or exc}",
                          reason="unreadable") from None
    rows = []
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            row = json.loads(line)
        except json.JSONDecodeError:
            raise ImgmtfError(f"{path}: line {number} is not JSON: a scan's rows are JSON Lines",
                              reason="unreadable") from None
        if isinstance(row, dict):
            rows.append(row)
    return rows


def measured_sensor(rows: Sequence[Mapping[str, Any]], source: str = "the rows",
                    gsd_m: float | None = None) -> Sensor:
    """A sensor whose transfer is the 2-D MTF a scan measured without a
    model: the across- and along-track sections rows (``summary``
    "sections") under the assumption the scan chose, the scene's first.
    Separable sections combine as a product, elliptical ones as the pixel
    times their remainder (their aspect); a bracket's (two orientations
    could not choose) as a product of its mid sections, exact on the axes.

    Parameters
    ----------
    rows : sequence of mapping
        A scan's rows (:func:`read_scan_rows`).
    source : str, optional
        What messages call them (the file).
    gsd_m : float, optional
        The pixel, m (default the rows', else 1).

    Returns
    -------
    Sensor
        One :class:`~imgmtf.sensor.stages.MeasuredMTF` stage.

    Raises
    ------
    ImgmtfError
        No sections rows for both directions (reason ``no-target``).

    Examples
    --------
    >>> f = [0.0, 0.5, 1.0]
    >>> rows = [{"summary": "sections", "scope": "scene", "direction": d, "assumption": "separable",
    ...          "chosen_assumption": "separable", "frequencies_cy_px": f, "mtf": m}
    ...         for d, m in (("across-track", [1.0, 0.3, 0.1]), ("along-track", [1.0, 0.2, 0.05]))]
    >>> round(measured_sensor(rows).mtf_nyquist("along"), 4)
    0.2
    """
    sections = [r for r in rows if r.get("summary") == "sections" and r.get("frequencies_cy_px") and r.get("mtf")]
    chosen = None
    for scope in SCOPES:
        mine = [r for r in sections if r.get("scope") == scope and r.get("assumption") == r.get("chosen_assumption")]
        # an image without track information names its axes instead (horizontal: across its columns)
        by_direction = {TRACK_OF.get(str(r.get("direction")), r.get("direction")): r for r in mine}
        if {"across-track", "along-track"} <= set(by_direction):
            chosen = by_direction
            break
    if chosen is None:
        raise ImgmtfError(f"{source}: no across- and along-track (or horizontal and vertical) rows measured "
                          "without a model (summary "
                          "'sections'): a scan of a target with edges in two directions gives them",
                          reason="no-target")
    across, along = chosen["across-track"], chosen["along-track"]
    if list(across["frequencies_cy_px"]) != list(along["frequencies_cy_px"]):
        raise ParameterError(f"{source}: the across- and along-track sections are on different frequencies")
    assumption = across.get("assumption")
    combination = "elliptical" if assumption == "elliptical" else "separable"
    stage = MeasuredMTF(tuple(across["frequencies_cy_px"]), tuple(across["mtf"]), tuple(along["mtf"]),
                        combination, float(across.get("aspect") or 1.0))
    gsd = gsd_m or across.get("gsd_m") or 1.0
    return Sensor(float(gsd), [stage])
