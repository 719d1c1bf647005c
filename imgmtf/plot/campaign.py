"""Figures of a calibration campaign: a figure of merit against the
acquisition time, each acquisition with its interval, the requirement, the
pre-launch value and the drift line."""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.dates import AutoDateLocator, ConciseDateFormatter
from matplotlib.figure import Figure, SubFigure

from ._common import figure_axes, title_once

if TYPE_CHECKING:
    from ..campaign.trend import Trend

# figure -> (axis label, its interval's columns in the targets layer)
TREND_FIGURES = {
    "mtf_nyquist": ("MTF at Nyquist", ("mtf_nyquist_ci_low", "mtf_nyquist_ci_high")),
    "mtf50_cy_px": ("MTF50 (cycles/pixel)", ("mtf50_ci_low_cy_px", "mtf50_ci_high_cy_px")),
    "fwhm_px": ("FWHM of the LSF (px)", None),
    "rer": ("RER (relative edge response)", None),
}


def plot_trend(rows: Sequence[Mapping], figure: str = "mtf_nyquist", *, trend: Trend | None = None,
               requirement: float | None = None, baseline: float | None = None,
               ax: Axes | None = None) -> Figure | SubFigure:
    """One figure of merit against acquisition time.

    Parameters
    ----------
    rows : sequence of mapping
        Rows of a campaign store's ``targets`` layer (one group: a platform,
        band, direction and method), with ``acquired_utc``; a fit whose
        ``misfit`` is set is marked with a cross.
    figure : {"mtf_nyquist", "mtf50_cy_px", "fwhm_px", "rer"}, optional
        The figure of merit (default the MTF at Nyquist).
    trend : imgmtf.campaign.trend.Trend, optional
        The drift fitted to them, drawn as a line with its slope per year.
    requirement, baseline : float, optional
        The requirement and the pre-launch value (horizontal lines), in the
        figure's unit.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        An unknown ``figure``.

    Examples
    --------
    >>> from imgmtf.plot import plot_trend
    >>> rows = [{"acquired_utc": "2021-06-01", "mtf_nyquist": 0.27},
    ...         {"acquired_utc": "2022-06-01", "mtf_nyquist": 0.26}]
    >>> plot_trend(rows, requirement=0.2).axes[0].get_ylabel()
    'MTF at Nyquist'
    """
    from ..campaign.trend import parse_utc, years_since
    from ..errors import ParameterError
    if figure not in TREND_FIGURES:
        raise ParameterError(f"figure must be one of {', '.join(TREND_FIGURES)}, got {figure!r}")
    label, bounds = TREND_FIGURES[figure]
    fig, ax = figure_axes(ax, (6.0, 3.6))
    usable = [r for r in rows if r.get("acquired_utc") and r.get(figure) is not None]
    if not usable:
        ax.text(0.5, 0.5, "none in these results", transform=ax.transAxes, ha="center", va="center", color="0.4")
        ax.set(xticks=[], yticks=[])
        title_once(ax, label)
        return fig
    # datetimes, which matplotlib's date converter plots but its type stubs do not list
    times: list[Any] = [parse_utc(r["acquired_utc"]).replace(tzinfo=None) for r in usable]
    values = np.array([r[figure] for r in usable], float)
    if bounds and usable:
        low = np.array([np.nan if r.get(bounds[0]) is None else r[bounds[0]] for r in usable], float)
        high = np.array([np.nan if r.get(bounds[1]) is None else r[bounds[1]] for r in usable], float)
        known = np.isfinite(low) & np.isfinite(high)
        errors = np.where(known, [values - low, high - values], 0.0)
        ax.errorbar(times, values, yerr=errors, fmt="o", ms=4, color="C0", ecolor="C0", elinewidth=1.0,
                    capsize=3, label="acquisition (95 % interval)", zorder=3)
    else:
        ax.plot(times, values, "o", ms=4, color="C0", label="acquisition", zorder=3)
    misfit = [t for t, r in zip(times, usable) if r.get("misfit")]
    if misfit:
        ax.plot(misfit, [r[figure] for r in usable if r.get("misfit")], "x", ms=9, color="C3", zorder=4,
                label="the model misfits: may be biased")
    if trend is not None and trend.has_slope:       # one acquisition, or misfit rows: points, no line
        span = np.array([trend.first_utc, trend.last_utc])
        ends: list[Any] = [parse_utc(t).replace(tzinfo=None) for t in span]
        years = years_since(list(span), trend.first_utc)
        interval = (f" [{trend.slope_ci_low:+.4f}, {trend.slope_ci_high:+.4f}]"
                    if np.isfinite(trend.slope_ci_low) else "")
        flag = ": drift" if trend.drift else ""
        ax.plot(ends, trend.value_at(years), "-", color="C3", lw=1.5,
                label=f"{trend.slope_per_year:+.4f}/year{interval}{flag}")
    if requirement is not None:
        ax.axhline(requirement, color="k", ls="--", lw=1.0, label=f"requirement {requirement:g}")
    if baseline is not None:
        ax.axhline(baseline, color="C2", ls=":", lw=1.5, label=f"pre-launch {baseline:.3f}")
    locator = AutoDateLocator(minticks=3, maxticks=8)
    ax.xaxis.set_major_locator(locator)
    ax.xaxis.set_major_formatter(ConciseDateFormatter(locator))
    ax.set(xlabel="acquisition time (UTC)", ylabel=label)
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    title_once(ax, label)
    return fig


def plot_campaign(rows: Sequence[Mapping], trends: Sequence[Trend] = (), *, requirement: float | None = None,
                  baseline: float | None = None, title: str = "") -> Figure:
    """The four figures of merit of one group (platform, band, direction,
    method) against time (:func:`plot_trend` each): MTF at Nyquist (with
    the requirement and the pre-launch value), MTF50, FWHM and RER.

    Parameters
    ----------
    rows : sequence of mapping
        Rows of a campaign store's ``targets`` layer for one group, with
        ``acquired_utc``.
    trends : sequence of imgmtf.campaign.trend.Trend, optional
        The group's drift per figure of merit.
    requirement, baseline : float, optional
        The MTF at Nyquist required and the pre-launch value.
    title : str, optional
        The figure's title (default none).

    Returns
    -------
    matplotlib.figure.Figure
        Four panels: MTF at Nyquist, MTF50 (cy/px), FWHM (px) and RER.

    Examples
    --------
    >>> from imgmtf.plot import plot_campaign
    >>> rows = [{"acquired_utc": "2021-06-01", "mtf_nyquist": 0.27, "mtf50_cy_px": 0.36, "fwhm_px": 1.2, "rer": 0.6}]
    >>> len(plot_campaign(rows, requirement=0.2, title="SYNTHSAT-1 PAN").axes)
    4
    """
    fig = Figure(figsize=(13.5, 6.6), layout="constrained")
    axes = fig.subplots(2, 2).ravel()
    by_figure = {t.figure: t for t in trends}
    for ax, figure in zip(axes, TREND_FIGURES):
        plot_trend(rows, figure, trend=by_figure.get(figure), ax=ax,
                   requirement=requirement if figure == "mtf_nyquist" else None,
                   baseline=baseline if figure == "mtf_nyquist" else None)
    if title:
        fig.suptitle(title, fontsize="medium")
    return fig
