"""The campaign report: ``trend.csv`` and one self-contained ``report.html``
from a campaign store.

The page holds the table of drifts of the MTF at Nyquist (per sensor,
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

import html
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..atomic import atomic_output, ensure_folder
from ..errors import FileWriteError
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

_STYLE = """
body { font: 15px/1.45 system-ui, -apple-system, "Segoe UI", sans-serif; margin: 0 auto; max-width: 1240px;
       padding: 0 16px 40px; color: #1b1b1b; }
h1 { font-size: 1.5em; margin-top: 0.8em; } h2 { font-size: 1.2em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 8px 0; font-size: 0.92em; }
th, td { border: 1px solid #d0d0d0; padding: 3px 7px; text-align: left; vertical-align: top; }
th { background: #f2f2f2; } td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.drift td { background: #fff0ee; } table.trend td, .time { white-space: nowrap; }
table.trend td.note { white-space: normal; max-width: 16em; }
table.trend td .wrap { white-space: normal; display: inline-block; min-width: 12em; max-width: 18em; }
tr.other td, tr.misfit td { color: #666; } tr.misfit td { background: #f6f6f6; }
.note { color: #555; font-size: 0.92em; } .warning { color: #8a1c00; }
.pass { color: #1a6d1a; font-weight: 600; } .fail { color: #b00000; font-weight: 600; } .undecided { color: #8a5a00; }
img { max-width: 100%; height: auto; } img.thumb { width: 360px; margin: 2px; border: 1px solid #ddd; }
.figure { margin: 10px 0 24px; } code { font-size: 0.95em; }
"""


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
    page = _page(str(store_path), acquisitions, points, edges, found, need, prelaunch,
                 str(baseline) if baseline else None, figures)
    with atomic_output(report_html) as partial:
        try:
            Path(partial).write_text(page, encoding="utf-8")
        except OSError as exc:
            raise FileWriteError(f"{report_html}: cannot write: {exc.strerror or exc}") from None
    warnings = tuple(f"{store_path}: figure {stored} is missing (looked for {where}): moved or deleted"
                     for stored, where in figures.missing)
    return ReportFiles(trend_csv, report_html, found, warnings)


def _text(value, digits: int = 4) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    if isinstance(value, float):
        return f"{value:.{digits}g}" if abs(value) >= 1e-3 or value == 0 else f"{value:.2e}"
    return html.escape(str(value))


def _group_title(trend: Trend) -> str:
    how = trend.method or "unknown method"
    if trend.assumption:
        how += f" ({trend.assumption})"
    band = f", band {trend.band_name}" if trend.band_name else ""
    return f"{trend.sensor}{band}: {trend.direction or 'unknown direction'}, {how}"


def _sensor_note(points: Sequence[Mapping]) -> str:
    """What the page says of acquisitions that name no platform."""
    from .recommended import sensor_of
    unnamed = sorted({sensor_of(p) for p in points if not p.get("platform")})
    if not unnamed:
        return ""
    alone = [s for s in unnamed if s.endswith(" alone")]
    return (f'<p class="note">{len(unnamed)} sensor(s) without a platform name: each is keyed by what '
            "identifies its files (the camera's make, model and serial when tagged, else the image's size, data "
            "type, bands, GSD and software) and never trended with another"
            + (f"; {len(alone)} acquisition(s) of a store older than schema 2 stand alone" if alone else "")
            + ". Give <code>--platform</code> with <code>--campaign</code> to name them.</p>")


def _page(store: str, acquisitions: list[dict], points: list[Mapping], edges: list[dict], found: Sequence[Trend],
          requirement: Requirement | None, prelaunch: Mapping[str, float], baseline: str | None,
          figures: Figures) -> str:
    from ..plot.campaign import plot_campaign
    from .recommended import mark_recommended
    timed = [a for a in acquisitions if a.get("acquired_utc")]
    span = sorted(a["acquired_utc"] for a in timed)
    parts = [f"<h1>MTF calibration campaign: {html.escape(Path(store).name)}</h1>",
             f'<p class="note">Store <code>{html.escape(store)}</code>: {len(acquisitions)} acquisition(s)'
             + (f", {html.escape(span[0])} to {html.escape(span[-1])}" if span else "")
             + (f"; {len(acquisitions) - len(timed)} without an acquisition time, left out of the trends"
                if len(timed) < len(acquisitions) else "")
             + f". Report by imgmtf {html.escape(__version__)}, {utc_now()}."
             + (f" Requirement: MTF at Nyquist at least {html.escape(str(requirement))}."
                if requirement is not None else "")
             + (f" Pre-launch values from <code>{html.escape(baseline)}</code>: across-track "
                f"{prelaunch['across-track']:.4f}, along-track {prelaunch['along-track']:.4f}." if baseline else "")
             + "</p>", _sensor_note(points)]
    parts += _drift_table(found, requirement)
    by_group: dict[tuple, list[Trend]] = {}
    for trend in found:
        by_group.setdefault(tuple(getattr(trend, k) for k in GROUP_KEYS), []).append(trend)
    parts.append("<h2>Figures of merit against time</h2>")
    groups = {key: group for key, group in trend_points(points).items() if key[-2] and not key[-1]}
    if not groups:
        parts.append('<p class="note">No acquisition with a time and a recommended result: nothing to draw.</p>')
    else:
        parts.append('<p class="note">The recommended rows of each sensor, band and direction (the other '
                     "methods' trends are in the table above and in <code>trend.csv</code>). Click a figure to "
                     "open it at full resolution.</p>")
    for key, group in groups.items():
        direction = key[2]
        shown = by_group.get(key, [])
        fig = plot_campaign(group, shown, requirement=requirement.for_direction(shown[0].direction if shown else None)
                            if requirement else None, baseline=prelaunch.get(direction))
        title = html.escape(_group_title(shown[0])) if shown else html.escape(str(key))
        src, link = figures.render(fig, "trend")
        parts.append(f'<div class="figure"><h3>{title}</h3><a href="{html.escape(link)}"><img src="{src}" '
                     f'width="1215" height="594" alt="MTF at Nyquist, MTF50, FWHM and RER against time: {title}">'
                     "</a></div>")
    parts += _trend_table(found, "Drift of MTF50, FWHM and RER (recommended rows)", ("mtf50_cy_px", "fwhm_px", "rer"))
    parts += _acquisition_table(acquisitions, mark_recommended(points), edges, figures)
    if figures.missing:
        parts.insert(2, f'<p class="warning">{len(figures.missing)} figure(s) the store names are missing '
                     "(moved or deleted): listed under their acquisitions below.</p>")
    body = "\n".join(p for p in parts if p)
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">\n'
            f"<title>MTF campaign: {html.escape(Path(store).name)}</title>\n<style>{_STYLE}</style>\n"
            f"</head>\n<body>\n{body}\n</body>\n</html>\n")


def _when(text) -> str:
    """An ISO 8601 UTC time as a table shows it: to the minute, no T or Z."""
    if not text:
        return ""
    return html.escape(text[:16].replace("T", " ") if "T" in text else text)


def _order(found: Sequence[Trend]) -> list[Trend]:
    """Per sensor, band and direction: the recommended trend first, then the others, misfit ones last."""
    return sorted(found, key=lambda t: (str(t.sensor), str(t.band_name), str(t.direction), not t.recommended,
                                        t.misfit, str(t.method), str(t.assumption)))


def _sensor_band(trend: Trend) -> str:
    """The sensor and band cell (wraps: an unnamed sensor's key is long)."""
    band = f", band {_text(trend.band_name)}" if trend.band_name else ""
    return f'<span class="wrap">{_text(trend.sensor)}{band}</span>'


def _span(trend: Trend) -> str:
    """How many acquisitions, from when to when."""
    if trend.first_utc == trend.last_utc:
        return f"{trend.n_acquisitions}: {_when(trend.first_utc)}"
    return f"{trend.n_acquisitions}: {_when(trend.first_utc)} to {_when(trend.last_utc)}"


def _quoted(trend: Trend, only_misfit: bool) -> str:
    """The drift table's cell saying whether a trend's rows are the ones to quote."""
    because = html.escape(trend.recommended_because)
    if trend.misfit:
        text = "<strong>only misfit rows</strong>:<br>nothing to quote" if only_misfit else "misfit"
        return f'<span title="{because}">{text}</span>'
    if trend.recommended:
        return f'<strong title="{because}">recommended</strong>'
    return f'<span title="{because}">other</span>'


def _drift_table(found: Sequence[Trend], requirement: Requirement | None) -> list[str]:
    """The MTF at Nyquist of every group: the recommended one per direction first, the others marked."""
    chosen = _order([t for t in found if t.figure == "mtf_nyquist"])
    out = ["<h2>Drift of the MTF at Nyquist</h2>"]
    if not chosen:
        return [*out, '<p class="note">No acquisition with a time and a result yet.</p>']
    out.append('<p class="note">Per sensor, band and direction, the recommended rows (the ones to quote) first; '
               "misfit rows are never recommended and never trended. Slope of a weighted least-squares line per "
               f"year (365.25 days), with its {100 * chosen[0].confidence:g} % interval; a drift when the interval "
               "excludes 0; one acquisition gives no slope. "
               + ("The requirement is judged on the latest acquisition: pass when its interval lies above it, "
                  "undecided when it straddles it. " if requirement is not None else "")
               + "All in <code>trend.csv</code>.</p>")
    judged = requirement is not None
    head = ("sensor, band", "direction", "method", "quoted", "acquisitions (UTC)", "latest [interval]",
            *(("requirement",) if judged else ()), "slope per year", "interval", "drift")
    out.append('<table class="trend"><tr>' + "".join(f"<th>{h}</th>" for h in head) + "</tr>")
    directions: dict[tuple, list[Trend]] = {}
    for t in chosen:
        directions.setdefault((t.sensor, t.band_name, t.direction), []).append(t)
    for t in chosen:
        only_misfit = all(o.misfit for o in directions[t.sensor, t.band_name, t.direction])
        method = _text(t.method) + (f" ({_text(t.assumption)})" if t.assumption else "")
        cells = [_sensor_band(t), _text(t.direction), method, _quoted(t, only_misfit), _span(t)]
        latest = _text(t.latest) + (f" [{_mtf(t.latest_ci_low)}, {_mtf(t.latest_ci_high)}]"
                                    if math.isfinite(t.latest_ci_low) else "")
        numbers = [latest]
        if judged:
            verdict = requirement_verdict(t, requirement)
            need = requirement.for_direction(t.direction) if requirement else None
            numbers.append(f'<span class="{verdict}">{verdict}</span> (&ge; {need:g})' if verdict else "")
        if t.has_slope:
            interval = (f"[{t.slope_ci_low:+.4g}, {t.slope_ci_high:+.4g}]" if math.isfinite(t.slope_ci_low)
                        else "too few points")
            tail = "".join(f'<td class="num">{c}</td>' for c in (f"{t.slope_per_year:+.4g}", interval,
                                                                 "yes" if t.drift else "no"))
        else:
            tail = f'<td colspan="3" class="note">{html.escape(t.note)}</td>'
        row = ("".join(f"<td>{c}</td>" for c in cells) + "".join(f'<td class="num">{c}</td>' for c in numbers)
               + tail)
        kind = "drift" if t.drift else ("misfit" if t.misfit else ("other" if not t.recommended else ""))
        out.append(f'<tr class="{kind}">{row}</tr>')
    out.append("</table>")
    return out


def _trend_table(found: Sequence[Trend], title: str, figures: Sequence[str]) -> list[str]:
    """The recommended rows' drifts of ``figures`` as a table headed ``title``."""
    chosen = _order([t for t in found if t.figure in figures and t.recommended and not t.misfit])
    out = [f"<h2>{html.escape(title)}</h2>"]
    if not chosen:
        return [*out, '<p class="note">No recommended result with a time yet.</p>']
    head = ("sensor, band", "direction", "method", "figure", "acquisitions (UTC)", "latest", "slope per year",
            "interval", "drift")
    out.append('<table class="trend"><tr>' + "".join(f"<th>{h}</th>" for h in head) + "</tr>")
    for t in chosen:
        method = _text(t.method) + (f" ({_text(t.assumption)})" if t.assumption else "")
        cells = [_sensor_band(t), _text(t.direction), method, t.figure, _span(t)]
        if t.has_slope:
            interval = (f"[{t.slope_ci_low:+.4g}, {t.slope_ci_high:+.4g}]" if math.isfinite(t.slope_ci_low)
                        else "too few points")
            tail = "".join(f'<td class="num">{c}</td>' for c in (f"{t.slope_per_year:+.4g}", interval,
                                                                 "yes" if t.drift else "no"))
        else:
            tail = f'<td colspan="3" class="note">{html.escape(t.note)}</td>'
        row = "".join(f"<td>{c}</td>" for c in cells) + f'<td class="num">{_text(t.latest)}</td>' + tail
        out.append(f'<tr class="{"drift" if t.drift else ""}">{row}</tr>')
    out.append("</table>")
    return out


# the acquisitions table's columns: heading, and the acquisition's key (None: built apart)
_ACQUISITION_COLUMNS = (("acquired (UTC)", None), ("platform", "platform"), ("instrument", "instrument"),
                        ("band", "band_name"), ("GSD (m)", "gsd_m"), ("level", "level"), ("product", "product_id"),
                        ("site", "site"), ("file", None), ("SHA-256", None), ("edges", None),
                        ("MTF at Nyquist [95 % interval]", None))


def _mtf(value) -> str:
    return "" if value is None else f"{value:.4f}"


def _result_line(row: Mapping) -> str:
    """One result of an acquisition: where, which direction, how, its MTF at Nyquist."""
    where = f"target {row['target_id']}" if row.get("target_id") is not None else _text(row.get("scope"))
    interval = (f" [{_mtf(row.get('mtf_nyquist_ci_low'))}, {_mtf(row.get('mtf_nyquist_ci_high'))}]"
                if row.get("mtf_nyquist_ci_low") is not None else "")
    misfit = " <strong>misfit</strong>" if row.get("misfit") else ""
    if row.get("recommended"):
        misfit += " <em>recommended</em>"
    direction = _text(row.get("direction"))
    if row.get("direction") not in ("across-track", "along-track") and row.get("normal_angle_deg") is not None:
        direction += f" {row['normal_angle_deg']:.1f} deg"
    return (f'<span class="time">{where}, {direction}, {_text(row.get("method"))}: '
            f"{_mtf(row.get('mtf_nyquist'))}{interval}{misfit}</span>")


def _acquisition_table(acquisitions: list[dict], points: Sequence[Mapping], edges: list[dict],
                       store_figures: Figures) -> list[str]:
    out = ["<h2>Acquisitions</h2>"]
    if not acquisitions:
        return [*out, '<p class="note">The store holds no acquisition.</p>']
    # a fact no acquisition knows gets no column
    columns = [(h, k) for h, k in _ACQUISITION_COLUMNS if k is None or any(a.get(k) is not None for a in acquisitions)]
    out.append("<table><tr>" + "".join(f"<th>{h}</th>" for h, _ in columns) + "</tr>")
    ordered = sorted(acquisitions, key=lambda a: (a.get("acquired_utc") or "~", a.get("path") or ""))
    figures = []
    for a in ordered:
        ident = a["acquisition_id"]
        mine = [t for t in points if t.get("acquisition_id") == ident]
        when = _when(a.get("acquired_utc")) or "<em>no time</em>"
        source = json.loads(a["sources"]).get("acquired_utc") if a.get("sources") else None
        if source and a.get("acquired_utc"):
            when += f'<br><span class="note">from {html.escape(source)}</span>'
        path = str(a.get("path") or "")
        built = {"acquired (UTC)": f'<td class="time">{when}</td>',
                 "file": f'<td title="{html.escape(path)}"><code>{html.escape(Path(path).name)}</code></td>',
                 "SHA-256": f"<td><code>{_text((a.get('sha256') or '')[:12])}</code></td>",
                 "edges": f'<td class="num">{sum(e.get("acquisition_id") == ident for e in edges)}</td>',
                 "MTF at Nyquist [95 % interval]": "<td>" + "<br>".join(_result_line(t) for t in mine) + "</td>"}
        out.append("<tr>" + "".join(built[h] if k is None else f"<td>{_text(a.get(k))}</td>" for h, k in columns)
                   + "</tr>")
        figures.append(_acquisition_figures(a, [e for e in edges if e.get("acquisition_id") == ident], mine,
                                            store_figures))
    out.append("</table>")
    shown = [f for f in figures[::-1] if f][:MAX_ACQUISITIONS_WITH_FIGURES][::-1]     # the latest
    if shown:
        left = sum(bool(f) for f in figures) - len(shown)
        out += ["<h2>Figures of each acquisition</h2>",
                *((f'<p class="note">The latest {len(shown)} acquisitions\' figures; {left} earlier ones have '
                   "theirs beside their files.</p>",) if left else ()),
                *(part for f in shown for part in f)]
    return out


def _acquisition_figures(acquisition: dict, edges: list[dict], targets: list[Mapping], figures: Figures) -> list[str]:
    """The acquisition's overview and first edge figures, embedded and each
    a link to its file at full resolution; those the store names that are
    missing, listed."""
    shown = []
    before = len(figures.missing)
    overview = figures.stored(acquisition.get("overview"))
    if overview:
        src, link = overview
        shown.append(f'<a href="{html.escape(link)}"><img src="{src}" style="max-width: 760px" alt="overview of '
                     f'{html.escape(str(acquisition.get("path")))}"></a>')
    paths = list(dict.fromkeys(p for p in (r.get("plot") for r in (*targets, *edges)) if p))
    present: list[tuple[str, str, str]] = []
    examined = 0
    for path in paths:
        if len(present) == MAX_EDGE_FIGURES:
            break
        examined += 1
        found = figures.stored(path)
        if found:
            present.append((path, *found))
    for path, src, link in present:
        shown.append(f'<a href="{html.escape(link)}"><img class="thumb" src="{src}" '
                     f'alt="{html.escape(Path(path).name)}" title="{html.escape(path)}"></a>')
    more = len(paths) - examined
    lost = figures.missing[before:]
    if not shown and not lost:
        return []
    name = html.escape(f"{acquisition.get('acquired_utc') or 'no time'}: {acquisition.get('path')}")
    note = f'<p class="note">and {more} more edge figure(s) beside the scan\'s outputs</p>' if more > 0 else ""
    if lost:
        note += ('<p class="warning">Missing (moved or deleted): '
                 + ", ".join(f'<code title="looked for {html.escape(where)}">{html.escape(stored)}</code>'
                             for stored, where in lost) + "</p>")
    return [f'<div class="figure"><h3>{name}</h3>' + "".join(shown) + note + "</div>"]
