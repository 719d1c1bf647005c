"""The fitted model's MTF along a direction and its delta-method band:
the transfer of the sensor at the fitted coordinates and of its copies
with one coordinate stepped, and the band the covariance gives them."""
from __future__ import annotations

import math
from collections.abc import Sequence
from statistics import NormalDist
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

from ...metrics import first_crossing
from ...sensor.model import Sensor, check_angle


class FittedModel(Protocol):
    """What a band differentiates: a fit's free coordinates (how many, their
    bounds) and the sensor at them (:class:`.model.Model`, the bars' model)."""

    @property
    def n_free(self) -> int: ...

    def bounds(self) -> tuple[np.ndarray, np.ndarray]: ...

    def sensor(self, u: np.ndarray) -> Sensor: ...


def band_sensors(model: FittedModel, u: np.ndarray) -> tuple[Sensor, list[tuple[float, Sensor]]]:
    """The sensor at ``u`` and, for each free parameter, its step and the
    sensor with it stepped: what :func:`model_mtf_band` differentiates,
    the same at every angle (made once for a scene's thousands of edges,
    each made again per edge had cost a dense chart's scene fit a tenth
    of its time)."""
    n = model.n_free
    upper = model.bounds()[1] if n else np.zeros(0)
    steps = []
    for k in range(n):
        h = 1e-4 * max(u[k], 0.05 * upper[k] ** 0.5)
        h = -h if u[k] + h > upper[k] else h
        shifted = u.copy()
        shifted[k] += h
        steps.append((h, model.sensor(shifted)))
    return model.sensor(u), steps


def model_mtf_band(model: FittedModel, u: np.ndarray, covariance: np.ndarray, f: np.ndarray, angle_deg: float,
              gsd: float, confidence: float, sensors: tuple[Sensor, list[tuple[float, Sensor]]] | None = None):
    """The model's MTF at ``f`` along ``angle_deg`` and its delta-method
    band; ``sensors`` (:func:`band_sensors` of ``model`` and ``u``) when
    several angles are asked for."""
    value, gradients = _mtf_and_gradients(model, u, f, angle_deg, gsd, sensors)
    return delta_band(value, gradients, covariance, confidence)


def _mtf_and_gradients(model: FittedModel, u: np.ndarray, f: np.ndarray, angle_deg: float, gsd: float,
                       sensors: tuple[Sensor, list[tuple[float, Sensor]]] | None):
    """The model's MTF at ``f`` along ``angle_deg`` and its derivatives in
    the free coordinates (by forward steps; stacked on a last axis, None
    without a free coordinate)."""
    sensor, steps = band_sensors(model, u) if sensors is None else sensors
    n = model.n_free
    value, *stepped = normal_mtfs([sensor] + [shifted for _, shifted in steps[:n]], f, angle_deg, gsd)
    if n == 0:
        return value, None
    return value, np.stack([(mtf - value) / h for (h, _), mtf in zip(steps, stepped)], axis=-1)


def delta_band(value: np.ndarray, gradients: np.ndarray | None, covariance: np.ndarray, confidence: float, *,
               each_alone: bool = False):
    """An MTF ``value``, its delta-method band's lower and upper bounds
    (clipped to [0, 1]) from its ``gradients`` (on a last axis; None
    without a free coordinate) and their ``covariance``; ``each_alone``:
    each value's quadratic form made by itself, as for one value (a
    batched einsum may sum in another order: an edge's band the same bit
    for bit whatever the edges beside it)."""
    if gradients is None:
        return value, value, value
    n = gradients.shape[-1]
    c = covariance[:n, :n]
    forms = [np.einsum("...i,ij,...j->...", g, c, g) for g in gradients] if each_alone else \
        np.einsum("...i,ij,...j->...", gradients, c, gradients)
    se = np.sqrt(np.maximum(forms, 0.0))
    z = NormalDist().inv_cdf(0.5 + confidence / 2)
    return value, np.clip(value - z * se, 0.0, 1.0), np.clip(value + z * se, 0.0, 1.0)


#: the frequencies (cy/px) a model's MTF50 is read on: 4001 to 2 cy/px
MTF50_GRID_CY_PX = np.linspace(0.0, 2.0, 4001)
#: Nyquist's place on that grid (0.5 cy/px exactly)
NYQUIST_INDEX = 1000
#: how many of its frequencies are tried first: to Nyquist, below which a sampled
#: system's MTF50 usually lies (its MTF at Nyquist under a half); the others only
#: when a curve has not crossed 0.5 there
MTF50_FIRST = NYQUIST_INDEX + 1


