"""Figures of one measurement (edge or bar): locations, profile, LSF, MTF."""
from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure
from numpy.typing import ArrayLike

from ..estimate.spectrum import NYQUIST
from ..kinds import get_kind
from ._common import check_truth, expect, figure_axes, title_once, warning_lines

if TYPE_CHECKING:
    from ..estimate.results import MTFResult


def _view_px(result: MTFResult) -> float:
    """Half-width (px) of a profile view that shows the LSF's core and the
    start of its tails."""
    return float(min(max(6.0, 2.5 * result.lsf_half_width_px), np.abs(result.samples_x_px).max()))


def plot_locations(result: MTFResult, ax: Axes | None = None) -> Figure | SubFigure:
    """Per-row sub-pixel target locations and the fitted line (paper Fig.
    5a), at equal scale in both axes so that the tilt looks as it is, in
    the pixel coordinates of the image measured (its ROI's offset added:
    a file's with ``imgmtf measure --roi``, a scene's for a scan's edge);
    the rows' RMS scatter about the line is in the legend.

    Parameters
    ----------
    result : EdgeResult or PulseResult
        A measurement (:func:`imgmtf.measure_edge`, :func:`imgmtf.measure_pulse`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``result`` is not a measurement.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.plot import plot_locations
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> plot_locations(imgmtf.measure_edge(chip.image)).axes[0].get_aspect()
    1.0
    """
    expect(result, "result")
    fig, ax = figure_axes(ax)
    g = result.geometry
    kept = g.kept
    fitted = g.slope * g.rows + g.intercept
    rms = float(np.sqrt(np.mean((g.locations[kept] - fitted[kept]) ** 2)))
    x0, y0 = result.roi[:2]

    def image_xy(along, across):
        # a near-horizontal target was measured on the transposed chip: draw it as the image shows it,
        # where the image has it
        return (along + x0, across + y0) if g.transposed else (across + x0, along + y0)
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
    title_once(ax, f"{result.target.capitalize()}: normal at {result.normal_angle_deg:.2f} deg, "
               f"tilt {result.tilt_deg:.2f} deg")
    # the line may run anywhere in these axes: its legend goes under them, off the data
    ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=2, frameon=False)
    return fig


def plot_profile(result: MTFResult, ax: Axes | None = None) -> Figure | SubFigure:
    """Over-sampled profile samples and the resampled profile: the ESF of an
    edge (paper Fig. 5b) or the PRF of a pulse, normalised; the LSF window's
    flat core is shaded, its taper lighter.

    Parameters
    ----------
    result : EdgeResult or PulseResult
        A measurement (:func:`imgmtf.measure_edge`, :func:`imgmtf.measure_pulse`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``result`` is not a measurement.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.plot import plot_profile
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> plot_profile(imgmtf.measure_edge(chip.image)).axes[0].get_xlabel()
    'distance from the line along the normal (px)'
    """
    expect(result, "result")
    fig, ax = figure_axes(ax)
    x, profile, (lo, hi) = result.normalised_profile()
    name = get_kind(result.target).profile_label.format(width_px=result.width_px)
    ax.plot(result.samples_x_px, (result.samples_dn - lo) / (hi - lo), ".", ms=1.5,
            color="0.6", label="pixels")
    ax.plot(x, profile, "-", color="C0", label=f"{result.method} profile")
    _window_bands(ax, result)
    view = _view_px(result)
    ax.set(xlim=(-view, view), xlabel="distance from the line along the normal (px)", ylabel="normalised DN")
    title_once(ax, f"{name} (SNR {result.snr:.0f})")
    # a double bar's or a wide pulse's profile fills the axes: the legend goes under them, off the data
    ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=2, frameon=False)
    return fig


def _window_bands(ax, result):
    centre = 0.0
    core, taper = result.lsf_half_width_px, result.params.get("lsf_taper_px", 0.0)
    ax.axvspan(centre - core, centre + core, color="C2", alpha=0.08, lw=0, label="LSF window core (data)")
    for sign in (-1, 1):
        ax.axvspan(centre + sign * core, centre + sign * (core + taper), color="C2", alpha=0.04, lw=0,
                   label="taper to the tail model" if sign > 0 else None)


