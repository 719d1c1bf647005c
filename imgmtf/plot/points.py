"""Figures of a point-target measurement (:func:`imgmtf.estimate.mtf2d.measure_points`):
the targets found on the chip, the stacked 2-D PSF, the 2-D MTF and the
MTF across and along track with their intervals and the truth when known."""
from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure

from ._common import figure_axes, title_once, warning_lines

if TYPE_CHECKING:
    from ..estimate.mtf2d.points import PointsResult

#: how each refusal is drawn: (marker, colour)
_REFUSED_STYLE = {"faint": ("+", "0.55"), "edge": ("s", "tab:orange"), "blended": ("x", "tab:red"),
                  "clipped": ("D", "tab:purple"), "extended": ("|", "tab:brown"), "hot-pixel": (".", "tab:pink"),
                  "fit": ("*", "tab:red")}
_COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple")


def _expect_points(result: object) -> None:
    from ..errors import ParameterError
    from ..estimate.mtf2d.points import PointsResult as Result
    if not isinstance(result, Result):
        raise ParameterError(f"this figure draws a point-target measurement (measure_points), "
                             f"got {type(result).__name__}")


def plot_point_sources(result: PointsResult, image: np.ndarray, ax: Axes | None = None) -> Figure | SubFigure:
    """The chip with every target found: those used circled, those refused
    marked by their reason.

    Parameters
    ----------
    result : PointsResult
        A point-target measurement.
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
    >>> from imgmtf.estimate.mtf2d import measure_points
    >>> from imgmtf.sensor.points import PointArray, render_points
    >>> chip = render_points(imgmtf.Sensor(), PointArray(4, 4), 64)
    >>> fig = plot_point_sources(measure_points(chip.image, intervals="none"), chip.image)
    >>> len(fig.axes)
    1
    """
    _expect_points(result)
    fig, ax = figure_axes(ax, (4.6, 4.2))
    data = np.asarray(image, float)
    low, high = np.nanpercentile(data, [1, 99.8])
    ax.imshow(data, cmap="gray", vmin=low, vmax=high if high > low else low + 1, interpolation="nearest")
    used = result.used
    if used:
        ax.scatter([s.x_px for s in used], [s.y_px for s in used], s=90, facecolors="none", edgecolors="tab:green",
                   linewidths=1.2, label=f"used ({len(used)})")
    refused: dict[str, list] = {}
    for source in result.refused:
        refused.setdefault(source.status, []).append(source)
    for reason, sources in sorted(refused.items()):
        marker, colour = _REFUSED_STYLE.get(reason, ("x", "tab:red"))
        ax.scatter([s.x_px for s in sources], [s.y_px for s in sources], s=40, marker=marker, color=colour,
                   label=f"{reason} ({len(sources)})")
    ax.set_xlabel("x (column), px")
    ax.set_ylabel("y (row), px")
    title_once(ax, f"{len(used)} {result.polarity} targets used, {len(result.refused)} refused")
    if used or refused:
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7, frameon=False)
    return fig


