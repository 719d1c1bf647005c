"""Figures of a sensor fit: measured against model MTF per edge, residuals."""
from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure

from ..estimate.fit.report import MISFIT_BIN_PX, residual_means
from ..estimate.spectrum import NYQUIST
from ._common import check_truth, expect, figure_axes
from .sensor import plot_psf

if TYPE_CHECKING:
    from ..estimate.fit import SensorFit


def plot_fit_edge(fit: SensorFit, index: int, ax: Axes | None = None,
                  truth: Callable[[np.ndarray], np.ndarray] | None = None) -> Figure | SubFigure:
    """One edge of a sensor fit: its measured (non-parametric) MTF against
    the fitted model's along its normal, the model's interval as a band
    (drawn, and magnified about Nyquist in an inset, where it is too
    narrow to see at full scale), and ``truth(f)`` (cy/px) when known (a
    chip imgmtf simulated).

    Parameters
    ----------
    fit : SensorFit
        A sensor fit (:func:`imgmtf.fit_sensor`).
    index : int
        The edge, an index into ``fit.edges`` (negative from the end).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).
    truth : callable, optional
        The edge's true MTF as a function of frequency (cy/px), when known.

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``fit`` is not a sensor fit, an ``index`` outside its edges, or ``truth`` not a function.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.plot import plot_fit_edge
    >>> fit = imgmtf.fit_sensor([imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60).image])
    >>> plot_fit_edge(fit, 0).axes[0].get_xlabel()
    'frequency along the normal (cy/px)'
    """
    expect(fit, "fit")
    check_truth(truth)
    check_edge_index(fit, index)
    fig, ax = figure_axes(ax)
    edge = fit.edges[index]
    m = edge.measurement
    f = np.linspace(0.0, 1.0, 201)
    value, low, high = fit.mtf_band(f, edge.normal_angle_deg, edge.gsd_m)
    lo, hi = edge.mtf_nyquist_ci
    percent = f"{100 * fit.confidence:g} %"
    # above the curve's tail, right of Nyquist, where no data lie
    inset = ax.inset_axes((0.56, 0.5, 0.41, 0.42))
    half = 0.03
    near = (f >= NYQUIST - half) & (f <= NYQUIST + half)
    for axes, span in ((ax, slice(None)), (inset, near)):
        axes.fill_between(f[span], low[span], high[span], color="C0", alpha=0.35, lw=0,
                          label=f"model's {percent} interval")
        axes.plot(f[span], value[span], color="C0", lw=1.6, label=f"model: {edge.mtf_nyquist:.4f} "
                                                                  f"[{lo:.4f}, {hi:.4f}]")
        measured = (np.abs(m.frequencies_cy_px - NYQUIST) <= half + 1e-9) if axes is inset else slice(None)
        axes.plot(m.frequencies_cy_px[measured], m.mtf[measured], "--", color="k", lw=1.0,
                  label=f"measured: {edge.measured_mtf_nyquist:.4f}")
        if truth is not None:
            axes.plot(f[span], truth(f[span]), ":", color="C3", lw=1.4,
                      label=f"true: {float(truth(np.array([NYQUIST]))[0]):.4f}")
        axes.axvline(NYQUIST, color="0.5", ls="--", lw=0.8)
    window = np.concatenate([low[near], high[near], m.mtf[np.abs(m.frequencies_cy_px - NYQUIST) <= half + 1e-9]])
    window = window[np.isfinite(window)]
    pad = 0.15 * max(float(np.ptp(window)), 0.01)
    inset.set(xlim=(NYQUIST - half, NYQUIST + half), ylim=(window.min() - pad, window.max() + pad))
    inset.tick_params(labelsize=7)
    inset.set_title("about Nyquist", fontsize=7, pad=2)
    verdict = f": MISFIT (structure {100 * edge.misfit_fraction:.2f} % of the step)" if edge.misfit else ""
    ax.set_title(f"{_short(edge.source)}\nnormal {edge.normal_angle_deg:.1f} deg ({edge.direction}){verdict}",
                 fontsize="medium", color="C3" if edge.misfit else "black")
    ax.set(xlim=(0, 1), ylim=(0, 1.05), xlabel="frequency along the normal (cy/px)", ylabel="MTF")
    ax.legend(fontsize="small", title=f"at Nyquist ({percent} interval)", title_fontsize="small",
              loc="upper center", bbox_to_anchor=(0.5, -0.2), ncols=2, frameon=False)   # below, off the data
    return fig


