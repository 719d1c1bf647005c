"""Figures of a Siemens-star measurement (:func:`imgmtf.measure_star`): the
star with its sectors, its Nyquist circle and its unresolved zone; the MTF
in each direction with its interval and the truth when known; the MTF at
Nyquist and MTF50 against direction."""
from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure
from matplotlib.patches import Circle

from ._common import figure_axes, title_once, warning_lines

if TYPE_CHECKING:
    from ..estimate.star.result import StarResult


def _expect_star(result: object) -> None:
    from ..errors import ParameterError
    from ..estimate.star.result import StarResult as Result
    if not isinstance(result, Result):
        raise ParameterError(f"this figure draws a Siemens-star measurement (measure_star), "
                             f"got {type(result).__name__}")


def _colours(n: int) -> list:
    from matplotlib import colormaps
    return [colormaps["tab10"](k % 10) for k in range(n)]


def plot_star_image(result: StarResult, image: np.ndarray, ax: Axes | None = None) -> Figure | SubFigure:
    """The star with the sectors each direction is read on, the radii read,
    its Nyquist circle and its unresolved zone.

    Parameters
    ----------
    result : StarResult
        A star measurement.
    image : numpy.ndarray
        The chip it was made from, DN.
    ax : matplotlib.axes.Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render_star(imgmtf.Sensor(), imgmtf.SiemensStar(cycles=32), 101)
    >>> len(plot_star_image(imgmtf.measure_star(chip.image, intervals="none"), chip.image).axes)
    1
    """
    _expect_star(result)
    fig, ax = figure_axes(ax, (4.8, 4.4))
    data = np.asarray(image, float)
    low, high = np.nanpercentile(data, [0.5, 99.5])
    ax.imshow(data, cmap="gray", vmin=low, vmax=high if high > low else low + 1, interpolation="nearest")
    x, y = result.centre_px
    n = len(result.directions)
    width = 180.0 / n
    for colour, d in zip(_colours(n), result.directions):
        # a direction's sectors lie about the position angles of its frequency's normal
        for side in (0.0, 180.0):
            middle = math.radians(d.angle_deg + 90.0 + side)
            ax.plot([x + result.inner_radius_px * math.cos(middle), x + result.outer_radius_px * math.cos(middle)],
                    [y + result.inner_radius_px * math.sin(middle), y + result.outer_radius_px * math.sin(middle)],
                    color=colour, lw=1.6, label=d.direction if side == 0.0 else None)
            edge = math.radians(d.angle_deg + 90.0 + side - width / 2)
            ax.plot([x, x + result.outer_radius_px * math.cos(edge)], [y, y + result.outer_radius_px * math.sin(edge)],
                    color="0.75", lw=0.4, ls=":")
    circles = [(result.outer_radius_px, "tab:green", "-", f"radii read ({result.inner_radius_px:.0f} to "
                f"{result.outer_radius_px:.0f} px)"),
               (result.nyquist_radius_px, "tab:orange", "--", f"Nyquist, r = {result.nyquist_radius_px:.1f} px")]
    if math.isfinite(result.unresolved_radius_px):
        circles.append((result.unresolved_radius_px, "tab:red", "-",
                        f"unresolved (MTF 0.1), r = {result.unresolved_radius_px:.1f} px"))
    else:                                   # the MTF stays above 0.1 on every ring read: resolved to the inner one
        ax.plot([], [], color="tab:red", lw=1.3, label=f"unresolved zone inside r = {result.inner_radius_px:.0f} px "
                                                         "(MTF over 0.1 on every ring read)")
    for radius, colour, style, label in circles:
        ax.add_patch(Circle((x, y), radius, fill=False, color=colour, ls=style, lw=1.3, label=label))
    ax.add_patch(Circle((x, y), result.inner_radius_px, fill=False, color="tab:green", lw=0.8))
    ax.plot([x], [y], "+", color="tab:red", ms=10)
    ax.set_xlim(-0.5, data.shape[1] - 0.5)
    ax.set_ylim(data.shape[0] - 0.5, -0.5)
    ax.set_xlabel("x (column), px")
    ax.set_ylabel("y (row), px")
    title_once(ax, f"{result.profile} star, {result.cycles} cycles, centre ({x:.2f}, {y:.2f}) px")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7, frameon=False)
    return fig


