"""What every figure module shares: the checks of what it is given, new axes
when none are, a title that defers to the caller's."""
from __future__ import annotations

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
