"""Figures of the paper's study (``imgmtf reproduce``)."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..estimate.spectrum import NYQUIST
from ..metrics import fwhm
from ._common import figure_axes


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
    # at high SNR the estimates hug the truth: the upper right is clear of them
    axes[0].legend(fontsize="small", loc="upper right")
    return fig


def plot_estimates(kind: str, curves: dict, methods, width_px: float = 0.0):
    """Each method's estimate of a noise-free chip against the truth (paper
    Figs. 9 and 10): the LSF of an edge (or the pulse response of a bar
    ``width_px`` wide), the MTF, and the MTF's error, as published (top) and
    with each method's own blur divided out (bottom, imgmtf's default).
    ``curves`` as :func:`imgmtf.reproduce.estimator_tables` returns it."""
    fig = Figure(figsize=(15, 10.5), layout="constrained")
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
        # under each panel: inside, they sat on the peaks and on the zero line the errors are read against
        below = dict(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.17), ncols=2, frameon=False)
        profile_ax.legend(**below)
        mtf_ax.legend(**below, title="MTF at Nyquist", title_fontsize="small")
        error_ax.legend(**{**below, "ncols": 4})
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


def plot_threshold(found, relative, fraction, chips_per_level: int, thresholds: bool = True):
    """Fraction of estimates within +-``relative`` of the truth against SNR,
    per method, with its 95 % binomial (Wilson) interval for
    ``chips_per_level`` chips at each SNR, and the ``fraction`` criterion;
    each method's threshold in the legend unless ``thresholds`` is false (a
    quick run: too few chips per level for one, as its report says)."""
    fig, ax = figure_axes(None, (7, 5.2))
    z = 1.96
    for i, (method, info) in enumerate(found.items()):
        snrs = np.array(sorted(info["fractions"]), float)
        p = np.array([info["fractions"][s] for s in sorted(info["fractions"])])
        n = chips_per_level
        centre = (p + z * z / (2 * n)) / (1 + z * z / n)
        half = z / (1 + z * z / n) * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
        threshold = info["threshold"]
        reached = ("threshold n/a (too few chips)" if not thresholds else f"threshold SNR {threshold:g}"
                   if np.isfinite(threshold) else "never within the criterion")
        ax.fill_between(snrs, centre - half, centre + half, color=f"C{i}", alpha=0.12, lw=0)
        ax.semilogx(snrs, p, "o-", ms=3, color=f"C{i}", label=f"{method}: {reached}")
    ax.axhline(fraction, color="0.5", ls="--", lw=0.8, label=f"criterion: {100 * fraction:g} %")
    ax.set(title=f"Estimates within +-{100 * relative:.0f} % of the true MTF at Nyquist\n"
                 f"({chips_per_level} chips per SNR; bands: 95 % intervals)",
           xlabel="SNR (step / noise std)", ylabel="fraction of estimates", ylim=(0, 1.02))
    ax.title.set_fontsize("medium")
    ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=2, frameon=False)
    return fig
