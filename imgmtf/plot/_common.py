"""What every figure module shares: the checks of what it is given, new axes
when none are, a title that defers to the caller's, a header's warnings."""
from __future__ import annotations

import textwrap
from collections.abc import Sequence
from typing import overload

from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure


def expect(value: object, kind: str) -> None:
    """Refuse, with a ParameterError, a ``value`` that is not what the figure
    draws: a measurement ("result"), a sensor ("sensor") or a fit ("fit")."""
    from ..errors import ParameterError
    from ..estimate.fit import SensorFit
    from ..estimate.results import MTFResult
    from ..sensor.model import Sensor
    expected = {"result": (MTFResult, "a measurement (imgmtf.measure_edge or measure_pulse)"),
                "sensor": (Sensor, "an imgmtf.Sensor"), "fit": (SensorFit, "a fit (imgmtf.fit_sensor)")}
    cls, what = expected[kind]
    if not isinstance(value, cls):
        raise ParameterError(f"this figure draws {what}, got {type(value).__name__}")


def check_truth(truth: object) -> None:
    """Refuse a ``truth`` that is not a function of frequency (cy/px) or None."""
    if truth is not None and not callable(truth):
        from ..errors import ParameterError
        hint = (" (for a sensor: lambda f: sensor.normal_transfer(f, result.normal_angle_deg))"
                if hasattr(truth, "normal_transfer") else "")
        raise ParameterError(f"truth must be a function of frequency in cy/px, got {type(truth).__name__}{hint}")


@overload
def figure_axes(ax: None, size: tuple[float, float] = ...) -> tuple[Figure, Axes]: ...
@overload
def figure_axes(ax: Axes | None, size: tuple[float, float] = ...) -> tuple[Figure | SubFigure, Axes]: ...


def figure_axes(ax: Axes | None, size: tuple[float, float] = (5.0, 3.6)) -> tuple[Figure | SubFigure, Axes]:
    """``ax``'s figure (a SubFigure when ``ax`` lies in one) and ``ax``, or a
    new figure of ``size`` (inches) and its axes."""
    if ax is None:
        fig = Figure(figsize=size, layout="constrained")
        return fig, fig.add_subplot()
    return ax.figure, ax


def title_once(ax: Axes, text: str) -> None:
    """Title the axes unless the caller already has."""
    if not ax.get_title():
        ax.set_title(text)


#: warnings a figure's header prints in full; the rest it counts
HEADER_WARNINGS = 3
#: a header line's most characters: a long warning wraps (its end is often what to do about it)
HEADER_WIDTH = 150


def warning_lines(warnings: Sequence[str], shown: int = HEADER_WARNINGS) -> list[str]:
    """A figure header's warnings: the first ``shown`` numbered, each
    wrapped at :data:`HEADER_WIDTH` characters (at most four lines, not
    cut short), and a count of the others, so that none is dropped unsaid.

    Parameters
    ----------
    warnings : sequence of str
        The record's warnings.
    shown : int, optional
        How many to print in full (default :data:`HEADER_WARNINGS`).

    Returns
    -------
    list of str
        The header's lines (none when there is no warning).

    Examples
    --------
    >>> warning_lines(["low SNR", "few rows", "tilted", "clipped"], shown=2)      # doctest: +NORMALIZE_WHITESPACE
    ['warning 1 of 4: low SNR', 'warning 2 of 4: few rows',
     'and 2 more warning(s), listed in full by the text table and the record (JSON, CSV)']
    """
    lines = []
    for i, warning in enumerate(warnings[:shown]):
        lines += textwrap.wrap(f"warning {i + 1} of {len(warnings)}: {warning}", HEADER_WIDTH, max_lines=4,
                               placeholder=" [...]")
    if len(warnings) > shown:
        lines.append(f"and {len(warnings) - shown} more warning(s), listed in full by the text table and the "
                     "record (JSON, CSV)")
    return lines
