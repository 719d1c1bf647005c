"""Drift: how a figure (MTF at Nyquist, MTF50, FWHM, RER) of one sensor,
band, direction and method changes with time over a campaign.

Rows are grouped by sensor (the platform named, or what identifies an
unnamed one's files: :func:`imgmtf.campaign.recommended.sensor_of`), band,
direction, method and assumption, and whether they are the recommended
rows (:func:`imgmtf.campaign.recommended.mark_recommended`) or misfit:
two sensors, two methods or a quoted and an unquoted series are never
one line.  A group of misfit rows is listed but not trended (its values
may be biased); a group with one acquisition time has no slope.

The drift is the slope of a weighted least-squares line through the
figure against the acquisition time, in the figure's units per year
(365.25 days).  Each point weighs by the inverse variance its interval
implies (half-width over the normal quantile of its confidence); the
slope's interval is Student-t with n - 2 degrees of freedom, its standard
error scaled by the Birge ratio when the points scatter more than their
intervals say (as :func:`imgmtf.scene.combine.combine` does).  Points
without an interval (FWHM, RER, ``--intervals none``) weigh equally and
the scatter alone gives the standard error.  A drift is flagged when the
interval excludes 0.
"""
from __future__ import annotations

import csv
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass
from datetime import UTC, datetime
from statistics import NormalDist

import numpy as np
from numpy.typing import ArrayLike

from ..atomic import atomic_output
from ..errors import FileWriteError, ParameterError
from ..estimate.geometry import AXIS_DIRECTIONS
from ..records import CANDIDATE_SCOPE, SCENE_SCOPE, TARGET_SCOPE

YEAR_S = 365.25 * 86400.0
# figure -> its interval's columns in the targets layer (None: it has none)
FIGURES = {
    "mtf_nyquist": ("mtf_nyquist_ci_low", "mtf_nyquist_ci_high"),
    "mtf50_cy_px": ("mtf50_ci_low_cy_px", "mtf50_ci_high_cy_px"),
    "fwhm_px": None,
    "rer": None,
}
GROUP_KEYS = ("sensor", "band_name", "direction", "method", "assumption", "recommended", "misfit")
TREND_COLUMNS = ("sensor", "platform", "band_name", "direction", "scope", "method", "assumption", "recommended",
                 "misfit",
                 "recommended_because", "figure", "n_acquisitions", "n_points", "first_utc", "last_utc", "latest",
                 "latest_ci_low", "latest_ci_high", "value_at_first", "slope_per_year", "slope_ci_low",
                 "slope_ci_high", "confidence", "weights", "consistency", "drift", "requirement", "meets_requirement",
                 "note")
NOTE_MISFIT = "misfit: not trended (the sensor model does not fit; its values may be biased)"
NOTE_ONE = "one acquisition: no slope"
NOTE_TWO = "two acquisitions: a slope without interval"


@dataclass(frozen=True)
class Line:
    """A straight line fitted to (t, y): ``intercept`` at t = 0, ``slope``
    with its interval (``low``, ``high``; NaN with fewer than 3 points),
    ``consistency`` (the Birge ratio; NaN without intervals or with 2
    points) and the ``weights`` used ("inverse-variance" or "equal")."""

    intercept: float
    slope: float
    low: float
    high: float
    consistency: float
    weights: str


@dataclass(frozen=True)
class Trend:
    """The drift of one figure of one sensor, band, direction, method and
    assumption (the columns of ``trend.csv``): ``scope`` what its points
    summarise (:func:`points_scope`: the scene, its targets, measured
    edges, or a mix across acquisitions); ``recommended`` when its rows
    are the ones to quote in that scope, ``misfit`` when they are misfit fits (no
    slope then); ``latest`` the last acquisition's value with its
    interval; ``drift`` True when the slope's interval excludes 0; the
    slope NaN with one acquisition time (``note`` says why)."""

    sensor: str
    platform: str | None
    band_name: str | None
    direction: str | None
    method: str | None
    assumption: str | None
    recommended: bool
    misfit: bool
    recommended_because: str
    figure: str
    n_acquisitions: int
    n_points: int
    first_utc: str
    last_utc: str
    latest: float
    latest_ci_low: float
    latest_ci_high: float
    value_at_first: float
    slope_per_year: float
    slope_ci_low: float
    slope_ci_high: float
    confidence: float
    weights: str
    consistency: float
    drift: bool
    note: str = ""
    scope: str = ""

    @property
    def has_slope(self) -> bool:
        """A line was fitted (two acquisition times at least, not misfit)."""
        return math.isfinite(self.slope_per_year)

    def value_at(self, years: np.ndarray) -> np.ndarray:
        """The line at ``years`` after the first acquisition."""
        return self.value_at_first + self.slope_per_year * np.asarray(years, float)


