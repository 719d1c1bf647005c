"""The campaign report: ``trend.csv`` and one self-contained ``report.html``
from a campaign store.

The page holds, per platform, band, direction and method, the four
figures of merit against time (:func:`imgmtf.plot.plot_campaign`) with the
requirement, the pre-launch value and the drift; the table of drifts; and
the table of acquisitions with each one's overview and edge figures when
the store recorded them.  Every figure is embedded (PNG, base64) and the
style is inline: the page fetches nothing, so it opens offline, from a
mail attachment or an archive, as it was written.
"""
from __future__ import annotations

import base64
import html
import io
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..atomic import atomic_output, ensure_folder
from ..errors import FileWriteError, ParameterError
from ..records import utc_now
from ..version import __version__
from .store import read_layer
from .trend import GROUP_KEYS, Trend, campaign_rows, trend_points, trends, write_trend_csv

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
.note { color: #555; font-size: 0.92em; }
img { max-width: 100%; height: auto; } img.thumb { width: 360px; margin: 2px; border: 1px solid #ddd; }
.figure { margin: 10px 0 24px; } code { font-size: 0.95em; }
"""


@dataclass(frozen=True)
class ReportFiles:
    """What :func:`write_report` wrote: ``trend_csv``, ``report_html``, and
    the ``trends`` found."""

    trend_csv: str
    report_html: str
    trends: tuple[Trend, ...]


def baseline_values(sensor_path: str | Path | None) -> dict[str, float]:
    """The pre-launch MTF at Nyquist per direction (``across-track``,
    ``along-track``) of a sensor TOML (:meth:`imgmtf.Sensor.from_toml`);
    empty without one."""
    if sensor_path is None:
        return {}
    from ..sensor.model import Sensor
    sensor = Sensor.from_toml(sensor_path)
    return {"across-track": sensor.mtf_nyquist("across"), "along-track": sensor.mtf_nyquist("along")}


def write_report(store_path: str | Path, out_dir: str | Path, *, requirement: float | None = None,
                 baseline: str | Path | None = None, confidence: float = 0.95) -> ReportFiles:
    """Write ``trend.csv`` and ``report.html`` of a campaign store into ``out_dir``.

    Parameters
    ----------
    store_path : str or pathlib.Path
        The campaign store (:mod:`imgmtf.campaign.store`).
    out_dir : str or pathlib.Path
        The folder (created if missing).
    requirement : float, optional
        The MTF at Nyquist required, drawn as a line.
    baseline : str or pathlib.Path, optional
        A sensor TOML whose across- and along-track MTF at Nyquist are the
        pre-launch values drawn against those directions.
    confidence : float
        Of the drift intervals.

    Returns
    -------
    ReportFiles

    Raises
    ------
    StoreError
        The store cannot be read.
    ConfigError
        The sensor TOML cannot be read.
    FileWriteError
        An output cannot be written.
    ParameterError
        A requirement that is not a finite number.
    """
    if requirement is not None and not math.isfinite(requirement):
        raise ParameterError(f"the requirement must be a finite MTF, got {requirement!r}")
    acquisitions = read_layer(store_path, "acquisitions")
    targets = read_layer(store_path, "targets")
    edges = read_layer(store_path, "edges")
    points = campaign_rows(targets, edges)
    found = tuple(trends(points, confidence))
    prelaunch = baseline_values(baseline)
    folder = ensure_folder(out_dir)
    trend_csv, report_html = str(folder / "trend.csv"), str(folder / "report.html")
    write_trend_csv(found, trend_csv)
    page = _page(str(store_path), acquisitions, points, edges, found, requirement, prelaunch,
                 str(baseline) if baseline else None)
    with atomic_output(report_html) as partial:
        try:
            Path(partial).write_text(page, encoding="utf-8")
        except OSError as exc:
            raise FileWriteError(f"{report_html}: cannot write: {exc.strerror or exc}") from None
    return ReportFiles(trend_csv, report_html, found)


def _png(fig) -> str:
    """A matplotlib figure as an embedded PNG's ``src``."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90)
    return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


def _embedded(path: str | None) -> str | None:
    """An image file's ``src`` as data (PNG, JPEG, SVG), None when it is not there."""
    if not path:
        return None
    kinds = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".svg": "image/svg+xml"}
    kind = kinds.get(Path(path).suffix.lower())
    try:
        data = Path(path).read_bytes() if kind else None
    except OSError:
        return None
    return f"data:{kind};base64," + base64.b64encode(data).decode("ascii") if data else None


def _text(value, digits: int = 4) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    if isinstance(value, float):
        return f"{value:.{digits}g}" if abs(value) >= 1e-3 or value == 0 else f"{value:.2e}"
    return html.escape(str(value))


def _group_title(key: Sequence) -> str:
    platform, band, direction, method = (v if v is not None else "unknown" for v in key)
    return f"{platform}, band {band}: {direction}, {method}"


def _page(store: str, acquisitions: list[dict], points: list[Mapping], edges: list[dict], found: Sequence[Trend],
          requirement: float | None, prelaunch: Mapping[str, float], baseline: str | None) -> str:
    from ..plot.campaign import plot_campaign
    timed = [a for a in acquisitions if a.get("acquired_utc")]
    span = sorted(a["acquired_utc"] for a in timed)
    parts = [f"<h1>MTF calibration campaign: {html.escape(Path(store).name)}</h1>",
             f'<p class="note">Store <code>{html.escape(store)}</code>: {len(acquisitions)} acquisition(s)'
             + (f", {html.escape(span[0])} to {html.escape(span[-1])}" if span else "")
             + (f"; {len(acquisitions) - len(timed)} without an acquisition time, left out of the trends"
                if len(timed) < len(acquisitions) else "")
             + f". Report by imgmtf {html.escape(__version__)}, {utc_now()}."
             + (f" Requirement: MTF at Nyquist {requirement:g}." if requirement is not None else "")
             + (f" Pre-launch values from <code>{html.escape(baseline)}</code>: across-track "
                f"{prelaunch['across-track']:.4f}, along-track {prelaunch['along-track']:.4f}." if baseline else "")
             + "</p>"]
    parts += _trend_table(found, "Drift of the MTF at Nyquist", ("mtf_nyquist",))
    by_group: dict[tuple, list[Trend]] = {}
    for trend in found:
        by_group.setdefault(tuple(getattr(trend, k) for k in GROUP_KEYS), []).append(trend)
    parts.append("<h2>Figures of merit against time</h2>")
    groups = trend_points(points)
    if not groups:
        parts.append('<p class="note">No acquisition with a time and a result: nothing to trend.</p>')
    for key, group in groups.items():
        direction = key[2]
        fig = plot_campaign(group, by_group.get(key, []), requirement=requirement,
                            baseline=prelaunch.get(direction))
        title = html.escape(_group_title(key))
        parts.append(f'<div class="figure"><h3>{title}</h3><img src="{_png(fig)}" width="1215" height="594" '
                     f'alt="MTF at Nyquist, MTF50, FWHM and RER against time: {title}"></div>')
    parts += _trend_table(found, "Drift of MTF50, FWHM and RER", ("mtf50_cy_px", "fwhm_px", "rer"))
    parts += _acquisition_table(acquisitions, points, edges)
    body = "\n".join(parts)
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">\n'
            f"<title>MTF campaign: {html.escape(Path(store).name)}</title>\n<style>{_STYLE}</style>\n"
            f"</head>\n<body>\n{body}\n</body>\n</html>\n")


