"""Figures of the paper's study (``imgmtf reproduce``)."""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from ..estimate.spectrum import NYQUIST
from ..kinds import get_kind
from ..metrics import fwhm
from ._common import figure_axes

if TYPE_CHECKING:
    from ..sensor.noise import GroundNoise


def plot_noise_sweep(rows: Sequence[Mapping[str, Any]], methods: Sequence[str], true_nyquist: float,
                     title: str) -> Figure:
    """MTF at Nyquist against measured SNR, one panel per method, the true
    MTF as a line (paper Figs. 12 and 14).

    Parameters
    ----------
    rows : sequence of mapping
        One per chip, ``results`` mapping each method to its (MTF at
        Nyquist, SNR).
    methods : sequence of str
        The resampling methods, a panel each.
    true_nyquist : float
        The true MTF at Nyquist.
    title : str
        The noise swept ("System noise", "Ground noise"), heading each panel.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per method.

    Examples
    --------
    >>> from imgmtf.plot import plot_noise_sweep
    >>> rows = [{"results": {"msg": (0.27, 50.0)}}, {"results": {"msg": (0.26, 500.0)}}]
    >>> plot_noise_sweep(rows, ["msg"], 0.2667, "System noise").axes[0].get_title()
    'System noise: msg'
    """
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


def plot_estimates(kind: str, curves: dict, methods: Sequence[str], width_px: float = 0.0,
                   paper_figure: int | None = None) -> Figure:
    """Each method's estimate of a noise-free chip against the truth (paper
    Figs. 9 and 10): the LSF of an edge (or the pulse response of a bar
    ``width_px`` wide), the MTF, and the MTF's error, as published (top) and
    with each method's own blur divided out (bottom, imgmtf's default).
    ``curves`` as :func:`imgmtf.reproduce.estimator_tables` returns it.

    Parameters
    ----------
    kind : {"edge", "pulse"}
        The target.
    curves : dict
        ``"truth"``: (x_px, profile, f_cy_px, mtf); ``"as published"`` and
        ``"corrected"``: each method's measurement.
    methods : sequence of str
        The resampling methods drawn.
    width_px : float, optional
        The bar's width, px (a pulse; default 0).
    paper_figure : int, optional
        The paper's figure these estimates reproduce, named in the title.

    Returns
    -------
    matplotlib.figure.Figure
        Two rows (as published, corrected) of three panels: the profile,
        the MTF and its error.

    Examples
    --------
    >>> from imgmtf.reproduce import estimator_tables                  # doctest: +SKIP
    >>> from imgmtf.plot import plot_estimates                         # doctest: +SKIP
    >>> rows, curves = estimator_tables(["msg"])                       # doctest: +SKIP
    >>> len(plot_estimates("edge", curves["edge"], ["msg"]).axes)       # doctest: +SKIP
    6
    """
    fig = Figure(figsize=(15, 10.5), layout="constrained")
    axes = fig.subplots(2, 3)
    x_true, profile_true, f_true, mtf_true = curves["truth"]
    target = get_kind(kind)
    name = f"{target.lsf_label} ({target.lsf_scale})"
    view = 4.0 + width_px / 2
    for row, variant in zip(axes, ("as published", "corrected")):
        profile_ax, mtf_ax, error_ax = row
        profile_ax.plot(x_true, profile_true, color="k", lw=2.4, alpha=0.35,
                        label=f"true: FWHM {fwhm(x_true, profile_true):.3f} px")
        mtf_ax.plot(f_true, mtf_true, color="k", lw=2.4, alpha=0.35,
                    label=f"true: {float(np.interp(NYQUIST, f_true, mtf_true)):.4f}")
        for i, method in enumerate(methods):
            r = curves[variant][method]
            x, profile, _ = r.lsf_like()
            colour = f"C{i}"
            profile_ax.plot(x, profile, color=colour, lw=1.0, label=f"{method}: FWHM {fwhm(x, profile):.3f} px")
            mtf_ax.plot(r.frequencies_cy_px, r.mtf, color=colour, lw=1.0, label=f"{method}: {r.mtf_nyquist:.4f}")
            error_ax.plot(r.frequencies_cy_px, r.mtf - np.interp(r.frequencies_cy_px, f_true, mtf_true),
                          color=colour, lw=1.0, label=method)
        profile_ax.set(xlim=(-view, view), xlabel="distance along the normal (px)", ylabel=name,
                       title=f"{target.lsf_label}, {variant}")
        masked = np.isnan(curves[variant][methods[0]].mtf)
        if target.masked_by and masked.any():
            f_masked = curves[variant][methods[0]].frequencies_cy_px[masked]
            for ax in (mtf_ax, error_ax):
                ax.axvspan(f_masked.min(), f_masked.max(), color="0.5", alpha=0.12, lw=0,
                           label=f"masked: {target.masked_by} zero" if ax is mtf_ax else None)
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
    reproduced = "" if paper_figure is None else f" (paper Fig. {paper_figure})"
    fig.suptitle(f"Estimates of a noise-free {target.described.format(width_px=width_px)} (40 x 40 px, 6 deg, "
                 f"the paper's sensor) by each method against the truth{reproduced}\ntop: as published, each "
                 "method's own blur left in; bottom: corrected, each method's blur divided out (imgmtf's default)")
    return fig


