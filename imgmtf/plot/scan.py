"""The overview figure of a scene scan: every candidate coloured by its verdict."""
from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure

from ..records import TARGET_SCOPE

if TYPE_CHECKING:
    from ..records import Record

_DIRECTION_SHORT = {"across-track": "across", "along-track": "along", "oblique": "oblique", "unknown": ""}


#: a reason's candidates up to which the legend lists their ids and the image labels them;
#: beyond, the legend counts them (their ids are in the table and the CSV)
MAX_LISTED = 24
#: one colour per reason, saturated enough to read on black and on white
PALETTE = ("#ff7f0e", "#e0202a", "#b07cff", "#ffd92f", "#ff5ec4", "#17d4e8", "#c5d625", "#ff9f9f",
           "#4f8bff", "#ffffff", "#b58b5b", "#9edae5")
ACCEPTED = "#00ff00"
#: the opacity of rejected candidates: a reason's few, labelled ones, and the many of a common reason
REJECTED_ALPHA, CROWD_ALPHA = 0.6, 0.45


def plot_scan(overview: np.ndarray, scale: float, records: Iterable[Record | Mapping[str, Any]],
              summaries: Iterable[Record | Mapping[str, Any]] = (), levels: tuple[float, float] | None = None,
              ax: Axes | None = None, width_in: float = 10.0) -> Figure | SubFigure:
    """The overview of a scan: the scene with every candidate drawn, coloured
    by its verdict and labelled with its id, as the table and the CSV list
    them.

    Parameters
    ----------
    overview : numpy.ndarray, shape (rows, cols)
        The scene decimated by ``scale`` scene px per overview px (DN).
    scale : float
        Scene pixels per overview pixel.
    records : iterable of Record or mapping
        The candidates' records (:class:`imgmtf.Record`, as
        :func:`imgmtf.scan_scene` returns them, or their ``to_dict()``):
        accepted ones are drawn as their tilted ROI (``roi_polygon_px``,
        outlined, unfilled: the scene shows through) and segment in
        green, above the rest; rejected ones as a line coloured by
        reason (outlined in black where the reason's few candidates carry
        their ids, so that they read on any background).  Each accepted
        candidate carries its id, and so do the rejected ones of a reason
        with at most ``MAX_LISTED`` candidates.
    summaries : iterable of Record or mapping, optional
        The per-target summaries (``scope`` "target", records or
        dicts, as :func:`imgmtf.summarise_scan` returns them): each
        target is labelled beside its centre with, per direction, MTF at
        Nyquist and MTF50 (cy/px), where it covers neither the accepted
        half-edges nor another label (a leader to its target when moved
        away), inside the image; many targets' labels shrink to the rows
        to quote, and a few targets that fill the image (a checkerboard's
        crop) are tagged by id with their labels beside the image.
    levels : (float, float), optional
        (black, white) DN of the display; default the 0.5 and 99.5
        percentiles.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on; a new figure, sized to the scene's aspect
        with no blank margins, when None.
    width_in : float, optional
        The new figure's width (inches), the legend's column to the right
        of the image included (default 10).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding the axes.

    Notes
    -----
    The legend, outside the image on its right, counts the candidates of
    each verdict and reason and lists their ids.  Drawn with one
    collection per reason and one for the accepted ROIs, so that a scene
    with thousands of candidates draws in a fraction of a second.

    Examples
    --------
    >>> import numpy as np
    >>> fig = plot_scan(np.zeros((50, 80)), 1.0, [])
    >>> float(fig.get_figwidth())
    10.0
    """
    from matplotlib import patheffects
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.lines import Line2D

    from ..records import Record
    candidates: list[Mapping[str, Any]] = [r.to_dict() if isinstance(r, Record) else r
                                           for r in records]     # scan_scene's own output
    summary_rows: list[Mapping[str, Any]] = [r.to_dict() if isinstance(r, Record) else r for r in summaries]
    height, width = overview.shape
    extent_w, extent_h = width * scale, height * scale
    fig: Figure | SubFigure
    if ax is None:
        margins = (0.7, 2.6, 0.55, 0.45)            # left, right (the legend), bottom, top (in)
        image_w = width_in - margins[0] - margins[1]
        image_h = image_w * extent_h / max(extent_w, 1e-9)
        fig = Figure(figsize=(width_in, max(image_h, 2.2) + margins[2] + margins[3]))
        fig_h = fig.get_figheight()
        ax = fig.add_axes((margins[0] / width_in, (fig_h - margins[3] - image_h) / fig_h, image_w / width_in,
                           image_h / fig_h))
    fig = ax.figure
    finite = np.isfinite(overview)
    lo, hi = levels or (np.percentile(overview[finite], [0.5, 99.5]) if finite.any() else (0.0, 1.0))
    ax.imshow(overview, cmap="gray", vmin=lo, vmax=hi if hi > lo else lo + 1,
              extent=(-0.5, extent_w - 0.5, extent_h - 0.5, -0.5), interpolation="nearest")
    ax.set(xlim=(-0.5, extent_w - 0.5), ylim=(extent_h - 0.5, -0.5))
    ax.tick_params(labelsize=8)
    ax.set_xlabel("column (px)", fontsize=8)
    ax.set_ylabel("row (px)", fontsize=8)
    accepted = [r for r in candidates if r.get("status") == "accepted"]
    rejected = [r for r in candidates if r.get("status") != "accepted"]
    outline = [patheffects.Stroke(linewidth=3.2, foreground="black"), patheffects.Normal()]
    labels = _Labels(ax, extent_w)
    handles = []
    by_reason: dict[str, list] = {}
    for r in rejected:
        by_reason.setdefault(r.get("reason") or "rejected", []).append(r)
    width = 1.2 if len(rejected) <= 300 else 0.8          # thousands of lines: thinner, the scene still shows
    unlabelled = 0
    for k, (reason, group) in enumerate(sorted(by_reason.items(), key=lambda kv: (-len(kv[1]), kv[0]))):
        colour = PALETTE[k % len(PALETTE)]
        # rejected: half-opaque; a reason too common to label bare (hundreds of outlines would hide the scene)
        listed = len(group) <= MAX_LISTED
        style = {"path_effects": outline, "alpha": REJECTED_ALPHA} if listed else {"alpha": CROWD_ALPHA}
        ax.add_collection(LineCollection([_ends(r) for r in group], colors=colour, linewidths=width, zorder=3,
                                         **style))
        handles.append(Line2D([], [], color=colour, lw=1.6, label=_legend_label(reason, group), **style))
        if listed:
            for r in group:
                labels.add(r, colour, "black", zorder=5)
        else:
            unlabelled += len(group)
    if accepted:
        polygons = [r["roi_polygon_px"] for r in accepted if r.get("roi_polygon_px")]
        ax.add_collection(PolyCollection(polygons, facecolors="none", edgecolors=ACCEPTED, linewidths=0.8,
                                         linestyles=(0, (4, 2)), alpha=0.8, zorder=4))
        ax.add_collection(LineCollection([_ends(r) for r in accepted], colors=ACCEPTED, linewidths=2.0,
                                         path_effects=outline, zorder=4))
        handles.insert(0, Line2D([], [], color=ACCEPTED, lw=2.2, path_effects=outline,
                                 label=_legend_label("accepted", accepted)))
        for r in accepted:          # each accepted half-edge's id, as in the table and the CSV
            labels.add(r, (0.85, 1.0, 0.85, 0.95), "#004d00", zorder=7, weight="bold")
    targets = [s for s in summary_rows if s.get("scope") == TARGET_SCOPE]
    target_labels = []
    for target_id in sorted({s["target_id"] for s in targets}):
        # of the sections, the chosen assumption's rows only (the table and the CSV hold the others)
        # a row with an MTF50 but no MTF at Nyquist (a blur that takes Nyquist under the noise) is labelled too
        rows = [s for s in targets if s["target_id"] == target_id
                and (s.get("mtf_nyquist") is not None or s.get("mtf50_cy_px") is not None)
                and (s.get("summary") != "sections" or s.get("assumption") == s.get("chosen_assumption"))]
        if rows:
            quoted = [s for s in rows if s.get("recommended")] or rows
            full = "\n".join([f"T{target_id}"] + [_row(s) for s in rows])
            short = "\n".join([f"T{target_id}"] + [_row(s, short=True) for s in quoted])
            target_labels.append(((rows[0]["x_px"], rows[0]["y_px"]), full, short))
    if handles:         # before the labels: a label set beside the image goes below it
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=8,
                  title="candidates (ids)", title_fontsize=8, alignment="left", frameon=False)
    # the ROIs' outlines and the labelled rejections are data a label should not hide either
    outlines = [(tuple(polygon[k - 1]), tuple(polygon[k])) for r in accepted if r.get("roi_polygon_px")
                for polygon in [r["roi_polygon_px"]] for k in range(len(polygon))]
    labelled = [_ends(r) for group in by_reason.values() if len(group) <= MAX_LISTED for r in group]
    compact = _place_target_labels(ax, target_labels, [_ends(r) for r in accepted], outlines, labelled)
    n_targets = len({s["target_id"] for s in targets})
    ids = "ids as in the table and the CSV" + (f", {unlabelled} in reasons too common to label" if unlabelled
                                                 else "")
    title = (f"{len(accepted)} accepted half-edge{'s' * (len(accepted) != 1)} in {n_targets} "
             f"target{'s' * (n_targets != 1)}, {len(rejected)} rejected (coloured by reason); {ids}")
    if target_labels:
        title += ("\ntarget labels: MTF at Nyquist | MTF50 cy/px, the rows to quote only (all rows in the table)"
                  if compact else "\ntarget labels: MTF at Nyquist | MTF50 cy/px per direction, * the row to quote")
    ax.set_title(title, fontsize=8.5, loc="left")
    return fig