def fit_line(t: ArrayLike, y: ArrayLike, sd: ArrayLike | None = None, confidence: float = 0.95) -> Line:
    """Weighted least-squares line through (``t``, ``y``).

    Parameters
    ----------
    t, y : array_like
        Abscissae and values (finite; two different t at least).
    sd : array_like, optional
        Each value's standard deviation (weights 1/sd^2); None or any
        non-finite or zero entry: equal weights.
    confidence : float
        Of the slope's Student-t interval (n - 2 degrees of freedom).

    Returns
    -------
    Line
        With inverse-variance weights the slope's standard error is
        sqrt(max(1, chi^2/(n-2)) / S), S = sum w (t - t_w)^2 (the intervals'
        own, widened by the Birge ratio when the points scatter more);
        with equal weights sqrt(s^2 / S), s^2 the residual variance.

    Raises
    ------
    ParameterError
        Fewer than two points, or all at one t.

    Examples
    --------
    >>> line = fit_line([0, 1, 2, 3], [1.0, 0.9, 0.8, 0.7], sd=[0.01] * 4)
    >>> round(line.slope, 6), round(line.high - line.slope, 6), line.weights
    (-0.1, 0.019242, 'inverse-variance')
    """
    t, y = np.asarray(t, float), np.asarray(y, float)
    if t.size < 2 or np.ptp(t) == 0:
        raise ParameterError("a trend needs two acquisitions at different times at least")
    weighted = sd is not None and bool(np.all(np.isfinite(sd))) and bool(np.all(np.asarray(sd, float) > 0))
    w = 1.0 / np.asarray(sd, float) ** 2 if weighted else np.ones_like(t)
    t_mean = np.sum(w * t) / np.sum(w)
    spread = np.sum(w * (t - t_mean) ** 2)
    slope = float(np.sum(w * (t - t_mean) * y) / spread)
    if abs(slope) * np.ptp(t) <= 1e-12 * np.max(np.abs(y)):
        slope = 0.0             # a constant series: rounding, not a slope
    intercept = float(np.sum(w * y) / np.sum(w) - slope * t_mean)
    dof = t.size - 2
    if dof < 1:
        return Line(intercept, slope, math.nan, math.nan, math.nan, "inverse-variance" if weighted else "equal")
    from .._stats import t_quantile
    chi2 = float(np.sum(w * (y - intercept - slope * t) ** 2))
    scale = max(1.0, chi2 / dof) if weighted else chi2 / dof
    half = t_quantile(0.5 + confidence / 2, dof) * math.sqrt(scale / spread)
    consistency = math.sqrt(chi2 / dof) if weighted else math.nan
    return Line(intercept, slope, slope - half, slope + half, consistency,
                "inverse-variance" if weighted else "equal")


def years_since(times: Sequence[str], origin: str) -> np.ndarray:
    """Times (ISO 8601 UTC; a date is its midnight) as years after ``origin``."""
    start = parse_utc(origin)
    return np.array([(parse_utc(t) - start).total_seconds() / YEAR_S for t in times])


def parse_utc(text: str) -> datetime:
    """An acquisition time of the store (``2021-11-21`` or ``2021-11-21T08:15:02Z``) as an aware datetime."""
    moment = datetime.fromisoformat(text)
    return moment if moment.tzinfo else moment.replace(tzinfo=UTC)


