"""The campaign report: ``trend.csv`` and one self-contained ``report.html``
from a campaign store.

The page is rendered from a Jinja2 template
(``imgmtf/campaign/templates/report.html``, autoescaping on: every value
from the store is text, never markup).  It holds the table of drifts of the MTF at Nyquist (per sensor,
band and direction the recommended rows first, the others marked, the
requirement judged); per sensor, band and direction the recommended
rows' four figures of merit against time
(:func:`imgmtf.plot.plot_campaign`) with the requirement, the pre-launch
value and the drift; and the table of acquisitions with each one's
overview and edge figures when the store recorded them.  Every figure is
embedded (PNG, base64) and the style is inline: the page fetches nothing,
so it opens offline, from a mail attachment or an archive, as it was
written; each figure is also a link to its file at full resolution (the
report's own in ``figures/`` beside the page, the store's where the store
keeps them), and a figure the store names that is missing is listed.
"""
from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..atomic import atomic_output, ensure_folder
from ..errors import FileWriteError
from ..estimate.geometry import AXIS_DIRECTIONS
from ..records import utc_now
from ..version import __version__
from .report_figures import Figures
from .store import read_layer
from .trend import (
    GROUP_KEYS,
    Requirement,
    Trend,
    campaign_rows,
    requirement_verdict,
    trend_points,
    trends,
    write_trend_csv,
)

MAX_EDGE_FIGURES = 8            # edge figures shown per acquisition (the rest are counted)
MAX_ACQUISITIONS_WITH_FIGURES = 12   # the latest acquisitions whose figures the page embeds (a page, not an archive)

@dataclass(frozen=True)
class ReportFiles:
    """What :func:`write_report` wrote: ``trend_csv``, ``report_html``, the
    ``trends`` found, and ``warnings`` (figures the store names that are
    missing, said on the page too)."""

    trend_csv: str
    report_html: str
    trends: tuple[Trend, ...]
    warnings: tuple[str, ...] = ()


def baseline_values(sensor_path: str | Path | None) -> dict[str, float]:
    """The pre-launch MTF at Nyquist per direction (``across-track``,
    ``along-track``) of a sensor TOML (:meth:`imgmtf.Sensor.from_toml`);
    empty without one."""
    if sensor_path is None:
        return {}
    from ..sensor.model import Sensor
    sensor = Sensor.from_toml(sensor_path)
    return {"across-track": sensor.mtf_nyquist("across"), "along-track": sensor.mtf_nyquist("along")}


def write_report(store_path: str | Path, out_dir: str | Path, *, requirement: float | str | Requirement | None = None,
                 baseline: str | Path | None = None, confidence: float = 0.95) -> ReportFiles:
    """Write ``trend.csv``, ``report.html`` and its figures (``figures/``)
    of a campaign store into ``out_dir``.

    The drift table shows per sensor, band and direction the recommended
    rows' trend first and marks the others (other methods, misfit fits:
    listed, never trended or drawn); a direction whose rows all misfit is
    said to have nothing to quote.  A group of one acquisition has no
    slope and is drawn as a point.

    Parameters
    ----------
    store_path : str or pathlib.Path
        The campaign store (:mod:`imgmtf.campaign.store`).
    out_dir : str or pathlib.Path
        The folder (created if missing).
    requirement : float, str or Requirement, optional
        The lowest acceptable MTF at Nyquist, for every direction or per
        direction (:meth:`~imgmtf.campaign.trend.Requirement.parse`:
        ``across=0.12,along=0.10``): drawn as a line, and each trend's
        latest acquisition judged against it (pass, fail, or undecided
        when its interval straddles it).
    baseline : str or pathlib.Path, optional
        A sensor TOML whose across- and along-track MTF at Nyquist are the
        pre-launch values drawn against those directions.
    confidence : float, optional
        Confidence level of the drift intervals (default 0.95).

    Returns
    -------
    ReportFiles
        The paths of ``trend.csv`` and ``report.html``, the drifts found
        and the warnings (figures the store names that are missing).

    Raises
    ------
    StoreError
        The store cannot be read.
    ConfigError
        The sensor TOML cannot be read.
    FileWriteError
        An output cannot be written.
    ParameterError
        A requirement that is not an MTF from 0 to 1 (per direction).
    """
    need = Requirement.of(requirement)
    acquisitions = read_layer(store_path, "acquisitions")
    targets = read_layer(store_path, "targets")
    edges = read_layer(store_path, "edges")
    points = campaign_rows(targets, edges)
    found = tuple(trends(points, confidence))
    prelaunch = baseline_values(baseline)
    folder = ensure_folder(out_dir)
    trend_csv, report_html = str(folder / "trend.csv"), str(folder / "report.html")
    write_trend_csv(found, trend_csv, need)
    figures = Figures(Path(folder), Path(store_path))
    figures.clear()
    context = _context(str(store_path), acquisitions, points, edges, found, need, prelaunch,
                       str(baseline) if baseline else None, figures)
    page = _environment().get_template("report.html").render(**context)
    with atomic_output(report_html) as partial:
        try:
            Path(partial).write_text(page, encoding="utf-8")
        except OSError as exc:
            raise FileWriteError(f"{report_html}: cannot write: {exc.strerror or exc}") from None
    warnings = tuple(f"{store_path}: figure {stored} is missing (looked for {where}): moved or deleted"
                     for stored, where in figures.missing)
    return ReportFiles(trend_csv, report_html, found, warnings)


