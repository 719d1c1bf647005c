"""A sensor fit (:func:`imgmtf.fit_sensor`) as the summary rows a campaign
store keeps: the model's MTF across and along track."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..records import SCENE_SCOPE, Record, utc_now

if TYPE_CHECKING:
    from ..estimate.fit import SensorFit

_DIRECTIONS = {"across": ("across-track", 0.0), "along": ("along-track", 90.0)}


def fit_summaries(fit: SensorFit, path: str, band: int | str | None = None, *, plot: str | None = None,
                  run_utc: str | None = None) -> list[Record]:
    """The across- and along-track rows of a sensor fit of ``path``'s edges
    (``summary`` "fit", ``scope`` "scene", ``status`` "fitted"), one per
    direction some edge constrains: the model's MTF at Nyquist and MTF50
    (cy/px) with their intervals, the number of edges on that axis and
    whether the model misfits, and the model's FWHM (px).  A direction no edge constrains is left out:
    its value is the other axis's, tied, not a measurement.

    Examples
    --------
    >>> import imgmtf
    >>> fit = imgmtf.fit_sensor([imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60).image])
    >>> [(r.figures["direction"], round(r.figures["mtf_nyquist"], 3)) for r in fit_summaries(fit, "chip.tif")]
    [('across-track', 0.266)]
    """
    rows = []
    for axis, (direction, normal) in _DIRECTIONS.items():
        figures = fit.directions[axis]
        if not figures.get("constrained"):
            continue
        edges = [e for e in fit.edges if e.constrains == axis]
        rows.append(Record(
            str(path), band, "edge", "", "fitted",
            figures={"summary": "fit", "direction": direction, "normal_angle_deg": normal,
                     "mtf_nyquist": figures["mtf_nyquist"], "mtf_nyquist_ci": list(figures["mtf_nyquist_ci"]),
                     "mtf50_cy_px": figures.get("mtf50_cy_px"), "mtf50_ci_cy_px": list(figures.get("mtf50_cy_px_ci")
                                                                                        or (None, None)),
                     "fwhm_px": fit.sensor.fwhm_m(axis) / fit.sensor.gsd_m,
                     "n_edges": len(edges), "constrained": True, "misfit": fit.misfit,
                     "gsd_m": edges[0].gsd_m if edges else None, "warnings": list(fit.warnings)},
            site={"scope": SCENE_SCOPE}, plot=plot,
            params={"stages": [s.name for s in fit.sensor.stages], "confidence": fit.confidence},
            run_utc=run_utc or utc_now()))
    return rows