def plot_fit_residuals(fit: SensorFit, ax: Axes | None = None) -> Figure | SubFigure:
    """Each edge's residuals (data - model) averaged in 0.25 px bins along
    its normal, in % of its step, with the noise's 2-sigma band of a bin
    mean: structure outside it is what the misfit warning reports.  The
    means are of the fit's 1/32 px bins (:class:`imgmtf.estimate.fit.EdgeFit`'s
    ``samples_x_px``, ``residuals_dn``, ``bin_counts``), each by its
    count in the 0.25 px bin its mean falls in: within a 1/32 px bin's
    reach of each edge of those bins, samples may count on the other side
    from where the misfit test, which bins the samples, counts them.

    Parameters
    ----------
    fit : SensorFit
        A sensor fit (:func:`imgmtf.fit_sensor`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``fit`` is not a sensor fit.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.plot import plot_fit_residuals
    >>> fit = imgmtf.fit_sensor([imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60).image])
    >>> plot_fit_residuals(fit).axes[0].get_ylabel()
    'data - model (% of the step)'
    """
    expect(fit, "fit")
    fig, ax = figure_axes(ax)
    for i, edge in enumerate(fit.edges):
        centre, mean, count = residual_means(edge.samples_x_px - edge.offset_px, edge.residuals_dn,
                                             edge.bin_counts, 6.0)
        scale = 100.0 / abs(edge.step_dn)
        line, = ax.plot(centre, mean * scale, ".-", lw=0.8, ms=3, color=f"C{i % 10}",
                        label=f"{_short(edge.source)}: {100 * edge.misfit_fraction:.2f} %")
        ax.fill_between(centre, -2 * edge.noise_dn / np.sqrt(count) * scale,
                        2 * edge.noise_dn / np.sqrt(count) * scale, color=line.get_color(), alpha=0.12, lw=0)
    ax.axhline(0, color="0.4", lw=0.8)
    ax.set(title=f"Residuals along the normal ({MISFIT_BIN_PX:g} px bins)", xlabel="distance from the edge (px)",
           ylabel="data - model (% of the step)")
    ax.legend(fontsize="small", title="structure (RMS)", title_fontsize="small", loc="upper center",
              bbox_to_anchor=(0.5, -0.2), ncols=2, frameon=False)       # below the axes, off the data
    return fig


def plot_fit_lsf(fit: SensorFit, index: int, ax: Axes | None = None,
                 others: Mapping[str, SensorFit] | None = None, reach_px: float = 8.0) -> Figure | SubFigure:
    """One edge's measured line spread function on a log scale against the
    fitted model's along the same direction (and other fits' to compare):
    the shape of the blur, which an MTF alone hides (a Gaussian's LSF is a
    parabola here, an exponential wing a straight line, a one-sided lag a
    lean, a halo a raised foot).

    Parameters
    ----------
    fit : SensorFit
        A sensor fit (:func:`imgmtf.fit_sensor`).
    index : int
        The edge, an index into ``fit.edges`` (negative from the end).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).
    others : mapping of str to SensorFit, optional
        Other fits of the same edges, by label, drawn dashed.
    reach_px : float, optional
        Distances drawn either side of the edge, px (default 8).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``fit`` or one of ``others`` is not a sensor fit, or an ``index``
        outside its edges.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.plot import plot_fit_lsf
    >>> fit = imgmtf.fit_sensor([imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60).image])
    >>> plot_fit_lsf(fit, 0).axes[0].get_yscale()
    'log'
    """
    from ..estimate.fit.data import profile_angle_deg
    expect(fit, "fit")
    for other in (others or {}).values():
        expect(other, "fit")
    check_edge_index(fit, index)
    fig, ax = figure_axes(ax)
    edge = fit.edges[index]
    m = edge.measurement
    x, lsf = np.asarray(m.lsf_x_px, float), np.asarray(m.lsf, float)
    lsf = lsf / float(np.trapezoid(lsf, x))         # unit area, as every model's
    peak = float(lsf.max())
    near = np.abs(x) <= reach_px
    ax.plot(x[near], lsf[near] / peak, color="k", lw=1.2, label="measured (no model)")
    angle = profile_angle_deg(m)
    d = np.linspace(-reach_px, reach_px, 801)
    fits = {f"{'+'.join(s.name for s in fit.sensor.stages)}" + (" (misfit)" if fit.misfit else ""): fit}
    fits.update({label + (" (misfit)" if other.misfit else ""): other for label, other in (others or {}).items()})
    for k, (label, model) in enumerate(fits.items()):
        response = model.sensor.line_response(angle, model.edges[index].gsd_m)
        # the measured profile's distances are from the located edge, the model's from its fitted offset
        model_lsf = response.lsf(d - model.edges[index].offset_px)
        ax.plot(d, model_lsf / peak, ls="-" if k == 0 else "--", lw=1.4, color=f"C{k}", label=label)
    ax.set_yscale("log")
    ax.set(xlim=(-reach_px, reach_px), ylim=(1e-3, 1.5), xlabel="distance along the profile (px)",
           ylabel="LSF (peak = 1)")
    ax.set_title(f"{_short(edge.source)}\nnormal {edge.normal_angle_deg:.1f} deg ({edge.direction})",
                 fontsize="medium")
    ax.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.18), frameon=False)   # off the data
    return fig


