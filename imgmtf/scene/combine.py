"""One result per target and per direction: the accepted half-edges of a
target (and of the whole scene) combined.

Half-edges are grouped into direction families by their normals
(:func:`normal_families`): normals within ``FAMILY_SPREAD_DEG`` of each
other measure the same cut through the MTF; farther apart they are
different directions and are never averaged.  Within a family the MTF at
Nyquist and MTF50 are combined by precision (:func:`combine`): each
half-edge weighs by the inverse variance its confidence interval implies,
the combined interval is the weighted mean's, widened by the Birge ratio
when the half-edges disagree more than their intervals allow.  Without
intervals (``--intervals none``) the mean is unweighted and has none.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._stats import t_quantile
from ..errors import ParameterError
from ..estimate.geometry import direction_label
from ..estimate.results import finite
from ..records import SCENE_SCOPE, TARGET_SCOPE, Record
from ..safe_json import finite_values

FAMILY_SPREAD_DEG = 20.0        # normals of one direction family differ by at most this
FAMILY_GAP_DEG = 10.0           # a gap this wide between sorted normals separates two families


@dataclass(frozen=True)
class Combined:
    """A figure combined over several half-edges: ``value``, its interval
    (``low``, ``high``; NaN without intervals), the Birge ratio
    ``consistency`` (the scatter of the values over what their intervals
    predict; NaN for one value), and the ``weights`` used
    ("inverse-variance" or "equal")."""

    value: float
    low: float
    high: float
    consistency: float
    weights: str


def normal_families(normals_deg: ArrayLike) -> np.ndarray:
    """Direction families of edge normals (deg, any range; 180 deg apart
    is one direction): a label per normal, normals of one family within
    ``FAMILY_SPREAD_DEG`` of each other, families separated by gaps of at
    least ``FAMILY_GAP_DEG`` where the normals allow.

    Examples
    --------
    >>> normal_families([16.8, -73.2, 17.1, 106.9, 45.0]).tolist()
    [0, 1, 0, 1, 2]
    """
    angles = np.mod(np.asarray(normals_deg, float), 180.0)
    n = angles.size
    labels = np.zeros(n, int)
    if n < 2:
        return labels
    order = np.argsort(angles)
    sorted_ = angles[order]
    gaps = np.diff(np.concatenate([sorted_, [sorted_[0] + 180.0]]))
    start = (int(np.argmax(gaps)) + 1) % n          # begin after the widest gap: no family wraps
    ring = np.roll(order, -start)
    unwrapped = np.mod(angles[ring] - angles[ring[0]], 180.0)
    label, first = 0, 0.0
    for k, a in enumerate(unwrapped):
        if k and (a - unwrapped[k - 1] >= FAMILY_GAP_DEG or a - first > FAMILY_SPREAD_DEG):
            label, first = label + 1, a
        labels[ring[k]] = label
    # number families by their first member, as given
    _, first_seen = np.unique(labels, return_index=True)
    renumber = np.argsort(np.argsort(first_seen))
    return renumber[labels]


def combine(values: ArrayLike, intervals: ArrayLike, rows: ArrayLike, confidence: float = 0.95) -> Combined:
    """Combine estimates of one figure weighted by precision.

    Parameters
    ----------
    values : sequence of float
        The estimates (NaN for none).
    intervals : sequence of (float, float)
        Their (low, high) confidence intervals (NaN when none).
    rows : sequence of int
        The rows each estimate used (the degrees of freedom of its
        Student-t interval).
    confidence : float, optional
        The intervals' confidence, and the combined one's (default 0.95).

    Returns
    -------
    Combined
        The inverse-variance weighted mean (each standard deviation is the
        interval's half-width over its Student-t quantile) and its normal
        interval, widened by the Birge ratio sqrt(chi^2 / (n - 1)) when that
        exceeds 1 (the estimates scatter more than their intervals say; the
        Particle Data Group's scale factor).  Without finite intervals, the
        plain mean and no interval.  One estimate keeps its own interval.

    Raises
    ------
    ValueError
        No finite value to combine.

    Examples
    --------
    >>> c = combine([0.26, 0.27], [(0.25, 0.27), (0.25, 0.29)], [40, 40])
    >>> round(c.value, 4), c.weights
    (0.262, 'inverse-variance')
    """
    x = np.asarray(values, float)
    bounds = np.asarray(intervals, float).reshape(-1, 2)
    rows = np.asarray(rows, float)
    finite = np.isfinite(x)
    if not finite.any():
        raise ValueError("no finite value to combine")
    x, bounds, rows = x[finite], bounds[finite], rows[finite]
    if x.size == 1:                     # one estimate: its own interval, as the estimator gave it
        return Combined(float(x[0]), float(bounds[0, 0]), float(bounds[0, 1]), math.nan,
                        "inverse-variance" if np.isfinite(bounds[0]).all() else "equal")
    w = precision_weights(bounds, rows, confidence)
    if w is None:
        return Combined(float(np.mean(x)), math.nan, math.nan, math.nan, "equal")
    mean = float(np.sum(w * x) / np.sum(w))
    sd_mean = 1.0 / math.sqrt(float(np.sum(w)))
    n = x.size
    birge = math.sqrt(float(np.sum(w * (x - mean) ** 2)) / (n - 1)) if n > 1 else math.nan
    half_width = NormalDist().inv_cdf(0.5 + confidence / 2) * sd_mean * max(1.0, birge)
    return Combined(mean, mean - half_width, mean + half_width, birge, "inverse-variance")


def summarise_scan(records: list[Record]) -> list[Record]:
    """Per-target and per-scene summary records of a scan's accepted
    half-edges: for each target (``target_id``) and for the scene, one
    record per direction family, with ``status`` "combined" and ``scope``
    "target" or "scene".

    Each carries ``direction`` (of the family's mean normal, as the
    estimators label one), ``normal_angle_deg`` (the mean normal),
    ``n_edges`` and ``edge_ids`` (the candidates' ids), ``mtf_nyquist`` and
    ``mtf50_cy_px`` with their intervals (``mtf_nyquist_ci``,
    ``mtf50_ci_cy_px``), ``consistency`` (the Birge ratio of MTF at Nyquist)
    and ``weights``; a target's also its centre (``x_px``, ``y_px``, the
    mean of its half-edges' ends).

    Parameters
    ----------
    records : list of Record
        A scan's records (:func:`imgmtf.scene.measure.scan_scene`); only the
        accepted ones that carry an MTF at Nyquist are combined.

    Returns
    -------
    list of Record
        The targets' summaries (by ``target_id``), then the scene's; empty
        when no record was accepted.

    Raises
    ------
    ParameterError
        ``records`` is not a collection of Records.

    Examples
    --------
    >>> from imgmtf.scene.measure import scan_scene                   # doctest: +SKIP
    >>> [(r.site["scope"], r.figures["direction"], r.figures["mtf50_cy_px"])
    ...  for r in summarise_scan(scan_scene("baotou.tif"))]                 # doctest: +SKIP
    [('target', 'oblique', 0.1724), ('target', 'oblique', 0.1740), ('scene', ...), ...]
    """
    try:
        records = list(records)
    except TypeError:
        raise ParameterError(f"records must be a list of a scan's Records, got {records!r}") from None
    strays = [r for r in records if not isinstance(r, Record)]
    if strays:
        raise ParameterError(f"records must be a scan's Records (imgmtf.scan_scene), got {strays[0]!r}")
    accepted = [r for r in records if r.ok and r.figures.get("mtf_nyquist") is not None]
    if not accepted:
        return []
    families = normal_families([r.figures["normal_angle_deg"] for r in accepted])
    out: list[Record] = []
    # each target's half-edges gathered in one pass (a pass per target grew as targets x half-edges: a
    # dense chart's 484 targets took a second)
    by_target: dict[int, list[tuple[Record, int]]] = {}
    for r, f in zip(accepted, families):
        if r.site.get("target_id") is not None:
            by_target.setdefault(int(r.site["target_id"]), []).append((r, f))
    for target in sorted(by_target):
        out += _family_records(by_target[target], {"scope": TARGET_SCOPE, "target_id": target})
    out += _family_records(list(zip(accepted, families)), {"scope": SCENE_SCOPE})
    return out


def _family_records(members: list[tuple[Record, int]], site: dict) -> list[Record]:
    out = []
    for family in sorted({f for _, f in members}):
        group = [r for r, f in members if f == family]
        out.append(_summary(group, site))
    return out


def precision_weights(intervals: ArrayLike, rows: ArrayLike, confidence: float = 0.95) -> np.ndarray | None:
    """Each estimate's weight 1 / sd^2, its standard deviation the
    interval's half-width over its Student-t quantile (``rows`` - 1
    degrees of freedom); None when an interval is missing or empty.

    Examples
    --------
    >>> w = precision_weights([(0.25, 0.27), (0.25, 0.29)], [40, 40])
    >>> round(float(w[0] / w[1]), 3)                 # half the width: four times the weight
    4.0
    """
    bounds = np.asarray(intervals, float).reshape(-1, 2)
    counts = np.asarray(rows, float).tolist()
    # each distinct count's quantile once: a scene's thousands of half-edges share a few hundred (a NaN
    # count is found again as the same object)
    quantiles = {n: t_quantile(0.5 + confidence / 2, max(int(n) - 1, 1) if math.isfinite(n) else 1)
                 for n in set(counts)}
    quantile = np.array([quantiles[n] for n in counts])
    sd = (bounds[:, 1] - bounds[:, 0]) / 2 / quantile
    if not (np.isfinite(sd).all() and (sd > 0).all()):
        return None
    return 1.0 / sd ** 2


def _weighted_average(values, weights) -> np.ndarray:
    """Mean over the first axis of ``values`` (None or NaN where a half-edge
    has none) with ``weights`` (equal when None); NaN where none is finite."""
    x = np.array(values, float)         # None as NaN, without a Python step per value (a curve has 101)
    x = x.reshape(len(x), -1)
    w = np.ones(x.shape[0]) if weights is None else np.asarray(weights, float)
    w = np.where(np.isfinite(x), w[:, None], 0.0)
    total = w.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, np.sum(w * np.nan_to_num(x), axis=0) / total, np.nan)


def _summary(group: list[Record], site: dict) -> Record:
    first = group[0]
    confidence = (first.params.get("intervals") or {}).get("confidence", 0.95)
    rows = [r.figures.get("rows_used") or 0 for r in group]
    intervals = [_pair(r.figures.get("mtf_nyquist_ci")) for r in group]
    nyquist = combine([r.figures["mtf_nyquist"] for r in group], intervals, rows, confidence)
    fifty = [r.figures.get("mtf50_cy_px") for r in group]
    mtf50 = (combine([math.nan if v is None else v for v in fifty],
                     [_pair(r.figures.get("mtf50_ci_cy_px")) for r in group], rows, confidence)
             if any(v is not None for v in fifty) else None)
    normal = _mean_normal([r.figures["normal_angle_deg"] for r in group])
    track = first.params.get("track_azimuth_deg")
    figures: dict[str, Any] = {
        "summary": "combined", "direction": direction_label(normal, track), "normal_angle_deg": round(normal, 3),
        "n_edges": len(group), "edge_ids": [r.site.get("id") for r in group],
        "mtf_nyquist": finite(nyquist.value), "mtf_nyquist_ci": [finite(nyquist.low), finite(nyquist.high)],
        "mtf50_cy_px": finite(mtf50.value) if mtf50 else None,
        "mtf50_ci_cy_px": [finite(mtf50.low), finite(mtf50.high)] if mtf50 else [None, None],
        "consistency": finite(nyquist.consistency), "weights": nyquist.weights,
        "rows_used": int(sum(rows)), "gsd_m": first.figures.get("gsd_m"),
    }
    # FWHM and RER have no interval of their own: averaged with the weights
    # the MTF at Nyquist earned, as the curve is
    weights = precision_weights(intervals, rows, confidence)
    for key in ("fwhm_px", "rer"):
        figures[key] = finite(float(_weighted_average([r.figures.get(key) for r in group], weights)[0]))
    snrs = [r.figures.get("snr") for r in group]
    figures["snr_min"] = finite(min((v for v in snrs if v is not None), default=math.nan))
    if figures["gsd_m"]:
        if mtf50:
            figures["mtf50_cy_m"] = finite(mtf50.value / figures["gsd_m"])
        if figures["fwhm_px"] is not None:
            figures["fwhm_m"] = finite(figures["fwhm_px"] * figures["gsd_m"])
    frequencies = first.figures.get("frequencies_cy_px")
    curves = [r.figures.get("mtf") or [] for r in group]
    if frequencies and all(len(c) == len(frequencies) for c in curves):
        curve = _weighted_average(curves, weights)
        figures.update(frequencies_cy_px=list(frequencies), mtf=finite_values(curve))
    where = dict(site)
    if site["scope"] == TARGET_SCOPE:
        ends = np.array([[r.site[k] for k in ("x0_px", "y0_px", "x1_px", "y1_px")] for r in group]).reshape(-1, 2)
        where.update(x_px=round(float(ends[:, 0].mean()), 2), y_px=round(float(ends[:, 1].mean()), 2))
    return Record(first.path, first.band, first.target, first.method, "combined", figures=figures, site=where,
                  params={"intervals": first.params.get("intervals"), "track_azimuth_deg": track,
                          "scan": first.params.get("scan")}, run_utc=first.run_utc)


def _pair(interval) -> tuple[float, float]:
    low, high = interval or (None, None)
    return (math.nan if low is None else low, math.nan if high is None else high)


def _mean_normal(normals_deg) -> float:
    """Mean of normals (deg) as directions (180 deg apart is one), in (-90, 90]."""
    doubled = np.radians(2.0 * np.asarray(normals_deg, float))
    mean = math.degrees(math.atan2(np.sin(doubled).mean(), np.cos(doubled).mean())) / 2.0
    return 90.0 if mean == -90.0 else mean
