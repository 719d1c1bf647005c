"""The overview figure of a scene scan: every candidate coloured by its verdict."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

_DIRECTION_SHORT = {"across-track": "across", "along-track": "along", "oblique": "oblique", "unknown": ""}


def plot_scan(overview: np.ndarray, scale: float, records, summaries=(), levels=None, ax=None,
              width_in: float = 10.0):
    """The overview of a scan: the scene with its accepted targets
    prominent and labelled, its rejected candidates faint.

    Parameters
    ----------
    overview : 2-D array, the scene decimated by ``scale`` scene px per
        overview px (DN).
    scale : scene pixels per overview pixel.
    records : the candidates' records (:class:`imgmtf.Record`, as
        :func:`imgmtf.scan_scene` returns them, or their ``to_dict()``):
        accepted ones are drawn as their tilted ROI (``roi_polygon_px``)
        and segment in green; rejected ones as a thin faint line coloured
        by reason, each reason counted in the legend.
    summaries : the per-target summaries (``scope`` "target", records or
        dicts, as :func:`imgmtf.summarise_scan` returns them): each
        target is labelled at its centre with, per direction, MTF at
        Nyquist and MTF50 (cy/px).
    levels : (black, white) DN of the display; default the 0.5 and 99.5
        percentiles.
    ax : an axes to draw on; a new figure, sized to the scene's aspect
        with no blank margins, when None.
    width_in : the new figure's width (inches).

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    Drawn with one collection per reason and one for the accepted ROIs,
    so that a scene with thousands of candidates draws in a fraction of a
    second.

    Example
    -------
    >>> import numpy as np
    >>> fig = plot_scan(np.zeros((50, 80)), 1.0, [])
    >>> float(fig.get_figwidth())
    10.0
    """
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.lines import Line2D

    from ..records import Record
    records = [r.to_dict() if isinstance(r, Record) else r for r in records]     # scan_scene's own output
    summaries = [r.to_dict() if isinstance(r, Record) else r for r in summaries]
    height, width = overview.shape
    extent_w, extent_h = width * scale, height * scale
    if ax is None:
        margins = (0.7, 0.1, 0.55, 0.45)            # left, right, bottom, top (in): axis labels, title
        image_w = width_in - margins[0] - margins[1]
        image_h = image_w * extent_h / max(extent_w, 1e-9)
        fig = Figure(figsize=(width_in, image_h + margins[2] + margins[3]))
        fig_h = fig.get_figheight()
        ax = fig.add_axes((margins[0] / width_in, margins[2] / fig_h, image_w / width_in, image_h / fig_h))
    fig = ax.figure
    finite = np.isfinite(overview)
    lo, hi = levels or (np.percentile(overview[finite], [0.5, 99.5]) if finite.any() else (0.0, 1.0))
    ax.imshow(overview, cmap="gray", vmin=lo, vmax=hi if hi > lo else lo + 1,
              extent=(-0.5, extent_w - 0.5, extent_h - 0.5, -0.5), interpolation="nearest")
    ax.set(xlim=(-0.5, extent_w - 0.5), ylim=(extent_h - 0.5, -0.5))
    ax.tick_params(labelsize=7)
    ax.set_xlabel("column (px)", fontsize=7)
    ax.set_ylabel("row (px)", fontsize=7)
    accepted = [r for r in records if r.get("status") == "accepted"]
    rejected = [r for r in records if r.get("status") != "accepted"]
    handles = []
    by_reason: dict[str, list] = {}
    for r in rejected:
        by_reason.setdefault(r.get("reason") or "rejected", []).append(
            [(r["x0_px"], r["y0_px"]), (r["x1_px"], r["y1_px"])])
    palette = ["#ff7f0e", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f",
               "#1f77b4", "#aec7e8", "#ffbb78", "#c5b0d5"]
    for k, (reason, lines) in enumerate(sorted(by_reason.items(), key=lambda kv: -len(kv[1]))):
        colour = palette[k % len(palette)]
        ax.add_collection(LineCollection(lines, colors=colour, linewidths=0.6, alpha=0.45))
        handles.append(Line2D([], [], color=colour, lw=1.5, alpha=0.7, label=f"{reason} ({len(lines)})"))
    if accepted:
        polygons = [r["roi_polygon_px"] for r in accepted if r.get("roi_polygon_px")]
        ax.add_collection(PolyCollection(polygons, facecolors=(0.2, 1.0, 0.2, 0.08), edgecolors="#00e000",
                                         linewidths=1.0))
        ax.add_collection(LineCollection([[(r["x0_px"], r["y0_px"]), (r["x1_px"], r["y1_px"])] for r in accepted],
                                         colors="#00ff00", linewidths=1.6))
        handles.insert(0, Line2D([], [], color="#00e000", lw=2.5, label=f"accepted ({len(accepted)})"))
        centres = {s["target_id"]: (s["x_px"], s["y_px"]) for s in summaries if s.get("scope") == "target"}
        for r in accepted:          # each accepted half-edge's id, as in the table and the CSV
            if r.get("id") is None:
                continue
            ends = np.array([[r["x0_px"], r["y0_px"]], [r["x1_px"], r["y1_px"]]])
            # near the end away from the target's label (at its centre), a fifth of the way in
            far = int(np.argmax(np.hypot(*(ends - centres.get(r.get("target_id"), ends.mean(axis=0))).T)))
            x, y = 0.8 * ends[far] + 0.2 * ends[1 - far]
            ax.text(x, y, str(r["id"]), fontsize=6.5, color="#004d00", ha="center", va="center",
                    bbox={"boxstyle": "circle,pad=0.15", "fc": (0.85, 1.0, 0.85, 0.85), "ec": "none"})
    targets = [s for s in summaries if s.get("scope") == "target"]
    for target_id in sorted({s["target_id"] for s in targets}):
        rows = [s for s in targets if s["target_id"] == target_id and s.get("mtf_nyquist") is not None]
        lines = [f"T{target_id}"] + [f"{_label(s)}: {_num(s.get('mtf_nyquist'))} | {_num(s.get('mtf50_cy_px'))}"
                                     for s in rows]
        if len(lines) == 1:
            continue
        x, y = rows[0]["x_px"], rows[0]["y_px"]
        right, low = x > 0.7 * extent_w, y < 0.15 * extent_h       # keep the label inside the image
        ax.annotate("\n".join(lines), (x, y), xytext=(-6 if right else 6, -6 if low else 6),
                    textcoords="offset points", fontsize=6.5, color="black", va="top" if low else "bottom",
                    ha="right" if right else "left", annotation_clip=True,
                    bbox={"boxstyle": "round,pad=0.25", "fc": (0.85, 1.0, 0.85, 0.8), "ec": "#00a000", "lw": 0.8})
    n_targets = len({s["target_id"] for s in targets})
    ax.set_title(f"{len(accepted)} accepted half-edge{'s' * (len(accepted) != 1)} in {n_targets} "
                 f"target{'s' * (n_targets != 1)} (labels: MTF at Nyquist | MTF50 cy/px per direction); "
                 f"{len(rejected)} rejected", fontsize=8, loc="left")
    if handles:
        ax.legend(handles=handles, loc="upper right", fontsize=7, framealpha=0.8, title="candidates",
                  title_fontsize=7)
    return fig


def _label(summary: dict) -> str:
    """A summary's line in its target's label: a combined direction and its
    normal, or the sensor model's fit across or along track (and whether it
    fits)."""
    direction = _DIRECTION_SHORT.get(summary["direction"], summary["direction"])
    if summary.get("summary") == "fit":
        return f"fit {direction}{' (misfit)' if summary.get('misfit') else ''}"
    return f"{direction} {summary['normal_angle_deg']:.0f}\u00b0"


def _num(value) -> str:
    return "-" if value is None else f"{value:.3f}"