def _environment():
    """The Jinja2 environment of the report's template, autoescaping HTML."""
    from jinja2 import Environment, PackageLoader, StrictUndefined, select_autoescape
    return Environment(loader=PackageLoader("imgmtf.campaign", "templates"), undefined=StrictUndefined,
                       autoescape=select_autoescape(("html",), default=True), keep_trailing_newline=True)


def _text(value, digits: int = 4) -> str:
    """A value as a table shows it (text; the template escapes it)."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    if isinstance(value, float):
        return f"{value:.{digits}g}" if abs(value) >= 1e-3 or value == 0 else f"{value:.2e}"
    return str(value)


def _mtf(value) -> str:
    return "" if value is None or not math.isfinite(value) else f"{value:.4f}"


def _when(text) -> str:
    """An ISO 8601 UTC time as a table shows it: to the minute, no T or Z."""
    if not text:
        return ""
    return text[:16].replace("T", " ") if "T" in text else text


def _group_title(trend: Trend) -> str:
    how = trend.method or "unknown method"
    if trend.assumption:
        how += f" ({trend.assumption})"
    band = f", band {trend.band_name}" if trend.band_name else ""
    return f"{trend.sensor}{band}: {trend.direction or 'unknown direction'}, {trend.scope}, {how}"


def _unnamed(points: Sequence[Mapping]) -> dict | None:
    """How many sensors name no platform, and how many acquisitions stand alone."""
    from .recommended import sensor_of
    unnamed = sorted({sensor_of(p) for p in points if not p.get("platform")})
    if not unnamed:
        return None
    return {"count": len(unnamed), "alone": sum(s.endswith(" alone") for s in unnamed)}


def _context(store: str, acquisitions: list[dict], points: list[Mapping], edges: list[dict],
             found: Sequence[Trend], requirement: Requirement | None, prelaunch: Mapping[str, float],
             baseline: str | None, figures: Figures) -> dict:
    """What the template shows (values as text; the template adds the markup and escapes them)."""
    from .recommended import mark_recommended
    timed = sorted(a["acquired_utc"] for a in acquisitions if a.get("acquired_utc"))
    context = {"store": store, "store_name": Path(store).name, "n_acquisitions": len(acquisitions),
               "span": (timed[0], timed[-1]) if timed else None, "untimed": len(acquisitions) - len(timed),
               "version": __version__, "now": utc_now(),
               "requirement": str(requirement) if requirement is not None else None,
               "baseline": {"path": baseline, "across": f"{prelaunch['across-track']:.4f}",
                            "along": f"{prelaunch['along-track']:.4f}"} if baseline else None,
               "unnamed": _unnamed(points), "drift": _drift_rows(found, requirement),
               "groups": _trend_figures(points, found, requirement, prelaunch, figures),
               "others": [_trend_row(t) for t in _order(found)
                          if t.figure in ("mtf50_cy_px", "fwhm_px", "rer") and t.recommended and not t.misfit]}
    context.update(_acquisition_rows(acquisitions, mark_recommended(points), edges, figures))
    context["missing"] = len(figures.missing)
    return context


def _trend_figures(points: list[Mapping], found: Sequence[Trend], requirement: Requirement | None,
                   prelaunch: Mapping[str, float], figures: Figures) -> list[dict]:
    """The recommended series' figures: title, embedded source, link to the full-resolution file."""
    from ..plot.campaign import plot_campaign
    by_group: dict[tuple, list[Trend]] = {}
    for trend in found:
        by_group.setdefault(tuple(getattr(trend, k) for k in GROUP_KEYS), []).append(trend)
    out = []
    for key, group in trend_points(points).items():
        shown = by_group.get(key, [])
        if not (key[-2] and not key[-1] and shown):          # recommended, not misfit
            continue
        need = requirement.for_direction(shown[0].direction) if requirement else None
        fig = plot_campaign(group, shown, requirement=need, baseline=prelaunch.get(key[2]))
        src, link = figures.render(fig, "trend")
        out.append({"title": _group_title(shown[0]), "src": src, "link": link})
    return out


