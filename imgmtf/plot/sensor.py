"""Figures of the sensor model: its PSF, LSFs and every stage's MTF."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure

from ..estimate.spectrum import NYQUIST
from ._common import expect, figure_axes

if TYPE_CHECKING:
    from ..sensor.model import Sensor


def _view_radius_m(sensor: Sensor) -> float:
    """Half-width (m) of the view that shows the PSF's core and shoulders."""
    return 1.5 * max(sensor.fwhm_m("across"), sensor.fwhm_m("along"), sensor.gsd_m)


def plot_psf(sensor: Sensor, ax: Axes | None = None, oversampling: int = 20,
             pixel_units: bool = False) -> Figure | SubFigure:
    """The system PSF image (paper Fig. 2a), axes in metres, its core and
    shoulders shown in a square of 3 FWHM.

    Parameters
    ----------
    sensor : Sensor
        The sensor model.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).
    oversampling : int, optional
        PSF samples per GSD in each axis (default 20).
    pixel_units : bool, optional
        The sensor's GSD is a pixel, not a length on the ground (a camera's
        fit, no GSD known): axes "x (px)", "y (px)" (default: across and
        along track, m).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``sensor`` is not a Sensor.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> from imgmtf.plot import plot_psf
    >>> plot_psf(Sensor()).axes[0].get_xlabel()
    'across track x (m)'
    """
    expect(sensor, "sensor")
    fig, ax = figure_axes(ax)
    psf = sensor.psf(oversampling)
    half = psf.data.shape[0] // 2 * psf.step_m
    image = ax.imshow(psf.data / psf.data.max(), extent=(-half, half, half, -half), cmap="magma",
                      interpolation="nearest")
    r = _view_radius_m(sensor)
    names = ("x (px)", "y (px)") if pixel_units else ("across track x (m)", "along track y (m)")
    ax.set(xlim=(-r, r), ylim=(r, -r), title="System PSF (peak = 1)", xlabel=names[0], ylabel=names[1])
    fig.colorbar(image, ax=ax, shrink=0.8)
    return fig


def plot_sensor_lsf(sensor: Sensor, ax: Axes | None = None) -> Figure | SubFigure:
    """Across- and along-track LSFs with their FWHM (paper Fig. 2b, c).

    Parameters
    ----------
    sensor : Sensor
        The sensor model.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``sensor`` is not a Sensor.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> from imgmtf.plot import plot_sensor_lsf
    >>> plot_sensor_lsf(Sensor()).axes[0].get_legend_handles_labels()[1]
    ['across track, FWHM 1.240 m', 'along track, FWHM 1.251 m']
    """
    expect(sensor, "sensor")
    fig, ax = figure_axes(ax)
    for direction in ("across", "along"):
        x, lsf = sensor.lsf(direction)
        ax.plot(x, lsf / lsf.max(), label=f"{direction} track, FWHM {sensor.fwhm_m(direction):.3f} m")
    ax.axhline(0.5, color="0.6", lw=0.8, ls=":")
    r = 2 * _view_radius_m(sensor)
    ax.set(xlim=(-r, r), title="Line spread functions", xlabel="distance (m)", ylabel="normalised LSF")
    # under the axes: inside, it would sit on the half maximum where the FWHM is read
    ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.16), frameon=False)
    return fig


def plot_sensor_mtf(sensor: Sensor, ax: Axes | None = None, direction: str | None = None) -> Figure | SubFigure:
    """The system MTF with its value at Nyquist (paper Fig. 3): across and
    along track, or in one ``direction`` with each stage's MTF beside it.

    Parameters
    ----------
    sensor : Sensor
        The sensor model.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).
    direction : {"across", "along"}, optional
        One axis, with each stage's MTF; default both axes, the system's only.

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``sensor`` is not a Sensor.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> from imgmtf.plot import plot_sensor_mtf
    >>> plot_sensor_mtf(Sensor(), direction="across").axes[0].get_legend_handles_labels()[1]
    ['optics: 0.4721', 'detector: 0.6366', 'motion: 1.0000', 'electronics: 0.8869', 'system: 0.2665']
    """
    expect(sensor, "sensor")
    fig, ax = figure_axes(ax)
    f = np.linspace(0, 1.0, 401)
    if direction is None:
        for d in ("across", "along"):
            ax.plot(f, sensor.mtf(f, d), label=f"{d} track, MTF@Nyquist {sensor.mtf_nyquist(d):.4f}")
        title = "System MTF"
    else:
        for i, (name, part) in enumerate(sensor.components().items()):
            ax.plot(f, part.mtf(f, direction), lw=1.0, ls=("--", "-.", ":")[i % 3], color=f"C{i + 1}",
                    label=f"{name}: {part.mtf_nyquist(direction):.4f}")
        ax.plot(f, sensor.mtf(f, direction), color="k", lw=2.0,
                label=f"system: {sensor.mtf_nyquist(direction):.4f}")
        title = f"MTF {direction} track (at Nyquist)"
    ax.axvline(NYQUIST, color="0.5", ls="--", lw=0.8)
    ax.set(title=title, xlabel="frequency (cy/px)", ylabel="MTF", ylim=(0, 1.02), xlim=(0, 1))
    ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=2, frameon=False)
    return fig


def plot_sensor(sensor: Sensor) -> Figure:
    """PSF, LSFs, and each stage's MTF beside the system's across and along
    track (the paper's Figs. 2-3).

    Parameters
    ----------
    sensor : Sensor
        The sensor model.

    Returns
    -------
    matplotlib.figure.Figure
        Four panels: :func:`plot_psf`, :func:`plot_sensor_lsf` and
        :func:`plot_sensor_mtf` across and along track.

    Raises
    ------
    ParameterError
        ``sensor`` is not a Sensor.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> from imgmtf.plot import plot_sensor
    >>> len(plot_sensor(Sensor()).axes)          # four panels and the PSF's colour bar
    5
    """
    expect(sensor, "sensor")
    fig = Figure(figsize=(17, 4.4), layout="constrained")
    axes = fig.subplots(1, 4)
    plot_psf(sensor, axes[0])
    plot_sensor_lsf(sensor, axes[1])
    plot_sensor_mtf(sensor, axes[2], "across")
    plot_sensor_mtf(sensor, axes[3], "along")
    fig.suptitle(f"Sensor, GSD {sensor.gsd_m:g} m: {', '.join(s.name for s in sensor.stages)}")
    return fig