def _when(text) -> str:
    """An ISO 8601 UTC time as a table shows it: to the minute, no T or Z."""
    if not text:
        return ""
    return html.escape(text[:16].replace("T", " ") if "T" in text else text)


def _trend_table(found: Sequence[Trend], title: str, figures: Sequence[str]) -> list[str]:
    """The drifts of ``figures`` as a table headed ``title``."""
    chosen = [t for t in found if t.figure in figures]
    out = [f"<h2>{html.escape(title)}</h2>"]
    if not chosen:
        return [*out, '<p class="note">No group has acquisitions at two times yet.</p>']
    out.append('<p class="note">Slope of a weighted least-squares line per year (365.25 days), with its '
               f"{100 * chosen[0].confidence:g} % interval; a drift when the interval excludes 0. All in "
               "<code>trend.csv</code>.</p>")
    head = ("platform", "band", "direction", "method", *(("figure",) if len(figures) > 1 else ()),
            "acquisitions", "first (UTC)", "last (UTC)", "value at first", "slope per year", "interval", "drift")
    out.append('<table class="trend"><tr>' + "".join(f"<th>{h}</th>" for h in head) + "</tr>")
    for t in chosen:
        interval = (f"[{t.slope_ci_low:+.4g}, {t.slope_ci_high:+.4g}]" if math.isfinite(t.slope_ci_low)
                    else "too few points")
        cells = [_text(t.platform), _text(t.band_name), _text(t.direction), _text(t.method),
                 *((t.figure,) if len(figures) > 1 else ()), str(t.n_acquisitions), _when(t.first_utc),
                 _when(t.last_utc)]
        numbers = [_text(t.value_at_first), f"{t.slope_per_year:+.4g}", interval, "yes" if t.drift else "no"]
        row = "".join(f"<td>{c}</td>" for c in cells) + "".join(f'<td class="num">{c}</td>' for c in numbers)
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
    direction = _text(row.get("direction"))
    if row.get("direction") not in ("across-track", "along-track") and row.get("normal_angle_deg") is not None:
        direction += f" {row['normal_angle_deg']:.1f} deg"
    return (f'<span class="time">{where}, {direction}, {_text(row.get("method"))}: '
            f"{_mtf(row.get('mtf_nyquist'))}{interval}{misfit}</span>")


