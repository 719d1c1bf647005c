"""Figures.  Each function draws on ``ax`` (a new figure when None) and
returns the figure; nothing here touches pyplot's global state, so the
figures render with the Agg canvas whatever the session's backend."""
from __future__ import annotations

import textwrap

import numpy as np
from matplotlib.figure import Figure

from .estimate.spectrum import NYQUIST
from .metrics import fwhm


def _expect(value, kind: str) -> None:
    """Refuse, with a ParameterError, a ``value`` that is not what the figure
    draws: a measurement ("result"), a sensor ("sensor") or a fit ("fit")."""
    from .errors import ParameterError
    from .estimate.fit import SensorFit
    from .estimate.results import MTFResult
    from .sensor.model import Sensor
    expected = {"result": (MTFResult, "a measurement (imgmtf.measure_edge or measure_pulse)"),
                "sensor": (Sensor, "an imgmtf.Sensor"), "fit": (SensorFit, "a fit (imgmtf.fit_sensor)")}
    cls, what = expected[kind]
    if not isinstance(value, cls):
        raise ParameterError(f"this figure draws {what}, got {type(value).__name__}")


def _truth(truth) -> None:
    """Refuse a ``truth`` that is not a function of frequency (cy/px) or None."""
    if truth is not None and not callable(truth):
        from .errors import ParameterError
        hint = (" (for a sensor: lambda f: sensor.normal_transfer(f, result.normal_angle_deg))"
                if hasattr(truth, "normal_transfer") else "")
        raise ParameterError(f"truth must be a function of frequency in cy/px, got {type(truth).__name__}{hint}")


def _axes(ax, size=(5.0, 3.6)):
    if ax is None:
        fig = Figure(figsize=size, layout="constrained")
        return fig, fig.add_subplot()
    return ax.figure, ax


# -- the sensor model --------------------------------------------------------
def _view_radius_m(sensor) -> float:
    """Half-width (m) of the view that shows the PSF's core and shoulders."""
    return 1.5 * max(sensor.fwhm_m("across"), sensor.fwhm_m("along"), sensor.gsd_m)


def plot_psf(sensor, ax=None, oversampling: int = 20):
    """The system PSF image (paper Fig. 2a), axes in metres, its core and
    shoulders shown in a square of 3 FWHM."""
    _expect(sensor, "sensor")
    fig, ax = _axes(ax)
    psf = sensor.psf(oversampling)
    half = psf.data.shape[0] // 2 * psf.step_m
    image = ax.imshow(psf.data / psf.data.max(), extent=(-half, half, half, -half), cmap="magma",
                      interpolation="nearest")
    r = _view_radius_m(sensor)
    ax.set(xlim=(-r, r), ylim=(r, -r), title="System PSF (peak = 1)", xlabel="across track x (m)",
           ylabel="along track y (m)")
    fig.colorbar(image, ax=ax, shrink=0.8)
    return fig


def plot_sensor_lsf(sensor, ax=None):
    """Across- and along-track LSFs with their FWHM (paper Fig. 2b, c)."""
    _expect(sensor, "sensor")
    fig, ax = _axes(ax)
    for direction in ("across", "along"):
        x, lsf = sensor.lsf(direction)
        ax.plot(x, lsf / lsf.max(), label=f"{direction} track, FWHM {sensor.fwhm_m(direction):.3f} m")
    ax.axhline(0.5, color="0.6", lw=0.8, ls=":")
    r = 2 * _view_radius_m(sensor)
    ax.set(xlim=(-r, r), title="Line spread functions", xlabel="distance (m)", ylabel="normalised LSF")
    ax.legend(fontsize="small")
    return fig


