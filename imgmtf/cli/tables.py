"""The text the commands print: the measure table's rows, the scan table and
the fit report (figures in px units, '-' where undefined)."""
from __future__ import annotations

import textwrap

import click

from ..errors import READ_REASONS
from ..kinds import get_kind
from .hints import hinted_warning, refusal_hint, rejection_hint

#: the columns a text table's rows fit in
TABLE_WIDTH = 120
#: the widest a table's path column grows (characters), so that its rows fit 120 columns
MAX_PATH_COLUMN = 36


#: the widest fit's edge column grows: its rows' other columns take 73 characters
FIT_EDGE_COLUMN = 46


def path_labels(paths, width: int = MAX_PATH_COLUMN) -> tuple[dict[str, str], str]:
    """Each path (or source, ``path[x,y,w,h]``) as a table's column shows
    it, and the folder left out of every label (``""`` for none): the paths
    as given when the longest fits ``width``; else below the folder they
    all share, and a label still too long keeps its start and its end
    (the file's name and extension, an ROI) about ``...``.

    Examples
    --------
    >>> path_labels(["a.tif", "data/b.tif"])
    ({'a.tif': 'a.tif', 'data/b.tif': 'data/b.tif'}, '')
    >>> labels, folder = path_labels(["/archive/site/2021/scene_a.tif", "/archive/site/2022/b.tif"], width=20)
    >>> list(labels.values()), folder
    (['2021/scene_a.tif', '2022/b.tif'], '/archive/site')
    """
    import os
    paths = list(dict.fromkeys(paths))
    if not paths or max(map(len, paths)) <= width:
        return {p: p for p in paths}, ""
    try:
        folder = os.path.commonpath([os.path.dirname(p) or "." for p in paths])
    except ValueError:                      # absolute and relative paths mixed: no folder shared
        folder = ""
    cut = len(folder.rstrip("/")) + 1 if folder and folder != "." else 0
    labels = {p: p[cut:] if cut else p for p in paths}
    head = (width - 3) // 3
    short = {p: label if len(label) <= width else label[:head] + "..." + label[-(width - 3 - head):]
             for p, label in labels.items()}
    # labels that no longer tell the paths apart are not shortened
    return (short if len(set(short.values())) == len(short) else labels), folder if cut else ""


class TextRows:
    """The text table of ``measure``, one row per record as it comes: the
    path column as wide as the longest input's label (:func:`path_labels`:
    at most :data:`MAX_PATH_COLUMN`, so that rows fit 120 columns), the
    band column when bands were asked for."""

    def __init__(self, kind: str, paths=(), bands: bool = False):
        self.kind, self.bands = kind, bands
        self.labels, self.folder = path_labels(paths)
        self.path_width = max([4, *map(len, self.labels.values())])

    def header(self, confidence: float) -> None:
        last = get_kind(self.kind).column
        if self.folder:
            click.echo(f"paths below {self.folder}/")
        first = f"{'path':<{self.path_width}}" + (f" {'band':>4}" if self.bands else "")
        blank = " " * len(first)
        click.echo(f"{first} {'normal':>7} {'tilt':>5} {'dir':>7} {'SNR':>5} {'MTF@Nyq':>7} "
                   f"{f'{100 * confidence:g}% interval':>17} {'MTF50':>7} {'FWHM':>6} {last.heading:>6}")
        click.echo(f"{blank} {'deg':>7} {'deg':>5} {'':>7} {'':>5} {'':>7} {'':>17} "
                   f"{'cy/px':>7} {'px':>6} {last.unit:>6}".rstrip())

    def write(self, record) -> None:
        """A record's rows; a file that cannot be read, one error line on
        stderr instead (as ``scan`` and ``fit`` say it; its CSV and JSON row stay)."""
        if record.status == "error" and record.reason in READ_REASONS:
            click.echo(f"imgmtf: error: {record.error}{refusal_hint(record.reason, record.error or '', record.path)}",
                       err=True)
            return
        click.echo(text_row(record.to_dict(), self.kind, self.path_width, self.bands,
                            self.labels.get(record.path)))