def plot_lsf(result: MTFResult, ax: Axes | None = None) -> Figure | SubFigure:
    """The recovered LSF with its full width at half maximum marked.

    Parameters
    ----------
    result : EdgeResult or PulseResult
        A measurement (:func:`imgmtf.measure_edge`, :func:`imgmtf.measure_pulse`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``result`` is not a measurement.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.plot import plot_lsf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> plot_lsf(imgmtf.measure_edge(chip.image)).axes[0].get_ylabel()
    'LSF (1/px)'
    """
    expect(result, "result")
    fig, ax = figure_axes(ax)
    x, lsf = result.lsf_x_px, result.lsf
    ax.plot(x, lsf, color="C0", label="LSF")
    peak = float(lsf.max())
    centre = float(x[np.argmax(lsf)])
    ax.hlines(peak / 2, centre - result.fwhm_px / 2, centre + result.fwhm_px / 2, color="C3",
              label=f"FWHM {result.fwhm_px:.3f} px" + (f" ({result.fwhm_m:.3g} m)" if result.gsd_m else ""))
    view = max(4.0, 2.5 * result.fwhm_px)
    ax.set(xlim=(centre - view, centre + view), xlabel="distance along the normal (px)", ylabel="LSF (1/px)")
    title_once(ax, "Line spread function")
    # under the axes: a ringing or two-lobed LSF reaches every corner
    ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=2, frameon=False)
    return fig


def plot_mtf(result: MTFResult, ax: Axes | None = None, truth: Callable[[np.ndarray], np.ndarray] | None = None,
             color: str | None = None, label: str | None = None) -> Figure | SubFigure:
    """The MTF along the normal with MTF at Nyquist and MTF50 marked with
    their confidence intervals, the frequencies beyond the noise limit
    shaded, and ``truth(f)`` (cycles/pixel) overlaid when known.

    Parameters
    ----------
    result : EdgeResult or PulseResult
        A measurement (:func:`imgmtf.measure_edge`, :func:`imgmtf.measure_pulse`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).
    truth : callable, optional
        The true MTF as a function of frequency (cy/px), when known (a chip
        imgmtf rendered: :meth:`imgmtf.Chip.true_mtf`).
    color : str, optional
        The curve's matplotlib colour (default the axes' next).
    label : str, optional
        The curve's legend entry (default "measured").

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``result`` is not a measurement, or ``truth`` is not a function.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.plot import plot_mtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> plot_mtf(imgmtf.measure_edge(chip.image), truth=chip.true_mtf).axes[0].get_xlabel()
    'frequency along the normal (cy/px)'
    """
    expect(result, "result")
    check_truth(truth)
    fig, ax = figure_axes(ax)
    f = result.frequencies_cy_px
    line, = ax.plot(f, result.mtf, color=color, label=label or "measured")
    c = line.get_color()
    model = getattr(result, "model_mtf", None)         # a sensor model fitted where the divisor hides the MTF
    if model is not None:
        ax.fill_between(model.frequencies_cy_px, model.low, model.high, color="tab:orange", alpha=0.3, lw=0,
                        zorder=1, label=f"its {model.confidence:.0%} interval")
        ax.plot(model.frequencies_cy_px, model.mtf, "-.", color="tab:orange", lw=1.2, zorder=1,
                label=f"sensor model ({model.stages}) fitted to the profile")
    from_model = getattr(result, "model_figures", ())
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
                label=f"MTF@Nyquist {_figure(result.mtf_nyquist, missing=missing_cause(result, 'mtf_nyquist'))}"
                      f"{interval}{' (model)' if 'mtf_nyquist' in from_model else ''}")
    ci50 = result.mtf50_ci_cy_px
    xerr = ([[result.mtf50_cy_px - ci50.low], [ci50.high - result.mtf50_cy_px]] if np.isfinite(ci50.low) else None)
    interval50 = f" [{ci50.low:.4f}, {ci50.high:.4f}]" if xerr else ""
    ax.errorbar([result.mtf50_cy_px], [0.5], xerr=xerr, fmt="s", color=c, capsize=3, ms=4,
                label=f"MTF50 {_figure(result.mtf50_cy_px, 'cy/px', missing_cause(result, 'mtf50'))}{interval50}"
                      f"{' (model)' if 'mtf50_cy_px' in from_model else ''}")
    if getattr(result, "sharpened", False):
        # a sharpened product's MTF rises above 1: its peak marked, the axis taken above it
        ax.axhline(1.0, color="0.5", lw=0.6)
        ax.plot([result.mtf_peak_cy_px], [result.mtf_peak], "^", color=c, ms=5,
                label=f"peak {result.mtf_peak:.3f} at {result.mtf_peak_cy_px:.3f} cy/px (sharpened)")
    top = max(1.05, float(np.nanmax(result.mtf)) + 0.05)
    ax.set(xlim=(0, f.max()), ylim=(0, top), xlabel="frequency along the normal (cy/px)", ylabel="MTF")
    if result.gsd_m:
        gsd = result.gsd_m

        def per_metre(f_cy_px: ArrayLike) -> np.ndarray:
            return np.divide(f_cy_px, gsd)

        def per_pixel(f_cy_m: ArrayLike) -> np.ndarray:
            return np.multiply(f_cy_m, gsd)

        ax.secondary_xaxis("top", functions=(per_metre, per_pixel)).set_xlabel("frequency (cy/m)")
    title_once(ax, "MTF")
    # below the axes: inside, its seven entries covered the curve and its MTF50 marker
    ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=2, frameon=False)
    return fig