def _order(found: Sequence[Trend]) -> list[Trend]:
    """Per sensor, band and direction: the recommended trend first, then the others, misfit ones last."""
    return sorted(found, key=lambda t: (str(t.sensor), str(t.band_name), str(t.direction), not t.recommended,
                                        t.misfit, t.scope, str(t.method), str(t.assumption)))


def _trend_row(t: Trend) -> dict:
    """A trend as a table row: who, what, when, the latest value and the slope (or why there is none)."""
    band = f", band {t.band_name}" if t.band_name else ""
    span = f"{t.n_acquisitions}: {_when(t.first_utc)[:10]}"          # dates: the times are in the acquisitions
    if t.first_utc[:10] != t.last_utc[:10]:
        span += f" to {_when(t.last_utc)[:10]}"
    interval = ""
    if t.has_slope:
        interval = (f"[{t.slope_ci_low:+.4g}, {t.slope_ci_high:+.4g}]" if math.isfinite(t.slope_ci_low)
                    else "too few points")
    return {"sensor": f"{t.sensor}{band}", "direction": _text(t.direction), "scope": t.scope, "figure": t.figure,
            "method": _text(t.method) + (f" ({t.assumption})" if t.assumption else ""), "span": span,
            "latest": _text(t.latest), "slope": f"{t.slope_per_year:+.4g}" if t.has_slope else None,
            "interval": interval, "drift": t.drift, "note": t.note, "because": t.recommended_because,
            "kind": "drift" if t.drift else ("misfit" if t.misfit else ("other" if not t.recommended else ""))}


def _drift_rows(found: Sequence[Trend], requirement: Requirement | None) -> dict:
    """The MTF at Nyquist of every group: the recommended one per direction first, the others marked."""
    chosen = _order([t for t in found if t.figure == "mtf_nyquist"])
    directions: dict[tuple, list[Trend]] = {}
    for t in chosen:
        directions.setdefault((t.sensor, t.band_name, t.direction), []).append(t)
    rows = []
    for t in chosen:
        row = _trend_row(t)
        if math.isfinite(t.latest_ci_low):
            row["latest"] += f" [{_mtf(t.latest_ci_low)}, {_mtf(t.latest_ci_high)}]"
        if t.misfit:
            only = all(o.misfit for o in directions[t.sensor, t.band_name, t.direction])
            row["quoted"] = "only misfit" if only else "misfit"
        else:
            row["quoted"] = "recommended" if t.recommended else "other"
        need = requirement.for_direction(t.direction) if requirement else None
        row.update(verdict=requirement_verdict(t, requirement), need=f"{need:g}" if need is not None else "")
        rows.append(row)
    confidence = f"{100 * chosen[0].confidence:g}" if chosen else ""
    return {"rows": rows, "confidence": confidence, "judged": requirement is not None}


