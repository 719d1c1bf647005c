"""Figures of a restoration: the MTF per axis (sensor, filter, restored,
target), the restored edge response, and the sharpness-noise trade-off."""
from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure

from ..estimate.spectrum import NYQUIST
from ._common import figure_axes, title_once

if TYPE_CHECKING:
    from ..restore.design import RestorationFilter
    from ..sensor.model import Sensor


def _expect_filter(restoration: object) -> None:
    from ..restore.design import RestorationFilter
    if not isinstance(restoration, RestorationFilter):
        from ..errors import ParameterError
        raise ParameterError(f"this figure draws a restoration filter (imgmtf.design_filter), "
                             f"got {type(restoration).__name__}")


def plot_restored_mtf(restoration: RestorationFilter, direction: str = "across",
                      ax: Axes | None = None, gain_axis: bool | None = None) -> Figure | SubFigure:
    """Along one axis: the sensor's MTF, the filter's transfer, the restored
    MTF and the target, to twice Nyquist (the filter's transfer repeats
    every 1 cy/px), with the values at Nyquist in the legend.  A filter
    whose gain rises above ``SHARED_AXIS_GAIN`` is drawn against an axis of
    its own on the right, so that a high gain leaves the MTF curves their
    full height.

    Parameters
    ----------
    restoration : RestorationFilter
        The filter (:func:`imgmtf.design_filter`).
    direction : {"across", "along"}, optional
        The axis: across track (x, the default) or along track (y).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).
    gain_axis : bool, optional
        Draw the filter against an axis of its own (default: when its gain
        rises above ``SHARED_AXIS_GAIN``); a figure of both axes decides
        once for both.

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``restoration`` is not a RestorationFilter.

    Examples
    --------
    >>> from imgmtf import Sensor, design_filter
    >>> from imgmtf.plot import plot_restored_mtf
    >>> fig = plot_restored_mtf(design_filter(Sensor(), 0.3, kernel_size=7), "along")
    >>> fig.axes[0].get_xlabel()
    'frequency along track (cy/px)'
    """
    _expect_filter(restoration)
    from ..restore.report import axis_curves
    fig, ax = figure_axes(ax)
    f = np.linspace(0.0, 1.0, 401)
    c = axis_curves(restoration, direction, f)
    at = {k: float(v[200]) for k, v in c.items()}
    ax.plot(f, c["system"], color="C0", label=f"sensor: {at['system']:.3f}")
    ax.plot(f, c["restored"], color="k", lw=2.0, label=f"restored: {at['restored']:.3f}")
    ax.plot(f[:201], c["target"][:201], color="C2", ls=":", lw=2.0, label=f"target: {at['target']:.3f}")
    ax.axvline(NYQUIST, color="0.5", ls="--", lw=0.8)
    low, high = float(c["filter"].min()), float(c["filter"].max())
    gain_ax = ax.twinx() if (high > SHARED_AXIS_GAIN if gain_axis is None else gain_axis) else ax
    gain_ax.plot(f, c["filter"], color="C1", ls="--", label=f"filter: {at['filter']:.2f}"
                 + (" (right axis)" if gain_ax is not ax else ""))
    mtf_top = max(1.05, float(max(c["system"].max(), c["restored"].max(), c["target"].max())) * 1.05)
    ax.set(xlim=(0, 1), ylim=(min(0.0, low * 1.05) if gain_ax is ax else 0.0,
                              max(mtf_top, high * 1.05) if gain_ax is ax else mtf_top),
           xlabel=f"frequency {'across' if direction == 'across' else 'along'} track (cy/px)",
           ylabel="MTF, filter gain" if gain_ax is ax else "MTF")
    if gain_ax is not ax:
        gain_ax.set(ylim=(min(0.0, low * 1.05), high * 1.05), ylabel="filter gain")
        gain_ax.tick_params(axis="y", colors="C1")
        gain_ax.yaxis.label.set_color("C1")
    title_once(ax, f"{direction.capitalize()} track")
    handles = [h for a in dict.fromkeys((ax, gain_ax)) for h in a.get_legend_handles_labels()[0]]
    ax.legend(handles=handles, fontsize="small", title="at Nyquist", title_fontsize="small", loc="upper center",
              bbox_to_anchor=(0.5, -0.16), ncols=2)       # off the data, which fill the axes
    return fig


#: the filter gain up to which the filter shares the MTF's axis; above, it has its own
SHARED_AXIS_GAIN = 1.5
#: across and along edge responses closer than this (of the step) are drawn as one
SAME_RESPONSE = 0.02