def trend_points(rows: Iterable[Mapping]) -> dict[tuple, list[Mapping]]:
    """The targets layer's rows that make each trend, by :data:`GROUP_KEYS`
    (sensor, band name, direction, method, assumption, recommended,
    misfit; the rows marked by
    :func:`imgmtf.campaign.recommended.mark_recommended`): per acquisition
    its scene-wide rows, or its targets' rows when it has no scene-wide
    one; rows without an acquisition time, and fits of a direction no
    edge constrained, are left out.  Oblique (or unknown) directions are
    told apart by their normals
    (:func:`imgmtf.scene.combine.normal_families`): their label becomes
    ``oblique (normal 17 deg)``."""
    from .recommended import mark_recommended
    usable = [r for r in mark_recommended(rows) if r.get("acquired_utc") and r.get("mtf_nyquist") is not None
              and r.get("constrained") != 0]
    groups: dict[tuple, dict[str, list[Mapping]]] = {}
    for row in _by_normal(usable):
        key = tuple(row.get(k) for k in GROUP_KEYS)
        groups.setdefault(key, {}).setdefault(row["acquisition_id"], []).append(row)
    out = {}
    for key, by_acquisition in groups.items():
        points: list[Mapping] = []
        for members in by_acquisition.values():
            scene = [r for r in members if r.get("scope") == SCENE_SCOPE]
            points += scene or members
        out[key] = sorted(points, key=lambda r: parse_utc(r["acquired_utc"]))
    return dict(sorted(out.items(), key=lambda item: tuple(str(v) for v in item[0])))


def _by_normal(rows: Sequence[Mapping]) -> list[Mapping]:
    """``rows`` with each oblique or unknown direction labelled by its
    family of normals, so that a target's two oblique directions make two
    trends, not one."""
    from ..scene.combine import normal_families

    plain = [r for r in rows if r.get("direction") in AXIS_DIRECTIONS or r.get("normal_angle_deg") is None]
    out = list(plain)
    rest: dict[tuple, list[Mapping]] = {}
    for row in rows:
        if not any(row is r for r in plain):
            rest.setdefault(tuple(row.get(k) for k in GROUP_KEYS), []).append(row)
    for members in rest.values():
        normals = np.array([r["normal_angle_deg"] for r in members], float)
        families = normal_families(normals)
        for family in np.unique(families):
            chosen = np.mod(normals[families == family], 180.0)
            mean = float(np.degrees(np.angle(np.mean(np.exp(2j * np.radians(chosen))))) / 2)
            for row, f in zip(members, families):
                if f == family:
                    out.append({**row, "direction": f"{row['direction']} (normal {mean:.0f} deg)"})
    return out


#: a trend's scope by the scopes of its points
_SCOPE_NAMES = {SCENE_SCOPE: "scene", TARGET_SCOPE: "targets", CANDIDATE_SCOPE: "edges"}


def points_scope(points: Sequence[Mapping]) -> str:
    """What a trend's points summarise: ``scene`` (scene-wide rows),
    ``targets`` (a target's rows, in acquisitions without a scene-wide
    one), ``edges`` (measured chips), or these names joined by `` and ``
    when acquisitions differ (an old store's row has no scope: ``unknown``).

    A scan stores one recommended row per scope and direction, so the
    scene's and a target's recommended rows may differ in method; the
    scope tells their trends apart.

    Examples
    --------
    >>> points_scope([{"scope": "scene"}, {"scope": "scene"}])
    'scene'
    >>> points_scope([{"scope": "target"}, {"scope": "scene"}, {}])
    'scene and targets and unknown'
    """
    names = {_SCOPE_NAMES.get(str(p.get("scope")), "unknown") for p in points}
    order = [*_SCOPE_NAMES.values(), "unknown"]
    return " and ".join(sorted(names, key=order.index))


def campaign_rows(targets: Iterable[Mapping], edges: Iterable[Mapping] = ()) -> list[Mapping]:
    """The rows a campaign's trends are made of: the targets layer's rows,
    and for an acquisition that has none (``imgmtf measure --campaign``)
    its measured edges (status ``ok``), each a point of method ``edge``."""
    targets = list(targets)
    summarised = {row.get("acquisition_id") for row in targets}
    chips = [{**row, "method": "edge", "scope": CANDIDATE_SCOPE} for row in edges
             if row.get("acquisition_id") not in summarised and row.get("status") == "ok"]
    return [*targets, *chips]