# the acquisitions table's columns: heading, and the acquisition's key (None: built apart)
_ACQUISITION_COLUMNS = (("acquired (UTC)", None), ("platform", "platform"), ("instrument", "instrument"),
                        ("band", "band_name"), ("GSD (m)", "gsd_m"), ("level", "level"), ("product", "product_id"),
                        ("site", "site"), ("file", None), ("SHA-256", None), ("edges", None),
                        ("MTF at Nyquist [95 % interval]", None))


def _result(row: Mapping) -> dict:
    """One result of an acquisition: where, which direction, how, its MTF at Nyquist; misfit, recommended."""
    where = f"target {row['target_id']}" if row.get("target_id") is not None else _text(row.get("scope"))
    interval = (f" [{_mtf(row.get('mtf_nyquist_ci_low'))}, {_mtf(row.get('mtf_nyquist_ci_high'))}]"
                if row.get("mtf_nyquist_ci_low") is not None else "")
    direction = _text(row.get("direction"))
    if row.get("direction") not in AXIS_DIRECTIONS and row.get("normal_angle_deg") is not None:
        direction += f" {row['normal_angle_deg']:.1f} deg"
    how = _text(row.get("method")) + (f" ({row['assumption']})" if row.get("assumption") else "")
    return {"text": f"{where}, {direction}, {how}: {_mtf(row.get('mtf_nyquist'))}{interval}",
            "misfit": bool(row.get("misfit")), "recommended": bool(row.get("recommended"))}


def _acquisition_rows(acquisitions: list[dict], points: Sequence[Mapping], edges: list[dict],
                      figures: Figures) -> dict:
    """The acquisitions table (a fact no acquisition knows gets no column) and the latest acquisitions' figures."""
    columns = [h for h, k in _ACQUISITION_COLUMNS if k is None or any(a.get(k) is not None for a in acquisitions)]
    facts = {h: k for h, k in _ACQUISITION_COLUMNS if k}
    rows, blocks = [], []
    for a in sorted(acquisitions, key=lambda a: (a.get("acquired_utc") or "~", a.get("path") or "")):
        ident = a["acquisition_id"]
        mine = [t for t in points if t.get("acquisition_id") == ident]
        own_edges = [e for e in edges if e.get("acquisition_id") == ident]
        path = str(a.get("path") or "")
        rows.append({"when": _when(a.get("acquired_utc")), "path": path, "file": Path(path).name,
                     "source": json.loads(a["sources"]).get("acquired_utc") if a.get("sources") else None,
                     "sha": (a.get("sha256") or "")[:12], "edges": len(own_edges),
                     "facts": {h: _text(a.get(k)) for h, k in facts.items()}, "results": [_result(t) for t in mine]})
        blocks.append(_acquisition_figures(a, own_edges, mine, figures))
    shown = [b for b in blocks[::-1] if b][:MAX_ACQUISITIONS_WITH_FIGURES][::-1]      # the latest
    return {"columns": columns, "acquisitions": rows, "shown": shown,
            "earlier": sum(bool(b) for b in blocks) - len(shown)}


def _acquisition_figures(acquisition: dict, edges: list[dict], targets: list[Mapping], figures: Figures) -> dict:
    """The acquisition's overview and first edge figures, embedded and each
    a link to its file at full resolution; those the store names that are
    missing, listed.  Empty when it has none."""
    before = len(figures.missing)
    overview = figures.stored(acquisition.get("overview"))
    paths = list(dict.fromkeys(p for p in (r.get("plot") for r in (*targets, *edges)) if p))
    thumbs: list[dict] = []
    examined = 0
    for path in paths:
        if len(thumbs) == MAX_EDGE_FIGURES:
            break
        examined += 1
        found = figures.stored(path)
        if found:
            thumbs.append({"src": found[0], "link": found[1], "name": Path(path).name, "stored": path})
    lost = figures.missing[before:]
    if not (overview or thumbs or lost):
        return {}
    return {"name": f"{acquisition.get('acquired_utc') or 'no time'}: {acquisition.get('path')}",
            "path": str(acquisition.get("path")), "more": len(paths) - examined, "lost": lost, "thumbs": thumbs,
            "overview": {"src": overview[0], "link": overview[1]} if overview else None}