def model_nyquist_mtf50_bands(model: FittedModel, u: np.ndarray, covariance: np.ndarray, angle_deg: float, gsd: float,
                              confidence: float, sensors: tuple[Sensor, list[tuple[float, Sensor]]] | None = None):
    """The model's MTF at Nyquist along ``angle_deg`` with its band, and its
    MTF50 (cy/px) with its interval: where its MTF and the band's bounds
    first fall to 0.5 on :data:`MTF50_GRID_CY_PX`; the numbers of
    :func:`model_mtf_band` at 0.5 cy/px and of
    :func:`imgmtf.metrics.first_crossing` of its curves on the whole grid,
    bit for bit, in a quarter of the transfers.  The curves are made on the
    grid's first :data:`MTF50_FIRST` frequencies, and on all of it only
    when one has not crossed 0.5 there (each frequency's value is its own,
    and a first crossing among the first frequencies is the whole curve's).

    Returns
    -------
    nyquist : tuple of float
        The MTF at 0.5 cy/px, its band's lower and upper bounds.
    mtf50 : float
        The MTF50, cy/px (NaN where the MTF stays above 0.5 to 2 cy/px).
    interval : tuple of float
        Where the band's lower and upper bounds fall to 0.5, cy/px.

    Examples
    --------
    >>> import imgmtf as im
    >>> from imgmtf.estimate.fit.data import edge_data
    >>> from imgmtf.estimate.fit.model import Model, initial_stages
    >>> edges = [im.measure_edge(im.render(im.Sensor(), im.Target("edge", a), 60).image) for a in (5.0, 84.0)]
    >>> model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0),
    ...               [edge_data(e, k, None) for k, e in enumerate(edges)])
    >>> u = model.initial_vector()[: model.n_free]
    >>> (value, low, high), mtf50, (below, above) = model_nyquist_mtf50_bands(
    ...     model, u, np.eye(model.n_free) * 1e-4, 0.0, 1.0, 0.95)
    >>> bool(low < value < high), bool(below < mtf50 < above)
    (True, True)
    """
    for size in (MTF50_FIRST, MTF50_GRID_CY_PX.size):
        f = MTF50_GRID_CY_PX[:size]
        value, gradients = _mtf_and_gradients(model, u, f, angle_deg, gsd, sensors)
        curves = delta_band(value, gradients, covariance, confidence)
        mtf50, low, high = (first_crossing(f, curve, 0.5) for curve in curves)
        if not math.isnan(mtf50 + low + high):
            break
    # one frequency's band formed alone (a batched quadratic form may sum in another order)
    nyquist = delta_band(value[NYQUIST_INDEX], None if gradients is None else gradients[NYQUIST_INDEX], covariance,
                    confidence)
    return nyquist, mtf50, (low, high)


def normal_mtfs(sensors: Sequence[Sensor], f_cy_px: ArrayLike, angle_deg: float, gsd_m: float) -> list[np.ndarray]:
    """Each sensor's MTF along the normal of an edge tilted ``angle_deg``
    at ``f_cy_px`` cy/px of ``gsd_m`` m: ``np.abs(sensor.normal_transfer(f,
    angle_deg, gsd_m))``, bit for bit, with the frequencies formed once and
    a stage several sensors share (a stepped sensor's unstepped stages)
    computed once (:func:`sensor_transfers`).

    Examples
    --------
    >>> from imgmtf.sensor.stages import Detector, GaussianOptics
    >>> optics = GaussianOptics(0.4, 0.4)
    >>> sensors = [Sensor(1.0, [optics, Detector(1.0, 1.0)]), Sensor(1.0, [optics, Detector(1.1, 1.0)])]
    >>> f = np.linspace(0.0, 1.0, 5)
    >>> mtfs = normal_mtfs(sensors, f, 30.0, 1.0)
    >>> all(np.array_equal(m, np.abs(s.normal_transfer(f, 30.0, 1.0))) for s, m in zip(sensors, mtfs))
    True
    """
    if not sensors:
        return []
    gsd = sensors[0]._gsd(gsd_m)
    a = math.radians(check_angle(angle_deg))
    f = np.asarray(f_cy_px, float) / gsd
    return [np.abs(t) for t in sensor_transfers(sensors, f * math.cos(a), f * math.sin(a))]


def sensor_transfers(sensors: Sequence[Sensor], fx: ArrayLike, fy: ArrayLike) -> list[np.ndarray]:
    """Each sensor's :meth:`imgmtf.Sensor.transfer` at (``fx``, ``fy``)
    cy/m, bit for bit (the stages' product in their order, from ones), a
    stage object several sensors hold computed once for them all.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Detector, GaussianOptics
    >>> optics = GaussianOptics(0.4, 0.4)
    >>> sensors = [Sensor(1.0, [optics, Detector(1.0, 1.0)]), Sensor(1.0, [optics, Detector(0.9, 1.0)])]
    >>> f = np.array([0.1, 0.5])
    >>> [bool(np.array_equal(t, s.transfer(f, 0.0))) for s, t in zip(sensors, sensor_transfers(sensors, f, 0.0))]
    [True, True]
    """
    shape = np.broadcast(np.asarray(fx), np.asarray(fy)).shape
    made: dict[tuple[int, float], np.ndarray] = {}
    out = []
    for sensor in sensors:
        value = np.ones(shape)
        for stage in sensor.stages:
            # keyed by the object: the sensors, alive throughout, hold it (equal stages of other objects are
            # computed again, as they would be)
            key = (id(stage), sensor.gsd_m)
            if key not in made:
                made[key] = stage.transfer(fx, fy, sensor.gsd_m)
            value = value * made[key]
        out.append(value)
    return out