def text_row(record: dict, kind: str, path_width: int = 32, bands: bool = False, label: str | None = None) -> str:
    """One record as rows of the text table: figures in px units, a
    ground line in metres when the GSD is known, then its warnings; the
    path shown as ``label`` when given."""
    first = f"{label or record['path']:<{path_width}}"
    if bands:
        band = record["band"]
        first += f" {'lum' if band == 'luminance' else '' if band is None else band:>4}"
    indent = " " * len(first)
    feature = feature_line(record, indent)
    if record["status"] == "error":
        hint = refusal_hint(record.get("reason"), record.get("error") or "", record["path"])
        # an error stays on one line, whatever its length: one line to grep per file that failed
        return f"{first} error: {record['error']}{hint}" + (f"\n{feature}" if feature else "")
    last = record.get(get_kind(kind).column.field)
    lo, hi = record.get("mtf_nyquist_ci") or (None, None)
    interval = f"[{lo:.4f},{hi:.4f}]" if lo is not None and hi is not None else "-"
    direction = direction_cell(record.get("direction"))
    cells = [f"{first} {num_cell(record.get('normal_angle_deg'), 7, 2)} "
             f"{num_cell(record.get('tilt_deg'), 5, 1)} {direction:>7} "
             f"{snr_cell(record.get('snr'))} {num_cell(record.get('mtf_nyquist'), 7, 4)} {interval:>17} "
             f"{num_cell(record.get('mtf50_cy_px'), 7, 4)} {num_cell(record.get('fwhm_px'), 6, 3)} "
             f"{num_cell(last, 6, 0 if isinstance(last, int) else 3)}"]
    if feature:
        cells.append(feature)
    if record.get("radial_distance_px") is not None:
        cells.append(f"{indent} {record.get('field_direction') or 'at the optical centre'}, "
                     f"{record['radial_distance_px']:g} px from the optical centre")
    if record.get("gsd_m"):     # MTF50 '-' behind a bar's sinc zero; a FWHM the target has none of (a star's) left out
        fwhm = record.get("fwhm_m")
        cells.append(f"{indent} on the ground (GSD {record['gsd_m']:g} m): MTF50 "
                     f"{ground_cell(record.get('mtf50_cy_m'))} cy/m" + ("" if fwhm is None else f", FWHM {fwhm:.4g} m"))
    if record["status"] == "untrusted":
        cells.append(f"{indent} error: {record['error']}")
    cells += [warning_text(f"{indent} ", w) for w in record.get("warnings") or []]
    return "\n".join(cells)


def echo_lines(lines: list[str]) -> None:
    """Print ``lines`` with one echo (as an echo each would: none for no line)."""
    if lines:
        click.echo("\n".join(lines))


def echo_wrapped(text: str, indent: str = "    ") -> None:
    """Print a table's heading or note wrapped to :data:`TABLE_WIDTH`
    columns, its later lines indented by ``indent``."""
    click.echo(_fill(text, "", indent))


def _fill(text: str, first: str, later: str) -> str:
    """``text`` wrapped to :data:`TABLE_WIDTH` columns after the indents
    ``first`` and ``later``, never between a number and its per cent
    sign ("0.25 %")."""
    kept = text.replace(" %", "\N{NO-BREAK SPACE}%")
    return textwrap.fill(kept, TABLE_WIDTH, initial_indent=first, subsequent_indent=later, break_long_words=False,
                         break_on_hyphens=False).replace("\N{NO-BREAK SPACE}", " ")


def warning_text(indent: str, warning: str, hint: bool = True) -> str:
    """A warning (with its hint, unless ``hint`` is False) under a table's
    row: wrapped to the table's :data:`TABLE_WIDTH` columns, its lines after
    the first under its words (a whole warning on one line ran to 250
    columns)."""
    head = f"{indent}warning: "
    return _fill(hinted_warning(warning) if hint else warning, head, " " * len(head))


