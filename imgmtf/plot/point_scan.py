"""The overview figure of a scene scanned for point arrays
(:func:`imgmtf.scene.points.scan_points`): every array's ROI coloured by
its verdict, the accepted ones labelled with their MTF across and along."""
from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure

from .scan import ACCEPTED, PALETTE

if TYPE_CHECKING:
    from ..records import Record

#: a refused target's mark (a cross: its shape, not its colour, tells it from the ROIs)
REFUSED_POINT = "#ff3b3b"
_SHORT = {"across-track": "across", "along-track": "along", "image-x": "x", "image-y": "y"}


def plot_point_scan(overview: np.ndarray, scale: float, records: Iterable[Record | Mapping[str, Any]],
                    summaries: Iterable[Record | Mapping[str, Any]] = (),
                    levels: tuple[float, float] | None = None, ax: Axes | None = None,
                    width_in: float = 10.0) -> Figure | SubFigure:
    """The overview of a point-array scan: the scene, each array's ROI (green
    when accepted, coloured by reason when rejected) labelled ``A<n>`` with,
    per direction, the MTF at Nyquist and its interval; each target of the
    windows circled where it passed the measurement's checks (kept), crossed
    where it was refused (``point_targets``).

    Parameters
    ----------
    overview : numpy.ndarray, shape (rows, cols)
        The scene decimated by ``scale`` scene px per overview px (DN).
    scale : float
        Scene pixels per overview pixel.
    records : iterable of Record or mapping
        The arrays' records (:func:`imgmtf.scene.points.scan_points`, or
        their ``to_dict()``): ``target_id``, ``roi``, ``status``, and for
        accepted ones ``direction``, ``mtf_nyquist``, ``mtf_nyquist_ci``;
        ``point_targets`` (:func:`imgmtf.scene.points.point_targets`) where
        known.
    summaries : iterable of Record or mapping, optional
        The scene's rows per direction (their MTF at Nyquist goes in the
        title, ``*`` on the one to quote).
    levels : (float, float), optional
        (black, white) DN of the display; default the 0.5 and 99.5
        percentiles.
    ax : matplotlib.axes.Axes, optional
        The axes; a new figure sized to the scene when None.
    width_in : float, optional
        The new figure's width, inches (default 10).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding the axes.

    Examples
    --------
    >>> rows = [{"target_id": 1, "roi": [10, 10, 40, 30], "status": "accepted", "direction": "across-track",
    ...          "mtf_nyquist": 0.23, "mtf_nyquist_ci": [0.21, 0.25]}]
    >>> fig = plot_point_scan(np.zeros((60, 80)), 1.0, rows)
    >>> fig.axes[0].get_title(loc="left").split(";")[0]
    '1 point array accepted, 0 rejected'
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle

    from ..records import Record
    rows = [r.to_dict() if isinstance(r, Record) else dict(r) for r in records]
    scene_rows = [r.to_dict() if isinstance(r, Record) else dict(r) for r in summaries]
    height, width = overview.shape
    extent_w, extent_h = width * scale, height * scale
    fig: Figure | SubFigure
    if ax is None:
        margins = (0.7, 2.4, 0.55, 0.45)
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
    ax.tick_params(labelsize=7)
    ax.set_xlabel("column (px)", fontsize=7)
    ax.set_ylabel("row (px)", fontsize=7)
    arrays: dict[Any, list[dict]] = {}
    for r in rows:
        arrays.setdefault(r.get("target_id"), []).append(r)
    reasons = sorted({r.get("reason") or "rejected" for r in rows if r.get("status") != "accepted"})
    colours = {reason: PALETTE[k % len(PALETTE)] for k, reason in enumerate(reasons)}
    accepted = 0
    for number, members in sorted(arrays.items(), key=lambda item: str(item[0])):
        first = members[0]
        x, y, w, h = first["roi"]
        ok = first.get("status") == "accepted"
        accepted += ok
        colour = ACCEPTED if ok else colours[first.get("reason") or "rejected"]
        ax.add_patch(Rectangle((x - 0.5, y - 0.5), w, h, fill=False, edgecolor=colour, linewidth=1.4, zorder=4))
        lines = [f"A{number}"]
        if ok:
            lines += [f"{_short(m)}: {_interval(m)}" for m in members]
        else:
            lines.append(first.get("reason") or "rejected")
        # above the box, or inside its top where the box starts at the image's top (a label above is clipped)
        above = y - 0.5 > 0.04 * extent_h
        ax.text(x - 0.5 + (0 if above else 0.01 * extent_w), y - 1.5 if above else y + 0.01 * extent_h,
                "\n".join(lines), fontsize=6, color="black", ha="left", va="bottom" if above else "top", zorder=6,
                clip_on=True, bbox={"boxstyle": "round,pad=0.2", "fc": (0.85, 1.0, 0.85, 0.9) if ok else "white",
                                    "ec": colour, "lw": 0.6})
    targets = [t for members in arrays.values() for t in members[0].get("point_targets") or []]
    used = [(t["x_px"], t["y_px"]) for t in targets if t.get("status") == "used"]
    refused = [(t["x_px"], t["y_px"]) for t in targets if t.get("status") != "used"]
    # a ring about 6 scene px across around each target (its blur shows inside), kept readable when
    # the overview shrinks a large scene: between 5 and 14 points
    points_per_px = ax.get_window_extent().width * 72.0 / fig.dpi / max(extent_w, 1.0)
    size = float(np.clip(6.0 * points_per_px, 5.0, 14.0))
    if used:
        ax.plot(*zip(*used), "o", ms=size, mfc="none", mec=ACCEPTED, mew=0.9, zorder=5)
    if refused:
        ax.plot(*zip(*refused), "x", ms=size * 0.7, color=REFUSED_POINT, mew=1.0, zorder=5)
    handles = [Line2D([], [], color=ACCEPTED, lw=2, label=f"accepted ({accepted})")]
    handles += [Line2D([], [], color=colours[reason], lw=2,
                       label=f"{reason} ({sum(1 for m in arrays.values() if m[0].get('reason') == reason)})")
                for reason in reasons]
    if targets:     # the targets of each window: which the measurement used, which it refused
        counts: dict[str, int] = {}
        for t in targets:
            if t.get("status") != "used":
                counts[t["status"]] = counts.get(t["status"], 0) + 1
        handles.append(Line2D([], [], ls="none", marker="o", mfc="none", mec=ACCEPTED, ms=6,
                              label=f"target kept ({len(used)})"))
        if refused:
            # a reason a line: a star field's counts on one line ran off the figure
            why = "\n".join(f"  {n} {reason}" for reason, n in sorted(counts.items()))
            handles.append(Line2D([], [], ls="none", marker="x", color=REFUSED_POINT, ms=6,
                                  label=f"target refused ({len(refused)})\n{why}"))
    quoted = ", ".join(f"{'*' if s.get('recommended') else ''}{_short(s)} "
                       f"{_interval(s)}" for s in scene_rows if s.get("mtf_nyquist") is not None)
    ax.set_title(f"{accepted} point array{'s' * (accepted != 1)} accepted, {len(arrays) - accepted} rejected; "
                 f"labels: MTF at Nyquist [interval] per direction" + (f"; scene: {quoted}" if quoted else ""),
                 fontsize=7.5, loc="left")
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=7,
              title="point arrays", title_fontsize=7, alignment="left", frameon=False)
    return fig


def _interval(row: Mapping[str, Any]) -> str:
    value = row.get("mtf_nyquist")
    low, high = row.get("mtf_nyquist_ci") or (None, None)
    text = "-" if value is None else f"{value:.3f}"
    return text + (f" [{low:.3f}, {high:.3f}]" if low is not None and high is not None else "")


def _short(row: Mapping[str, Any]) -> str:
    direction = str(row.get("direction"))
    return _SHORT.get(direction, direction)