def plot_restored_edge(restoration: RestorationFilter, ax: Axes | None = None) -> Figure | SubFigure:
    """The edge response before and after restoration across and along
    track (0 dark, 1 bright), in pixels from the edge, with the RER and
    overshoot of each; across and along drawn as one pair of curves where
    they differ by less than ``SAME_RESPONSE`` of the step (four curves
    on top of each other read as none).

    Parameters
    ----------
    restoration : RestorationFilter
        The filter (:func:`imgmtf.design_filter`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``restoration`` is not a RestorationFilter.

    Examples
    --------
    >>> from imgmtf import Sensor, design_filter
    >>> from imgmtf.plot import plot_restored_edge
    >>> fig = plot_restored_edge(design_filter(Sensor(), 0.3, kernel_size=7))
    >>> len(fig.axes[0].lines)            # before and after (across = along here), the 0 and 1 levels
    4
    """
    _expect_filter(restoration)
    from ..restore.report import edge_responses, restoration_report
    fig, ax = figure_axes(ax)
    report = restoration_report(restoration)
    grid = np.arange(-6.0, 6.0 + 1 / 64, 1 / 32)
    curves = {d: edge_responses(restoration, d, grid) for d in ("across", "along")}
    a, b = report.axes["across"], report.axes["along"]
    apart = max(float(np.abs(curves["across"][k] - curves["along"][k]).max()) for k in (1, 2))
    if apart < SAME_RESPONSE:
        x, before, after = curves["across"]
        ax.plot(x, before, color="C0", ls="--", lw=1.2,
                label=f"sensor: RER {a.rer_before:.3f} across, {b.rer_before:.3f} along")
        ax.plot(x, after, color="k", lw=1.8, label=f"restored: RER {a.rer_after:.3f} across, {b.rer_after:.3f} "
                                                     f"along; overshoot {max(a.overshoot_pct, b.overshoot_pct):.1f} %")
        note = f"across and along within {100 * apart:.1f} % of the step: one curve"
    else:
        note = ""
        for i, direction in enumerate(("across", "along")):
            x, before, after = curves[direction]
            r = report.axes[direction]
            ax.plot(x, before, color=f"C{i}", ls="--", lw=1.0, label=f"{direction}, sensor: RER {r.rer_before:.3f}")
            ax.plot(x, after, color=f"C{i}", lw=1.8,
                    label=f"{direction}, restored: RER {r.rer_after:.3f}, overshoot {r.overshoot_pct:.1f} %")
    for level in (0.0, 1.0):
        ax.axhline(level, color="0.6", lw=0.7, ls=":")
    ax.set(xlim=(-6, 6), xlabel="distance from the edge (px)", ylabel="edge response")
    title_once(ax, f"Edge response (noise gain {report.noise_gain:.2f})")
    ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=1, title=note or None,
              title_fontsize="small")    # off the data
    return fig


def plot_restoration(restoration: RestorationFilter) -> Figure:
    """The restoration's figure: the MTF across and along track and the
    edge response before and after.

    Parameters
    ----------
    restoration : RestorationFilter
        The filter (:func:`imgmtf.design_filter`).

    Returns
    -------
    matplotlib.figure.Figure
        Three panels: :func:`plot_restored_mtf` across and along track and
        :func:`plot_restored_edge`.

    Raises
    ------
    ParameterError
        ``restoration`` is not a RestorationFilter.

    Examples
    --------
    >>> from imgmtf import Sensor, design_filter
    >>> from imgmtf.plot import plot_restoration
    >>> len(plot_restoration(design_filter(Sensor(), 0.3, kernel_size=7)).axes)
    3
    """
    _expect_filter(restoration)
    fig = Figure(figsize=(14.0, 5.0), layout="constrained")
    axes = fig.subplots(1, 3)
    from ..restore.report import axis_curves
    f = np.linspace(0.0, 1.0, 401)
    separate = max(float(axis_curves(restoration, d, f)["filter"].max()) for d in ("across", "along")) \
        > SHARED_AXIS_GAIN                      # both panels alike
    plot_restored_mtf(restoration, "across", ax=axes[0], gain_axis=separate)
    plot_restored_mtf(restoration, "along", ax=axes[1], gain_axis=separate)
    plot_restored_edge(restoration, ax=axes[2])
    form = "FFT" if restoration.kernel_size is None else "spatial"
    fig.suptitle(f"Restoration to MTF {restoration.target_nyquist:g} at Nyquist: {form} form, "
                 f"{restoration.taps.shape[0]} x {restoration.taps.shape[0]} taps, noise gain "
                 f"{restoration.noise_gain:.2f}{' (limited)' if restoration.limited else ''}")
    return fig


def plot_restore_tradeoff(sensor: Sensor, targets: Iterable[float] = (0.2, 0.3, 0.4, 0.5), *,
                          kernel_size: int | None = None, ax: Axes | None = None) -> Figure | SubFigure:
    """Achieved MTF at Nyquist (across track) against the filter's noise
    gain, one curve per target as the noise-gain limit tightens; the sensor's
    own MTF at Nyquist (noise gain 1) marked.

    Parameters
    ----------
    sensor : Sensor
        The system to compensate.
    targets : iterable of float, optional
        Target MTFs at Nyquist (0.5 cy/px), each in (0, 1]; one curve each.
    kernel_size : int, optional
        Side (odd, 3 to 63 px) of a spatial kernel; None for the FFT form.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``sensor`` is not a Sensor, or a target out of range.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> from imgmtf.plot import plot_restore_tradeoff
    >>> fig = plot_restore_tradeoff(Sensor(), (0.3, 0.4), kernel_size=7)
    >>> len(fig.axes[0].lines)            # a curve per target and the sensor alone
    3
    """
    from ..restore.design import design_filter
    from ..restore.report import tradeoff
    from ..sensor.model import Sensor
    if not isinstance(sensor, Sensor):
        from ..errors import ParameterError
        raise ParameterError(f"this figure draws an imgmtf.Sensor, got {type(sensor).__name__}")
    fig, ax = figure_axes(ax, size=(5.6, 4.0))
    for i, target in enumerate(targets):
        free = design_filter(sensor, target, kernel_size=kernel_size).noise_gain
        limits = np.linspace(1.0, free, 8) if free > 1.0 else np.array([free])
        gains, mtf = tradeoff(sensor, target, limits, kernel_size=kernel_size)
        ax.plot(gains, mtf, "o-", ms=3, color=f"C{i}", label=f"target {target:g}")
    ax.plot([1.0], [sensor.mtf_nyquist("across")], "k*", ms=10, label="sensor alone")
    ax.set(xlabel="noise gain (restored / input noise std)", ylabel="MTF at Nyquist across track")
    title_once(ax, "Sharpness against noise")
    ax.legend(fontsize="small", loc="lower right")
    return fig