def direction_cell(direction: str | None) -> str:
    """A direction as the table's 7-character ``dir`` column shows it:
    across and along track short, an angle without its unit (the
    ``normal`` column beside it is in degrees), '-' for none.

    Examples
    --------
    >>> [direction_cell(d) for d in ("across-track", "112.5deg", "45deg", None)]
    ['across', '112.5', '45', '-']
    """
    if not direction:
        return "-"
    direction = SHORT_DIRECTIONS.get(direction, direction)
    return direction[:-3] if direction.endswith("deg") else direction


def feature_line(record: dict, indent: str) -> str:
    """The vector feature a row measured (--roi-file): its id, window and
    attributes; '' for a row of no feature."""
    if record.get("feature_id") is None:
        return ""
    attributes = ", ".join(f"{k}={v}" for k, v in (record.get("feature") or {}).items())
    window = record.get("feature_window_px")
    where = f" (x {window[0]}, y {window[1]}, {window[2]} x {window[3]} px)" if window else ""
    return f"{indent} feature {record['feature_id']}{where}" + (f": {attributes}" if attributes else "")


def ground_cell(value) -> str:
    """A figure in metres to 4 significant digits; '-' where it is not
    defined (a bar's MTF50 behind its sinc's zero)."""
    return "-" if value is None else f"{value:.4g}"


def snr_cell(value) -> str:
    """The SNR in the table's 5 characters: to the unit up to 99999, then
    in thousands (a noise-free chip's can reach millions)."""
    if value is None:
        return f"{'-':>5}"
    return f"{value:5.0f}" if value < 99999.5 else f"{value / 1000:4.0f}k"


def num_cell(value, width: int, decimals: int) -> str:
    """A figure to ``decimals`` places right-aligned in ``width``; '-' where
    undefined; never a signed zero ("-0.00" reads as 0.00)."""
    if value is None:
        return f"{'-':>{width}}"
    text = f"{value:.{decimals}f}"
    return f"{text.removeprefix('-') if float(text) == 0 else text:>{width}}"


def _parameter_name(key: str, pixel_units: bool) -> str:
    """A fitted parameter's name as the table shows it: with no GSD its
    value is in px, and the name says so (``optics.sigma_x_px``, not ``_m``).

    Examples
    --------
    >>> _parameter_name("electronics.cutoff_cy_m", True), _parameter_name("optics.sigma_x_m", False)
    ('electronics.cutoff_cy_px', 'optics.sigma_x_m')
    """
    return key[:-2] + "_px" if pixel_units and key.endswith("_m") else key