def _once(ax, prefix: str, label: str) -> str:
    """``label``, unless a label starting with ``prefix`` is already in the
    axes' legend (several measurements drawn on one axes)."""
    drawn = ax.get_legend_handles_labels()[1]
    return "_nolegend_" if any(d.startswith(prefix) for d in drawn) else label


def _figure(value: float, unit: str = "", missing: str = "undefined") -> str:
    """A figure as the plots print it, with its unit; where it is NaN, why
    (``missing``, see :func:`missing_cause`)."""
    if not np.isfinite(value):
        return missing
    return f"{value:.4f} {unit}" if unit else f"{value:.4f}"


def missing_cause(result, figure: str) -> str:
    """Why ``figure`` ("mtf_nyquist" or "mtf50") of ``result`` is missing
    (NaN), in the words a figure prints: the bar's sinc masks the
    frequencies where it would be read, or the curve does not reach it (an
    MTF that stays above 0.5, as a forced chip's may), or it is undefined.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60)
    >>> result = imgmtf.measure_edge(chip.image)
    >>> from dataclasses import replace
    >>> sharp = replace(result, mtf50_cy_px=float("nan"), mtf=np.maximum(result.mtf, 0.6))
    >>> missing_cause(sharp, "mtf50")
    'undefined: the MTF stays above 0.5 up to 1 cy/px'
    """
    f, mtf = result.frequencies_cy_px, result.mtf
    masked = ~np.isfinite(mtf)
    masking = get_kind(result.target).masked_by      # what zeroes the kind's divisor, if anything
    if figure == "mtf_nyquist":
        return f"masked by {masking}" if masking and masked[np.argmin(np.abs(f - NYQUIST))] else "undefined"
    first_masked = int(np.argmax(masked)) if masked.any() else mtf.size
    if masking and masked.any() and np.all(mtf[:first_masked] > 0.5):
        return f"masked by {masking}"
    if first_masked and np.all(mtf[:first_masked] > 0.5):
        return f"undefined: the MTF stays above 0.5 up to {f[first_masked - 1]:g} cy/px"
    return "undefined"