def plot_sensor_mtf(sensor, ax=None, direction: str | None = None):
    """The system MTF with its value at Nyquist (paper Fig. 3): across and
    along track, or in one ``direction`` with each stage's MTF beside it."""
    _expect(sensor, "sensor")
    fig, ax = _axes(ax)
    f = np.linspace(0, 1.0, 401)
    if direction is None:
        for d in ("across", "along"):
            ax.plot(f, sensor.mtf(f, d), label=f"{d} track, MTF@Nyquist {sensor.mtf_nyquist(d):.4f}")
        title = "System MTF"
    else:
        for i, (name, part) in enumerate(sensor.components().items()):
            ax.plot(f, part.mtf(f, direction), lw=1.0, ls=("--", "-.", ":")[i % 3], color=f"C{i + 1}",
                    label=f"{name}: {part.mtf_nyquist(direction):.4f}")
        ax.plot(f, sensor.mtf(f, direction), color="k", lw=2.0,
                label=f"system: {sensor.mtf_nyquist(direction):.4f}")
        title = f"MTF {direction} track (at Nyquist)"
    ax.axvline(NYQUIST, color="0.5", ls="--", lw=0.8)
    ax.set(title=title, xlabel="frequency (cycles/pixel)", ylabel="MTF", ylim=(0, 1.02), xlim=(0, 1))
    ax.legend(fontsize="small")
    return fig


def plot_sensor(sensor):
    """PSF, LSFs, and each stage's MTF beside the system's across and along
    track (the paper's Figs. 2-3)."""
    _expect(sensor, "sensor")
    fig = Figure(figsize=(17, 4), layout="constrained")
    axes = fig.subplots(1, 4)
    plot_psf(sensor, axes[0])
    plot_sensor_lsf(sensor, axes[1])
    plot_sensor_mtf(sensor, axes[2], "across")
    plot_sensor_mtf(sensor, axes[3], "along")
    fig.suptitle(f"Sensor, GSD {sensor.gsd_m:g} m: {', '.join(s.name for s in sensor.stages)}")
    return fig


# -- a sensor fit ----------------------------------------------------------------
def plot_fit_edge(fit, index: int, ax=None):
    """One edge of a sensor fit: its measured (non-parametric) MTF against
    the fitted model's along its normal, with the model's interval."""
    _expect(fit, "fit")
    if not -len(fit.edges) <= index < len(fit.edges):
        from .errors import ParameterError
        raise ParameterError(f"edge index {index} is outside the fit's {len(fit.edges)} edge(s)")
    fig, ax = _axes(ax)
    edge = fit.edges[index]
    m = edge.measurement
    f = np.linspace(0.0, 1.0, 201)
    value, low, high = fit.mtf_band(f, edge.normal_angle_deg, edge.gsd_m)
    lo, hi = edge.mtf_nyquist_ci
    ax.fill_between(f, low, high, color="C0", alpha=0.3, lw=0)
    ax.plot(f, value, color="C0", lw=2.0, label=f"model: {edge.mtf_nyquist:.4f} [{lo:.4f}, {hi:.4f}]")
    ax.plot(m.frequencies_cy_px, m.mtf, "--", color="k", lw=1.0,
            label=f"measured: {edge.measured_mtf_nyquist:.4f}")
    ax.axvline(NYQUIST, color="0.5", ls="--", lw=0.8)
    name = edge.source if len(edge.source) <= 32 else "..." + edge.source[-29:]
    ax.set(title=f"{name}: normal {edge.normal_angle_deg:.1f} deg ({edge.direction})", xlim=(0, 1), ylim=(0, 1.05),
           xlabel="frequency along the normal (cycles/pixel)", ylabel="MTF")
    ax.legend(fontsize="small", title=f"at Nyquist ({100 * fit.confidence:g} % interval)",
              title_fontsize="small")
    return fig