def print_fit(result) -> None:
    edges = result.edges
    scale = "no GSD: lengths in px" if result.pixel_units else f"GSD {result.sensor.gsd_m:g} m"
    click.echo(f"fit of {', '.join(s.name for s in result.sensor.stages)} to {len(edges)} edge(s), "
               f"{scale}; reduced chi-square {result.reduced_chi_square:.3g}")
    if result.choice is not None:
        tried = "; ".join(f"{'+'.join(c.stages)}: BIC {c.bic:.0f}{', misfit' if c.misfit else ''}"
                          for c in result.choice.candidates)
        failed = "".join(f"; {'+'.join(stages)}: did not converge" for stages, _ in result.choice.failed)
        click.echo(f"stages auto: {result.choice.reason} ({tried}{failed})")
    click.echo(f"{'parameter':<28} {'value':>11} {'std err':>10} {'unit':<5} status")
    for p in result.parameters:
        se = f"{p.standard_error:10.4g}" if p.status == "fitted" else f"{'-':>10}"
        unit = "cy/px" if result.pixel_units and p.unit == "cy/m" else p.unit
        head = f"{_parameter_name(p.key, result.pixel_units):<28} {p.value:11.5g} {se} {unit:<5} "
        status = textwrap.wrap(f"{p.status}{': ' + p.note if p.note else ''}", TABLE_WIDTH - len(head),
                               subsequent_indent="  ")         # a long note under its status: 120 columns
        click.echo("\n".join([head + status[0], *(" " * len(head) + line for line in status[1:])]))
    for a, b, r in result.correlations:
        a, b = (_parameter_name(k, result.pixel_units) for k in (a, b))
        click.echo(f"correlated: {a} and {b} (r = {r:+.3f}): the data constrain a combination of them "
                   "better than each")
    pct = f"{100 * result.confidence:g}%"
    labels, folder = path_labels((e.source for e in edges), width=FIT_EDGE_COLUMN)
    width = max([4, *map(len, labels.values())])
    if folder:
        click.echo(f"edges below {folder}/")
    click.echo(f"{'edge':<{width}} {'normal':>6} {'dir':>7} {'axis':>6} {'MTF@Nyq':>7} {pct + ' interval':>17} "
               f"{'measured':>8} {'chi2':>6} {'misfit':>7}")
    axes = {"across": "x", "along": "y"} if result.pixel_units else {}
    for e in edges:
        lo, hi = e.mtf_nyquist_ci
        direction = direction_cell(e.direction)
        click.echo(f"{labels[e.source]:<{width}} {e.normal_angle_deg:6.2f} {direction:>7} "
                   f"{axes.get(e.constrains, e.constrains):>6} {e.mtf_nyquist:7.4f} "
                   f"{f'[{lo:.4f},{hi:.4f}]':>17} {e.measured_mtf_nyquist:8.4f} {e.reduced_chi_square:6.3g} "
                   f"{100 * e.misfit_fraction:6.2f}%")
    click.echo(f"{'direction':<10} {'MTF@Nyq':>7} {pct + ' interval':>17} {'MTF50 cy/px':>11}")
    names = {"across": "horizontal", "along": "vertical"} if result.pixel_units else {}
    for name, d in result.directions.items():
        lo, hi = d["mtf_nyquist_ci"]
        click.echo(f"{names.get(name, name):<10} {d['mtf_nyquist']:7.4f} {f'[{lo:.4f},{hi:.4f}]':>17} "
                   f"{num_cell(d['mtf50_cy_px'], 11, 4)}{'' if d['constrained'] else '  (no edge: extrapolated)'}")
    for warning in result.warnings:
        click.echo(warning_text("", warning))


