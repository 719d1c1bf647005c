"""What a restoration filter gains in sharpness and costs in noise and ringing.

Every figure comes from the sensor model and the filter's taps, in closed
form, per axis (across track: x, columns; along track: y, rows):

* the MTF at Nyquist (0.5 cy/px) of the sensor, designed (the target) and
  achieved (``|H W|``, the restored system's), and the restored MTF's peak
  below Nyquist;
* the edge response before and after: the sensor's exact edge response
  (:meth:`imgmtf.Sensor.line_response`) and its sum shifted by the taps
  collapsed onto the axis, which is what a slanted edge across the restored
  image traces; from them the RER (the rise between -0.5 and +0.5 px of the
  edge), the overshoot (above the bright level) and undershoot (below the
  dark), and the ringing, the largest departure from the step 3 px or more
  from the edge, all as percentages of the step;
* the noise gain, the root of the sum of the squared taps.
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..sensor.model import DIRECTIONS, Sensor, direction_angle
from .design import RestorationFilter, target_transfer

#: where the ringing is read: this far from the edge, px
RINGING_FROM_PX = 3.0
#: sampling of the edge responses, px
EDGE_STEP_PX = 1.0 / 32.0


@dataclass(frozen=True)
class AxisFigures:
    """A restoration's figures of merit along one axis (see the module docstring)."""

    direction: str
    system_mtf_nyquist: float
    designed_mtf_nyquist: float
    achieved_mtf_nyquist: float
    peak_mtf_below_nyquist: float
    rer_before: float
    rer_after: float
    overshoot_pct: float
    undershoot_pct: float
    ringing_pct: float


@dataclass(frozen=True)
class RestorationReport:
    """The figures of merit of a :class:`RestorationFilter`: ``noise_gain``
    and one :class:`AxisFigures` per axis (``across``, ``along``).

    Attributes
    ----------
    noise_gain : float
        The filter's white-noise gain, the root of the sum of its squared
        taps (1: no gain).
    axes : dict of str to AxisFigures
        Per axis (``across``, ``along``): the MTF at Nyquist of the sensor,
        designed and achieved, the RER before and after, the overshoot,
        undershoot and ringing (% of the step).

    Examples
    --------
    >>> from imgmtf import Sensor, design_filter, restoration_report
    >>> report = restoration_report(design_filter(Sensor(), 0.3, kernel_size=9))
    >>> a = report.axes["across"]
    >>> round(a.system_mtf_nyquist, 3), round(a.achieved_mtf_nyquist, 2), a.rer_after > a.rer_before
    (0.267, 0.3, True)
    """

    noise_gain: float
    axes: dict[str, AxisFigures]

    def to_dict(self) -> dict:
        return {"noise_gain": self.noise_gain,
                "axes": {name: {k: v for k, v in asdict(a).items() if k != "direction"}
                         for name, a in self.axes.items()}}


def restoration_report(restoration: RestorationFilter) -> RestorationReport:
    """The figures of merit of ``restoration`` (see the module docstring).

    Parameters
    ----------
    restoration : RestorationFilter
        A designed filter (:func:`imgmtf.design_filter`).

    Returns
    -------
    RestorationReport
        Its noise gain and its figures per axis, in closed form.

    Examples
    --------
    >>> from imgmtf import Sensor, design_filter, restoration_report
    >>> report = restoration_report(design_filter(Sensor(), 0.3, kernel_size=9))
    >>> report.noise_gain > 1, sorted(report.axes)
    (True, ['across', 'along'])
    """
    return RestorationReport(restoration.noise_gain,
                             {d: _axis_figures(restoration, d) for d in DIRECTIONS})


def axis_curves(restoration: RestorationFilter, direction: str, f_cy_px: ArrayLike) -> dict[str, np.ndarray]:
    """The transfers along one axis at ``f_cy_px``: ``system`` (the sensor's
    MTF, ``|H|``), ``filter`` (the filter's transfer; its modulus when it is
    complex, for a sensor with a phase), ``restored`` (their product's
    magnitude) and ``target``."""
    f = np.asarray(f_cy_px, float)
    system = restoration.system_transfer(f, direction)
    gain = restoration.axis_transfer(f, direction)
    return {"system": np.abs(system), "filter": np.abs(gain) if np.iscomplexobj(gain) else gain,
            "restored": np.abs(system * gain),
            "target": target_transfer(f, restoration.target_nyquist)}


def edge_responses(restoration: RestorationFilter, direction: str,
                   x_px: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(x_px, before, after)``: the edge response across an edge whose
    normal points along ``direction``, from 0 (dark) to 1 (bright), before
    and after restoration, at signed distances ``x_px`` (default: a grid
    reaching the kernel's radius and the sensor's blur beyond it)."""
    sensor, gsd = restoration.sensor, restoration.gsd_m
    response = sensor.line_response(direction_angle(direction), gsd)
    if x_px is None:
        reach = restoration.radius_px + sensor.support_radius_m() / gsd + 4.0
        x_px = np.arange(-reach, reach + EDGE_STEP_PX / 2, EDGE_STEP_PX)
    x = np.asarray(x_px, float)
    # the taps seen by an edge along the axis: summed over the other axis
    collapsed = restoration.taps.sum(axis=0 if direction == "across" else 1)
    offsets = np.arange(collapsed.size) - collapsed.size // 2
    after = sum(k * response.esf(x - j) for k, j in zip(collapsed, offsets))
    return x, response.esf(x), np.asarray(after)


def tradeoff(sensor: Sensor, target_nyquist: float, noise_gains: Iterable[float], *, kernel_size: int | None = None,
             direction: str = "across") -> tuple[np.ndarray, np.ndarray]:
    """``(noise_gain, achieved_mtf_nyquist)``: what a target costs as the
    noise-gain limit tightens, one design per limit in ``noise_gains``
    (a limit the target does not reach gives the unlimited design).

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> from imgmtf.restore.report import tradeoff
    >>> gains, mtf = tradeoff(Sensor(), 0.4, [1.1, 1.2, 10.0])
    >>> [round(float(g), 2) for g in gains], [round(float(m), 3) for m in mtf]
    ([1.1, 1.2, 1.35], [0.308, 0.352, 0.398])
    """
    from .design import design_filter
    designs = [design_filter(sensor, target_nyquist, max_noise_gain=g, kernel_size=kernel_size)
               for g in noise_gains]
    return (np.array([d.noise_gain for d in designs]),
            np.array([float(np.abs(d.system_transfer(0.5, direction) * d.axis_transfer(0.5, direction)))
                      for d in designs]))


def _axis_figures(restoration: RestorationFilter, direction: str) -> AxisFigures:
    curves = axis_curves(restoration, direction, np.linspace(0.0, 0.5, 501))
    _, at_half, after_half = edge_responses(restoration, direction, np.array([-0.5, 0.5]))
    x, _, after = edge_responses(restoration, direction)
    step = (x > 0).astype(float)
    far = np.abs(x) >= RINGING_FROM_PX
    return AxisFigures(
        direction,
        system_mtf_nyquist=float(curves["system"][-1]),
        designed_mtf_nyquist=restoration.target_nyquist,
        achieved_mtf_nyquist=float(curves["restored"][-1]),
        peak_mtf_below_nyquist=float(curves["restored"].max()),
        rer_before=float(at_half[1] - at_half[0]),
        rer_after=float(after_half[1] - after_half[0]),
        overshoot_pct=100 * max(float(after.max()) - 1.0, 0.0),
        undershoot_pct=100 * max(-float(after.min()), 0.0),
        ringing_pct=100 * float(np.abs(after - step)[far].max()) if far.any() else 0.0,
    )