#: where a target's label may go: its box's corner this many points from the
#: target's centre, nearest first, in each quadrant
LABEL_OFFSETS_PT = (6.0, 20.0, 40.0, 64.0, 100.0, 150.0)
#: what covering an accepted half-edge costs a label's spot, per point of the
#: edge sampled every few points (display px^2: a point weighs as a small label's corner)
EDGE_POINT_COST = 400.0


#: the same for a point of an accepted half-edge's ROI outline or of a labelled rejected
#: candidate: data too, but a label over them hides less than over an edge (and a label
#: sent far to avoid them draws a leader across the scene)
OTHER_POINT_COST = 100.0
#: what each ring farther from its target costs a label's spot, per its box's area
RING_COST = 0.3
_HA = {1: "left", -1: "right", 0: "center"}
_VA = {1: "bottom", -1: "top", 0: "center"}
#: up to this many targets' labels go beside the image when they cannot avoid its half-edges
MAX_ASIDE = 3
#: the label styles tried in turn, (compact, font size pt): the first with
#: which every label finds a free spot inside the image is kept
LABEL_STYLES = ((False, 8.0), (False, 6.5), (True, 7.0), (True, 6.0), (True, 5.0))


def _place_target_labels(ax, labels: list[tuple[tuple[float, float], str, str]],
                         segments: Sequence[Sequence[tuple[float, float]]] = (),
                         outlines: Sequence[Sequence[tuple[float, float]]] = (),
                         others: Sequence[Sequence[tuple[float, float]]] = ()) -> bool:
    """Each target's label beside its centre where it covers no accepted
    half-edge (``segments``, whose junction is the target's centre) nor
    their ROIs' ``outlines``, as little of ``others`` (the labelled
    rejections) as it can, no
    label placed before it (nor an id) and stays inside the image: the
    nearest free spot of the four quadrants at :data:`LABEL_OFFSETS_PT`,
    or the least covered one; a label moved off its first ring gets a
    leader.  Each label is ``(xy, full text, compact text)``; the styles
    of :data:`LABEL_STYLES` are tried in turn (smaller text, then the
    compact texts) until every label is free of the others and inside the
    image.  Up to :data:`MAX_ASIDE` labels that cannot avoid the
    half-edges or their ROIs' outlines (a checkerboard's crop, all
    target) go in full to the
    column right of the image, each target tagged by its id.  Returns
    whether the compact texts were drawn."""
    if not labels:
        return False
    frame = ax.get_window_extent()
    ids = [t.get_window_extent() for t in ax.texts]           # the ids drawn already
    pad = 3.0 * ax.figure.dpi / 72.0                             # the label's box around its text
    edge_points = _sampled(ax, segments, step_pt=4.0)
    outline_points = _sampled(ax, outlines, step_pt=4.0)
    other_points = _sampled(ax, others, step_pt=4.0)
    for compact, fontsize in LABEL_STYLES:
        style = _label_style(fontsize)
        spots = []
        taken: list = []
        all_free = True
        for xy, full, short in labels:
            text = short if compact else full
            probe = ax.annotate(text, xy, xytext=(0.0, 0.0), **style)
            # (hard: outside the image or over another label, soft: over ids and edges, ring, offset, box)
            best: tuple = (math.inf, math.inf, 0, (LABEL_OFFSETS_PT[0], LABEL_OFFSETS_PT[0]), None, True)
            for ring, offset in enumerate((0.0, *LABEL_OFFSETS_PT)):
                for sx, sy in ((1, 1), (-1, 1), (1, -1), (-1, -1)) if offset else ((0, 0),):
                    # ring 0: centred on the target (inside a chart's square); then its quadrants
                    probe.xyann = (sx * offset, sy * offset)
                    probe.set_horizontalalignment(_HA[sx])
                    probe.set_verticalalignment(_VA[sy])
                    box = probe.get_window_extent().padded(pad)
                    hard = box.width * box.height - _overlap(box, frame) + sum(_overlap(box, t) for t in taken)
                    covered, outlined = _inside(edge_points, box), _inside(outline_points, box)
                    covers = covered + outlined > 0
                    soft = (sum(_overlap(box, t) for t in ids) + EDGE_POINT_COST * covered
                            + OTHER_POINT_COST * (outlined + _inside(other_points, box)))
                    soft += RING_COST * ring * box.width * box.height     # near its target first
                    if (hard, soft) < best[:2]:
                        best = (hard, soft, ring, probe.xyann, box, covers)
                if best[0] == 0 and best[1] <= RING_COST * ring * best[4].width * best[4].height:
                    break           # nothing farther can do better
            probe.remove()
            all_free &= best[0] < 1.0
            spots.append((xy, text, best[2], best[3], best[5]))
            taken.append(best[4])
        if all_free:
            break
    if len(spots) <= MAX_ASIDE and any(spot[4] for spot in spots):
        # a scene that is its few targets (a checkerboard's crop) has no free spot: the labels go
        # to the column right of the image, below the legend, each target tagged by its id only
        from matplotlib.offsetbox import AnchoredText
        from matplotlib.transforms import Bbox
        aside = AnchoredText("\n\n".join(full for _, full, _ in labels), loc="lower left",     # in full: room there
                             bbox_to_anchor=(1.01, 0.0), bbox_transform=ax.transAxes, borderpad=0.0,
                             prop={"fontsize": 7.5})
        aside.patch.set(boxstyle="round,pad=0.3", facecolor=(0.9, 1.0, 0.9), edgecolor="#00a000", lw=0.8)
        ax.add_artist(aside)
        legend = ax.get_legend()
        fits = True
        if legend is not None and _overlap(aside.get_window_extent(), legend.get_window_extent()) > 0:
            # a tall legend: the box goes right under it, as long as the figure holds it
            below = float(ax.transAxes.inverted().transform(legend.get_window_extent().p0)[1]) - 0.03
            aside.set_bbox_to_anchor(Bbox.from_bounds(1.01, below, 0.0, 0.0), transform=ax.transAxes)
            aside.loc = 2           # upper left
            fits = aside.get_window_extent().y0 >= 0
            if not fits:
                aside.remove()
        if fits:
            for xy, text, *_ in spots:
                tag = text.split("\n")[0]
                ax.annotate(tag, xy, xytext=(4.0, 4.0), ha="left", va="bottom", **{**_label_style(7.0), "zorder": 8})
            return False
    for xy, text, ring, (dx, dy), _ in spots:
        leader = {"arrowprops": {"arrowstyle": "-", "color": "#00a000", "lw": 0.6, "alpha": 0.8}} if ring > 1 else {}
        ax.annotate(text, xy, xytext=(dx, dy), ha=_HA[int(np.sign(dx))], va=_VA[int(np.sign(dy))], **style, **leader)
    return compact