def plot_ground_noise_layers(ground_noise: GroundNoise, seed: int | None, size: int = 200,
                             grains: Sequence[int] = (1, 5, 10, 20), oversampling: int = 20) -> Figure:
    """Example ground-noise layers and the composite (paper Fig. 13), on a
    ``size`` x ``size`` grid of sub-pixel cells (``oversampling`` cells per
    pixel).

    Parameters
    ----------
    ground_noise : GroundNoise
        The noise model.
    seed : int or None
        The noise's seed.
    size : int, optional
        The grid's side, sub-pixel cells (default 200).
    grains : sequence of int, optional
        The layers shown, by grain (sub-pixel cells; default 1, 5, 10, 20).
    oversampling : int, optional
        Sub-pixel cells per pixel, for the title's size in px (default 20).

    Returns
    -------
    matplotlib.figure.Figure
        A panel per layer and one of their sum.

    Examples
    --------
    >>> from imgmtf import GroundNoise
    >>> from imgmtf.plot import plot_ground_noise_layers
    >>> len(plot_ground_noise_layers(GroundNoise(), seed=1, size=40).axes)
    5
    """
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


def plot_threshold(found: Mapping[str, Mapping[str, Any]], relative: float, fraction: float, chips_per_level: int,
                   thresholds: bool = True) -> Figure:
    """Fraction of estimates within +-``relative`` of the truth against SNR,
    per method, with its 95 % binomial (Wilson) interval for
    ``chips_per_level`` chips at each SNR, and the ``fraction`` criterion;
    each method's threshold in the legend unless ``thresholds`` is false (a
    quick run: too few chips per level for one, as its report says).

    Parameters
    ----------
    found : mapping
        Per method: ``fractions`` (SNR -> fraction of estimates within the
        criterion) and ``threshold`` (the SNR from which they stay above
        ``fraction``; NaN for none).
    relative : float
        The criterion's half-width, a fraction of the true MTF at Nyquist.
    fraction : float
        The fraction of estimates the criterion asks for.
    chips_per_level : int
        Chips measured at each SNR.
    thresholds : bool, optional
        Write each method's threshold in the legend (default True).

    Returns
    -------
    matplotlib.figure.Figure
        The fractions against SNR.

    Examples
    --------
    >>> from imgmtf.plot import plot_threshold
    >>> found = {"msg": {"fractions": {10.0: 0.2, 100.0: 0.9, 1000.0: 1.0}, "threshold": 100.0}}
    >>> plot_threshold(found, 0.05, 0.9, 20).axes[0].get_legend_handles_labels()[1]
    ['msg: threshold SNR 100', 'criterion: 90 %']
    """
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