def plot_fit_residuals(fit, ax=None):
    """Each edge's residuals (data - model) averaged in 0.25 px bins along
    its normal, in % of its step, with the noise's 2-sigma band of a bin
    mean: structure outside it is what the misfit warning reports."""
    _expect(fit, "fit")
    fig, ax = _axes(ax)
    for i, edge in enumerate(fit.edges):
        x = edge.samples_x_px - edge.offset_px
        keep = np.abs(x) <= 6.0
        bins = np.floor(x[keep] / 0.25).astype(int)
        bins -= bins.min()
        count = np.bincount(bins)
        used = count >= 3
        mean = np.bincount(bins, weights=edge.residuals_dn[keep])[used] / count[used]
        centre = (np.nonzero(used)[0] + 0.5) * 0.25 + np.floor(x[keep].min() / 0.25) * 0.25
        scale = 100.0 / abs(edge.step_dn)
        line, = ax.plot(centre, mean * scale, ".-", lw=0.8, ms=3, color=f"C{i % 10}",
                        label=f"{edge.source[-24:]}: {100 * edge.misfit_fraction:.2f} %")
        ax.fill_between(centre, -2 * edge.noise_dn / np.sqrt(count[used]) * scale,
                        2 * edge.noise_dn / np.sqrt(count[used]) * scale, color=line.get_color(), alpha=0.12, lw=0)
    ax.axhline(0, color="0.4", lw=0.8)
    ax.set(title="Residuals along the normal (0.25 px bins)", xlabel="distance from the edge (px)",
           ylabel="data - model (% of the step)")
    ax.legend(fontsize="small", title="structure (RMS)", title_fontsize="small", loc="lower right")
    return fig