def trends(rows: Iterable[Mapping], confidence: float = 0.95) -> list[Trend]:
    """The drift of every figure (:data:`FIGURES`) of every group
    (:func:`trend_points`) of a store's targets layer
    (:func:`imgmtf.campaign.store.read_layer`).  A group of one
    acquisition time, or of misfit rows, gets a Trend without a slope
    (NaN; its ``note`` says why), so that it is listed, not drawn as a line.

    Examples
    --------
    >>> rows = [{"acquisition_id": str(k), "acquired_utc": f"{2020 + k}-01-01", "platform": "Sim",
    ...          "band_name": "pan", "direction": "across-track", "method": "fit", "scope": "scene",
    ...          "mtf_nyquist": 0.30 - 0.01 * k, "fwhm_px": 1.2} for k in range(4)]
    >>> [(t.figure, round(t.slope_per_year, 4), t.n_acquisitions, t.drift) for t in trends(rows)]
    [('mtf_nyquist', -0.01, 4, True), ('fwhm_px', 0.0, 4, False)]
    """
    z = NormalDist().inv_cdf(0.5 + confidence / 2)
    out = []
    for key, points in trend_points(rows).items():
        group = dict(zip(GROUP_KEYS, key))
        platform = points[0].get("platform")
        for figure, bounds in FIGURES.items():
            usable = [p for p in points if p.get(figure) is not None and math.isfinite(p[figure])]
            if not usable:
                continue
            times = [p["acquired_utc"] for p in usable]
            first, last = usable[0], usable[-1]
            low, high = (last.get(b) for b in bounds) if bounds else (None, None)
            common = dict(**group, platform=platform, recommended_because=last.get("recommended_because") or "",
                          scope=points_scope(usable),
                          figure=figure,
                          n_acquisitions=len({p["acquisition_id"] for p in usable}), n_points=len(usable),
                          first_utc=times[0], last_utc=times[-1], latest=float(last[figure]),
                          latest_ci_low=math.nan if low is None else float(low),
                          latest_ci_high=math.nan if high is None else float(high), confidence=confidence)
            if group["misfit"] or len({parse_utc(t) for t in times}) < 2:
                out.append(Trend(**common, value_at_first=float(first[figure]), slope_per_year=math.nan,
                                 slope_ci_low=math.nan, slope_ci_high=math.nan, weights="", consistency=math.nan,
                                 drift=False, note=NOTE_MISFIT if group["misfit"] else NOTE_ONE))
                continue
            sd = None
            if bounds:
                sd = np.array([_half_width(p, bounds) / z for p in usable])
            line = fit_line(years_since(times, times[0]), [p[figure] for p in usable], sd, confidence)
            out.append(Trend(**common, value_at_first=line.intercept, slope_per_year=line.slope,
                             slope_ci_low=line.low, slope_ci_high=line.high, weights=line.weights,
                             consistency=line.consistency, drift=bool(line.low > 0 or line.high < 0),
                             note="" if math.isfinite(line.low) else NOTE_TWO))
    return out


_DIRECTION_NAMES = {"across": "across-track", "along": "along-track"}