def check_edge_index(fit: SensorFit, index: int) -> None:
    """Refuse an ``index`` outside the fit's edges (negative from the end)."""
    if not -len(fit.edges) <= index < len(fit.edges):
        from ..errors import ParameterError
        raise ParameterError(f"edge index {index} is outside the fit's {len(fit.edges)} edge(s)")


def _short(source: str, width: int = 26) -> str:
    """An edge's file name (its folder left out), shortened in the middle."""
    name = Path(source).name or source
    return name if len(name) <= width else name[: width // 2 - 2] + "..." + name[-(width // 2 - 1):]


def plot_fit(fit: SensorFit, max_edges: int = 6,
             truths: Iterable[Callable[[np.ndarray], np.ndarray] | None] | None = None) -> Figure:
    """Measured against model MTF for each edge (the first ``max_edges``),
    the residuals along the normals, and the fitted sensor's 2-D PSF;
    ``truths`` the true MTF of each edge (a function of cy/px, or None)
    when known.

    Parameters
    ----------
    fit : SensorFit
        A sensor fit (:func:`imgmtf.fit_sensor`).
    max_edges : int, optional
        The most edges drawn, each in its panel (default 6).
    truths : iterable of callable or None, optional
        Each edge's true MTF (cy/px), in the order of ``fit.edges``.

    Returns
    -------
    matplotlib.figure.Figure
        A panel per edge shown (:func:`plot_fit_edge`), the residuals
        (:func:`plot_fit_residuals`) and the fitted PSF.

    Raises
    ------
    ParameterError
        ``fit`` is not a sensor fit, or a truth is not a function.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.plot import plot_fit
    >>> fit = imgmtf.fit_sensor([imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60).image])
    >>> sum(ax.get_visible() for ax in plot_fit(fit).axes[:3])      # the edge, residuals, PSF
    3
    """
    expect(fit, "fit")
    truths = list(truths) if truths is not None else [None] * len(fit.edges)
    shown = min(len(fit.edges), max_edges)
    panels = shown + 2
    cols = 2 if panels <= 4 else 3          # a page's width: more columns shrink the text when shown
    rows = -(-panels // cols)
    fig = Figure(figsize=(5.0 * cols, 4.8 * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    for i in range(shown):
        plot_fit_edge(fit, i, axes[i], truth=truths[i])
    plot_fit_residuals(fit, axes[shown])
    plot_psf(fit.sensor, axes[shown + 1], pixel_units=fit.pixel_units)
    axes[shown + 1].set_title("Fitted system PSF (peak = 1)")
    for ax in axes[panels:]:
        ax.set_visible(False)
    held = [p.key for p in fit.parameters if p.status != "fitted" and p.note != "not fitted"]
    more = f" (first {shown} of {len(fit.edges)} edges)" if shown < len(fit.edges) else ""
    misfit = [e for e in fit.edges if e.misfit]
    verdict = ""
    if misfit:
        verdict = (f"MISFIT: the model does not fit {len(misfit)} of its {len(fit.edges)} edges (residual structure "
                   f"up to {100 * max(e.misfit_fraction for e in misfit):.2f} % of the step): its MTF may be biased")
    elif fit.misfit:
        verdict = "MISFIT: a fitted parameter sits at the bound of its range: its MTF may be biased"
    import textwrap
    lines = [*verdict.splitlines(), f"Fit of {', '.join(s.name for s in fit.sensor.stages)}{more}: reduced "
             f"chi-square {fit.reduced_chi_square:.3g}", *([f"held or tied: {', '.join(held)}"] if held else [])]
    # wrapped to the figure's width (about 12 characters an inch at this size), never cut at its edges
    width = int(12 * fig.get_figwidth())
    fig.suptitle("\n".join(textwrap.fill(line, width) for line in lines),
                 fontsize="large" if fit.misfit else "medium", color="C3" if fit.misfit else "black")
    return fig