def plot_fit(fit, max_edges: int = 6):
    """Measured against model MTF for each edge (the first ``max_edges``),
    the residuals along the normals, and the fitted sensor's 2-D PSF."""
    _expect(fit, "fit")
    shown = min(len(fit.edges), max_edges)
    panels = shown + 2
    cols = min(panels, 4)
    rows = -(-panels // cols)
    fig = Figure(figsize=(4.4 * cols, 3.7 * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    for i in range(shown):
        plot_fit_edge(fit, i, axes[i])
    plot_fit_residuals(fit, axes[shown])
    plot_psf(fit.sensor, axes[shown + 1])
    axes[shown + 1].set_title("Fitted system PSF (peak = 1)")
    for ax in axes[panels:]:
        ax.set_visible(False)
    held = [p.key for p in fit.parameters if p.status != "fitted" and p.note != "not fitted"]
    more = f" (first {shown} of {len(fit.edges)} edges)" if shown < len(fit.edges) else ""
    fig.suptitle(f"Fit of {', '.join(s.name for s in fit.sensor.stages)}{more}: reduced chi-square "
                 f"{fit.reduced_chi_square:.3g}" + (f"; held or tied: {', '.join(held)}" if held else ""),
                 fontsize="medium")
    return fig


# -- a measurement (edge or pulse) ---------------------------------------------
def _title(ax, text: str) -> None:
    """Title the axes unless the caller already has."""
    if not ax.get_title():
        ax.set_title(text)


def _view_px(result) -> float:
    """Half-width (px) of a profile view that shows the LSF's core and the
    start of its tails."""
    return float(min(max(6.0, 2.5 * result.lsf_half_width_px), np.abs(result.samples_x_px).max()))


def plot_locations(result, ax=None):
    """Per-row sub-pixel target locations and the fitted line (paper Fig.
    5a), at equal scale in both axes so that the tilt looks as it is; the
    rows' RMS scatter about the line is in the legend."""
    _expect(result, "result")
    fig, ax = _axes(ax)
    g = result.geometry
    kept = g.kept
    fitted = g.slope * g.rows + g.intercept
    rms = float(np.sqrt(np.mean((g.locations[kept] - fitted[kept]) ** 2)))

    def image_xy(along, across):
        # a near-horizontal target was measured on the transposed chip: draw it as the image shows it
        return (along, across) if g.transposed else (across, along)
    line = "column" if g.transposed else "row"
    ax.plot(*image_xy(g.rows[kept], g.locations[kept]), "o", ms=3, mfc="none",
            label=f"{line} {result.target} location (scatter {rms:.3f} px RMS)")
    if (~kept).any():
        ax.plot(*image_xy(g.rows[~kept], g.locations[~kept]), "x", color="C3",
                label=f"rejected ({(~kept).sum()})")
    ax.plot(*image_xy(g.rows, fitted), "-", color="C1", label="least-squares line")
    ax.set_aspect("equal", adjustable="datalim")
    ax.invert_yaxis()
    ax.set(xlabel="column (px)", ylabel="row (px)")
    _title(ax, f"{result.target.capitalize()}: normal at {result.normal_angle_deg:.2f} deg, "
               f"tilt {result.tilt_deg:.2f} deg")
    ax.legend(fontsize="small")
    return fig


def plot_profile(result, ax=None):
    """Over-sampled profile samples and the resampled profile: the ESF of an
    edge (paper Fig. 5b) or the PRF of a pulse, normalised; the LSF window's
    flat core is shaded, its taper lighter."""
    _expect(result, "result")
    fig, ax = _axes(ax)
    if result.target == "edge":
        lo, hi = result.levels_dn
        x, profile, name = result.esf_x_px, result.esf, "ESF"
    else:
        lo, hi = result.background_dn, result.peak_dn
        x, profile, name = result.prf_x_px, result.prf, f"PRF, bar {result.pulse_width_px:.2f} px"
    ax.plot(result.samples_x_px, (result.samples_dn - lo) / (hi - lo), ".", ms=1.5,
            color="0.6", label="pixels")
    ax.plot(x, profile, "-", color="C0", label=f"{result.method} profile")
    _window_bands(ax, result)
    view = _view_px(result)
    ax.set(xlim=(-view, view), xlabel="distance from the line along the normal (px)", ylabel="normalised DN")
    _title(ax, f"{name} (SNR {result.snr:.0f})")
    ax.legend(fontsize="small", loc="best")
    return fig


def _window_bands(ax, result):
    centre = 0.0
    core, taper = result.lsf_half_width_px, result.params.get("lsf_taper_px", 0.0)
    ax.axvspan(centre - core, centre + core, color="C2", alpha=0.08, lw=0, label="LSF window core (data)")
    for sign in (-1, 1):
        ax.axvspan(centre + sign * core, centre + sign * (core + taper), color="C2", alpha=0.04, lw=0,
                   label="taper to the tail model" if sign > 0 else None)


def plot_lsf(result, ax=None):
    """The recovered LSF with its full width at half maximum marked."""
    _expect(result, "result")
    fig, ax = _axes(ax)
    x, lsf = result.lsf_x_px, result.lsf
    ax.plot(x, lsf, color="C0", label="LSF")
    peak = float(lsf.max())
    centre = float(x[np.argmax(lsf)])
    ax.hlines(peak / 2, centre - result.fwhm_px / 2, centre + result.fwhm_px / 2, color="C3",
              label=f"FWHM {result.fwhm_px:.3f} px" + (f" ({result.fwhm_m:.3g} m)" if result.gsd_m else ""))
    view = max(4.0, 2.5 * result.fwhm_px)
    ax.set(xlim=(centre - view, centre + view), xlabel="distance along the normal (px)", ylabel="LSF (1/px)")
    _title(ax, "Line spread function")
    ax.legend(fontsize="small")
    return fig


def plot_mtf(result, ax=None, truth=None, color: str | None = None, label: str | None = None):
    """The MTF along the normal with MTF at Nyquist and MTF50 marked with
    their confidence intervals, the frequencies beyond the noise limit
    shaded, and ``truth(f)`` (cycles/pixel) overlaid when known."""
    _expect(result, "result")
    _truth(truth)
    fig, ax = _axes(ax)
    f = result.frequencies_cy_px
    line, = ax.plot(f, result.mtf, color=color, label=label or "measured")
    c = line.get_color()
    if truth is not None:
        ax.plot(f, truth(f), "--", color="0.2", lw=1.0, label="true")
    if np.isfinite(result.noise_limit_cy_px) and result.noise_limit_cy_px < f.max():
        ax.axvspan(result.noise_limit_cy_px, f.max(), color="0.5", alpha=0.1, lw=0,
                   label=_once(ax, "below 3 x its noise",
                               f"below 3 x its noise (from {result.noise_limit_cy_px:.2f} cy/px)"))
    ax.axvline(NYQUIST, color="0.5", ls=":", lw=0.8, label=_once(ax, "Nyquist", "Nyquist, 0.5 cy/px"))
    ci = result.mtf_nyquist_ci
    yerr = ([[result.mtf_nyquist - ci.low], [ci.high - result.mtf_nyquist]] if np.isfinite(ci.low) else None)
    interval = f" [{ci.low:.4f}, {ci.high:.4f}]" if yerr else ""
    ax.errorbar([NYQUIST], [result.mtf_nyquist], yerr=yerr, fmt="o", color=c, capsize=3, ms=4,
                label=f"MTF@Nyquist {_figure(result.mtf_nyquist)}{interval}")
    ci50 = result.mtf50_ci_cy_px
    xerr = ([[result.mtf50_cy_px - ci50.low], [ci50.high - result.mtf50_cy_px]] if np.isfinite(ci50.low) else None)
    interval50 = f" [{ci50.low:.4f}, {ci50.high:.4f}]" if xerr else ""
    ax.errorbar([result.mtf50_cy_px], [0.5], xerr=xerr, fmt="s", color=c, capsize=3, ms=4,
                label=f"MTF50 {_figure(result.mtf50_cy_px, 'cy/px')}{interval50}")
    top = max(1.05, float(np.nanmax(result.mtf)) + 0.05)
    ax.set(xlim=(0, f.max()), ylim=(0, top), xlabel="frequency along the normal (cy/px)", ylabel="MTF")
    if result.gsd_m:
        gsd = result.gsd_m
        ax.secondary_xaxis("top", functions=(lambda x: x / gsd, lambda x: x * gsd)).set_xlabel(
            "frequency (cy/m)")
    _title(ax, "MTF")
    ax.legend(fontsize="small")
    return fig


def _once(ax, prefix: str, label: str) -> str:
    """``label``, unless a label starting with ``prefix`` is already in the
    axes' legend (several measurements drawn on one axes)."""
    drawn = ax.get_legend_handles_labels()[1]
    return "_nolegend_" if any(d.startswith(prefix) for d in drawn) else label


def _figure(value: float, unit: str = "") -> str:
    """A figure as the plots print it, with its unit; a bar's sinc can mask
    it (NaN), and then it has none."""
    if not np.isfinite(value):
        return "masked by the bar's sinc"
    return f"{value:.4f} {unit}" if unit else f"{value:.4f}"


def plot_measurement(result, truth=None, title: str | None = None):
    """Target locations, profile (ESF or PRF), LSF and MTF of one
    measurement, headed by ``title`` (the file) and the figures a report
    quotes; ``truth(f)`` overlays a known MTF."""
    _expect(result, "result")
    _truth(truth)
    fig = Figure(figsize=(12, 8.5), layout="constrained")
    axes = fig.subplots(2, 2)
    plot_locations(result, axes[0, 0])
    plot_profile(result, axes[0, 1])
    plot_lsf(result, axes[1, 0])
    plot_mtf(result, axes[1, 1], truth=truth)
    ci = result.mtf_nyquist_ci
    interval = f" [{ci.low:.4f}, {ci.high:.4f}]" if np.isfinite(ci.low) else ""
    summary = (f"MTF at Nyquist {_figure(result.mtf_nyquist)}{interval}, MTF50 {_figure(result.mtf50_cy_px, 'cy/px')}, "
               f"FWHM {result.fwhm_px:.3f} px, SNR {result.snr:.0f}, {result.direction}, "
               f"{result.rows_used} rows, method {result.method}")
    for i, warning in enumerate(result.warnings[:2]):
        summary += "\n" + textwrap.shorten(f"warning {i + 1} of {len(result.warnings)}: {warning}", 170,
                                           placeholder=" [...]")
    fig.suptitle(f"{title}\n{summary}" if title else summary, fontsize="medium")
    return fig


# -- a scene scan ------------------------------------------------------------------
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

    from .records import Record
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
        rows = [s for s in targets if s["target_id"] == target_id]
        lines = [f"T{target_id}"] + [
            f"{_DIRECTION_SHORT.get(s['direction'], s['direction'])} {s['normal_angle_deg']:.0f}\u00b0: "
            f"{_num(s.get('mtf_nyquist'))} | {_num(s.get('mtf50_cy_px'))}" for s in rows]
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


def _num(value) -> str:
    return "-" if value is None else f"{value:.3f}"


# -- the reproduction study ----------------------------------------------------
def plot_noise_sweep(rows, methods, true_nyquist, title):
    """MTF at Nyquist against measured SNR, one panel per method, the true
    MTF as a line (paper Figs. 12 and 14)."""
    fig = Figure(figsize=(4 * len(methods), 3.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(methods), sharey=True))
    for ax, method in zip(axes, methods):
        values = np.array([r["results"][method] for r in rows], float)
        ax.semilogx(values[:, 1], values[:, 0], "*", ms=4, color="C0", label="estimates")
        ax.axhline(true_nyquist, color="C3", label=f"true {true_nyquist:.4f}")
        ax.axvline(100, color="0.6", ls=":", lw=0.8)
        ax.set(title=f"{title}: {method}", xlabel="estimated SNR", ylim=(0, 2 * true_nyquist))
    axes[0].set_ylabel("MTF at Nyquist")
    axes[0].legend(fontsize="small")
    return fig


def plot_estimates(kind: str, curves: dict, methods, width_px: float = 0.0):
    """Each method's estimate of a noise-free chip against the truth (paper
    Figs. 9 and 10): the LSF of an edge (or the pulse response of a bar
    ``width_px`` wide), the MTF, and the MTF's error, as published (top) and
    with each method's own blur divided out (bottom, imgmtf's default).
    ``curves`` as :func:`imgmtf.reproduce.estimator_tables` returns it."""
    fig = Figure(figsize=(15, 8.2), layout="constrained")
    axes = fig.subplots(2, 3)
    x_true, profile_true, f_true, mtf_true = curves["truth"]
    name = "LSF (1/px)" if kind == "edge" else "pulse response (peak 1)"
    view = 4.0 if kind == "edge" else 4.0 + width_px / 2
    for row, variant in zip(axes, ("as published", "corrected")):
        profile_ax, mtf_ax, error_ax = row
        profile_ax.plot(x_true, profile_true, color="k", lw=2.4, alpha=0.35,
                        label=f"true: FWHM {fwhm(x_true, profile_true):.3f} px")
        mtf_ax.plot(f_true, mtf_true, color="k", lw=2.4, alpha=0.35,
                    label=f"true: {float(np.interp(NYQUIST, f_true, mtf_true)):.4f}")
        for i, method in enumerate(methods):
            r = curves[variant][method]
            x, profile = (r.lsf_x_px, r.lsf) if kind == "edge" else (r.prf_x_px, r.prf)
            colour = f"C{i}"
            profile_ax.plot(x, profile, color=colour, lw=1.0, label=f"{method}: FWHM {fwhm(x, profile):.3f} px")
            mtf_ax.plot(r.frequencies_cy_px, r.mtf, color=colour, lw=1.0, label=f"{method}: {r.mtf_nyquist:.4f}")
            error_ax.plot(r.frequencies_cy_px, r.mtf - np.interp(r.frequencies_cy_px, f_true, mtf_true),
                          color=colour, lw=1.0, label=method)
        profile_ax.set(xlim=(-view, view), xlabel="distance along the normal (px)", ylabel=name,
                       title=f"{'LSF' if kind == 'edge' else 'pulse response'}, {variant}")
        masked = np.isnan(curves[variant][methods[0]].mtf)
        if kind == "pulse" and masked.any():
            f_masked = curves[variant][methods[0]].frequencies_cy_px[masked]
            for ax in (mtf_ax, error_ax):
                ax.axvspan(f_masked.min(), f_masked.max(), color="0.5", alpha=0.12, lw=0,
                           label="masked: the bar's sinc zero" if ax is mtf_ax else None)
        mtf_ax.set(xlim=(0, 1), ylim=(0, 1.05), xlabel="frequency along the normal (cy/px)", ylabel="MTF",
                   title=f"MTF, {variant}")
        error_ax.axhline(0, color="k", lw=0.8)
        error_ax.set(xlim=(0, 1), xlabel="frequency along the normal (cy/px)", ylabel="estimate - true MTF",
                     title=f"MTF error, {variant}")
        for ax in (mtf_ax, error_ax):
            ax.axvline(NYQUIST, color="0.5", ls=":", lw=0.8)
        profile_ax.legend(fontsize="small")
        mtf_ax.legend(fontsize="small", title="MTF at Nyquist", title_fontsize="small")
        error_ax.legend(fontsize="small")
    target = "edge" if kind == "edge" else f"{width_px:g} px bar"
    fig.suptitle(f"Estimates of a noise-free {target} (40 x 40 px, 6 deg, the paper's sensor) by each method "
                 f"against the truth (paper Fig. {9 if kind == 'edge' else 10})\ntop: as published, each "
                 "method's own blur left in; bottom: corrected, each method's blur divided out (imgmtf's default)")
    return fig


def plot_ground_noise_layers(ground_noise, seed, size=200, grains=(1, 5, 10, 20), oversampling: int = 20):
    """Example ground-noise layers and the composite (paper Fig. 13), on a
    ``size`` x ``size`` grid of sub-pixel cells (``oversampling`` cells per
    pixel)."""
    panels = len(grains) + 1
    fig = Figure(figsize=(3.1 * panels, 3.9), layout="constrained")
    axes = fig.subplots(1, panels)
    rng = np.random.default_rng(seed)
    for ax, grain in zip(axes, grains):
        ax.imshow(ground_noise.layer(grain, (size, size), rng), cmap="gray")
        ax.set(title=f"{grain} x {grain} sub-pixel grains", xticks=[], yticks=[])
    axes[-1].imshow(ground_noise.sample((size, size), rng), cmap="gray")
    axes[-1].set(title=f"sum of {ground_noise.layers} layers", xticks=[], yticks=[])
    fig.suptitle(f"Ground noise before the PSF: each layer {ground_noise.layer_variance_dn2:g} DN^2; "
                 f"{size} x {size} sub-pixel cells = {size / oversampling:g} x {size / oversampling:g} px")
    return fig


def plot_threshold(found, relative, fraction, chips_per_level: int):
    """Fraction of estimates within +-``relative`` of the truth against SNR,
    per method, with its 95 % binomial (Wilson) interval for
    ``chips_per_level`` chips at each SNR, and the ``fraction`` criterion."""
    fig, ax = _axes(None, (7, 4.4))
    z = 1.96
    for i, (method, info) in enumerate(found.items()):
        snrs = np.array(sorted(info["fractions"]), float)
        p = np.array([info["fractions"][s] for s in sorted(info["fractions"])])
        n = chips_per_level
        centre = (p + z * z / (2 * n)) / (1 + z * z / n)
        half = z / (1 + z * z / n) * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
        threshold = info["threshold"]
        reached = f"threshold SNR {threshold:g}" if np.isfinite(threshold) else "never within the criterion"
        ax.fill_between(snrs, centre - half, centre + half, color=f"C{i}", alpha=0.12, lw=0)
        ax.semilogx(snrs, p, "o-", ms=3, color=f"C{i}", label=f"{method}: {reached}")
    ax.axhline(fraction, color="0.5", ls="--", lw=0.8, label=f"criterion: {100 * fraction:g} %")
    ax.set(title=f"Estimates within +-{100 * relative:.0f} % of the true MTF at Nyquist "
                 f"({chips_per_level} chips per SNR; bands: 95 % intervals)",
           xlabel="SNR (step / noise std)", ylabel="fraction of estimates", ylim=(0, 1.02))
    ax.title.set_fontsize("medium")
    ax.legend(fontsize="small", loc="lower right")
    return fig
