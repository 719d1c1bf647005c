"""The fitted model's MTF along a direction and its delta-method band:
the transfer of the sensor at the fitted coordinates and of its copies
with one coordinate stepped, and the band the covariance gives them."""
from __future__ import annotations

from statistics import NormalDist
from typing import TYPE_CHECKING

import numpy as np

from ...metrics import first_crossing
from ...sensor.model import Sensor

if TYPE_CHECKING:
    from .model import Model


def band_sensors(model: Model, u: np.ndarray) -> tuple[Sensor, list[tuple[float, Sensor]]]:
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


def model_mtf_band(model: Model, u: np.ndarray, covariance: np.ndarray, f: np.ndarray, angle_deg: float,
              gsd: float, confidence: float, sensors: tuple[Sensor, list[tuple[float, Sensor]]] | None = None):
    """The model's MTF at ``f`` along ``angle_deg`` and its delta-method
    band; ``sensors`` (:func:`band_sensors` of ``model`` and ``u``) when
    several angles are asked for."""
    sensor, steps = band_sensors(model, u) if sensors is None else sensors
    value = np.abs(sensor.normal_transfer(f, angle_deg, gsd))
    n = model.n_free
    if n == 0:
        return value, value, value
    grads = [(np.abs(shifted.normal_transfer(f, angle_deg, gsd)) - value) / h for h, shifted in steps]
    g = np.stack(grads, axis=-1)
    se = np.sqrt(np.maximum(np.einsum("...i,ij,...j->...", g, covariance[:n, :n], g), 0.0))
    z = NormalDist().inv_cdf(0.5 + confidence / 2)
    return value, np.clip(value - z * se, 0.0, 1.0), np.clip(value + z * se, 0.0, 1.0)


def model_mtf50_band(model, u, covariance, angle_deg, gsd, confidence, sensors=None):
    f = np.linspace(0.0, 2.0, 4001)
    value, low, high = model_mtf_band(model, u, covariance, f, angle_deg, gsd, confidence, sensors)
    return first_crossing(f, value, 0.5), (first_crossing(f, low, 0.5), first_crossing(f, high, 0.5))