def print_scan(scene, info, kind, records, summaries, written, fmt, verbose: bool = False) -> None:
    """A scene's scan: the accepted candidates, then (unless ``verbose``,
    which prints every candidate) one line per rejection reason with its
    count and example ids, then the combined and fitted rows."""
    if fmt == "json":
        import sys

        from ..records import JsonRows, write_whole
        rows = JsonRows()
        write_whole(sys.stdout, "".join(rows.line(r) + "\n" for r in (*records, *summaries)))
        return
    accepted = sum(r.ok for r in records)
    click.echo(f"{scene}: {info.width} x {info.height} px, {plural(len(records), f'candidate {kind}')}, "
               f"{accepted} accepted")
    print_features(records, kind)
    shown = records if verbose else [r for r in records if r.ok]
    if shown:
        click.echo(f"{'id':>4} {'rank':>4} {'tgt':>3} {'dir':>7} {'normal':>7} {'len':>5} {'SNR':>5} {'MTF@Nyq':>7} "
                   f"{'interval':>15} {'MTF50':>7}  ROI x,y,w,h / reason")
        click.echo(f"{'':>4} {'':>4} {'':>3} {'':>7} {'deg':>7} {'px':>5} {'':>5} {'':>7} {'':>15} {'cy/px':>7}")
    lines = []          # one echo for the table (an echo a row cost more than the row: a dense chart has thousands)
    for record in shown:
        r = record.to_dict()
        head = (f"{r['id']:>4} {r.get('rank') or '':>4} {r.get('target_id') or '':>3} "
                f"{SHORT_DIRECTIONS.get(r.get('direction'), r.get('direction') or '-'):>7} "
                f"{num_cell(r.get('normal_angle_deg'), 7, 2)} {r['length_px']:5.0f}")
        if record.ok:
            roi = ",".join(str(v) for v in r["roi"])
            lines.append(f"{head} {snr_cell(r.get('snr'))} {num_cell(r.get('mtf_nyquist'), 7, 4)} "
                         f"{interval_cell(r.get('mtf_nyquist_ci')):>15} {num_cell(r.get('mtf50_cy_px'), 7, 4)}  {roi}")
            for warning in r.get("warnings") or []:
                lines.append(warning_text(" " * (len(head) + 1), warning))
        else:       # the scene's name heads the table: the message need not repeat it
            lines.append(f"{head} {'rejected':>37}  {r['reason']}: {_rejection(r)}")
    echo_lines(lines)
    if not verbose:
        print_rejections([r for r in records if not r.ok])
    combined = [r for r in summaries if r.figures.get("summary") not in ("fit", "sections")]
    sections = [r for r in summaries if r.figures.get("summary") == "sections"]
    fitted = [r for r in summaries if r.figures.get("summary") == "fit"]
    if combined:
        echo_wrapped("combined per target and per direction, weighted by precision (consistency over 1: "
                     "the half-edges disagree beyond their intervals):")
        click.echo(f"{'scope':>6} {'tgt':>3} {'dir':>7} {'normal':>7} {'edges':>5} {'MTF@Nyq':>7} "
                   f"{'interval':>15} {'MTF50':>7} {'interval':>15} {'FWHM':>6} {'consist.':>8}")
        lines = []
        for summary in combined:
            r = summary.to_dict()
            lines.append(f"{r['scope']:>6} {r.get('target_id') or '':>3} "
                         f"{SHORT_DIRECTIONS.get(r['direction'], r['direction']):>7} "
                         f"{num_cell(r['normal_angle_deg'], 7, 2)} "
                         f"{r['n_edges']:>5} {num_cell(r['mtf_nyquist'], 7, 4)} "
                         f"{interval_cell(r['mtf_nyquist_ci']):>15} "
                         f"{num_cell(r.get('mtf50_cy_px'), 7, 4)} {interval_cell(r.get('mtf50_ci_cy_px')):>15} "
                         f"{num_cell(r.get('fwhm_px'), 6, 3)} {num_cell(r.get('consistency'), 8, 2)}")
        echo_lines(lines)
    if sections:
        print_sections(sections)
    if fitted:
        print_target_fits(fitted)
    print_recommended(sections + fitted)
    for path in written:
        click.echo(f"wrote {path}")


def print_features(records, kind: str) -> None:
    """With --roi-file: per feature, its attributes and how many of its
    candidates were accepted (the scan measured only those crossing one)."""
    counts: dict[str, list] = {}
    for record in records:
        fid = record.site.get("feature_id")
        if fid is not None:
            entry = counts.setdefault(fid, [record.site.get("feature") or {}, 0, 0,
                                            record.site.get("feature_window_px")])
            entry[1] += 1
            entry[2] += record.ok
    for fid, (attributes, found, accepted, window) in counts.items():
        shown = ", ".join(f"{k}={v}" for k, v in attributes.items())
        where = f" (x {window[0]}, y {window[1]}, {window[2]} x {window[3]} px)" if window else ""
        click.echo(f"  feature {fid}{where}{f' [{shown}]' if shown else ''}: {plural(found, f'candidate {kind}')} "
                   f"crossing it, {accepted} accepted")