def _label_style(fontsize: float) -> dict:
    return {"textcoords": "offset points", "fontsize": fontsize, "color": "black", "annotation_clip": True,
            "zorder": 8, "bbox": {"boxstyle": "round,pad=0.25", "fc": (0.9, 1.0, 0.9, 0.9), "ec": "#00a000",
                                  "lw": 0.8}}


def _sampled(ax, segments, step_pt: float) -> np.ndarray:
    """Points along ``segments`` (data coordinates) every ``step_pt``
    points or so, in display coordinates, shape (n, 2)."""
    points = []
    to_display = ax.transData.transform
    for (x0, y0), (x1, y1) in segments:
        (a, b), (c, d) = to_display([(x0, y0), (x1, y1)])
        n = max(int(math.hypot(c - a, d - b) / (step_pt * ax.figure.dpi / 72.0)), 1) + 1
        t = np.linspace(0.0, 1.0, n)[:, None]
        points.append(np.array([a, b]) + t * np.array([c - a, d - b]))
    return np.concatenate(points) if points else np.empty((0, 2))


def _inside(points: np.ndarray, box) -> int:
    """How many of ``points`` (display coordinates, shape (n, 2)) a display box holds."""
    if not points.size:
        return 0
    return int(np.count_nonzero((points[:, 0] > box.x0) & (points[:, 0] < box.x1)
                                & (points[:, 1] > box.y0) & (points[:, 1] < box.y1)))