def plot_star_mtf(result: StarResult, truth: Callable[[np.ndarray, float], np.ndarray] | None = None,
                  ax: Axes | None = None) -> Figure | SubFigure:
    """The MTF in each direction with its interval (shaded), each ring's
    own value (dots), and the truth (dashed) when known.

    Parameters
    ----------
    result : StarResult
        A star measurement.
    truth : callable, optional
        ``truth(f_cy_px, angle_deg)``: the true MTF along the direction at
        ``angle_deg`` from the x axis (a chip imgmtf rendered).
    ax : matplotlib.axes.Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render_star(imgmtf.Sensor(), imgmtf.SiemensStar(cycles=32), 101)
    >>> len(plot_star_mtf(imgmtf.measure_star(chip.image)).axes)
    1
    """
    _expect_star(result)
    fig, ax = figure_axes(ax, (5.6, 3.8))
    confidence = result.params.get("intervals", {}).get("confidence", 0.95)
    z = _z(confidence)
    for colour, d in zip(_colours(len(result.directions)), result.directions):
        ax.plot(d.frequencies_cy_px, d.mtf, color=colour, lw=1.4, label=f"{d.direction}: {d.mtf_nyquist:.3f}")
        if math.isfinite(z) and result.params.get("intervals", {}).get("method") != "none":
            ax.fill_between(d.frequencies_cy_px, d.mtf - z * d.standard_error, d.mtf + z * d.standard_error,
                            color=colour, alpha=0.2, lw=0)
        ax.plot(d.ring_frequencies_cy_px, d.ring_mtf, ".", color=colour, ms=2, alpha=0.6)
        if truth is not None:
            f = d.frequencies_cy_px
            # black, dashed, above the curves: in their colour it hid under them
            ax.plot(f, truth(f, d.angle_deg), color="black", ls="--", lw=0.9, zorder=3)
    if truth is not None:
        ax.plot([], [], color="black", ls="--", lw=0.9, label="truth (black, dashed)")
    ax.axvline(0.5, color="0.6", lw=0.8, ls=":")
    ax.set_xlim(0.0, max(0.8, max(float(d.frequencies_cy_px[-1]) for d in result.directions)))
    ax.set_ylim(0.0, 1.05)
    ax.set_xlabel("frequency, cy/px")
    ax.set_ylabel("MTF")
    title_once(ax, f"MTF per direction ({100 * confidence:g} % interval shaded; MTF at Nyquist in the legend)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7, frameon=False)
    return fig


def plot_star_directions(result: StarResult, truth: Callable[[np.ndarray, float], np.ndarray] | None = None,
                         ax: Axes | None = None) -> Figure | SubFigure:
    """The MTF at Nyquist and MTF50 (cy/px) against the direction, with
    their intervals, and the truth when known.

    Parameters
    ----------
    result : StarResult
        A star measurement.
    truth : callable, optional
        ``truth(f_cy_px, angle_deg)``, the true MTF.
    ax : matplotlib.axes.Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render_star(imgmtf.Sensor(), imgmtf.SiemensStar(cycles=32), 101)
    >>> len(plot_star_directions(imgmtf.measure_star(chip.image)).axes)
    1
    """
    _expect_star(result)
    fig, ax = figure_axes(ax, (5.0, 3.4))
    angles = np.array([d.angle_deg for d in result.directions])
    for key, interval, colour, label in (("mtf_nyquist", "mtf_nyquist_ci", "tab:blue", "MTF at Nyquist"),
                                         ("mtf50_cy_px", "mtf50_ci_cy_px", "tab:red", "MTF50, cy/px")):
        values = np.array([getattr(d, key) for d in result.directions])
        low = np.array([getattr(d, interval).low for d in result.directions])
        high = np.array([getattr(d, interval).high for d in result.directions])
        spread = np.vstack([values - low, high - values])
        ax.errorbar(angles, values, yerr=np.where(np.isfinite(spread), spread, 0.0), fmt="o-", color=colour,
                    capsize=3, ms=4, lw=1.0, label=label)
        if truth is not None:
            fine = np.linspace(0.0, 180.0, 37)
            if key == "mtf_nyquist":
                expected = np.array([float(truth(np.array(0.5), a)) for a in fine])
            else:
                f = np.linspace(0.0, 1.0, 501)
                from ..metrics import first_crossing
                expected = np.array([float(first_crossing(f, truth(f, a), 0.5)) for a in fine])
            ax.plot(fine, expected, color="black", ls="--", lw=0.9, zorder=3, label=f"truth, {label}")
    ax.set_xlim(-5.0, 185.0)
    ax.set_xticks(np.arange(0, 181, 45))
    ax.set_xlabel("direction of the frequency, deg from x (90: along the rows)")
    ax.set_ylabel("MTF, or cy/px")
    title_once(ax, "against direction")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7, frameon=False)
    return fig