@dataclass(frozen=True)
class Requirement:
    """The lowest acceptable MTF at Nyquist: one ``default`` for every
    direction, and values ``per_direction`` (direction label -> value)
    that override it for theirs.

    Examples
    --------
    >>> need = Requirement.parse("across=0.12,along=0.10")
    >>> need.for_direction("across-track"), need.for_direction("oblique (normal 17 deg)"), str(need)
    (0.12, None, 'across-track 0.12, along-track 0.1')
    >>> str(Requirement.parse("0.1,along=0.08"))
    'along-track 0.08, 0.1 in any other direction'
    """

    default: float | None = None
    per_direction: tuple[tuple[str, float], ...] = ()

    def for_direction(self, direction: str | None) -> float | None:
        """The value a trend of ``direction`` is judged against (None: none applies)."""
        return dict(self.per_direction).get(str(direction), self.default)

    def __str__(self) -> str:
        parts = [f"{d} {v:g}" for d, v in self.per_direction]
        if self.default is not None:
            parts.append(f"{self.default:g} in any other direction" if parts else f"{self.default:g}")
        return ", ".join(parts)

    @classmethod
    def of(cls, value: float | str | Requirement | None) -> Requirement | None:
        """A requirement from a number (every direction), its text (:meth:`parse`) or itself."""
        if value is None or isinstance(value, Requirement):
            return value
        return cls.parse(value) if isinstance(value, str) else cls.parse(repr(float(value)))

    @classmethod
    def parse(cls, text: str) -> Requirement:
        """``0.1`` (every direction), ``across=0.12,along=0.10`` (``across``
        and ``along`` stand for ``across-track`` and ``along-track``; any
        direction label of the store may be named), or both
        (``0.1,along=0.08``: the value for the directions not named).

        Raises
        ------
        ParameterError
            An item that is not ``MTF`` or ``DIRECTION=MTF`` with MTF a
            number from 0 to 1, or a direction named twice.
        """
        default, named = None, {}
        for item in (part.strip() for part in str(text).split(",")):
            direction, equals, value = item.rpartition("=")
            direction = _DIRECTION_NAMES.get(direction.strip(), direction.strip())
            try:
                number = float(value)
            except ValueError:
                number = math.nan
            if not (0.0 <= number <= 1.0) or (equals and not direction):
                raise ParameterError(f"requirement {item!r} is not an MTF from 0 to 1 or DIRECTION=MTF "
                                     "(e.g. 0.1 or across=0.12,along=0.10)")
            if direction in named or (not direction and default is not None):
                raise ParameterError(f"requirement {text!r} gives {direction or 'the default'} twice")
            if direction:
                named[direction] = number
            else:
                default = number
        return cls(default, tuple(named.items()))


def requirement_verdict(trend: Trend, requirement: float | Requirement | None) -> str:
    """Whether a trend's latest acquisition meets ``requirement`` (a
    lowest acceptable value of its figure): ``pass`` when its interval
    lies at or above it, ``fail`` when below, ``undecided`` when the
    interval straddles it; without an interval the value alone decides.
    Empty without a requirement (or none for the trend's direction), and
    for a misfit trend (its value is not one to judge).

    Examples
    --------
    >>> t = trends([{"acquisition_id": "a", "acquired_utc": "2021-01-01", "platform": "Sim", "direction": "x",
    ...              "mtf_nyquist": 0.11, "mtf_nyquist_ci_low": 0.09, "mtf_nyquist_ci_high": 0.13}])[0]
    >>> requirement_verdict(t, 0.08), requirement_verdict(t, 0.10), requirement_verdict(t, 0.14)
    ('pass', 'undecided', 'fail')
    """
    if isinstance(requirement, Requirement):
        requirement = requirement.for_direction(trend.direction)
    if requirement is None or trend.misfit:
        return ""
    low, high = trend.latest_ci_low, trend.latest_ci_high
    if not (math.isfinite(low) and math.isfinite(high)):
        low = high = trend.latest
    if low >= requirement:
        return "pass"
    return "fail" if high < requirement else "undecided"


def _half_width(row: Mapping, bounds: tuple[str, str]) -> float:
    low, high = (row.get(b) for b in bounds)
    if low is None or high is None:
        return math.nan
    return (high - low) / 2.0


def write_trend_csv(found: Sequence[Trend], path: str, requirement: float | Requirement | None = None) -> None:
    """``found`` as ``trend.csv`` (columns :data:`TREND_COLUMNS`; slopes in
    the figure's units per year; NaN as empty), written atomically; with a
    ``requirement`` on the MTF at Nyquist, its rows say whether their
    latest acquisition meets it (:func:`requirement_verdict`).

    Raises
    ------
    FileWriteError
        The file cannot be written.
    """
    with atomic_output(path) as partial:
        try:
            with open(partial, "w", newline="", encoding="utf-8") as fh:
                writer = csv.DictWriter(fh, fieldnames=list(TREND_COLUMNS))
                writer.writeheader()
                for trend in found:
                    need = Requirement.of(requirement)
                    judged = need.for_direction(trend.direction) if need and trend.figure == "mtf_nyquist" else None
                    writer.writerow({**{k: _cell(v) for k, v in asdict(trend).items()},
                                     "requirement": _cell(judged), "meets_requirement": requirement_verdict(trend,
                                                                                                          judged)})
        except OSError as exc:
            raise FileWriteError(f"{path}: cannot write: {exc.strerror or exc}") from None


def _cell(value):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    if isinstance(value, float):
        return f"{value:.6g}"
    return value
