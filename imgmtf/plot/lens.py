"""A lens profile's figure: MTF50 and the MTF at chosen frequencies
against the distance from the optical centre, sagittal solid and
meridional dashed, each edge a faint point and each ring's median a line
(as MTF Mapper's lens profile draws them)."""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure

from ._common import figure_axes, title_once

if TYPE_CHECKING:
    from ..scene.lens_profile import LensProfile

_STYLES = {"sagittal": "-", "meridional": "--"}
_MARKERS = {"sagittal": "o", "meridional": "s"}


def plot_lens_mtf(profile: LensProfile, ax: Axes | None = None) -> Figure | SubFigure:
    """The MTF at each of the profile's frequencies against the distance
    from the optical centre (px), sagittal solid, meridional dashed.

    Parameters
    ----------
    profile : LensProfile
        The profile (:func:`imgmtf.scene.lens_profile.lens_profile`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Examples
    --------
    >>> from imgmtf.scene.lens_profile import LensProfile, ProfileEdge, ProfileRing
    >>> profile = LensProfile((0.25,), (50.0, 50.0), (ProfileEdge(10.0, "sagittal", 0.3, (0.6,)),),
    ...                       (ProfileRing("sagittal", 0.0, 20.0, 1, 0.3, (0.6,)),))
    >>> plot_lens_mtf(profile).axes[0].get_ylabel()
    'MTF'
    """
    fig, ax = figure_axes(ax)
    for k, frequency in enumerate(profile.frequencies_cy_px):
        for direction, style in _STYLES.items():
            edges = [e for e in profile.edges if e.field_direction == direction]
            rings = [r for r in profile.rings if r.field_direction == direction]
            if edges:
                ax.plot([e.radius_px for e in edges], [e.mtf[k] for e in edges], _MARKERS[direction],
                        color=f"C{k}", alpha=0.3, ms=3)
            if rings:
                ax.plot([r.radius_px for r in rings], [r.mtf[k] for r in rings], style, color=f"C{k}", lw=1.6,
                        label=f"{direction}, {frequency:g} cy/px")
    ax.set(xlim=(0, None), ylim=(0, 1.02), xlabel="distance from the optical centre (px)", ylabel="MTF")
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    title_once(ax, "MTF across the field")
    return fig


def plot_lens_mtf50(profile: LensProfile, ax: Axes | None = None,
                    truth: Callable[[float, str], float] | None = None) -> Figure | SubFigure:
    """MTF50 (cy/px) against the distance from the optical centre (px),
    sagittal solid, meridional dashed, and the truth when known.

    Parameters
    ----------
    profile : LensProfile
        The profile (:func:`imgmtf.scene.lens_profile.lens_profile`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).
    truth : callable, optional
        ``truth(radius_px, "sagittal" or "meridional")``: the true MTF50,
        cy/px (a chart imgmtf made:
        :meth:`imgmtf.sensor.chart.FieldBlur.mtf50_cy_px`), drawn in red.

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Examples
    --------
    >>> from imgmtf.scene.lens_profile import LensProfile, ProfileEdge, ProfileRing
    >>> profile = LensProfile((0.25,), (50.0, 50.0), (ProfileEdge(10.0, "sagittal", 0.3, (0.6,)),),
    ...                       (ProfileRing("sagittal", 0.0, 20.0, 1, 0.3, (0.6,)),))
    >>> plot_lens_mtf50(profile).axes[0].get_ylabel()
    'MTF50 (cy/px)'
    """
    fig, ax = figure_axes(ax)
    top = 0.0
    for direction, style in _STYLES.items():
        edges = [e for e in profile.edges if e.field_direction == direction]
        rings = [r for r in profile.rings if r.field_direction == direction]
        if edges:
            ax.plot([e.radius_px for e in edges], [e.mtf50_cy_px for e in edges], _MARKERS[direction], color="k",
                    alpha=0.3, ms=3)
            top = max([top, *(e.mtf50_cy_px for e in edges if e.mtf50_cy_px == e.mtf50_cy_px)])
        if rings:
            ax.plot([r.radius_px for r in rings], [r.mtf50_cy_px for r in rings], style, color="k", lw=1.6,
                    label=direction)
        if truth is not None and edges:
            radii = np.linspace(0.0, max(e.radius_px for e in profile.edges), 50)
            ax.plot(radii, [truth(float(r), direction) for r in radii], style, color="C3", lw=0.9,
                    label=f"true, {direction}")
    ax.set(xlim=(0, None), ylim=(0, max(top * 1.1, 0.05)), xlabel="distance from the optical centre (px)",
           ylabel="MTF50 (cy/px)")
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    title_once(ax, "MTF50 across the field")
    return fig


def plot_lens_profile(profile: LensProfile, title: str | None = None,
                      truth: Callable[[float, str], float] | None = None) -> Figure:
    """The lens profile's figure: :func:`plot_lens_mtf50` beside
    :func:`plot_lens_mtf`.

    Parameters
    ----------
    profile : LensProfile
        The profile (:func:`imgmtf.scene.lens_profile.lens_profile`).
    title : str, optional
        The figure's title (default: the optical centre).
    truth : callable, optional
        The true MTF50 as :func:`plot_lens_mtf50` takes it.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels.

    Examples
    --------
    >>> from imgmtf.scene.lens_profile import LensProfile, ProfileEdge, ProfileRing
    >>> profile = LensProfile((0.25,), (50.0, 50.0), (ProfileEdge(10.0, "sagittal", 0.3, (0.6,)),),
    ...                       (ProfileRing("sagittal", 0.0, 20.0, 1, 0.3, (0.6,)),))
    >>> len(plot_lens_profile(profile).axes)
    2
    """
    fig = Figure(figsize=(11.0, 4.0), layout="constrained")
    left, right = fig.subplots(1, 2)
    plot_lens_mtf50(profile, left, truth=truth)
    plot_lens_mtf(profile, right)
    x, y = profile.centre_px
    fig.suptitle(f"{title + ': ' if title else ''}lens profile about the optical centre ({x:g}, {y:g}) px, "
                 f"{len(profile.edges)} edges")
    return fig