def _overlap(a, b) -> float:
    """The area two display boxes share (0 when apart)."""
    w = min(a.x1, b.x1) - max(a.x0, b.x0)
    h = min(a.y1, b.y1) - max(a.y0, b.y0)
    return w * h if w > 0 and h > 0 else 0.0


def _ends(record) -> list[tuple[float, float]]:
    return [(record["x0_px"], record["y0_px"]), (record["x1_px"], record["y1_px"])]


def _legend_label(name: str, group) -> str:
    """``name (count)`` and, when few enough, the ids (runs as 12-16),
    wrapped to the legend's column."""
    import textwrap
    label = f"{name} ({len(group)})"
    ids = sorted(r["id"] for r in group if r.get("id") is not None)
    if not ids or len(ids) > MAX_LISTED:
        return label
    # consecutive ids as one run: the run starts where an id does not follow its predecessor
    starts = [i for i in range(len(ids)) if i == 0 or ids[i] != ids[i - 1] + 1]
    ends = [*(s - 1 for s in starts[1:]), len(ids) - 1]
    runs = [f"{ids[s]}" if s == e else f"{ids[s]}-{ids[e]}" for s, e in zip(starts, ends)]
    return label + "\n" + "\n".join(textwrap.wrap(", ".join(runs), 26))