def plot_point_psf(result: PointsResult, ax: Axes | None = None) -> Figure | SubFigure:
    """The stacked 2-D PSF (pixel aperture and target size in), peak 1, with
    contours at 10 %, 30 %, 50 %, 70 % and 90 % of its peak; x across and y
    along track, px.

    Parameters
    ----------
    result : PointsResult
        A point-target measurement.
    ax : matplotlib.axes.Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.mtf2d import measure_points
    >>> from imgmtf.sensor.points import PointArray, render_points
    >>> chip = render_points(imgmtf.Sensor(), PointArray(4, 4), 64)
    >>> plot_point_psf(measure_points(chip.image, intervals="none")).axes[0].get_xlabel()
    'x (across track), px'
    """
    _expect_points(result)
    fig, ax = figure_axes(ax, (4.4, 3.8))
    psf = result.psf / np.max(result.psf)
    n = psf.shape[0]
    x = (np.arange(n) - n // 2) * result.psf_step_px
    keep = np.abs(x) <= 3.0
    psf, x = psf[np.ix_(keep, keep)], x[keep]
    half = result.psf_step_px / 2
    image = ax.imshow(psf, cmap="magma", origin="upper", extent=(x[0] - half, x[-1] + half, x[-1] + half, x[0] - half),
                      vmin=min(0.0, float(psf.min())), vmax=1.0)
    contours = ax.contour(x, x, psf, levels=[0.1, 0.3, 0.5, 0.7, 0.9], colors="white", linewidths=0.8)
    ax.clabel(contours, fmt="%.1f", fontsize=6)
    ax.set_xlabel("x (across track), px")
    ax.set_ylabel("y (along track), px")
    ax.set_aspect("equal")
    _colorbar(fig, ax, image, "PSF, peak 1")
    title_once(ax, f"stacked PSF ({len(result.used)} targets, {result.psf_step_px:g} px grid)")
    return fig


#: the truth's dashes across and along track (black, above the measured curves)
TRUTH_DASHES = ((0, (5.0, 3.0)), (0, (1.5, 2.0)))


def _colorbar(fig, ax: Axes, image, label: str) -> None:
    """A colour bar beside an equal-aspect panel, as an inset of its axes: a
    bar stolen from the layout's cell (``colorbar(ax=...)``) left the panel's
    y tick labels and axis label cut off the figure's left edge."""
    fig.colorbar(image, cax=ax.inset_axes((1.04, 0.0, 0.05, 1.0)), label=label)


def plot_point_mtf2d(result: PointsResult, ax: Axes | None = None) -> Figure | SubFigure:
    """The 2-D MTF, ``fx`` across and ``fy`` along track (cy/px), with
    contours at 0.1, 0.3, 0.5, 0.7 and 0.9; the Nyquist square dashed.

    Parameters
    ----------
    result : PointsResult
        A point-target measurement.
    ax : matplotlib.axes.Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.mtf2d import measure_points
    >>> from imgmtf.sensor.points import PointArray, render_points
    >>> chip = render_points(imgmtf.Sensor(), PointArray(4, 4), 64)
    >>> plot_point_mtf2d(measure_points(chip.image, intervals="none")).axes[0].get_xlabel()
    'fx (across track), cy/px'
    """
    _expect_points(result)
    fig, ax = figure_axes(ax, (4.4, 3.8))
    f = result.frequencies2d_cy_px
    step = (f[1] - f[0]) / 2
    image = ax.imshow(result.mtf2d, cmap="viridis", origin="lower", vmin=0.0, vmax=1.0,
                      extent=(f[0] - step, f[-1] + step, f[0] - step, f[-1] + step))
    contours = ax.contour(f, f, np.nan_to_num(result.mtf2d), levels=[0.1, 0.3, 0.5, 0.7, 0.9], colors="white",
                          linewidths=0.8)
    ax.clabel(contours, fmt="%.1f", fontsize=6)
    ax.plot([-0.5, 0.5, 0.5, -0.5, -0.5], [-0.5, -0.5, 0.5, 0.5, -0.5], "w--", lw=0.8)
    ax.set_xlabel("fx (across track), cy/px")
    ax.set_ylabel("fy (along track), cy/px")
    ax.set_aspect("equal")
    _colorbar(fig, ax, image, "MTF")
    title_once(ax, "2-D MTF (Nyquist dashed)")
    return fig


def plot_point_mtf(result: PointsResult, truth: Callable[[np.ndarray, float], np.ndarray] | None = None,
                   ax: Axes | None = None) -> Figure | SubFigure:
    """The MTF across and along track, each with its interval at Nyquist,
    and the truth (dashed) when known.

    Parameters
    ----------
    result : PointsResult
        A point-target measurement.
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
    >>> from imgmtf.estimate.mtf2d import measure_points
    >>> from imgmtf.sensor.points import PointArray, render_points
    >>> sensor = imgmtf.Sensor()
    >>> chip = render_points(sensor, PointArray(4, 4), 64)
    >>> truth = lambda f, angle: abs(sensor.normal_transfer(f, angle))
    >>> len(plot_point_mtf(measure_points(chip.image, intervals=20), truth).axes)    # a quick bootstrap
    1
    """
    _expect_points(result)
    fig, ax = figure_axes(ax, (5.0, 3.6))
    for k, (colour, section) in enumerate(zip(_COLOURS, result.directions)):
        ax.plot(section.frequencies_cy_px, section.mtf, color=colour, lw=1.5,
                label=f"{section.direction}: {section.mtf_nyquist:.3f} at Nyquist")
        ci = section.mtf_nyquist_ci
        if np.isfinite(ci.low) and np.isfinite(ci.high):
            spread = [[section.mtf_nyquist - ci.low], [ci.high - section.mtf_nyquist]]
            ax.errorbar([0.5], [section.mtf_nyquist], yerr=spread, color=colour, capsize=4, lw=1.2, fmt="o", ms=3)
        if truth is not None:
            f = section.frequencies_cy_px
            # black, dashed, above the measured curves: in their colour it hid under them
            ax.plot(f, truth(f, section.angle_deg), color="black", ls=TRUTH_DASHES[k % len(TRUTH_DASHES)], lw=1.1,
                    zorder=3,
                    label=f"truth {section.direction}: {float(truth(np.array(0.5), section.angle_deg)):.3f}")
    ax.axvline(0.5, color="0.6", lw=0.8, ls=":")
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(0.0, 1.05)
    ax.set_xlabel("frequency, cy/px")
    ax.set_ylabel("MTF")
    title_once(ax, "MTF from the point stack (95 % interval at Nyquist)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7, frameon=False)
    return fig


def plot_points(result: PointsResult, image: np.ndarray | None = None,
                truth: Callable[[np.ndarray, float], np.ndarray] | None = None, title: str | None = None,
                warnings: Iterable[str] | None = None) -> Figure:
    """The point-target measurement in four panels: the targets found on the
    chip (when ``image`` is given), the stacked PSF, the 2-D MTF, the MTF
    across and along track with intervals and truth.

    Parameters
    ----------
    result : PointsResult
        A point-target measurement.
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
        The panels of :func:`plot_point_sources`, :func:`plot_point_psf`,
        :func:`plot_point_mtf2d` and :func:`plot_point_mtf`.

    Raises
    ------
    ParameterError
        ``result`` is not a point-target measurement.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.mtf2d import measure_points
    >>> from imgmtf.sensor.points import PointArray, render_points
    >>> chip = render_points(imgmtf.Sensor(), PointArray(4, 4), 64)
    >>> fig = plot_points(measure_points(chip.image, intervals="none"), chip.image, title="chip")
    >>> len(fig.axes) >= 4
    True
    """
    _expect_points(result)
    fig = Figure(figsize=(12.5, 8.6), layout="constrained")
    grid = fig.add_gridspec(2, 2)
    if image is not None:
        plot_point_sources(result, image, fig.add_subplot(grid[0, 0]))
    plot_point_psf(result, fig.add_subplot(grid[0, 1]))
    plot_point_mtf2d(result, fig.add_subplot(grid[1, 0]))
    plot_point_mtf(result, truth, fig.add_subplot(grid[1, 1]))
    warnings = list(result.warnings if warnings is None else warnings)
    lines = [title or "point targets"]
    figures = ", ".join(f"{d.direction} MTF@Nyq {d.mtf_nyquist:.3f}, MTF50 {d.mtf50_cy_px:.3f} cy/px, "
                        f"FWHM {d.fwhm_px:.2f} px" for d in result.directions)
    lines.append(figures)
    lines += warning_lines(warnings)
    fig.suptitle("\n".join(lines), fontsize=9)
    return fig