def plot_measurement(result: MTFResult, truth: Callable[[np.ndarray], np.ndarray] | None = None,
                     title: str | None = None, warnings: Iterable[str] | None = None) -> Figure:
    """Target locations, profile (ESF or PRF), LSF and MTF of one
    measurement, headed by ``title`` (the file), the figures a report
    quotes and its warnings; ``truth(f)`` overlays a known MTF.  A
    measurement forced past failed checks says so first, in red (and when
    its number is not to be trusted at all, why); a sharpened product's
    says its figures are the product's, not the sensor's.

    ``warnings`` are those of the record the figure belongs to (default
    the result's; ``imgmtf measure`` adds the file's own, such as a
    photo's luminance): the header prints the first few and counts them
    all, so that none is dropped unsaid.

    Parameters
    ----------
    result : EdgeResult or PulseResult
        A measurement (:func:`imgmtf.measure_edge`, :func:`imgmtf.measure_pulse`).
    truth : callable, optional
        The true MTF as a function of frequency (cy/px), when known (a chip
        imgmtf rendered: :meth:`imgmtf.Chip.true_mtf`).
    title : str, optional
        The header's first line (the file measured).
    warnings : iterable of str, optional
        The warnings to print (default the result's).

    Returns
    -------
    matplotlib.figure.Figure
        Four panels: :func:`plot_locations`, :func:`plot_profile`,
        :func:`plot_lsf` and :func:`plot_mtf`.

    Raises
    ------
    ParameterError
        ``result`` is not a measurement, or ``truth`` is not a function.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.plot import plot_measurement
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> len(plot_measurement(imgmtf.measure_edge(chip.image), truth=chip.true_mtf, title="chip").axes)
    4
    """
    expect(result, "result")
    check_truth(truth)
    fig = Figure(figsize=(12, 8.5), layout="constrained")
    axes = fig.subplots(2, 2)
    plot_locations(result, axes[0, 0])
    plot_profile(result, axes[0, 1])
    plot_lsf(result, axes[1, 0])
    plot_mtf(result, axes[1, 1], truth=truth)
    ci = result.mtf_nyquist_ci
    interval = f" [{ci.low:.4f}, {ci.high:.4f}]" if np.isfinite(ci.low) else ""
    summary = (f"MTF at Nyquist {_figure(result.mtf_nyquist, missing=missing_cause(result, 'mtf_nyquist'))}"
               f"{interval}, MTF50 {_figure(result.mtf50_cy_px, 'cy/px', missing_cause(result, 'mtf50'))}, "
               f"FWHM {result.fwhm_px:.3f} px, SNR {result.snr:.0f}, {result.direction}, "
               f"{result.rows_used} rows, method {result.method}")
    warnings = list(result.warnings if warnings is None else warnings)
    summary = "\n".join([summary, *warning_lines(warnings)])
    verdict, colour = measurement_verdict(result)
    head = "\n".join(line for line in (title, verdict) if line)
    fig.suptitle(f"{head}\n{summary}" if head else summary, fontsize="medium", color=colour)
    return fig


def measurement_verdict(result: MTFResult) -> tuple[str, str]:
    """What the figure's header says first, and its colour: a number
    forced past failed checks (``FORCED``), one not to be trusted even
    so (``UNTRUSTED``, :func:`imgmtf.estimate.gate.untrusted_when_forced`),
    a sharpened product; ``""`` and black for a measurement the gate
    passed.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> measurement_verdict(imgmtf.measure_edge(chip.image))
    ('', 'black')
    """
    from ..estimate.gate import untrusted_when_forced
    lines, colour = [], "black"
    failed = sorted({c.reason for c in result.checks if c.failed})
    if failed:
        colour = "C3"
        untrusted = untrusted_when_forced(result.checks)
        lines.append(f"FORCED past {len(failed)} failed check(s) ({', '.join(failed)})"
                     + (f"; UNTRUSTED ({untrusted.reason}): not to be used" if untrusted is not None
                        else ": measured anyway"))
    if getattr(result, "sharpened", False):
        colour = "C3" if failed else "darkorange"
        lines.append(f"SHARPENED: the MTF rises to {result.mtf_peak:.3f} at {result.mtf_peak_cy_px:.3f} cy/px: "
                     "the figures are the sharpened product's, not the sensor's")
    return "\n".join(lines), colour