class _Labels:
    """Each candidate's id at its segment's middle, or slid along it away
    from the labels already placed (parallel or collinear candidates)."""

    SPOTS = (0.5, 0.3, 0.7, 0.15, 0.85)

    def __init__(self, ax, extent_w: float):
        box = ax.get_position()
        # scene px per typographic point, from the axes' width on the figure
        self.px_per_pt = extent_w / max(box.width * ax.figure.get_figwidth() * 72.0, 1e-9)
        self.ax = ax
        self.placed: list[tuple[float, float]] = []

    def add(self, record, face, text_colour, zorder: int, weight: str = "normal") -> None:
        if record.get("id") is None:
            return
        (x0, y0), (x1, y1) = _ends(record)
        # an id's box, about a three-digit id's width and a line's height: two boxes apart
        # when their centres differ by more than that across or along
        width, height = 16.0 * self.px_per_pt, 10.0 * self.px_per_pt
        along = [(x0 + s * (x1 - x0), y0 + s * (y1 - y0)) for s in self.SPOTS]
        # collinear short candidates (a road's pieces) leave no free spot along them: stacked beside
        spots = along + [(x, y + 1.1 * k * height) for k in (-1, 1, -2, 2, -3, 3) for x, y in along]
        free = [p for p in spots if all(abs(p[0] - q[0]) > width or abs(p[1] - q[1]) > height for q in self.placed)]
        x, y = (free or spots)[0]
        self.placed.append((x, y))
        self.ax.text(x, y, str(record["id"]), fontsize=6.5, color=text_colour, ha="center", va="center",
                     weight=weight, zorder=zorder, clip_on=True,
                     bbox={"boxstyle": "round,pad=0.15", "fc": face, "ec": "black", "lw": 0.4})


def _label(summary: Mapping[str, Any]) -> str:
    """A summary's line in its target's label: a combined direction and its
    normal, the sections across or along track (and their assumption), or
    the sensor model's fit (and whether it fits); ``*`` marks the row to
    quote."""
    direction = _DIRECTION_SHORT.get(summary["direction"], summary["direction"])
    mark = "*" if summary.get("recommended") else ""
    if summary.get("summary") == "fit":
        return f"{mark}fit {direction}{' (misfit)' if summary.get('misfit') else ''}"
    if summary.get("summary") == "sections":
        return f"{mark}{direction} ({summary.get('assumption')})"
    return f"{direction} {summary['normal_angle_deg']:.0f}\u00b0"


def _row(summary: Mapping[str, Any], short: bool = False) -> str:
    """A summary's line in its target's label: its name, MTF at Nyquist and
    MTF50 (cy/px); ``short`` drops the sections' assumption."""
    name = _label(summary)
    if short:
        name = name.split(" (")[0]            # the sections' assumption (the table has it)
        name = name.replace("horizontal", "H").replace("vertical", "V")
        return f"{name} {_num(summary.get('mtf_nyquist'))}|{_num(summary.get('mtf50_cy_px'))}"
    return f"{name}: {_num(summary.get('mtf_nyquist'))} | {_num(summary.get('mtf50_cy_px'))}"



def _num(value) -> str:
    return "-" if value is None else f"{value:.3f}"