def print_lens_profile(profile) -> None:
    """A lens profile's rings: per direction and ring, its edges' median
    MTF50 and MTF at the profile's frequencies."""
    x, y = profile.centre_px
    click.echo(f"lens profile about the optical centre ({x:g}, {y:g}) px: medians per ring of the field")
    heads = "".join(f" {f'MTF@{f:g}':>9}" for f in profile.frequencies_cy_px)
    click.echo(f"{'direction':<10} {'ring px':>11} {'edges':>5} {'MTF50':>7}{heads}")
    click.echo(f"{'':<10} {'':>11} {'':>5} {'cy/px':>7}" + "".join(f" {'':>9}" for _ in profile.frequencies_cy_px))
    for ring in profile.rings:
        cells = "".join(f" {num_cell(v, 9, 4)}" for v in ring.mtf)
        click.echo(f"{ring.field_direction:<10} {f'{ring.inner_px:.0f}-{ring.outer_px:.0f}':>11} {ring.n_edges:>5} "
                   f"{num_cell(ring.mtf50_cy_px, 7, 4)}{cells}")


def print_target_fits(fitted) -> None:
    """The sensor model fitted to each target's half-edges, across and along
    track, and why a fit is not to be trusted (its misfit) or failed."""
    stages: list[str] = next((r.figures["stages"] for r in fitted if r.figures.get("stages")), [])
    echo_wrapped(f"fitted per target, {axes_words(fitted)} (sensor model: {', '.join(stages) or '-'}; "
                 "misfit p: the smallest p-value of structure in its half-edges' residuals):")
    click.echo(f" {'scope':>6} {'tgt':>3} {'dir':>7} {'edges':>5} {'MTF@Nyq':>7} {'interval':>15} "
               f"{'MTF50':>7} {'interval':>15} {'FWHM':>6} {'RER':>6} {'misfit p':>8}")
    warned: set[str] = set()
    hinted = False
    for summary in fitted:
        r = summary.to_dict()
        head = f"{_mark(r)}{r['scope']:>6} {r.get('target_id') or '':>3}"
        if not summary.ok:
            click.echo(f"{head} {'fit failed':>7}  {r['reason']}: {r['error'].removeprefix(r['path'] + ': ')}")
            continue
        p = r.get("misfit_p")
        click.echo(f"{head} {SHORT_DIRECTIONS.get(r['direction'], r['direction']):>7} {r['n_edges']:>5} "
                   f"{num_cell(r['mtf_nyquist'], 7, 4)} {interval_cell(r['mtf_nyquist_ci']):>15} "
                   f"{num_cell(r.get('mtf50_cy_px'), 7, 4)} {interval_cell(r.get('mtf50_ci_cy_px')):>15} "
                   f"{num_cell(r.get('fwhm_px'), 6, 3)} {num_cell(r.get('rer'), 6, 3)} "
                   f"{'-' if p is None else f'{p:.2g}':>8}{'  MISFIT' if r.get('misfit') else ''}")
        for warning in r.get("warnings") or []:
            if warning not in warned:           # across and along share their fit's warnings
                warned.add(warning)
                click.echo(warning_text(" " * 12, warning))
                if "does not fit" in warning and not hinted:
                    hinted = True
                    click.echo(f"{'':>11} (--fit-stages fits other stages; the combined and sections rows "
                               "assume no model)")


def print_sections(sections) -> None:
    """The 2-D MTF's across- and along-track sections from each target's
    combined directions, under each assumption, and why the chosen one."""
    click.echo(f"{axes_words(sections)} without a model (the 2-D MTF's sections from the combined directions, "
               "under each assumption):")
    click.echo(f" {'scope':>6} {'tgt':>3} {'dir':>7} {'assumption':>10} {'edges':>5} {'MTF@Nyq':>7} {'interval':>15} "
               f"{'MTF50':>7} {'interval':>15} {'FWHM':>6}")
    said: set[tuple] = set()
    lines = []
    for summary in sections:
        r = summary.to_dict()
        key = (r["scope"], r.get("target_id"))
        lines.append(f"{_mark(r)}{r['scope']:>6} {r.get('target_id') or '':>3} "
                     f"{SHORT_DIRECTIONS.get(r['direction'], r['direction']):>7} {r['assumption']:>10} "
                     f"{r['n_edges']:>5} {num_cell(r['mtf_nyquist'], 7, 4)} {interval_cell(r['mtf_nyquist_ci']):>15} "
                     f"{num_cell(r.get('mtf50_cy_px'), 7, 4)} {interval_cell(r.get('mtf50_ci_cy_px')):>15} "
                     f"{num_cell(r.get('fwhm_px'), 6, 3)}")
        if key not in said and r["assumption"] == r.get("chosen_assumption") and r["direction"] in ("along-track",
                                                                                                     "vertical"):
            said.add(key)
            lines.append(f"{'':>11} {r['chosen_assumption']}: {r.get('assumption_because')}")
    echo_lines(lines)