def plot_star(result: StarResult, image: np.ndarray | None = None,
              truth: Callable[[np.ndarray, float], np.ndarray] | None = None, title: str | None = None,
              warnings: Iterable[str] | None = None) -> Figure:
    """The star measurement in three panels: the star with its sectors,
    Nyquist circle and unresolved zone (when ``image`` is given), the MTF
    per direction, and the figures against direction.

    Parameters
    ----------
    result : StarResult
        A star measurement.
    image : numpy.ndarray, optional
        The chip, DN (the first panel is left out without it).
    truth : callable, optional
        ``truth(f_cy_px, angle_deg)``, the true MTF (a chip imgmtf rendered).
    title : str, optional
        The header's first line (the file measured).
    warnings : iterable of str, optional
        The warnings to print (default the result's).

    Returns
    -------
    matplotlib.figure.Figure
        The panels of :func:`plot_star_image`, :func:`plot_star_mtf` and
        :func:`plot_star_directions`.

    Raises
    ------
    ParameterError
        ``result`` is not a star measurement.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render_star(imgmtf.Sensor(), imgmtf.SiemensStar(cycles=32), 101)
    >>> fig = plot_star(imgmtf.measure_star(chip.image), chip.image, title="star")
    >>> len(fig.axes)
    3
    """
    _expect_star(result)
    fig = Figure(figsize=(13.0, 8.4), layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(1.0, 1.25))
    if image is not None:
        plot_star_image(result, image, fig.add_subplot(grid[:, 0]))
    plot_star_mtf(result, truth, fig.add_subplot(grid[0, 1]))
    plot_star_directions(result, truth, fig.add_subplot(grid[1, 1]))
    warnings = list(result.warnings if warnings is None else warnings)
    across, along = result.directions[0], result.directions[len(result.directions) // 2]
    lines = [title or "Siemens star",
             f"{across.direction} MTF@Nyq {across.mtf_nyquist:.3f}, MTF50 {across.mtf50_cy_px:.3f} cy/px; "
             f"{along.direction} MTF@Nyq {along.mtf_nyquist:.3f}, MTF50 {along.mtf50_cy_px:.3f} cy/px; "
             f"SNR {result.snr:.0f}"]
    lines += warning_lines(warnings)
    fig.suptitle("\n".join(lines), fontsize=9)
    return fig


def _z(confidence: float) -> float:
    from statistics import NormalDist
    try:
        return NormalDist().inv_cdf(0.5 + float(confidence) / 2.0)
    except (TypeError, ValueError):
        return math.nan
