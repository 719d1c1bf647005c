"""The figure of a 2-D MTF's across- and along-track sections: each
assumption's, the chosen one's interval, and the sections measured along
the normals they came from."""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure

from ._common import figure_axes, title_once

if TYPE_CHECKING:
    from ..estimate.mtf2d import MTF2D

_STYLES = {"separable": "--", "elliptical": ":", "bracket": "-"}
_COLOURS = {"across-track": "C0", "along-track": "C3"}


def plot_sections(result: MTF2D, measured: tuple[np.ndarray, np.ndarray] | None = None, ax: Axes | None = None,
                  truth: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None) -> Figure | SubFigure:
    """Across-track (MTF against u, cy/px) and along-track (against v)
    sections under each assumption (separable dashed, elliptical dotted,
    their bracket solid), the chosen assumption's interval as a band, the
    measured sections they were inverted from (grey, against frequency
    along their normals), and ``truth(u, v)`` when known.

    Parameters
    ----------
    result : MTF2D
        The sections (:func:`imgmtf.estimate.mtf2d.mtf2d_from_sections`).
    measured : (frequencies, mtfs), optional
        The measured sections, cy/px and (n normals, n frequencies), in the
        order of ``result.normals_deg``.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default a new figure's).
    truth : callable, optional
        The true 2-D MTF at (u, v), cy/px.

    Returns
    -------
    matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure holding ``ax``.

    Raises
    ------
    ParameterError
        ``result`` is not an MTF2D.

    Examples
    --------
    >>> import numpy as np
    >>> from imgmtf.estimate.mtf2d import mtf2d_from_sections
    >>> f = np.linspace(0, 1, 101)
    >>> m = [np.sinc(f) * np.exp(-2 * f ** 2)] * 2
    >>> plot_sections(mtf2d_from_sections([0.0, 90.0], f, m)).axes[0].get_xlabel()
    'frequency (cy/px): u across, v along, f along a normal'
    """
    from ..estimate.mtf2d import MTF2D
    if not isinstance(result, MTF2D):
        from ..errors import ParameterError
        raise ParameterError(f"this figure draws the sections of a 2-D MTF (MTF2D), got {type(result).__name__}")
    fig, ax = figure_axes(ax, (6.0, 4.2))
    if measured is not None:
        frequencies, mtfs = measured
        for k, (normal, curve) in enumerate(zip(result.normals_deg, np.atleast_2d(mtfs))):
            ax.plot(frequencies, curve, "o", ms=2.2, color=f"{0.35 + 0.2 * (k % 3):.2f}",
                    label=f"measured along {normal:.1f} deg")
    chosen = result.assumption
    for assumption, sections in result.alternatives.items():
        for section in sections:
            f = section.frequencies_cy_px
            short = section.direction.split("-")[0]
            ax.plot(f, section.mtf, _STYLES[assumption], color=_COLOURS[section.direction],
                    lw=2.0 if assumption == chosen else 1.1,
                    label=f"{short}, {assumption}{' (chosen)' if assumption == chosen else ''}")
            if assumption == chosen and np.isfinite(section.low).any():
                ax.fill_between(f, section.low, section.high, color=_COLOURS[section.direction], alpha=0.15, lw=0)
    if truth is not None:
        grid = result.across.frequencies_cy_px
        ax.plot(grid, truth(grid, 0.0 * grid), color="k", lw=0.8, label="truth across")
        ax.plot(grid, truth(0.0 * grid, grid), color="k", lw=0.8, ls="-.", label="truth along")
    ax.axvline(0.5, color="0.6", lw=0.7)
    ax.set(xlim=(0.0, float(result.across.frequencies_cy_px[-1])), ylim=(0.0, 1.02), ylabel="MTF",
           xlabel="frequency (cy/px): u across, v along, f along a normal")
    title_once(ax, f"Across and along track without a model: {chosen}")
    ax.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=3, frameon=False)
    return fig
