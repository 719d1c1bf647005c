"""Figures of a restoration: the MTF per axis (sensor, filter, restored,
target), the restored edge response, and the sharpness-noise trade-off."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..estimate.spectrum import NYQUIST
from ._common import figure_axes, title_once


def _expect_filter(restoration) -> None:
    from ..restore.design import RestorationFilter
    if not isinstance(restoration, RestorationFilter):
        from ..errors import ParameterError
        raise ParameterError(f"this figure draws a restoration filter (imgmtf.design_filter), "
                             f"got {type(restoration).__name__}")


def plot_restored_mtf(restoration, direction: str = "across", ax=None):
    """Along one axis: the sensor's MTF, the filter's transfer, the restored
    MTF and the target, to twice Nyquist (the filter's transfer repeats
    every 1 cy/px), with the values at Nyquist in the legend."""
    _expect_filter(restoration)
    from ..restore.report import axis_curves
    fig, ax = figure_axes(ax)
    f = np.linspace(0.0, 1.0, 401)
    c = axis_curves(restoration, direction, f)
    at = {k: float(v[200]) for k, v in c.items()}
    ax.plot(f, c["system"], color="C0", label=f"sensor: {at['system']:.3f}")
    ax.plot(f, c["filter"], color="C1", ls="--", label=f"filter: {at['filter']:.2f}")
    ax.plot(f, c["restored"], color="k", lw=2.0, label=f"restored: {at['restored']:.3f}")
    ax.plot(f[:201], c["target"][:201], color="C2", ls=":", lw=2.0, label=f"target: {at['target']:.3f}")
    ax.axvline(NYQUIST, color="0.5", ls="--", lw=0.8)
    top = max(1.05, float(c["filter"].max()) * 1.05)
    ax.set(xlim=(0, 1), ylim=(min(0.0, float(c["filter"].min()) * 1.05), top),
           xlabel=f"frequency {'across' if direction == 'across' else 'along'} track (cy/px)",
           ylabel="MTF, filter gain")
    title_once(ax, f"{direction.capitalize()} track")
    ax.legend(fontsize="x-small", title="at Nyquist", title_fontsize="x-small", loc="upper center",
              bbox_to_anchor=(0.5, -0.16), ncols=2)       # off the data, which fill the axes
    return fig


def plot_restored_edge(restoration, ax=None):
    """The edge response before and after restoration across and along
    track (0 dark, 1 bright), in pixels from the edge, with the RER and
    overshoot of each."""
    _expect_filter(restoration)
    from ..restore.report import edge_responses, restoration_report
    fig, ax = figure_axes(ax)
    report = restoration_report(restoration)
    for i, direction in enumerate(("across", "along")):
        x, before, after = edge_responses(restoration, direction, np.arange(-6.0, 6.0 + 1 / 64, 1 / 32))
        a = report.axes[direction]
        ax.plot(x, before, color=f"C{i}", ls="--", lw=1.0, label=f"{direction}, sensor: RER {a.rer_before:.3f}")
        ax.plot(x, after, color=f"C{i}", lw=2.6 - 1.4 * i,      # the thinner along line shows over the across
                label=f"{direction}, restored: RER {a.rer_after:.3f}, overshoot {a.overshoot_pct:.1f} %")
    for level in (0.0, 1.0):
        ax.axhline(level, color="0.6", lw=0.7, ls=":")
    ax.set(xlim=(-6, 6), xlabel="distance from the edge (px)", ylabel="edge response")
    title_once(ax, f"Edge response (noise gain {report.noise_gain:.2f})")
    ax.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=2)    # off the data
    return fig


def plot_restoration(restoration):
    """The restoration's figure: the MTF across and along track and the
    edge response before and after."""
    _expect_filter(restoration)
    fig = Figure(figsize=(14.0, 5.0), layout="constrained")
    axes = fig.subplots(1, 3)
    plot_restored_mtf(restoration, "across", ax=axes[0])
    plot_restored_mtf(restoration, "along", ax=axes[1])
    plot_restored_edge(restoration, ax=axes[2])
    form = "FFT" if restoration.kernel_size is None else "spatial"
    fig.suptitle(f"Restoration to MTF {restoration.target_nyquist:g} at Nyquist: {form} form, "
                 f"{restoration.taps.shape[0]} x {restoration.taps.shape[0]} taps, noise gain "
                 f"{restoration.noise_gain:.2f}{' (limited)' if restoration.limited else ''}")
    return fig


def plot_restore_tradeoff(sensor, targets=(0.2, 0.3, 0.4, 0.5), *, kernel_size: int | None = None, ax=None):
    """Achieved MTF at Nyquist (across track) against the filter's noise
    gain, one curve per target as the noise-gain limit tightens; the sensor's
    own MTF at Nyquist (noise gain 1) marked."""
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
