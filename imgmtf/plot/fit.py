"""Figures of a sensor fit: measured against model MTF per edge, residuals."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..estimate.spectrum import NYQUIST
from ._common import expect, figure_axes
from .sensor import plot_psf


def plot_fit_edge(fit, index: int, ax=None):
    """One edge of a sensor fit: its measured (non-parametric) MTF against
    the fitted model's along its normal, with the model's interval."""
    expect(fit, "fit")
    if not -len(fit.edges) <= index < len(fit.edges):
        from ..errors import ParameterError
        raise ParameterError(f"edge index {index} is outside the fit's {len(fit.edges)} edge(s)")
    fig, ax = figure_axes(ax)
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
    expect(fit, "fit")
    fig, ax = figure_axes(ax)
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
    expect(fit, "fit")
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