def _acquisition_table(acquisitions: list[dict], points: list[Mapping], edges: list[dict]) -> list[str]:
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
        figures.append(_acquisition_figures(a, [e for e in edges if e.get("acquisition_id") == ident], mine))
    out.append("</table>")
    shown = [f for f in figures[::-1] if f][:MAX_ACQUISITIONS_WITH_FIGURES][::-1]     # the latest
    if shown:
        left = sum(bool(f) for f in figures) - len(shown)
        out += ["<h2>Figures of each acquisition</h2>",
                *((f'<p class="note">The latest {len(shown)} acquisitions\' figures; {left} earlier ones have '
                   "theirs beside their files.</p>",) if left else ()),
                *(part for f in shown for part in f)]
    return out


def _acquisition_figures(acquisition: dict, edges: list[dict], targets: list[Mapping]) -> list[str]:
    """The acquisition's overview and first edge figures, embedded (those the store names and that exist)."""
    shown = []
    overview = _embedded(acquisition.get("overview"))
    if overview:
        shown.append(f'<img src="{overview}" style="max-width: 760px" alt="overview of '
                     f'{html.escape(str(acquisition.get("path")))}">')
    paths = list(dict.fromkeys(p for p in (r.get("plot") for r in (*targets, *edges)) if p))
    thumbs = [(p, _embedded(p)) for p in paths]
    present = [(p, src) for p, src in thumbs if src]
    for path, src in present[:MAX_EDGE_FIGURES]:
        shown.append(f'<img class="thumb" src="{src}" alt="{html.escape(Path(path).name)}" '
                     f'title="{html.escape(path)}">')
    more = len(present) - MAX_EDGE_FIGURES
    if not shown:
        return []
    name = html.escape(f"{acquisition.get('acquired_utc') or 'no time'}: {acquisition.get('path')}")
    note = f'<p class="note">and {more} more edge figure(s) beside the scan\'s outputs</p>' if more > 0 else ""
    return [f'<div class="figure"><h3>{name}</h3>' + "".join(shown) + note + "</div>"]