def axes_words(rows) -> str:
    """How a scan's summaries name their two directions: the image's axes
    for a camera's image (horizontal, vertical), else the track's."""
    if any(r.figures.get("direction") in ("horizontal", "vertical") for r in rows):
        return "horizontal and vertical"
    return "across and along track"


def print_recommended(rows) -> None:
    """The legend of the recommended rows' mark, and the directions whose
    only rows are misfit fits (no figure to quote)."""
    if not any(r.figures.get("recommended") is not None for r in rows):
        return
    if any(r.figures.get("recommended") for r in rows):
        pair = "horizontal/vertical" if axes_words(rows).startswith("horizontal") else "across/along"
        echo_wrapped(f"* the {pair} row to quote per target and direction: the model's fit when it fits and "
                     "agrees with the sections, else the sections' assumption", indent="  ")
    directions: dict[tuple, list] = {}
    for r in rows:
        if r.ok and r.figures.get("direction") in SHORT_DIRECTIONS:
            directions.setdefault((r.site.get("scope"), r.site.get("target_id"), r.figures["direction"]), []).append(r)
    for (scope, target, direction), group in directions.items():
        if not any(r.figures.get("recommended") for r in group):
            where = "the scene" if scope != "target" else f"target {target}"
            click.echo(f"{where} {direction}: only misfit fit rows, no figure to quote (the model does not fit; "
                       "a second orientation of edge gives the sections)")


def _mark(row: dict) -> str:
    return "*" if row.get("recommended") else " "


SHORT_DIRECTIONS = {"across-track": "across", "along-track": "along", "horizontal": "horiz", "vertical": "vert"}

MAX_EXAMPLE_IDS = 5


def print_rejections(rejected) -> None:
    """One line per rejection reason, most frequent first: how many, a few
    ids (as the overview labels them) and the first one's message."""
    by_reason: dict[str, list] = {}
    for record in rejected:
        by_reason.setdefault(record.reason, []).append(record)
    for reason, group in sorted(by_reason.items(), key=lambda item: (-len(item[1]), item[0])):
        ids = [str(r.get("id")) for r in group[:MAX_EXAMPLE_IDS]]
        more = f" and {len(group) - MAX_EXAMPLE_IDS} more" if len(group) > MAX_EXAMPLE_IDS else ""
        echo_wrapped(f"rejected {len(group):>4} {reason} (id {', '.join(ids)}{more}): "
                     f"e.g. {_rejection(group[0].to_dict())}", indent=" " * 14)
    if rejected:
        click.echo("  (--verbose lists every candidate)")


def _rejection(row: dict) -> str:
    """A rejected candidate's message without the scene's name (the table's
    heading names it), with the option that moves its limit."""
    message = row["error"].removeprefix(row["path"] + ": ")
    return message + rejection_hint(row["reason"], message)


def plural(count: int, noun: str) -> str:
    """"1 candidate edge", "17 candidate edges"."""
    return f"{count} {noun}{'' if count == 1 else 's'}"


def interval_cell(pair) -> str:
    lo, hi = pair or (None, None)
    return f"[{lo:.4f},{hi:.4f}]" if lo is not None and hi is not None else "-"
